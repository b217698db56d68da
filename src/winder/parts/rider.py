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


# ---- behaviour (the part protocol, :class:`~winder.parts._base.BodyElement`) -------------
from typing import Any  # noqa: E402

from winder.parts._base import RigidDisc  # noqa: E402


class RiderBody(RigidDisc):
    """A rider roll: free along ``z``, sense +1, its centre first guessed on top of the
    roll it rides; ``rides`` and its line-load schedule ``load`` are read by the
    ``rider_load`` effect."""

    table = "rider"
    role = "rider"
    place_key = "x"

    def __init__(self, part: Any, placed: Any) -> None:
        super().__init__(part)
        self.sense = 1
        ridden = placed[part.rides]
        self.free = ("z",)
        self.centre = (float(part.x), ridden.centre[1] + ridden.initial_radius + part.radius)
        #: the name of the body it rests on
        self.rides: str = part.rides
        #: the line-load schedule ``((radius [m], line load [N/m]), ...)``
        self.load: tuple[tuple[float, float], ...] = tuple(part.load)

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{len(self.load)}"
