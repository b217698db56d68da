"""Figures at scale (issue #36): every figure of the flexible machine (4 bodies of 8
segments, 3 sliced nips) is at most 4000 px tall, its legends tell every line apart
(colour, line style, marker), its labels do not overlap; the bounce has no edge artefact."""

from __future__ import annotations

from pathlib import Path

import matplotlib.colors as mcolors
import matplotlib.image as mimage
import numpy as np
import pytest
from conftest import MODELS
from matplotlib.collections import QuadMesh
from matplotlib.lines import Line2D

import winder
import winder.plots.figures as _plots
from winder.parts import body_elements
from winder.plots.campbell import campbell_figure
from winder.plots.flex import deflection, flexible_bodies
from winder.plots.layout import DPI, MAX_HEIGHT_PX, line_styles
from winder.plots.machine import machine_figures
from winder.plots.positions import positions_figures
from winder.plots.smooth import bounce, centred_mean, dirichlet_gain, window_samples

FLEX = MODELS / "two_drum_winder_flexible.toml"


@pytest.fixture(scope="module")
def flex_run():
    scene = winder.load_scene(FLEX)
    return scene, winder.simulate(scene, t_end=0.3)


def _style(handle) -> tuple[str, str, str]:
    """(colour, line style, marker) of a legend handle."""
    if isinstance(handle, Line2D):
        return (mcolors.to_hex(handle.get_color()), str(handle.get_linestyle()),
                str(handle.get_marker()))
    face = handle.get_facecolor()
    face = face[0] if np.ndim(face) == 2 else face
    return (mcolors.to_hex(face), "patch", "")


def _check(fig, name: str) -> dict:
    """What the tests assert of a figure about to be saved: its height [px], every
    legend's styles, the overlapping pairs of its axes' texts."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = [a.get_legend() for a in fig.axes if a.get_legend() is not None]
    legends += list(fig.legends)
    styles = [[_style(h) for h in leg.legend_handles] for leg in legends]
    overlaps = []
    for a in fig.axes:
        texts = [t for t in a.texts if t.get_visible() and t.get_text().strip()]
        boxes = [t.get_window_extent(renderer) for t in texts]
        overlaps += [(texts[i].get_text(), texts[j].get_text())
                     for i in range(len(boxes)) for j in range(i + 1, len(boxes))
                     if boxes[i].overlaps(boxes[j])]
    outside = [(leg.get_window_extent(renderer), fig.axes[0].get_window_extent(renderer),
                fig.bbox.frozen()) for leg in fig.legends]
    return {"height": fig.get_size_inches()[1] * DPI, "styles": styles,
            "overlaps": overlaps, "name": name, "outside": outside}


def _capture(monkeypatch) -> dict[str, dict]:
    seen: dict[str, dict] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        seen[Path(path).name] = _check(fig, Path(path).name) | {"fig": _summary(fig),
                                                                "figure": fig}
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    return seen


def _summary(fig) -> dict:
    meshes = [(a.get_title(), c) for a in fig.axes for c in a.collections
              if isinstance(c, QuadMesh) and a.get_title()]  # not the colour bars
    return {"axes": len([a for a in fig.axes if a.get_visible()]),
            "meshes": [(title, np.asarray(c.get_array())) for title, c in meshes]}


def _assert_readable(info: dict) -> None:
    assert info["height"] <= MAX_HEIGHT_PX, (info["name"], info["height"])
    for styles in info["styles"]:
        assert len(set(styles)) == len(styles), (info["name"], styles)
    assert not info["overlaps"], (info["name"], info["overlaps"])


def test_run_figures_of_the_flexible_machine(flex_run, tmp_path, monkeypatch) -> None:
    """Every run figure of the flexible machine: at most 4000 px tall (the positions
    figure was 21,296 px with 96 rows), legends with no two lines alike (the rolls
    figure listed 31 segments on 10 colours), no overlapping labels. The positions figure
    draws a flexible body as rows of its own (its segments' deflections as heat maps whose
    values are the channels' deflections, exactly), not a row per segment."""
    scene, res = flex_run
    seen = _capture(monkeypatch)
    paths = machine_figures(res, tmp_path, scene=scene)
    assert len(seen) == len(paths) >= 12
    for p in paths:  # the PNGs as written
        assert mimage.imread(p).shape[0] <= MAX_HEIGHT_PX, p.name
    for info in seen.values():
        _assert_readable(info)
    pos = seen["two_drum_winder_flexible_positions.png"]["fig"]
    bodies = flexible_bodies(scene)
    assert len(pos["meshes"]) == 2 * len(bodies)  # x and z per body, whatever N
    assert pos["axes"] <= 2 * 4 * len(bodies)  # rows (and colour bars) per body
    for b in bodies:
        for c in ("x", "z"):
            (values,) = [v for title, v in pos["meshes"]
                         if title.startswith(f"{b.name}: {c} deflection")]
            np.testing.assert_array_equal(values.reshape(b.segments, -1),
                                          1e3 * deflection(res, b, c).T)


def test_resonance_map_of_the_flexible_machine(tmp_path, monkeypatch) -> None:
    """The resonance map of the flexible machine (20 modes, 34 crossings at 4 radii):
    no two legend entries alike (there were 28 on 10 colours), the legend outside the
    chart, the crossings' numbers overlapping neither each other nor the bars' names
    ("1x1xdrum" was printed over itself), every crossing in the table once."""
    scene = winder.load_scene(FLEX)
    mm = winder.mode_map(scene, np.linspace(0.05, 0.6, 4))
    seen = _capture(monkeypatch)
    campbell_figure(mm, tmp_path / "modes.png", title="map")
    info = seen["modes.png"]
    _assert_readable(info)
    fig = info["figure"]
    chart = fig.axes[0]
    assert chart.get_legend() is None and len(fig.legends) == 1  # beside the chart
    legend, frame, page = info["outside"][0]
    assert legend.x0 >= frame.x1 and not legend.overlaps(frame)
    assert legend.x1 <= page.x1 + 0.5  # inside the figure
    crossings = mm.crossings(mm.shown())
    assert len(crossings) >= 20
    numbers = [n for t in chart.texts if t.get_text()[:1].isdigit()
               for n in t.get_text().split(",")]
    assert sorted(map(int, numbers)) == list(range(1, len(crossings) + 1))
    table = [t.get_text() for t in fig.axes[-1].texts]
    assert len(table) == len(crossings)
    for row, (c, _, rc) in zip(table, crossings, strict=True):
        assert c in row and f"r = {rc:.4f} m" in row


def test_line_styles_never_repeat() -> None:
    for n in (1, 6, 10, 11, 40, 400, 401, 1000):
        styles = line_styles(n)
        assert len(styles) == n and len(set(styles)) == n


# --- the bounce: a centred mean, valid-only edges -------------------------------------


def test_bounce_of_a_constant_is_zero_to_the_last_sample() -> None:
    t = np.arange(0.0, 10.0, 0.01)
    tb, b, used = bounce(t, np.full(t.size, 0.163936), 0.5)
    w = window_samples(t, 0.5)
    assert w == 51 and used == pytest.approx(0.51)
    assert tb[0] == t[25] and tb[-1] == t[-26]  # the samples with a whole window
    assert np.max(np.abs(b)) == 0.0


def test_bounce_of_a_sine_on_a_ramp_is_its_attenuated_sine() -> None:
    """``z = z0 + v t + A sin(2π f t)``: the centred mean passes the ramp exactly and the
    sine with the Dirichlet gain ``D = sin(π f w dt)/(w sin(π f dt))``, so the bounce is
    ``A (1 − D) sin(2π f t)`` at every sample with a whole window, first and last
    included (measured error 2e-16 m of 1e-3 m)."""
    dt, f, A = 0.01, 3.7, 1e-3
    t = np.arange(0.0, 8.0, dt)
    z = 0.16 + 0.004 * t + A * np.sin(2 * np.pi * f * t)
    tb, b, _ = bounce(t, z, 0.5)
    w = window_samples(t, 0.5)
    D = dirichlet_gain(f, dt, w)
    np.testing.assert_allclose(b, A * (1 - D) * np.sin(2 * np.pi * f * tb), rtol=0,
                               atol=1e-14)
    _, mean, _ = centred_mean(t, z, 0.5)
    np.testing.assert_allclose(mean, 0.16 + 0.004 * tb + A * D * np.sin(2 * np.pi * f * tb),
                               rtol=0, atol=1e-14)


def test_a_short_run_gets_a_window_it_can_hold() -> None:
    t = np.arange(0.0, 0.31, 0.01)  # 31 samples, shorter than the 0.5 s window
    w = window_samples(t, 0.5)
    assert w % 2 == 1 and w <= (len(t) + 1) // 2
    tb, b, used = bounce(t, t * 0 + 1.0, 0.5)
    assert len(tb) == len(t) - (w - 1) and used == pytest.approx(w * 0.01)


def test_the_positions_figure_draws_the_bounce_without_edge_artefact(tmp_path) -> None:
    """A roll rising 4 mm/s with a 1 mm bounce at 3.7 Hz: the figure's bounce line is the
    attenuated sine at every drawn sample, the last ones too (the block means interpolated
    before gave a spike of the ramp's half window, 1 mm, at the run's end)."""
    scene = winder.load_scene(MODELS / "two_drum_winder.toml")
    dt, f, A = 0.01, 3.7, 1e-3
    t = np.arange(0.0, 6.0, dt)
    z = 0.16 + 0.004 * t + A * np.sin(2 * np.pi * f * t)
    res = winder.Result({"t": t, "set_x": np.zeros_like(t), "set_z": z,
                         "rider_z": z + 0.5})
    drawn: dict[str, tuple] = {}

    def save(fig, path):
        for a in fig.axes:
            for line in a.get_lines():
                drawn[line.get_label()] = (line.get_xdata(), line.get_ydata())
        return path

    positions_figures(res, scene, body_elements(scene), tmp_path, "s", "s",
                      lambda *_: "", save)
    tb, b = drawn["set z − mean"]
    D = dirichlet_gain(f, dt, window_samples(t, 0.5))
    np.testing.assert_allclose(b, 1e3 * A * (1 - D) * np.sin(2 * np.pi * f * tb), rtol=0,
                               atol=1e-11)
    assert tb[-1] < t[-1] and tb[0] > t[0]  # no sample without a whole window


def test_rows_go_onto_pages_of_at_most_4000_px() -> None:
    """The layout rule by count: bodies' groups of rows packed in order onto pages, a
    group never split, each page's height (header + rows) at most 4000 px."""
    from winder.plots.layout import HEADER, ROW, pages, rows_per_page

    limit = rows_per_page()
    assert (HEADER + ROW * limit) * DPI <= MAX_HEIGHT_PX < (HEADER + ROW * (limit + 1)) * DPI
    for groups in ([3] * 40, [4, 5, 3, 2] * 9, [1] * 100, [limit] * 3):
        out = pages(groups)
        assert [i for page in out for i in page] == list(range(len(groups)))
        for page in out:
            assert (HEADER + ROW * sum(groups[i] for i in page)) * DPI <= MAX_HEIGHT_PX
        assert len(out) == len(pages(groups))  # deterministic
    assert len(pages([4] * 4)) == 1  # the flexible machine: 4 bodies of 4 rows, one page
