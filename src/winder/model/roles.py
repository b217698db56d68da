"""What a body is to the rest of the machine (issue #34): its declared roles
(:class:`Roles`: how it carries a web, how it bears on a nip, whether it is a paper roll or
a flexible body of segments, whether its bearings carry passive torques) and the
interface of a flexible body's segment (:class:`Segment`). Each body type declares them
(:meth:`winder.parts.BodyElement.roles_of`); the scene's checks, the effects, the FMU and
the figures ask them, never a table's name."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

__all__ = ["Roles", "Segment", "WEB_ROLES", "NIP_ROLES"]

#: How a body carries a web (machines.md §3, §5, §11): it pays the web off (an unwinding
#: roll), the web wraps it on its way (the entry drum, an idler), or the web winds onto it
#: (a wound roll).
WEB_ROLES = ("unwinds", "wraps", "winds")

#: How a body bears on a nip (machines.md §2, §4): its centre is ``fixed`` (it cannot carry
#: a nip's normal force alone), ``free`` to move, or ``riding`` (free, resting on the
#: paper roll it rides through a nip of its own).
NIP_ROLES = ("fixed", "free", "riding")


@dataclass(frozen=True)
class Roles:
    """What a body is to the rest of the machine, declared by its type for one part
    (:meth:`BodyElement.roles_of`): the scene's checks, the effects, the FMU and the
    figures ask these, never a table's name.

    web: how it carries a web (:data:`WEB_ROLES`; None: it carries none). nip: how it
    bears on a nip (:data:`NIP_ROLES`). paper: it is a paper roll (a rider may ride it).
    rides: a riding body's ridden body (a name; only with ``nip = "riding"``).
    segments: a flexible body's number of segments (its nips are sliced, one slice per
    segment; None: rigid). bearing_torques: its bearings carry passive torques (drag).
    roller: a roller of a web line (machines.md §11): a span may end at it and the next
    start there. wrap: the web's wrap angle on it [rad] where given (a roller).
    dancer: a roller's dancer carriage (with ``stiffness``, ``load``, ``travel`` and
    ``position(t_up, t_down)``, its static position), else None. paced: a roller whose
    speed its drive prescribes (a pull roll on a speed profile): the tension zone an unwind
    controls ends at it."""

    web: str | None = None
    nip: str = "fixed"
    paper: bool = False
    rides: str | None = None
    segments: int | None = None
    bearing_torques: bool = False
    roller: bool = False
    wrap: float | None = None
    dancer: Any = None
    paced: bool = False

    def __post_init__(self) -> None:
        if self.web is not None and self.web not in WEB_ROLES:
            raise ValueError(f"web: {self.web!r}; valid: None or one of {WEB_ROLES}")
        if self.nip not in NIP_ROLES:
            raise ValueError(f"nip: {self.nip!r}; valid: one of {NIP_ROLES}")
        if (self.rides is not None) != (self.nip == "riding"):
            raise ValueError(f"rides: {self.rides!r} with nip {self.nip!r}; valid: the "
                             "ridden body's name exactly where nip = 'riding'")
        if self.segments is not None and self.segments < 1:
            raise ValueError(f"segments: {self.segments!r}; valid: None or >= 1")

    @property
    def fixed(self) -> bool:
        """Its centre is fixed: a nip needs its other body free to move."""
        return self.nip == "fixed"


class Segment(Protocol):
    """A segment of a flexible body (issue #25), as the sliced nips
    (:mod:`winder.model.slices`) and the force elements ``flex_beam`` and ``rider_load``
    read it: a body element whose :attr:`BodyElement.segment` is itself."""

    #: its body's name (``NAME_s{i}`` is its own)
    name: str
    #: the flexible body's name
    segment_of: str
    #: its index along the axis (0: the drive end) and the body's number of segments
    index: int
    segments: int
    #: [m] the flexible body's length along its axis
    length: float
    #: the body's ``flex`` sub-table (:class:`~winder.parts.flex.FlexPart` or, for a paper
    #: roll, :class:`~winder.parts.flex.RollFlexPart`)
    flex: Any
    #: the axes its bearings (or chucks) hold; () carried by its nips
    bearing_axes: tuple[str, ...]
    #: the roles of its body (``paper``: a paper roll, bending with its radius)
    roles: Roles
    #: its body's translational axes
    free: tuple[str, ...]
