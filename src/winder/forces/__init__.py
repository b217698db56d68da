"""Force elements: one module per effect of ``[effects]`` (see :class:`ForceElement`)."""

from collections.abc import Iterable
from typing import Any

from winder.forces._base import ForceElement
from winder.forces.contact import Contact
from winder.forces.gravity import Gravity
from winder.forces.imbalance import Imbalance
from winder.forces.rider_load import RiderLoad
from winder.forces.slip_relaxation import SlipRelaxation
from winder.forces.tension_control import TensionController
from winder.forces.variable_mass import VariableMass
from winder.forces.web_momentum import WebMomentum
from winder.forces.web_tension import WebTension

__all__ = ["ForceElement", "FORCES", "DRIVES", "force_elements"]

#: The force elements by ``[effects]`` key (one registration line each).
FORCES: dict[str, type[ForceElement]] = {
    cls.name: cls for cls in (Gravity, Imbalance, VariableMass, Contact, SlipRelaxation,
                              WebMomentum, WebTension, RiderLoad)
}

#: Force elements a part's drive calls for (not ``[effects]`` keys), by drive kind.
DRIVES: dict[str, type[ForceElement]] = {"tension_control": TensionController}


def force_elements(effects: Any, bodies: Iterable[Any]) -> list[ForceElement]:
    """The force elements of a machine: those of the effects that are on (``effects``,
    with ``enabled()``), then those the bodies' drives call for (their ``drives``), in
    registration order (the machine orders them by their declarations)."""
    on = set(effects.enabled())
    calls = {name for b in bodies for name in b.drives}
    return [*(cls() for name, cls in FORCES.items() if name in on),
            *(cls() for name, cls in DRIVES.items() if name in calls)]
