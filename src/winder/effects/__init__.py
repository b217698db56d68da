"""Physical effects of the winder, one per module (see :class:`Effect` for the contract)."""

from ._base import Context, Effect
from .contact import Contact, ContactLaw, HuntCrossleyContact, LinearContact, make_contact_law
from .gravity import Gravity
from .imbalance import Imbalance
from .slip_relaxation import SlipRelaxation
from .variable_mass import VariableMass
from .web_momentum import WebMomentum

#: Effect classes by their ``[effects]`` key.
EFFECTS: dict[str, type[Effect]] = {cls.name: cls for cls in (
    VariableMass, WebMomentum, Gravity, Imbalance, Contact, SlipRelaxation)}

__all__ = ["EFFECTS", "Context", "Effect", "Contact", "ContactLaw", "LinearContact",
           "HuntCrossleyContact", "make_contact_law", "Gravity", "Imbalance",
           "SlipRelaxation", "VariableMass", "WebMomentum"]
