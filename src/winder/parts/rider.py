"""Rider rolls (machines spec §4, §8 ``[[rider]]``): constant bodies free along ``z``
resting on a paper roll under an applied line load."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from winder._schema import Key, Table
from winder.parts._base import Drawing, RigidDisc
from winder.parts._keys import MAX_COORD, NAME

__all__ = ["RiderPart", "RiderBody", "KEYS"]

#: The keys of ``[[rider]]``.
KEYS = Table((
    NAME,
    Key(name="rides", kind="ref", required=True,
        doc="name of the paper roll it rests on (through a [[nip]] with a = that roll, "
            "b = the rider)"),
    Key(name="radius", required=True, unit="m", lo=0.0, lo_open=True, hi=10.0,
        doc="rider radius (constant)"),
    Key(name="mass", required=True, unit="kg", lo=0.0, lo_open=True, hi=1e6,
        doc="rider mass"),
    Key(name="inertia", required=True, unit="kg·m²", lo=0.0, lo_open=True, hi=1e7,
        doc="polar inertia of the rider"),
    Key(name="x", required=True, unit="m", hi=MAX_COORD,
        doc="horizontal position of its axis (fixed; it moves along z)"),
    Key(name="load", kind="load", doc_unit="m, N/m", default_text="[] (no load)",
        doc="line-load schedule [[radius of the ridden roll, line load], ...], radii "
            "strictly increasing, interpolated linearly, held beyond the ends; the force "
            "is −width × load along z",
        items=(Key(name="radius", unit="m", lo=0.0, lo_open=True, hi=10.0,
                   doc="radius of the ridden roll"),
               Key(name="line_load", unit="N/m", lo=0.0, hi=1e7, doc="line load"))),
))


@dataclass(frozen=True)
class RiderPart:
    """``[[rider]]``: a rider roll resting on the paper roll it ``rides``, its centre ``x``
    fixed, under the line-load schedule ``load`` (``((radius, line_load), ...)``, empty:
    no load); keys, units, bounds and meanings: :data:`KEYS`."""

    name: str
    rides: str
    radius: float
    mass: float
    inertia: float
    x: float
    load: tuple[tuple[float, float], ...] = ()


# ---- behaviour (the part protocol, :class:`~winder.parts._base.BodyElement`) -------------
class RiderBody(RigidDisc):
    """A rider roll: free along ``z``, sense +1, its centre first guessed on top of the
    roll it rides; ``rides`` and its line-load schedule ``load`` are read by the
    ``rider_load`` effect."""

    table = "rider"
    role = "rider"
    place_key = "x"
    KEYS = KEYS
    part_cls = RiderPart

    @classmethod
    def fixed_centre(cls, part: Any) -> bool:
        return False

    @classmethod
    def initial_circle(cls, part: Any) -> None:
        """Left out of the overlap check: the machine places a rider on top of the roll
        it rides (the twin-drum winder of spec §10 starts it inside the drums' circles)."""
        return None

    def drawing(self) -> Drawing:
        """As long as the roll it rides."""
        return Drawing(colour="rider", width_of=self.rides)

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
