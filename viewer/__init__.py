"""winder.viewer: meshcat scene graph, animation of results, standalone HTML, snapshots."""

from ._animation import AnimationPlan, animate, check_drawable, plan_animation
from ._export import (
    export_html,
    find_chromium,
    screenshot,
    snapshot_html,
    snapshot_names,
    snapshots,
)
from ._scene_graph import COLOURS, COM_MARKER_GAIN, WinderGraph

__all__ = ["AnimationPlan", "COLOURS", "COM_MARKER_GAIN", "WinderGraph", "animate",
           "check_drawable", "export_html", "find_chromium", "plan_animation", "screenshot",
           "snapshot_html", "snapshot_names", "snapshots"]
