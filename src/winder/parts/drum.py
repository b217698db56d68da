"""Drums (machines spec §1, §6, §8 ``[[drum]]``): bodies with a fixed centre and a
constant radius, driven by a speed profile or a torque."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DrumPart", "SpeedProfileDrive", "TorqueDrive"]


@dataclass(frozen=True)
class SpeedProfileDrive:
    """``drive = { kind = "speed_profile" }``: the drum's speed is prescribed,
    ``Ω(t) = ratio · min(web_acceleration · t, web_speed) / R`` [rad/s];
    web_acceleration [0, 1000] [m/s²] (0: ``web_speed`` from ``t = 0``), web_speed
    [0, 1000] [m/s], ratio (0, 100] [-]."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    ratio: float = 1.0


@dataclass(frozen=True)
class TorqueDrive:
    """``drive = { kind = "torque" }``: the drum turns freely under the input torque
    ``torque`` (``|torque| <= 1e8`` [N·m], operation sense); ``web_speed`` [0, 1000] [m/s]
    is its initial surface speed."""

    kind: str = "torque"
    torque: float = 0.0
    web_speed: float = 0.0


@dataclass(frozen=True)
class DrumPart:
    """``[[drum]]``: name, radius (0, 10] [m], inertia (polar) (0, 1e7] [kg·m²], mass
    (0, 1e6] [kg], centre ``(x, z)`` [m] (fixed, ``|x|, |z| <= 1000``), sense ±1 (operation
    direction, spec §1), drive."""

    name: str
    radius: float
    inertia: float
    mass: float
    centre: tuple[float, float]
    sense: int = 1
    drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive()
