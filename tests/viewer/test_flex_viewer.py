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
