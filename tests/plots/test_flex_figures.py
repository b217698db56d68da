"""Figures of flexible parts (issue #25): a run of a flexible roll on a flexible drum
draws each body's deflection and twist and the nip's line load; the plotted data are the
result's channels."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import winder
from winder.parts import whole_elements
from winder.plots.flex import deflection, flexible_bodies, line_load_map
from winder.plots.machine import machine_figures

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "parts"))
import test_flex_roll as roll  # noqa: E402


def test_flexible_parts_have_their_figures(tmp_path: Path) -> None:
    drum = "length = 5.0\nflex = { segments = 3, EI = 2.26e9, kGA = 3.7e9, GJ = 1.7e9, " \
        "bearing_stiffness = 1e10, damping_ratio = 0.02 }"
    scene = roll.scene(3, drum=drum, damping=0.05)
    res = winder.simulate(scene, t_end=0.05)
    paths = machine_figures(res, tmp_path, scene=scene)
    names = {p.name for p in paths}
    assert {"flexroll_flex_drum.png", "flexroll_flex_roll.png",
            "flexroll_line_load_nip.png"} <= names
    assert all(p.stat().st_size > 1000 for p in paths)
    # the machine's figures draw each flexible part as one body, from the channels of its
    # rigid self (issue 32, item 4): drum speed and drive torque, roll speed, radius, z
    assert [b.name for b in whole_elements(scene)] == ["drum", "roll"]
    assert {"flexroll_drums.png", "flexroll_rolls.png", "flexroll_positions.png"} <= names
    bodies = {b.name: b for b in flexible_bodies(scene)}
    assert bodies["drum"].support == (0.0, 0.0) and bodies["roll"].support is None
    np.testing.assert_allclose(bodies["roll"].stations, [5 / 6, 2.5, 25 / 6])
    dz = deflection(res, bodies["drum"], "z")
    np.testing.assert_array_equal(dz[:, 1], res["drum_s1_z"])
    assert deflection(res, bodies["roll"], "x") is None  # the roll is free in z only
    np.testing.assert_allclose(deflection(res, bodies["roll"], "z").sum(axis=1), 0.0,
                               atol=1e-12)
    q = line_load_map(res, "nip", bodies["drum"])
    np.testing.assert_allclose(q.max(axis=1), res["nip_line_load_max"], rtol=1e-12)
    np.testing.assert_allclose(q.min(axis=1), res["nip_line_load_min"], rtol=1e-12)
