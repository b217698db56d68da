"""What the figures show: the drum-torque panel of Fig. 4 shows the whole range and its zoom
says what it clips; a nip has one colour in the run figures and the resonance map."""

from __future__ import annotations

from pathlib import Path

import matplotlib.colors as mcolors
import matplotlib.pyplot as plt
import numpy as np
import pytest
from conftest import MODELS

import winder
import winder.plots.figures as _plots
from winder.cli import main
from winder.plots.campbell import campbell_figure
from winder.plots.machine import machine_figures


def test_torque_panels_full_range_and_clipped_share() -> None:
    """A torque of ±10 N·m with 1 % of its samples spiking to +557 and −385 N·m (as the
    paper scene's impacts): the full panel holds both extremes, the zoom leaves out exactly
    the spikes and its title says so, with the full range."""
    t = np.linspace(0.0, 100.0, 20_001)
    torque = 10.0 * np.sin(2 * np.pi * t)
    spikes = np.arange(0, t.size, 100)  # 1 % of the samples, after t = 45 s too
    torque[spikes[::2]] = 557.0
    torque[spikes[1::2]] = -385.0
    share = spikes.size / t.size
    fig, (full, zoom) = plt.subplots(2, 1)
    try:
        _plots._torque_panels(full, zoom, t, torque, "N·m")
        lo, hi = full.get_ylim()
        assert lo <= -385.0 and hi >= 557.0
        zlo, zhi = zoom.get_ylim()
        assert -40.0 < zlo < -10.0 and 10.0 < zhi < 40.0  # the ±10 N·m signal, padded
        outside = np.mean((torque < zlo) | (torque > zhi))
        assert outside == pytest.approx(share, abs=1e-12)
        assert f"{share:.2%} of samples lie outside" in zoom.get_title()
        assert "-385 to 557 N·m" in zoom.get_title() and "-385 to 557 N·m" in full.get_title()
        assert full.get_ylabel() == zoom.get_ylabel() == "drum torque [N·m]"
    finally:
        plt.close(fig)


def _colours(monkeypatch: pytest.MonkeyPatch) -> dict[str, list[tuple[str, str, str]]]:
    """Capture, per saved figure, (axes title, artist label, colour as hex) of every line
    and filled area."""
    seen: dict[str, list[tuple[str, str, str]]] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        rows = []
        for a in fig.axes:
            for art in [*a.get_lines(), *a.collections]:
                label = art.get_label()
                if label.startswith("_"):
                    continue
                c = art.get_color() if hasattr(art, "get_xdata") else art.get_facecolor()[0]
                rows.append((a.get_title(), label, mcolors.to_hex(c)))
        seen[Path(path).name] = rows
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    return seen


def test_a_nip_has_one_colour_in_run_figures_and_resonance_map(tmp_path, monkeypatch):
    scene = winder.load_scene(MODELS / "two_drum_winder.toml")
    short = winder.simulate(scene, t_end=0.5, output_step=0.005)
    seen = _colours(monkeypatch)
    machine_figures(short, tmp_path, scene=scene)
    # the resonance map of the command line, its envelope from the same short run
    import winder.solve.simulate as sim

    monkeypatch.setattr(sim, "simulate", lambda *a, **k: short)
    assert main(["modes", str(MODELS / "two_drum_winder.toml"), "--points", "3",
                 "--plot", str(tmp_path / "modes.png")]) == 0
    want = {n: mcolors.to_hex(c) for n, c in _plots.nip_colours(scene).items()}
    assert len(set(want.values())) == len(want)  # three nips, three colours
    found: dict[str, set[str]] = {n: set() for n in want}
    for figure, rows in seen.items():
        for _, label, colour in rows:
            for n in want:  # run figures: "nip NAME (a–b)"; the map's envelope: "NAME"
                if label == n or label.startswith(f"nip {n} "):
                    found[n].add((figure, colour))
    for n, hits in found.items():
        figures = {f for f, _ in hits}
        assert {"two_drum_winder_nip_forces.png", "two_drum_winder_slip.png",
                "modes.png"} <= figures, (n, figures)
        assert {c for _, c in hits} == {want[n]}, (n, hits)
    # the map's bounce modes are drawn in colours no nip has (its lower panel shows nips)
    modes = {colour for _, label, colour in seen["modes.png"] if label.startswith("bounce mode")}
    assert len(modes) == 3 and not modes & set(want.values()), (modes, want)


def test_fig4_of_a_run_shows_the_whole_torque(tmp_path, monkeypatch):
    """The paper scene's first 60 s (ramp, first lift-offs): Fig. 4's full panel holds the
    drum torque's extremes, the zoom's title states the share of samples it clips."""
    res = winder.simulate(MODELS / "paper_winding.toml", t_end=60.0)
    torque = res["drum_torque"]
    limits: dict[str, list] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        limits[Path(path).name] = [(a.get_ylim(), a.get_title()) for a in fig.axes]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    _plots.paper_figures(res, tmp_path, closeup=res)
    (_, _), ((flo, fhi), ftitle), ((zlo, zhi), ztitle) = \
        limits["paper_winding_fig4_speeds_torque.png"]
    assert flo <= torque.min() and fhi >= torque.max()
    assert f"full range {torque.min():.0f} to {torque.max():.0f} N·m" in ftitle
    clipped = np.mean((torque < zlo) | (torque > zhi))
    assert 0.0 < clipped < 1.0  # the zoom leaves the ramp and the impacts out, and says so
    assert f"{clipped:.2%} of samples lie outside" in ztitle


def test_fig8_weight_line_uses_the_scene_gravity(monkeypatch, tmp_path: Path) -> None:
    """Fig. 8's weight line is ``m g`` with the scene's own ``g`` (here 3.7 m/s², as on
    Mars), not a fixed 9.81: the drawn values equal the mass channel times that g."""
    scene = winder.load_scene(MODELS / "paper_winding.toml").replace(scene={"gravity": 3.7})
    res = winder.simulate(scene, t_end=0.5)
    lines: dict[str, list] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        lines[Path(path).name] = [(ln.get_label(), ln.get_ydata()) for ln in fig.axes[0].lines]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    _plots.paper_figures(res, tmp_path, scene=scene, closeup=res)
    weight = [y for label, y in lines["paper_winding_fig8_normal_force.png"]
              if label.startswith("weight")]
    assert len(weight) == 1
    np.testing.assert_allclose(weight[0], res["mass"] * 3.7 / 1e3, rtol=1e-15)


def test_resonance_map_axis_is_the_maps_radii(tmp_path, monkeypatch):
    """With a map over 0.1–0.3 m and a simulated envelope over 0.05–0.8 m (the scene's whole
    run, as with ``winder modes --radius-max``), both panels show the map's radii (2 %
    margin), not the envelope's."""
    scene = winder.load_scene(MODELS / "paper_winding.toml")
    mm = winder.mode_map(scene, np.linspace(0.1, 0.3, 3))
    t = np.linspace(0.0, 100.0, 10_001)
    res = winder.Result({"t": t, "radius": np.linspace(0.05, 0.8, t.size),
                         "normal_force": np.full(t.size, 1e3)})
    limits: dict[str, list] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        limits[Path(path).name] = [a.get_xlim() for a in fig.axes]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    campbell_figure(mm, tmp_path / "map.png", result=res)
    for lo, hi in limits["map.png"]:
        assert lo == pytest.approx(0.1 - 0.004, abs=1e-12)
        assert hi == pytest.approx(0.3 + 0.004, abs=1e-12)
