"""Animation of a result: time compression and a spin rate that is visible, not aliased.

Playback: the whole run in ``playback`` seconds (default 30 s) at ``fps`` frames per
second. Rotation: a real roll turns at up to ~125 rad/s; sampled at 30 frames per second of
compressed time it would alias into random jitter. Drawn angles are therefore the real
angles times one gain ``spin_gain`` (same for drum and roll, so their ratio is kept),
chosen so that the fastest body turns at most ``max_turns_per_second`` (default 0.5)
turns per second of playback. Radius, height and the drum are otherwise true.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import meshcat
import numpy as np
from meshcat.animation import Animation

from winder._errors import WinderError
from winder._result import Result

from ._scene_graph import WinderGraph

__all__ = ["AnimationPlan", "DRAWN_CHANNELS", "check_drawable", "plan_animation", "animate"]

#: Channels the viewer draws (``drum_angle`` is optional: the drum is then still).
DRAWN_CHANNELS = ("radius", "z", "roll_angle", "roll_speed", "drum_speed")


def check_drawable(result: Result, where: str = "result") -> None:
    """Raise :class:`~winder.WinderError` (prefixed by ``where``, e.g. the file) unless
    ``result`` can be drawn: at least two samples on an increasing, finite time axis, the
    channels of :data:`DRAWN_CHANNELS` present and finite, and the radius > 0."""
    t = np.asarray(result.t, dtype=float)
    if len(t) < 2:
        raise WinderError(f"{where}: {len(t)} sample(s); the viewer needs at least 2")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise WinderError(f"{where}: the time axis is not finite and increasing")
    missing = [c for c in DRAWN_CHANNELS if c not in result]
    if missing:
        raise WinderError(f"{where}: no channel {', '.join(missing)} (the viewer draws "
                          f"{', '.join(DRAWN_CHANNELS)})")
    for c in (*DRAWN_CHANNELS, *(("drum_angle",) if "drum_angle" in result else ())):
        bad = np.flatnonzero(~np.isfinite(result[c]))
        if len(bad):
            raise WinderError(f"{where}: channel {c!r} is not finite at t = {t[bad[0]]:g} s "
                              f"(sample {bad[0]}: {float(result[c][bad[0]])!r})")
    small = np.flatnonzero(result["radius"] <= 0)
    if len(small):
        raise WinderError(f"{where}: radius {float(result['radius'][small[0]])!r} m at t = "
                          f"{t[small[0]]:g} s; a roll radius is > 0")


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
                   max_turns_per_second: float = 0.5) -> AnimationPlan:
    """Frame times and spin gain of an animation of ``result`` (see the module text)."""
    check_drawable(result)
    if not (math.isfinite(playback) and playback > 0):
        raise WinderError(f"playback must be finite and > 0 [s], got {playback!r}")
    t = result.t
    n = max(2, int(round(playback * fps)) + 1)
    times = np.linspace(t[0], t[-1], n)
    compression = (t[-1] - t[0]) / playback
    w_max = max(float(np.max(np.abs(result["roll_speed"]))),
                float(np.max(np.abs(result["drum_speed"]))), 1e-9)
    gain = min(1.0, 2 * math.pi * max_turns_per_second / (w_max * compression))
    return AnimationPlan(times, fps, gain)


def _sample(result: Result, name: str, times: np.ndarray) -> np.ndarray:
    return np.interp(times, result.t, result[name])


def animate(vis: meshcat.Visualizer, graph: WinderGraph, result: Result,
            plan: AnimationPlan) -> None:
    """Send the animation of ``result`` to ``vis`` (playing, looped)."""
    times = plan.times
    z = _sample(result, "z", times)
    r = _sample(result, "radius", times)
    phi = _sample(result, "roll_angle", times) * plan.spin_gain
    drum = result["drum_angle"] if "drum_angle" in result else None
    theta = (np.interp(times, result.t, drum) if drum is not None
             else np.zeros_like(times)) * plan.spin_gain
    anim = Animation(default_framerate=plan.fps)
    graph.show(vis, drum_angle=theta[0], z=z[0], roll_angle=phi[0], radius=r[0])
    root = graph.root
    for k in range(len(times)):
        Td, Tr = graph.poses(theta[k], z[k], phi[k])
        with anim.at_frame(vis, k) as frame:
            frame[root]["drum"].set_transform(Td)
            frame[root]["roll"].set_transform(Tr)
            frame[root]["roll"]["paper"].set_property("scale", "vector3",
                                                      [float(r[k]), 1.0, float(r[k])])
    vis.set_animation(anim, play=True, repetitions=1000)
