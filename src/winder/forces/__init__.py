"""Force elements: one module per effect of ``[effects]`` (see :class:`ForceElement`)."""

from collections.abc import Iterable
from typing import Any

from winder.forces._base import ForceElement
from winder.forces.bearing_friction import BearingFriction
from winder.forces.contact import Contact
from winder.forces.dancer_control import DancerController
from winder.forces.flex_beam import FlexBeam
from winder.forces.gravity import Gravity
from winder.forces.imbalance import Imbalance
from winder.forces.rider_load import RiderLoad
from winder.forces.slip_relaxation import SlipRelaxation
from winder.forces.tension_control import TensionController
from winder.forces.variable_mass import VariableMass
from winder.forces.web_momentum import WebMomentum
from winder.forces.web_tension import WebTension

__all__ = ["ForceElement", "FORCES", "DRIVES", "RUN_ORDER", "force_elements"]

#: The force elements by ``[effects]`` key (one registration line each), in the order of
#: ``[effects]`` in the scene reference and messages (spec order).
FORCES: dict[str, type[ForceElement]] = {
    cls.name: cls for cls in (VariableMass, WebMomentum, WebTension, Gravity, Imbalance,
                              Contact, SlipRelaxation, RiderLoad)
}

#: Force elements a part calls for (not ``[effects]`` keys; a body lists them in its
#: ``drives``): its drive's (by drive kind), a flexible body's beam (``flex_beam``).
DRIVES: dict[str, type[ForceElement]] = {"tension_control": TensionController,
                                         "flex_beam": FlexBeam,
                                         "bearing_friction": BearingFriction,
                                         "dancer_control": DancerController}

#: The order in which the built-in effects' force elements run where their declarations
#: (``provides``/``requires``/``uses``) leave it open: the order their forces are summed,
#: which the shipped results keep to round-off (a bouncing scene amplifies a reordered sum).
#: An effect not listed runs after these, in registration order; a new one needs no entry.
RUN_ORDER = ("gravity", "imbalance", "variable_mass", "contact", "slip_relaxation",
             "web_momentum", "web_tension", "rider_load")


def force_elements(effects: Any, bodies: Iterable[Any]) -> list[ForceElement]:
    """The force elements of a machine: those of the effects that are on (``effects``,
    with ``enabled()``) in :data:`RUN_ORDER` (the others after them, in registration
    order), then those the bodies' drives call for (their ``drives``), in registration
    order (the machine orders them by their declarations). An effect that is off is not
    instantiated."""
    on = set(effects.enabled())
    calls = {name for b in bodies for name in b.drives}
    effects_on = sorted((name for name in FORCES if name in on), key=_run_rank)
    return [*(FORCES[name]() for name in effects_on),
            *(cls() for name, cls in DRIVES.items() if name in calls)]


def _run_rank(name: str) -> int:
    """Where ``name`` runs among the effects (:data:`RUN_ORDER`; unlisted: after them)."""
    return RUN_ORDER.index(name) if name in RUN_ORDER else len(RUN_ORDER)
