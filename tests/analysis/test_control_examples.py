"""The control-design examples (``--quick``): the tension loop's margins and poles from
``winder.linearise`` checked in closed loop against the nonlinear line, and the MPC on
``winder.casadi_model`` against the built-in controller."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _run(name: str, tmp_path: Path) -> str:
    proc = subprocess.run([sys.executable, str(EXAMPLES / name), "--quick", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def test_tension_loop_design(tmp_path) -> None:
    """The same closed-loop poles at the full, half and empty parent (measured to 1.3e-12
    rad/s), the loop closed on the plant has the poles of the tension-controlled machine
    (measured 1.3e-5 … 1.2e-4 relative: the two operating points differ by the torque's
    feed-forward), positive margins, and the linear closed loop's set-point step equals
    the nonlinear line's (measured 1.3e-4 N of 24.8 N)."""
    out = _run("tension_loop_design.py", tmp_path)
    spread = float(re.search(r"equal at every diameter to (\S+) rad/s", out).group(1))
    assert spread < 1e-9
    agree = [float(x) for x in re.findall(r"tension-controlled machine's: (\S+)\)", out)]
    assert len(agree) == 3 and max(agree) < 1.5e-3
    margins = [float(x) for x in re.findall(r"phase margin (\S+)°", out)]
    assert len(margins) == 3 and min(margins) > 45.0
    err, peak = (float(x) for x in re.search(
        r"max difference (\S+) N of a (\S+) N response", out).groups())
    assert peak > 20.0 and err < 2e-3
    import matplotlib.image as mpimg

    img = mpimg.imread(tmp_path / "tension_loop_design.png")
    assert img.shape[:2] == (1000, 800) and np.ptp(img[..., :3]) > 0.5


def test_tension_mpc_holds_the_set_point(tmp_path) -> None:
    """The MPC on ``casadi_model`` holds the span tension on the first 2 s of the drums'
    ramp, in closed loop against the nonlinear line: after 0.5 s its error is below
    2e-4 N (measured max 1.3e-5 N; the built-in controller's 0.57 N, its start-up
    transient)."""
    out = _run("tension_mpc.py", tmp_path)
    got = {name: (float(a), float(b)) for name, a, b in re.findall(
        r"^(MPC|built-in controller): tension error over the ramp .*: max (\S+) N, "
        r"rms (\S+) N$", out, re.M)}
    assert got["MPC"][0] < 2e-4 and got["built-in controller"][0] > got["MPC"][0]
    assert (tmp_path / "tension_mpc.png").stat().st_size > 10_000
