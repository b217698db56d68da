"""The parts a machine is built from (machines spec §8), one module per part: drums, paper
rolls and rider rolls (bodies: a frozen dataclass of the scene's data, its keys ``KEYS``
and its :class:`BodyElement`, registered in :data:`PARTS`), nips and the web with its span
(frozen dataclasses and their keys). A scene file is read into them by
:func:`winder.load_scene`: ``[[TABLE]]`` of each registered body type, listed as
``scene.ATTRIBUTE`` (:class:`~winder.Scene` ``drums``, ``rolls``, ``riders``; every body
type in ``scene.bodies``), and ``nips``, ``webs``."""

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from winder.parts._base import (
    NIP_ROLES,
    WEB_ROLES,
    BodyElement,
    Drawing,
    RigidDisc,
    Roles,
    Segment,
    SubTable,
    TableReader,
)
from winder.parts._keys import CENTRE, MAX_COORD, NAME
from winder.parts.drum import DrumBody, DrumPart, SpeedProfileDrive, TorqueDrive
from winder.parts.idler import IdlerBody
from winder.parts.nip import CONTACT_LAWS, ContactLaw, FrictionLaw, NipPart
from winder.parts.rider import RiderBody, RiderPart
from winder.parts.roll import (
    AXES,
    ROLL_KINDS,
    UNWIND_DRIVE_KINDS,
    RollBody,
    RollPart,
    TensionControl,
    UnwindTorqueDrive,
)
from winder.parts.web import SpanPart, WebPart

__all__ = ["DrumPart", "SpeedProfileDrive", "TorqueDrive", "RollPart", "ROLL_KINDS", "AXES",
           "UnwindTorqueDrive", "TensionControl", "UNWIND_DRIVE_KINDS", "RiderPart",
           "NipPart", "ContactLaw", "FrictionLaw", "CONTACT_LAWS", "WebPart", "SpanPart",
           "BodyElement", "RigidDisc", "SubTable", "TableReader", "Drawing", "DrumBody",
           "RollBody", "RiderBody", "PARTS", "NAME", "CENTRE", "MAX_COORD", "body_elements",
           "body_types", "whole_elements", "Roles", "Segment", "WEB_ROLES", "NIP_ROLES"]

#: The body types by the scene attribute that lists their parts (``scene.drums``), in the
#: order the machine builds them (a body may rest on one built before it) and the scene
#: reads, checks and writes their tables: one registration line each.
PARTS: dict[str, type[BodyElement]] = {
    "drums": DrumBody,
    "rolls": RollBody,
    "riders": RiderBody,
    "idlers": IdlerBody,
}


def body_types() -> dict[str, type[BodyElement]]:
    """The body types now registered by their table name (``drum``: :class:`DrumBody`),
    in :data:`PARTS` order."""
    return {cls.table: cls for cls in PARTS.values()}


def body_elements(scene: Any, *, whole: bool = False) -> list[BodyElement]:
    """The body elements of ``scene``'s parts (:data:`PARTS` order, then the scene's); a
    flexible part's are its segments."""
    bodies: Mapping[str, Any] = getattr(scene, "bodies", None) or {}
    placed: dict[str, BodyElement] = {}
    for attr, cls in PARTS.items():
        parts = bodies.get(attr) if attr in bodies else getattr(scene, attr, None)
        for part in parts or ():
            if whole and getattr(part, "flex", None) is not None:
                part = replace(part, flex=None)
            for element in cls.elements(part, placed):
                placed[element.name] = element
    return list(placed.values())


def whole_elements(scene: Any) -> list[BodyElement]:
    """One body element per part of ``scene``: a flexible part's rigid self, whose
    body-level channels the flexible body keeps (:mod:`winder.model.whole_body`), for the
    figures and summaries that show a part as one body."""
    return body_elements(scene, whole=True)
