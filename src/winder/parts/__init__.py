"""The parts a machine is built from (machines spec §8): drums, paper rolls, rider rolls,
nips and the web with its span, as frozen dataclasses (one module per part). A scene file
is read into them by :func:`winder.load_scene` (:class:`~winder.Scene` fields ``drums``,
``rolls``, ``riders``, ``nips``, ``web``)."""

from winder.parts.drum import DrumPart, SpeedProfileDrive, TorqueDrive
from winder.parts.nip import CONTACT_LAWS, ContactLaw, FrictionLaw, NipPart
from winder.parts.rider import RiderPart
from winder.parts.roll import (
    AXES,
    ROLL_KINDS,
    UNWIND_DRIVE_KINDS,
    RollPart,
    TensionControl,
    UnwindTorqueDrive,
)
from winder.parts.web import SpanPart, WebPart

__all__ = ["DrumPart", "SpeedProfileDrive", "TorqueDrive", "RollPart", "ROLL_KINDS", "AXES",
           "UnwindTorqueDrive", "TensionControl", "UNWIND_DRIVE_KINDS", "RiderPart",
           "NipPart", "ContactLaw", "FrictionLaw", "CONTACT_LAWS", "WebPart", "SpanPart"]
