"""Rider rolls (machines spec §4, §8 ``[[rider]]``): constant bodies free along ``z``
resting on a paper roll under an applied line load."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RiderPart"]


@dataclass(frozen=True)
class RiderPart:
    """``[[rider]]``: name; rides (the name of the roll it rests on); radius (0, 10] [m],
    mass (0, 1e6] [kg], inertia (0, 1e7] [kg·m²]; x [m] (its fixed centre ``x``,
    ``|x| <= 1000``); load: the line-load schedule ``((radius [m], line_load [N/m]), ...)``
    with strictly increasing radii of the ridden roll in (0, 10] and line loads
    [0, 1e7], interpolated linearly and held beyond the ends (empty: no load)."""

    name: str
    rides: str
    radius: float
    mass: float
    inertia: float
    x: float
    load: tuple[tuple[float, float], ...] = ()
