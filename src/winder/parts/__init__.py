"""The parts a machine is built from (machines spec §8): drums, paper rolls, rider rolls,
nips and the web with its span, as frozen dataclasses (one module per part). A scene file
is read into them by :func:`winder.load_scene` (:class:`~winder.Scene` fields ``drums``,
``rolls``, ``riders``, ``nips``, ``web``)."""

from typing import Any

from winder.parts._base import BodyElement, RigidDisc
from winder.parts.drum import DrumBody, DrumPart, SpeedProfileDrive, TorqueDrive
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
           "BodyElement", "RigidDisc", "DrumBody", "RollBody", "RiderBody", "PARTS",
           "body_elements"]

#: The body types by the scene attribute that lists their parts, in the order the machine
#: builds them (a body may rest on one built before it): one registration line each.
PARTS: dict[str, type[BodyElement]] = {
    "drums": DrumBody,
    "rolls": RollBody,
    "riders": RiderBody,
}


def body_elements(scene: Any) -> list[BodyElement]:
    """The body elements of ``scene``'s parts (:data:`PARTS` order, then the scene's)."""
    placed: dict[str, BodyElement] = {}
    for attr, cls in PARTS.items():
        for part in getattr(scene, attr, None) or ():
            placed[part.name] = cls(part, placed)
    return list(placed.values())
