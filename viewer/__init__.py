"""winder.viewer: meshcat scene graph of any machine of parts, animation of results with
an on-screen readout, standalone HTML, snapshots."""

from winder.viewer._animation import AnimationPlan, animate, plan_animation
from winder.viewer._export import (
    export_html,
    find_chromium,
    screenshot,
    snapshot_html,
    snapshot_names,
    snapshots,
)
from winder.viewer._motion import BodyMotion, Motion, check_drawable, motion, web_path
from winder.viewer._readout import readout_text
from winder.viewer._scene_graph import COLOURS, COM_MARKER_GAIN, WinderGraph

__all__ = ["AnimationPlan", "BodyMotion", "COLOURS", "COM_MARKER_GAIN", "Motion",
           "WinderGraph", "animate", "check_drawable", "export_html", "find_chromium",
           "motion", "plan_animation", "readout_text", "screenshot", "snapshot_html",
           "snapshot_names", "snapshots", "web_path"]
