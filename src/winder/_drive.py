"""Drum drives: a prescribed web-speed profile, or a free drum driven by a torque."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from ._scene import Scene

__all__ = ["Drive", "SpeedProfile", "TorqueDrive", "make_drive"]


class Drive(ABC):
    """How the drum moves.

    1. ``states``: names of the states the drive adds to the state vector.
    2. :meth:`initial_state` gives their values at ``t = 0``.
    3. :meth:`kinematics` gives drum angle, speed and acceleration ``(θ, Ω, Ω̇)``
       [rad, rad/s, rad/s²] from ``t`` and the drive states; for a free drum ``Ω̇`` is
       computed by the system from the torque balance, and ``None`` is returned.
    4. :attr:`breakpoints` are times where the drive is not smooth.
    """

    states: tuple[str, ...] = ()

    def initial_state(self) -> list[float]:
        return []

    @abstractmethod
    def kinematics(self, t: float, states: list[float]) -> tuple[float, float, float | None]:
        """``(θ, Ω, Ω̇)``; ``Ω̇`` is ``None`` when the drum is a free DOF."""

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return ()


class SpeedProfile(Drive):
    """``Ω(t) = min(a_w t, v_w)/R``; ``a_w = 0``: ``Ω = v_w/R`` from ``t = 0`` (spec §5)."""

    def __init__(self, radius: float, web_acceleration: float, web_speed: float) -> None:
        self.R, self.a, self.v = radius, web_acceleration, web_speed
        self.t_ramp = web_speed / web_acceleration if web_acceleration > 0 else 0.0

    def kinematics(self, t: float, states: list[float]) -> tuple[float, float, float | None]:
        if t < self.t_ramp:
            return 0.5 * self.a * t * t / self.R, self.a * t / self.R, self.a / self.R
        theta0 = 0.5 * self.a * self.t_ramp**2 / self.R
        return theta0 + self.v * (t - self.t_ramp) / self.R, self.v / self.R, 0.0

    def web_speed(self, t: np.ndarray | float) -> np.ndarray:
        """Web speed ``min(a_w t, v_w)`` [m/s] at the time(s) ``t`` [s]."""
        t = np.asarray(t, dtype=float)
        return np.minimum(self.a * t, self.v) if self.a > 0 else np.full(t.shape, self.v)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        return (self.t_ramp,) if self.t_ramp > 0 else ()


class TorqueDrive(Drive):
    """Free drum: states ``(θ_d, Ω)``, driven by the input torque ``drum_torque`` [N·m]."""

    states = ("drum_angle", "drum_speed")

    def __init__(self, radius: float, initial_web_speed: float, torque: float) -> None:
        self.R = radius
        self.omega0 = initial_web_speed / radius
        self.torque = torque

    def initial_state(self) -> list[float]:
        return [0.0, self.omega0]

    def kinematics(self, t: float, states: list[float]) -> tuple[float, float, float | None]:
        return states[0], states[1], None


def make_drive(scene: Scene) -> Drive:
    d = scene.drum.drive
    if d.kind == "speed_profile":
        return SpeedProfile(scene.drum.radius, d.web_acceleration, d.web_speed)
    return TorqueDrive(scene.drum.radius, d.web_speed, d.torque)
