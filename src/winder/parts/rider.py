"""Rider rolls (machines spec §4, §8 ``[[rider]]``): constant bodies free along ``z``
resting on a paper roll under an applied line load; rigid, or flexible (issue #25: ``flex =
{ segments = N, ... }``, :mod:`winder.parts.flex`): then N segment bodies
(:class:`RiderSegment`), held in ``x`` at their ends by the rider's arms (bearings in
``x``) and resting in ``z``, joined by the force element ``flex_beam``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from winder._schema import Key, Table
from winder.parts._base import Drawing, RigidDisc, Roles, SubTable, TableReader, segment_count
from winder.parts._keys import MAX_COORD, NAME
from winder.parts.flex import FLEX_KEYS, FlexPart, parse_flex

__all__ = ["RiderPart", "RiderBody", "RiderSegment", "KEYS"]

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
    Key(name="length", unit="m", lo=0.0, lo_open=True, hi=50.0,
        default_text="required with flex; else unused",
        doc="length L of the rider along its axis"),
    Key(name="flex", kind="table", default_text="none: a rigid rider",
        doc="a flexible rider, a sub-table: the keys of [[drum]] flex (its bearings hold x "
            "only: it rests in z); its nip is sliced, one slice per segment"),
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
    length: float | None = None
    flex: FlexPart | None = None


# ---- behaviour (the part protocol, :class:`~winder.parts._base.BodyElement`) -------------
class RiderBody(RigidDisc):
    """A rider roll: free along ``z``, sense +1, its centre first guessed on top of the
    roll it rides; ``rides`` and its line-load schedule ``load`` are read by the
    ``rider_load`` effect."""

    table = "rider"
    role = "rider"
    place_key = "x"
    KEYS = KEYS
    SUB_TABLES = {"flex": SubTable(FLEX_KEYS, (FlexPart,))}
    part_cls = RiderPart

    @classmethod
    def parse(cls, reader: TableReader, label: str, raw: Any) -> RiderPart:
        """Its keys and its ``flex`` sub-table."""
        kw = reader.keys(label, raw, KEYS)
        if "flex" in raw:
            kw["flex"] = parse_flex(reader, label, raw["flex"], kw.get("length"))
        return RiderPart(**kw)

    @classmethod
    def elements(cls, part: Any, placed: Any) -> list[Any]:
        """A rigid rider: itself; a flexible one: its segments (:class:`RiderSegment`)."""
        if getattr(part, "flex", None) is None:
            return [cls(part, placed)]
        return [RiderSegment(part, i, placed) for i in range(part.flex.segments)]

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        """It rides the paper roll ``rides`` (free along ``z``); sliced where flexible."""
        return Roles(nip="riding", rides=part.rides,
                     segments=segment_count(part))

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
        ridden = placed[part.rides] if part.rides in placed else \
            next(b for b in placed.values() if b.segment_of == part.rides)  # flexible
        self.free = ("z",)
        self.centre = (float(part.x), ridden.centre[1] + ridden.initial_radius + part.radius)
        #: the name of the body it rests on
        self.rides: str = part.rides
        #: the line-load schedule ``((radius [m], line load [N/m]), ...)``
        self.load: tuple[tuple[float, float], ...] = tuple(part.load)

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{len(self.load)}"


class RiderSegment(RiderBody):
    """Segment ``i`` of a flexible rider (issue #25): a body ``NAME_s{i}`` free along ``x``
    (held at the rider's two ends by its arms, the bearings of ``flex``) and ``z`` (it
    rests on the roll through its slice of the nip), of mass ``m/N`` [kg] and polar inertia
    ``J/N`` [kg·m²]; its share ``1/N`` of the rider's load (``rider_load``). The beam and
    the torsion are the force element ``flex_beam``."""

    #: the axes its bearings hold (the beam's supports): the arms hold ``x`` only
    bearing_axes = ("x",)

    def __init__(self, part: Any, index: int, placed: Any) -> None:
        super().__init__(part, placed)
        flex = part.flex
        self.index, self.segments, self.flex = index, flex.segments, flex
        self.length = float(part.length)
        self.name = f"{part.name}_s{index}"
        self.segment_of = part.name
        self.whole_free = self.free  # the rigid rider's: z
        self.free = ("x", "z")
        self.drives = ("flex_beam",)

    def drawing(self) -> Drawing:
        h = self.length / self.segments
        return Drawing(colour="rider", width=h, y=(self.index + 0.5) * h - self.length / 2)

    def declare(self, machine: Any) -> None:
        n, part, N = self.name, self.part, self.segments
        machine.parameter(f"{n}.radius", part.radius)
        machine.parameter(f"{n}.inertia", part.inertia / N)
        machine.parameter(f"{n}.mass", part.mass / N)

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{self.index}/{self.segments}"
