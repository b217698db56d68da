"""winder.viewer: meshcat scene graph, animation of results, standalone HTML, snapshots."""

from ._animation import AnimationPlan, animate, plan_animation
from ._export import export_html, find_chromium, screenshot, snapshot_html, snapshots
from ._scene_graph import COLOURS, COM_MARKER_GAIN, WinderGraph

__all__ = ["AnimationPlan", "COLOURS", "COM_MARKER_GAIN", "WinderGraph", "animate",
           "export_html", "find_chromium", "plan_animation", "screenshot", "snapshot_html",
           "snapshots"]
