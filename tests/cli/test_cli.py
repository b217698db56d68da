"""The command line: free spin closed form through the full CLI path, errors, atomicity."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np

import winder
from winder.cli import main


def test_free_spin_matches_closed_form_through_cli(tmp_path, models_dir, capsys) -> None:
    out = tmp_path / "free.csv"
    assert main(["run", str(models_dir / "free_spin.toml"), "--out", str(out)]) == 0
    # contact off: no free coordinate rests on a nip, no balance to report a residual of
    printed = capsys.readouterr().out
    assert "initial static balance: nothing to solve (no free coordinate rests on a nip" \
        in printed and "residual" not in printed
    meta = winder.load_result(out.with_suffix(".npz")).meta
    assert meta["static_residual"] == 0.0 and meta["static_scale"] == 0.0
    with open(out) as fh:
        header = fh.readline().strip().split(",")
    assert tuple(header[:len(winder.CHANNELS)]) == winder.CHANNELS
    res = winder.load_result(out)
    r, w, t, J = res["radius"], res["roll_speed"], res.t, res["inertia"]
    rc, h, L, rho, Jc, w0 = 0.075, 160e-6, 2.0, 800.0, 0.12, 200.0
    J0 = Jc
    k = 0.5 * rho * math.pi * L
    t_closed = 2 * math.pi / (h * J0 * w0) * ((Jc - k * rc**4) * (r - rc) + k * (r**5 - rc**5) / 5)
    assert r[-1] > 2.5 * rc  # a real growth: J grows by > 30×
    assert np.max(np.abs(t_closed - t)) / t[-1] < 1e-8
    assert np.max(np.abs(J * w - J0 * w0)) / (J0 * w0) < 1e-8


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "winder", *args], capture_output=True,
                          text=True, timeout=120)


def test_bad_scene_exits_nonzero_with_one_line(tmp_path: Path, models_dir: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text((models_dir / "free_spin.toml").read_text().replace(
        "caliper = 160e-6", "caliper = -1.0"))
    out = tmp_path / "res.csv"
    proc = _run("run", str(bad), "--out", str(out))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "[paper] caliper" in lines[0] and str(bad) in lines[0]
    assert not out.exists()


def test_failed_run_leaves_no_partial_file(tmp_path: Path, models_dir: Path) -> None:
    out = tmp_path / "res.csv"
    out.write_text("previous\n")
    # a tiny RHS budget trips the guard in the middle of the run
    scene = tmp_path / "guarded.toml"
    scene.write_text((models_dir / "free_spin.toml").read_text().replace(
        "[solver]", "[solver]\nmax_rhs = 50"))
    proc = _run("run", str(scene), "--out", str(out))
    assert proc.returncode == 2 and "max_rhs" in proc.stderr
    assert out.read_text() == "previous\n"  # untouched
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".res")] == []


def test_npz_roundtrip(tmp_path: Path, models_dir: Path) -> None:
    res = winder.simulate(winder.load_scene(models_dir / "free_spin.toml"), t_end=5.0)
    back = winder.load_result(res.to_npz(tmp_path / "r.npz"))
    assert list(back) == list(res)
    for name in res:
        np.testing.assert_array_equal(back[name], res[name])
    assert back.meta["method"] == res.meta["method"]


def _pixels(png: Path, hex_rgb: str, tol: int = 30) -> np.ndarray:
    """Boolean mask of the pixels of one colour in a PNG (decoded)."""
    import matplotlib.image as mpimg

    img = np.round(255 * mpimg.imread(png)[..., :3]).astype(int)
    rgb = np.array([int(hex_rgb[i:i + 2], 16) for i in (1, 3, 5)])
    return np.all(np.abs(img - rgb) < tol, axis=-1)


def test_free_spin_figure_draws_the_conserved_momentum(tmp_path, models_dir, capsys) -> None:
    """The Fig. 2 PNG of a free spin: 8 × 6 in at 110 dpi; the J ω line (green, C2) is flat
    over the whole axes width (J ω conserved to 1e-8, drawn on ±10 %), while the ω line
    (blue, C0) falls from left to right as paper is added."""
    out = tmp_path / "plots"
    assert main(["run", str(models_dir / "free_spin.toml"), "--out", str(tmp_path / "r.npz"),
                 "--t-end", "100", "--plots", str(out)]) == 0
    (png,) = out.iterdir()
    assert png.name == "free_spin_fig2_free_spin.png"
    green = _pixels(png, "#2ca02c")
    assert green.shape == (660, 880)
    rows = np.bincount(np.nonzero(green)[0], minlength=660)
    line = rows.argmax()
    assert rows[line - 1:line + 2].sum() > 600  # one row across the ~700 px of the axes
    blue = _pixels(png, "#1f77b4")
    ys, xs = np.nonzero(blue[:330])  # upper axes
    left, right = ys[xs < xs.min() + 20].mean(), ys[xs > xs.max() - 20].mean()
    assert right - left > 50  # ω(100 s) well below ω(0): the curve ends lower


def test_balance_line_reports_a_solved_balance(tmp_path, models_dir, capsys) -> None:
    """The paper scene's roll rests on the nip: its residual against its weight."""
    assert main(["run", str(models_dir / "paper_winding.toml"), "--out",
                 str(tmp_path / "p.npz"), "--t-end", "0.05"]) == 0
    meta = winder.load_result(tmp_path / "p.npz").meta
    assert meta["static_scale"] > 30 * 9.81  # the core's weight at least
    assert (f"initial static balance: residual {meta['static_residual']:.1e} N of "
            f"{meta['static_scale']:.1e} N") in capsys.readouterr().out


def test_run_help_lists_every_method_and_backend(capsys) -> None:
    """`winder run --help` names the scene's [solver] choices, ROS2 included."""
    from winder.scene import BACKENDS, METHODS

    assert main(["run", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "ROS2" in METHODS
    assert f"integrator ({', '.join(METHODS)};" in text
    assert " or ".join(BACKENDS) in text
