"""Scenes of parts in `winder run --plots`, the run summary's static balance, a scene with
no static balance, and the sweep summary per nip (issue #14)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import MODELS, without_build_lines

import winder
import winder.plots.figures as _plots
from winder.analysis.sweep_summary import (
    BAND_COLUMNS,
    SCALAR_COLUMNS,
    default_band_edges,
    end_radius,
    nip_columns,
    summarise,
)
from winder.cli import main
from winder.plots.machine import machine_figures
from winder.plots.run import run_figures
from winder.solve.equilibrium import EquilibriumError

TWO_DRUM = MODELS / "two_drum_winder.toml"
NIPS = ("front_nip", "rear_nip", "rider_nip")


@pytest.fixture(scope="module")
def two_drum() -> winder.Scene:
    return winder.load_scene(TWO_DRUM)


@pytest.fixture(scope="module")
def short_run(two_drum: winder.Scene) -> winder.Result:
    return winder.simulate(two_drum, t_end=1.0, output_step=0.005)


def _drawn(monkeypatch: pytest.MonkeyPatch) -> dict[str, list[tuple[str, dict]]]:
    """Capture every figure's axes before it is saved: file name → [(title, {label:
    (x, y)})]."""
    drawn: dict[str, list[tuple[str, dict]]] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        drawn[Path(path).name] = [
            (a.get_title(), {ln.get_label(): (np.asarray(ln.get_xdata(), float),
                                              np.asarray(ln.get_ydata(), float))
                             for ln in a.get_lines() if not ln.get_label().startswith("_")})
            for a in fig.axes]
        drawn[Path(path).name + ":ylim"] = [(a.get_ylim(), ()) for a in fig.axes]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    return drawn


# ---- figures --------------------------------------------------------------------------------
def test_parts_figures_draw_the_channels(short_run, two_drum, tmp_path, monkeypatch) -> None:
    drawn = _drawn(monkeypatch)
    paths = run_figures(short_run, tmp_path, scene=two_drum)
    stem = "two_drum_winder"
    names = [f"{stem}_{k}.png" for k in ("drums", "rolls", "nip_forces", "positions", "slip")]
    assert [p.name for p in paths] == names
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)
    assert len(drawn) == 2 * len(names)
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)
    r, t = short_run, short_run.t

    def same(line: tuple[np.ndarray, np.ndarray], y: np.ndarray) -> None:
        np.testing.assert_array_equal(line[0], t)
        np.testing.assert_allclose(line[1], y, rtol=1e-15, atol=0)  # the data itself

    def mean(y: np.ndarray) -> np.ndarray:  # centred: 101 samples at 5 ms, whole ones only
        return np.convolve(y, np.full(101, 1 / 101), mode="valid")

    MEAN = "centred mean over 0.505 s"

    (title, speeds), *torques = drawn[names[0]]
    assert "[rad/s]" in title and len(torques) == 2
    for d, (title, lines) in zip(("front", "rear"), torques, strict=True):
        assert title == f"drum {d}: drive torque [kN·m]"
        same(speeds[f"drum {d}"], r[f"{d}_speed"])
        same(lines[f"drum {d}"], r[f"{d}_torque"] / 1e3)
        np.testing.assert_allclose(lines[MEAN][1], mean(r[f"{d}_torque"]) / 1e3,
                                   rtol=1e-12)  # measured 1e-16
        np.testing.assert_array_equal(lines[MEAN][0], t[50:-50])
    (_, speeds), (_, radii) = drawn[names[1]]
    same(speeds["roll set"], r["set_speed"])
    same(speeds["rider rider"], r["rider_speed"])
    same(radii["roll set"], r["set_radius"])
    *rows, (close_title, closeup) = drawn[names[2]]
    labels = {"front_nip": "nip front_nip (front–set)", "rear_nip": "nip rear_nip (rear–set)",
              "rider_nip": "nip rider_nip (set–rider)"}
    assert "[kN]" in rows[0][0] and "[kN]" in close_title
    for (title, lines), (n, lab) in zip(rows, labels.items(), strict=True):
        f = r[f"{n}_normal_force"]
        assert title.endswith(f"{lab}: {np.mean(f <= 0):.1%} of samples open")
        same(lines[lab], f / 1e3)
        np.testing.assert_allclose(lines[MEAN][1], mean(f) / 1e3, rtol=1e-12)
    assert set(closeup) == set(labels.values())
    top = max(r[f"{n}_normal_force"].max() for n in labels) / 1e3
    for (lo, hi), _ in drawn[names[2] + ":ylim"][:3]:  # one scale with 0 and every nip
        assert lo <= 0.0 and top <= hi <= 1.1 * top
    coords = [(title, lines) for title, lines in drawn[names[3]] if lines]  # no colour bars
    assert [next(iter(lines)) for _, lines in coords] == [
        "set x", "set z", "set z − mean", "rider z", "rider z − mean"]
    for _, lines in coords:
        (label, line), = lines.items()
        body, c, *bounce = label.split()
        if bounce:  # z less its centred mean, where the whole window lies in the run
            z = r[f"{body}_z"]
            np.testing.assert_array_equal(line[0], t[50:-50])
            np.testing.assert_allclose(line[1], 1e3 * (z[50:-50] - mean(z)), rtol=0,
                                       atol=1e-12)  # [mm]: measured 1e-16
            assert np.ptp(line[1]) > 0  # the start's bounce is seen, not flattened
        else:
            same(line, r[f"{body}_{c}"])
    slips = drawn[names[4]]
    for (title, lines), (n, lab) in zip(slips, labels.items(), strict=True):
        assert title.endswith(lab) and list(lines) == [lab]
        same(lines[lab], r[f"{n}_slip_velocity"])


def test_parts_figures_find_their_scene_in_the_result(short_run, tmp_path) -> None:
    """Without ``scene``, the scene stored in the result names the parts; a hostile scene
    name never leaves the directory."""
    res = winder.Result(dict(short_run) , dict(short_run.meta, scene="../../x\0y"))
    out = tmp_path / "plots"
    paths = run_figures(res, out)
    assert len(paths) == 5 and [p.parent for p in paths] == [out] * 5
    assert sorted(tmp_path.rglob("*")) == [out, *sorted(paths)]


# ---- run summary: static balance; a scene with none -----------------------------------------
def test_run_prints_the_static_balance(tmp_path, capsys) -> None:
    out = tmp_path / "r.npz"
    plots = tmp_path / "plots"  # a run shorter than the 0.5 s windows of the means
    assert main(["run", str(TWO_DRUM), "--out", str(out), "--t-end", "0.05", "--plots",
                 str(plots)]) == 0
    meta = winder.load_result(out).meta
    text = capsys.readouterr().out
    figures = sorted(plots.iterdir())
    assert len(figures) == 5 and all(f"  figure {p}" in text for p in figures)
    assert (f"initial static balance: residual {meta['static_residual']:.1e} N of "
            f"{meta['static_scale']:.1e} N") in text
    # the balance carries the set, rider and rider load: scale ≥ the set's core weight
    assert meta["static_scale"] > 40 * 9.81
    assert meta["static_residual"] <= 1e-6 * meta["static_scale"]


NO_BALANCE = """
[scene]
name = "no_balance"
duration = 1.0
output_step = 0.01
gravity = 9.81

[effects]
variable_mass = true
web_momentum = true
web_tension = true
gravity = true
contact = true
slip_relaxation = true

[paper]
density = 650.0
caliper = 70e-6

[[drum]]
name = "drum"
radius = 0.5
inertia = 600.0
mass = 3000.0
centre = [0.0, 0.0]
drive = { kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }

[[roll]]
name = "set"
centre = [0.0, 0.55]
free = ["x", "z"]
core_radius = 0.05
core_mass = 40.0
core_inertia = 0.1
width = 5.0
initial_radius = 0.05

[[nip]]
name = "nip"
a = "drum"
b = "set"
contact = { law = "linear", stiffness = 2.5e7, damping = 1.5e4 }

[web]
entry_nip = "nip"
tension = 1000.0
"""


def test_no_static_balance_names_the_body(tmp_path, capsys) -> None:
    """A light roll free in x and z on one drum, pulled along the tangent by a web tension
    of 1000 N above its weight (core only, 40 kg · 9.81 = 392 N): no position on the drum
    balances it (m g sin φ = T has no solution); the residual left is the tension."""
    path = tmp_path / "no_balance.toml"
    path.write_text(NO_BALANCE)
    with pytest.raises(EquilibriumError, match=r"body 'set' along x: force residual -1e\+03 N") \
            as info:
        winder.simulate(path)
    assert isinstance(info.value, ValueError)
    out = tmp_path / "r.npz"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    err = without_build_lines(err)
    assert err.startswith(f"winder: error: {path}: no static balance for body 'set'")
    assert "Traceback" not in err and not out.exists()


# ---- sweep summary of a scene of parts ------------------------------------------------------
def _synthetic(two_drum: winder.Scene) -> winder.Result:
    """Two-drum channels with known openings: radius 0.05 → 0.25 m over 4 s at 1 kHz, the
    front nip open in [1, 1.5) s, the rider nip open in [1.25, 2) s, the rear never."""
    t = np.arange(4000) / 1000.0
    r = 0.05 + 0.05 * t
    f = {"front_nip": 3e3 + 1e3 * np.sin(40 * t), "rear_nip": 5e3 + 2e3 * np.cos(30 * t),
         "rider_nip": 8e3 + 500 * np.sin(70 * t)}
    f["front_nip"][(t >= 1.0) & (t < 1.5)] = 0.0
    f["rider_nip"][(t >= 1.25) & (t < 2.0)] = 0.0
    ch = {"t": t, "set_radius": r}
    for n, fn in f.items():
        ch[f"{n}_normal_force"] = fn
        ch[f"{n}_penetration"] = fn / 2.5e7
    return winder.Result(ch, {"scene_dict": two_drum.to_dict(), "events": 4.0,
                              "effects": list(two_drum.effects.enabled())})


def test_sweep_summary_per_nip_against_direct_values(two_drum) -> None:
    res = _synthetic(two_drum)
    r = res["set_radius"]
    edges = np.array([0.05, 0.1, 0.15, 0.2, 0.25])
    s = summarise(res, edges, window=0.5, threshold=0.5)
    scalars, bands = nip_columns(NIPS)
    assert set(s) == {*SCALAR_COLUMNS, *BAND_COLUMNS, *scalars, *bands}
    band = [(r >= lo) & (r < hi) for lo, hi in zip(edges[:-1], edges[1:], strict=True)]
    for n in NIPS:
        fn = res[f"{n}_normal_force"]
        assert s[f"{n}.nip_force_peak"] == pytest.approx([fn[b].max() for b in band],
                                                         rel=1e-15)
        assert s[f"{n}.nip_force_rms"] == pytest.approx(
            [math.sqrt(np.mean(fn[b] ** 2)) for b in band], rel=1e-12)  # measured 2e-16
        assert s[f"{n}.liftoff_share"] == pytest.approx(np.mean(fn <= 0), abs=0)
    # the front nip opens at t = 1 s (r = 0.1 m), last open sample t = 1.499 s
    assert s["front_nip.liftoff_radius_first"] == pytest.approx(0.1, rel=1e-12)
    assert s["front_nip.liftoff_radius_last"] == pytest.approx(0.05 + 0.05 * 1.499,
                                                               rel=1e-12)
    assert math.isnan(s["rear_nip.liftoff_radius_first"])
    # all nips: in the air while any nip is open, t in [1, 2): 1000 of 4000 samples
    assert s["liftoff_share"] == pytest.approx(0.25, abs=1e-15)
    assert s["liftoff_share_band"] == pytest.approx([0.0, 1.0, 0.0, 0.0], abs=1e-15)
    assert s["liftoff_radius_first"] == pytest.approx(0.1, rel=1e-12)
    assert s["liftoff_radius_last"] == pytest.approx(0.05 + 0.05 * 1.999, rel=1e-12)
    for c in ("nip_force_peak", "nip_force_rms", "bounce_amplitude", "vibration_level"):
        assert s[c] == pytest.approx(np.max([s[f"{n}.{c}"] for n in NIPS], axis=0),
                                     rel=1e-15)
    # the bounce of a window: half peak-to-peak penetration; rear nip, first window
    pw = res["rear_nip_penetration"][:1000].reshape(2, 500)
    assert s["rear_nip.bounce_amplitude"][0] == pytest.approx(
        np.max((pw.max(axis=1) - pw.min(axis=1)) / 2), rel=1e-14)
    # vibration starts in the window t = 1.0 … 1.5 s: the rider nip swings 8.5 kN → 0
    # (level ≈ 1.06); the front nip's sine swings ±1/3 and a window all open has no mean
    # force, no level: the front nip never reaches 0.5
    assert s["vibration_start_radius"] == pytest.approx(np.mean(r[1000:1500]), rel=1e-12)
    assert s["rider_nip.vibration_start_radius"] == s["vibration_start_radius"]
    assert math.isnan(s["front_nip.vibration_start_radius"])
    fw = res["front_nip_normal_force"][:1000].reshape(2, 500)  # band 0: windows 0 and 1
    level = np.max((fw.max(axis=1) - fw.min(axis=1)) / 2 / fw.mean(axis=1))
    assert s["front_nip.vibration_level"][0] == pytest.approx(level, rel=1e-14)
    assert 0.3 < level < 1 / 3  # the sampled sine: ±1 kN on 3 kN
    assert s["contact_events"] == 4.0 and s["final_radius"] == r[-1]


def test_sweep_summary_legacy_columns_unchanged() -> None:
    """A single-drum result gets no per-nip columns; its columns are those of one nip."""
    scene = winder.load_scene(MODELS / "paper_winding.toml")
    res = winder.simulate(scene, t_end=2.0)
    edges = default_band_edges([scene], 2.0, 3)
    s = summarise(res, edges)
    assert set(s) == {*SCALAR_COLUMNS, *BAND_COLUMNS}
    fn, r = res["normal_force"], res["radius"]
    idx = np.clip(np.searchsorted(edges, r, side="right") - 1, 0, 2)
    peak = [fn[idx == i].max() if np.any(idx == i) else math.nan for i in range(3)]
    np.testing.assert_array_equal(s["nip_force_peak"], peak)
    assert s["liftoff_share"] == np.mean(fn <= 0)


def test_end_radius_of_a_parts_scene(two_drum) -> None:
    """r² = r₀² + h v T/π with the set's r₀ = 0.05 m, h = 70 µm, v = 41.7 m/s: the
    scene's comment gives r = 0.6 m at 414.5 s less the ramp's 59.6 s · 20.85 m/s deficit."""
    assert end_radius(two_drum, 100.0) == pytest.approx(
        math.sqrt(0.05**2 + 70e-6 * 41.7 * 100.0 / math.pi), rel=1e-15)
    edges = default_band_edges([two_drum], 100.0, 4)
    assert edges[0] == 0.05 and len(edges) == 5


def test_closeup_shows_the_first_opening(short_run, two_drum, tmp_path, monkeypatch) -> None:
    """The close-up row is the window −0.3 … +1 s around the first sample with a nip open
    (here the rear nip, forced open from t = 0.5 s; the rider nip from 0.6 s)."""
    t = short_run.t
    rear = np.where(t >= 0.5, 0.0, short_run["rear_nip_normal_force"])
    rider = np.where(t >= 0.6, 0.0, short_run["rider_nip_normal_force"])
    res = winder.Result(dict(short_run) | {"rear_nip_normal_force": rear,
                                           "rider_nip_normal_force": rider}, short_run.meta)
    drawn = _drawn(monkeypatch)
    machine_figures(res, tmp_path, scene=two_drum)
    *_, (title, lines) = drawn["two_drum_winder_nip_forces.png"]
    assert title.startswith("close-up: first opening, nip rear_nip (rear–set) at t ≈ 0.50 s")
    w = (t >= 0.2) & (t <= 1.5)
    x, y = lines["nip rear_nip (rear–set)"]
    np.testing.assert_array_equal(x, t[w])
    np.testing.assert_array_equal(y, rear[w] / 1e3)


def test_axis_labels_come_from_the_result_units(short_run, two_drum, tmp_path,
                                                monkeypatch) -> None:
    """The axes are labelled with the units the result carries (``Result.units``, with
    ``k``/``m`` for values drawn in thousands/thousandths): the run's own SI units; other
    unit texts give other labels; a result without units gets labels without brackets."""
    labels: dict[str, list[tuple[str, str]]] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        labels[Path(path).name] = [(a.get_ylabel(), a.get_xlabel()) for a in fig.axes]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    machine_figures(short_run, tmp_path, scene=two_drum)
    stem = "two_drum_winder"
    drums, nips = labels[f"{stem}_drums.png"], labels[f"{stem}_nip_forces.png"]
    assert drums[0][0] == "speed Ω [rad/s]" and drums[1][0] == "torque [kN·m]"
    assert drums[-1][1] == "t [s]" and nips[0][0] == "F_n [kN]"
    assert labels[f"{stem}_slip.png"][0][0] == "slip [m/s]"
    assert [y for y, _ in labels[f"{stem}_positions.png"] if y][:3] == [
        "x [m]", "z [m]", "bounce [mm]"]
    assert labels[f"{stem}_rolls.png"][1][0] == "radius r [m]"
    other = winder.Result(dict(short_run), short_run.meta,
                          units={**short_run.units, "front_speed": "rev/min", "t": "min",
                                 "front_torque": "lbf·ft"})
    machine_figures(other, tmp_path, scene=two_drum)
    drums = labels[f"{stem}_drums.png"]
    assert drums[0][0] == "speed Ω [rev/min]" and drums[1][0] == "torque [klbf·ft]"
    assert drums[-1][1] == "t [min]"
    labels.clear()
    machine_figures(winder.Result(dict(short_run), short_run.meta), tmp_path,
                           scene=two_drum)
    assert labels[f"{stem}_drums.png"][0][0] == "speed Ω"
    assert not any("[" in y + x for rows in labels.values() for y, x in rows)
