"""The examples that drive the native FMU through FMPy (no pythonfmu): the PI drum-speed
loop of the single-drum scene, the two-drum winder's two loops, the winder line's tension
loop."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import winder

fmpy = pytest.importorskip("fmpy", reason="FMPy is installed with winder[fmu]")


def test_closed_loop_example_writes_its_plot(tmp_path) -> None:
    """examples/speed_control_fmu.py: the PI loop holds the web speed on the ramp."""
    example = Path(__file__).resolve().parents[2] / "examples" / "speed_control_fmu.py"
    proc = subprocess.run([sys.executable, str(example), "--t-end", "8", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    err = float(proc.stdout.split("web-speed error after 2 s: max ")[1].split()[0])
    assert err < 5e-3  # m/s, on the 0.5 m/s² ramp
    # the figure (8 × 8 in at 100 dpi) draws the drum surface speed (blue, C0) on the
    # ramp min(0.5 t, 20) in the top axes: a straight rising line, 0 → 4 m/s
    import matplotlib.image as mpimg

    img = np.round(255 * mpimg.imread(tmp_path / "speed_control_fmu.png")[..., :3])
    assert img.shape == (800, 800, 3)
    blue = np.all(np.abs(img[:270] - [0x1F, 0x77, 0xB4]) < 40, axis=-1)
    blue[:130, :260] = False  # the legend
    ys, xs = np.nonzero(blue)
    assert np.ptp(xs) > 500 and np.ptp(ys) > 150  # spans the axes
    assert np.corrcoef(xs, ys)[0, 1] < -0.99  # measured -0.99994


def test_two_drum_example_tracks_and_conserves_paper(tmp_path) -> None:
    """examples/two_drum_speed_control_fmu.py: a PI loop per torque input holds each
    drum on the 0.7 m/s² ramp, and the paper the set winds by its surface speed equals
    the paper its radius holds, π (r² − r_c²) / h (measured 3e-5 relative: the
    trapezoidal sum over 10 ms samples)."""
    example = Path(__file__).resolve().parents[2] / "examples" / "two_drum_speed_control_fmu.py"
    proc = subprocess.run([sys.executable, str(example), "--t-end", "8", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = proc.stdout
    for drum in ("front", "rear"):
        err = float(out.split(f"{drum}: web-speed error after 2 s: max ")[1].split()[0])
        assert err < 3e-2  # m/s (measured 6e-3 front, 9e-3 rear)
    line = out.split("paper wound: ")[1].split("\n")[0]
    by_speed, by_radius = float(line.split()[0]), float(line.split(", ")[1].split()[0])
    assert by_speed > 20.0  # m: 0.7 m/s² · (8 s)² / 2 = 22.4 m on the ramp
    assert by_radius == pytest.approx(by_speed, rel=3e-4)


def test_tension_control_example_equals_the_model_controller(tmp_path, models_dir) -> None:
    """examples/tension_control_fmu.py over 5 s: its controller, outside the FMU, is the
    law of the in-model controller (winder_line_small.toml, same gains by the same rule),
    so the span tension and the unwind torque equal those of winder.simulate of that
    scene (measured 1.1e-5 of T* and of the peak torque: the 2 ms zero-order hold and
    the sampled ∫e against the continuous law). The tension stays within 1.8 N of
    T* = 1000 N from the start (measured 1.80 N at 0.2 s, 0.013 N after 1 s)."""
    from winder.model.mass_law import paper_roll_mass

    example = Path(__file__).resolve().parents[2] / "examples" / "tension_control_fmu.py"
    proc = subprocess.run([sys.executable, str(example), "--t-end", "5", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "the parent did not run out" in proc.stdout
    log = np.load(tmp_path / "tension_control_fmu.npz")
    t = log["t"]
    assert t[-1] == pytest.approx(5.0, rel=1e-12) and len(t) == 2501
    ref = winder.simulate(winder.load_scene(models_dir / "winder_line_small.toml"),
                          t_end=5.0, output_step=0.002, method="DOPRI5", rtol=1e-8,
                          atol=1e-10)
    T_ref = np.interp(t, ref.t, ref["span_tension"])
    tau_ref = np.interp(t, ref.t, ref["parent_torque"])
    assert np.max(np.abs(log["span_tension"] - T_ref)) / 1000.0 < 1.5e-4
    assert np.max(np.abs(log["tau"] - tau_ref)) / np.max(np.abs(tau_ref)) < 1.5e-4
    assert np.max(np.abs(log["e"])) < 2.5  # N (measured 1.80)
    assert np.max(np.abs(log["e"][t >= 1.0])) < 0.1  # N (measured 0.013)
    # the example's J(r) (the paper-roll law) is the model's parent inertia
    J = paper_roll_mass(log["parent_radius"], 0.4, 3000.0, 300.0, np.pi * 650.0 * 5.0)[1]
    np.testing.assert_allclose(J, log["parent_inertia"], rtol=1e-13)
    assert (tmp_path / "tension_control_fmu.png").stat().st_size > 10_000
