"""Force elements: one module per effect of ``[effects]`` (see :class:`ForceElement`)."""

from ._base import ForceElement
from .contact import Contact
from .gravity import Gravity
from .imbalance import Imbalance
from .rider_load import RiderLoad
from .slip_relaxation import SlipRelaxation
from .tension_control import TensionControl
from .variable_mass import VariableMass
from .web_momentum import WebMomentum
from .web_tension import WebTension

__all__ = ["ForceElement", "FORCES", "DRIVES"]

#: The force elements by ``[effects]`` key (one registration line each).
FORCES: dict[str, type[ForceElement]] = {
    cls.name: cls for cls in (Gravity, Imbalance, VariableMass, Contact, SlipRelaxation,
                              WebMomentum, WebTension, RiderLoad)
}

#: Force elements a part's drive calls for (not ``[effects]`` keys), by drive kind.
DRIVES: dict[str, type[ForceElement]] = {"tension_control": TensionControl}
