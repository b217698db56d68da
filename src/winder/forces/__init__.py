"""Force elements: one module per effect of ``[effects]`` (see :class:`ForceElement`)."""

from ._base import ForceElement
from .contact import Contact
from .gravity import Gravity
from .imbalance import Imbalance
from .rider_load import RiderLoad
from .slip_relaxation import SlipRelaxation
from .variable_mass import VariableMass
from .web_momentum import WebMomentum
from .web_tension import WebTension

__all__ = ["ForceElement", "FORCES"]

#: The force elements by ``[effects]`` key (one registration line each).
FORCES: dict[str, type[ForceElement]] = {
    cls.name: cls for cls in (Gravity, Imbalance, VariableMass, Contact, SlipRelaxation,
                              WebMomentum, WebTension, RiderLoad)
}
