"""The run figure of a web line (issue #34, :mod:`winder.plots.line`): the shipped line's
``STEM_line.png`` draws the result's own channels (every span's tension, the dancer's
position in mm between its travel ends taken from the scene, its speed, each roller's
load cell and traction under the limit 1), every legend beside its panel, at most
4000 px tall."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import MODELS

import winder
import winder.plots.figures as _plots
from winder.plots.layout import DPI, MAX_HEIGHT_PX
from winder.plots.run import run_figures

LINE = MODELS / "winder_line_dancer.toml"


@pytest.fixture(scope="module")
def line_run() -> tuple[winder.Scene, winder.Result]:
    scene = winder.load_scene(LINE)
    return scene, winder.simulate(scene, t_end=1.0, output_step=0.01)


def test_line_figure_draws_the_line_channels(line_run, tmp_path, monkeypatch) -> None:
    scene, r = line_run
    drawn: dict[str, list] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        if fig.get_layout_engine() is None:  # as _save lays it out
            fig.set_layout_engine("tight")
        fig.canvas.draw()
        rows = []
        for a in fig.axes:
            box, leg = a.get_window_extent(), a.get_legend()
            rows.append((a.get_title(), {ln.get_label(): np.asarray(ln.get_ydata(), float)
                                         for ln in a.get_lines()},
                         leg.get_window_extent().x0 >= box.x1 if leg else None))
        drawn[Path(path).name] = rows
        drawn[Path(path).name + ":px"] = [fig.get_size_inches()[1] * DPI]
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    paths = run_figures(r, tmp_path, scene=scene)
    assert "winder_line_dancer_line.png" in [p.name for p in paths]
    rows = drawn["winder_line_dancer_line.png"]
    assert drawn["winder_line_dancer_line.png:px"][0] <= MAX_HEIGHT_PX
    assert all(outside for _, _, outside in rows)  # every legend beside its panel
    spans, position, speed, load, traction = (lines for _, lines, _ in rows)
    for i in range(5):
        label = next(k for k in spans if k.startswith(f"span {i}:"))
        np.testing.assert_array_equal(spans[label], r[f"span{i}_tension"])
    np.testing.assert_array_equal(position["dancer position d"], 1e3 * r["dancer_position"])
    idler = next(x for x in scene.idlers if x.name == "dancer")
    lo, hi = idler.dancer.travel
    ends = {k: v for k, v in position.items() if "end of travel" in k}
    assert sorted(float(v[0]) for v in ends.values()) == [1e3 * lo, 1e3 * hi]
    np.testing.assert_array_equal(speed["dancer carriage speed ḋ"],
                                  1e3 * r["dancer_position_dot"])
    for n in ("guide1", "dancer", "guide2", "guide3"):
        np.testing.assert_array_equal(load[f"roller {n}"], r[f"{n}_load_cell"])
        np.testing.assert_array_equal(traction[f"roller {n}"], r[f"{n}_traction"])
    limit = traction["limit 1: the web slips on the roller"]
    assert list(limit) == [1.0, 1.0]
    # the load cell is the spans' bearing force over the wrap (§11), as drawn
    T1, T2 = r["span1_tension"], r["span2_tension"]
    np.testing.assert_allclose(load["roller dancer"], np.sqrt(T1**2 + T2**2 + 2 * T1 * T2),
                               rtol=1e-12)
