"""Animation of a result: time compression and a spin rate that is visible, not aliased.

Playback: the whole run in ``playback`` seconds (default 30 s) at ``fps`` frames per
second. Rotation: a real roll turns at up to ~300 rad/s; sampled at 30 frames per second
of compressed time it would alias into random jitter. Drawn angles are therefore the real
angles times one gain ``spin_gain`` (same for every body, so their ratios are kept),
chosen so that the fastest body turns at most ``max_turns_per_second`` (default 0.5)
turns per second of playback. Radii, centres and the web are otherwise true.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import meshcat
import numpy as np
from meshcat.animation import Animation
from winder.viewer._motion import (
    Motion,
    check_drawable,
    motion,
    scene_of,
    speed_channels,
)
from winder.viewer._readout import readout_text
from winder.viewer._scene_graph import WinderGraph, apply_poses

from winder._errors import WinderError
from winder.io.result import Result
from winder.scene.load import Scene

__all__ = ["AnimationPlan", "check_drawable", "plan_animation", "animate",
           "animation_motion"]


@dataclass(frozen=True)
class AnimationPlan:
    """Frame times [s of simulation], frame rate [1/s], spin gain [-]."""

    times: np.ndarray
    fps: int
    spin_gain: float

    @property
    def compression(self) -> float:
        """Seconds of simulation per second of playback."""
        span = self.times[-1] - self.times[0]
        return span / max(len(self.times) - 1, 1) * self.fps


def plan_animation(result: Result, *, playback: float = 30.0, fps: int = 30,
                   max_turns_per_second: float = 0.5,
                   scene: Scene | None = None) -> AnimationPlan:
    """Frame times and spin gain of an animation of ``result`` (see the module text);
    ``scene`` defaults to the one stored in the result."""
    check_drawable(result, scene=scene)
    if not (math.isfinite(playback) and playback > 0):
        raise WinderError(f"playback must be finite and > 0 [s], got {playback!r}")
    t = result.t
    n = max(2, int(round(playback * fps)) + 1)
    times = np.linspace(t[0], t[-1], n)
    compression = (t[-1] - t[0]) / playback
    speeds = speed_channels(scene_of(result, scene))
    w_max = max(max(float(np.max(np.abs(result[c]))) for c in speeds if c in result), 1e-9)
    gain = min(1.0, 2 * math.pi * max_turns_per_second / (w_max * compression))
    return AnimationPlan(times, fps, gain)


def animation_motion(graph: WinderGraph, result: Result, plan: AnimationPlan) -> Motion:
    """The machine of ``graph`` at the frame times of ``plan`` (angles times the gain)."""
    return motion(graph.scene, result, plan.times, spin_gain=plan.spin_gain)


def animate(vis: meshcat.Visualizer, graph: WinderGraph, result: Result,
            plan: AnimationPlan) -> list[str]:
    """Send the animation of ``result`` to ``vis`` (playing, looped); the camera frames
    every body over the whole run. Returns the readout text of every frame."""
    m = animation_motion(graph, result, plan)
    anim = Animation(default_framerate=plan.fps)
    graph.set_camera(vis, m.extent())
    graph.show(vis, m, 0)
    root = graph.root
    for k in range(len(m.times)):
        with anim.at_frame(vis, k) as frame:
            apply_poses(frame[root], graph.pose_commands(m, k),
                        lambda node, v: node.set_property("scale", "vector3", v))
    vis.set_animation(anim, play=True, repetitions=1000)
    return [readout_text(m, k) for k in range(len(m.times))]
