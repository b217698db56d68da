"""Nips (machines spec §2, §8 ``[[nip]]``): the contact between two bodies, with its own
contact law and friction."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["NipPart", "ContactLaw", "FrictionLaw", "CONTACT_LAWS"]

CONTACT_LAWS = ("linear", "hunt_crossley")


@dataclass(frozen=True)
class ContactLaw:
    """``contact``: law (``linear`` | ``hunt_crossley``), stiffness (0, 1e18] [N/m or
    N/m^p], damping [0, 1e12] [N·s/m] (linear), exponent ``p`` [1, 3] [-] and hc_damping
    ``α`` [0, 1e4] [s/m] (Hunt–Crossley)."""

    law: str = "linear"
    stiffness: float = 1e7
    damping: float = 0.0
    exponent: float = 1.5
    hc_damping: float = 0.0


@dataclass(frozen=True)
class FrictionLaw:
    """``friction``: mu [0, 10] [-], slip_velocity ``v_ref`` (0, 1000] [m/s],
    relaxation_length ``σ`` (0, 1000] [m], min_speed ``v_min`` (0, 1000] [m/s]."""

    mu: float = 0.3
    slip_velocity: float = 0.05
    relaxation_length: float = 0.01
    min_speed: float = 0.1


@dataclass(frozen=True)
class NipPart:
    """``[[nip]]``: name; bodies ``a`` (the lower or supplying body) and ``b`` (names of
    two different bodies, not both with a fixed centre); contact and friction laws."""

    name: str
    a: str
    b: str
    contact: ContactLaw = field(default_factory=ContactLaw)
    friction: FrictionLaw = field(default_factory=FrictionLaw)
