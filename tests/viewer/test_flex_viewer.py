"""The viewer and a flexible body (issue #25): its segments drawn side by side along the
axis, their bending exaggerated by DEFLECTION_GAIN about their mean centre."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from winder.viewer._scene_graph import DEFLECTION_GAIN, WinderGraph

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "parts"))
import test_flex_nip as flexnip  # noqa: E402


def test_segments_along_the_axis_with_their_bending_exaggerated() -> None:
    graph = WinderGraph(flexnip.scene(4))
    assert graph.length == pytest.approx(flexnip.L)
    frame = {b.name: (b.centre[0], b.centre[1], 0.0) for b in graph.machine.bodies}
    sag = [0.0, -1e-4, -1e-4, 0.0]
    for i, dz in enumerate(sag):
        x, z, th = frame[f"drum_s{i}"]
        frame[f"drum_s{i}"] = (x, z + dz, th)
    poses = graph.poses(frame)
    mean = np.mean(sag)
    for i, dz in enumerate(sag):
        pose = poses[f"drum_s{i}"]
        assert pose[1, 3] == pytest.approx((i + 0.5) * flexnip.L / 4 - flexnip.L / 2)
        assert pose[2, 3] == pytest.approx(mean + DEFLECTION_GAIN * (dz - mean))
    assert poses["roll"][1, 3] == 0.0


def test_readout_has_a_line_per_flexible_body_and_per_sliced_nip() -> None:
    """The flexible machine (4 bodies of 8 segments, 3 sliced nips) at its last sample:
    the readout is 9 lines (it was 65: a line per segment and per slice); a body's line
    gives its segments' largest and mean deflection, a nip's its slices' total, least and
    largest force. Oracles: the deflections from the channels as the figures take them
    (winder.plots.flex.deflection), the total against the scene nip's own channel
    (flex_beam writes it: the other path), to the printed resolution."""
    from winder.viewer._motion import motion
    from winder.viewer._readout import readout_text

    import winder
    from winder.plots.flex import deflection, flexible_bodies

    models = Path(__file__).resolve().parents[2] / "models"
    scene = winder.load_scene(models / "two_drum_winder_flexible.toml")
    res = winder.simulate(scene, t_end=0.05)
    k = len(res.t) - 1
    lines = readout_text(motion(scene, res, res.t), k).splitlines()
    assert len(lines) == 1 + 1 + 4 + 3  # t, the set's radius, 4 bodies, 3 nips
    rows = {line.split()[0]: line for line in lines}
    for b in flexible_bodies(scene):
        d = np.hypot(*(deflection(res, b, c)[k] for c in ("x", "z")))
        got = rows[b.name].split("δ max ")[1].split()
        assert float(got[0]) == pytest.approx(1e3 * d.max(), abs=6e-4)  # printed 3 decimals
        assert float(got[2]) == pytest.approx(1e3 * d.mean(), abs=6e-4)
        speed = np.mean([res[f"{b.name}_s{i}_speed"][k] for i in range(b.segments)])
        assert float(rows[b.name].split()[1]) == pytest.approx(speed, abs=6e-3)
    for nip in ("front_nip", "rear_nip", "rider_nip"):
        total = float(rows[nip].split()[2])
        assert total == pytest.approx(res[f"{nip}_normal_force"][k] / 1e3, rel=1e-9,
                                      abs=6e-4)
        each = [res[f"{nip}_s{i}_normal_force"][k] / 1e3 for i in range(8)]
        assert f"8 slices {min(each):.3f}–{max(each):.3f} kN" in rows[nip]
