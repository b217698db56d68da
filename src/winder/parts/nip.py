"""Nips (machines spec §2, §8 ``[[nip]]``): the contact between two bodies, with its own
contact law and friction."""

from __future__ import annotations

from dataclasses import dataclass, field

from winder._schema import Key, Table
from winder.parts._keys import NAME

__all__ = ["NipPart", "ContactLaw", "FrictionLaw", "CONTACT_LAWS", "KEYS", "CONTACT_KEYS",
           "FRICTION_KEYS"]

CONTACT_LAWS = ("linear", "hunt_crossley")

#: The keys of ``[[nip]]`` (its ``contact`` and ``friction``: :data:`CONTACT_KEYS`,
#: :data:`FRICTION_KEYS`).
KEYS = Table((
    NAME,
    Key(name="a", kind="ref", required=True,
        doc="the lower or supplying body (the drum under a roll, the roll under a rider)"),
    Key(name="b", kind="ref", required=True, doc="the other body"),
    Key(name="contact", kind="table", default_text="required while effects.contact is on",
        doc="the contact law, a sub-table: keys below"),
    Key(name="friction", kind="table", doc="the friction law, a sub-table: keys below"),
))

#: The keys of a nip's contact law (and of the single-drum format's ``[contact]``).
CONTACT_KEYS = Table((
    Key(name="law", kind="str", choices=CONTACT_LAWS,
        doc="linear: F_n = max(0, k δ + c δ̇); hunt_crossley: F_n = max(0, k δ^p (1 + α δ̇))"),
    Key(name="stiffness", unit="N/m", doc_unit="N/m (N/m^p)", lo=0.0, lo_open=True, hi=1e18,
        fmu="contact_stiffness", law_units=(("hunt_crossley", "N/m^p"),),
        doc="stiffness k of the nip"),
    Key(name="damping", unit="N·s/m", lo=0.0, hi=1e12, fmu="contact_damping",
        doc="damping c of the linear law"),
    Key(name="exponent", unit="-", lo=1.0, hi=3.0, doc="exponent p of the Hunt–Crossley law"),
    Key(name="hc_damping", unit="s/m", lo=0.0, hi=1e4,
        doc="damping α of the Hunt–Crossley law"),
))

#: The keys of a nip's friction law (and of the single-drum format's ``[friction]``).
FRICTION_KEYS = Table((
    Key(name="mu", unit="-", lo=0.0, hi=10.0, fmu="mu",
        doc="friction coefficient μ: F_ss = μ F_n tanh(v_s / v_ref)"),
    Key(name="slip_velocity", unit="m/s", lo=0.0, lo_open=True, hi=1e3,
        fmu="slip_reference_velocity",
        doc="slip velocity scale v_ref of the tanh law"),
    Key(name="relaxation_length", unit="m", lo=0.0, lo_open=True, hi=1e3,
        fmu="relaxation_length",
        doc="relaxation length σ: dF_t/dt = (|u_a| + v_min)/σ (F_ss − F_t)"),
    Key(name="min_speed", unit="m/s", lo=0.0, lo_open=True, hi=1e3,
        doc="speed v_min added in the relaxation rate (keeps it finite at standstill)"),
))


@dataclass(frozen=True)
class ContactLaw:
    """``contact``: law (``linear`` | ``hunt_crossley``), stiffness [N/m or N/m^p],
    damping [N·s/m] (linear), exponent ``p`` [-] and hc_damping ``α`` [s/m]
    (Hunt–Crossley); bounds and meanings: :data:`CONTACT_KEYS`."""

    law: str = "linear"
    stiffness: float = 1e7
    damping: float = 0.0
    exponent: float = 1.5
    hc_damping: float = 0.0


@dataclass(frozen=True)
class FrictionLaw:
    """``friction``: mu [-], slip_velocity ``v_ref`` [m/s], relaxation_length ``σ`` [m],
    min_speed ``v_min`` [m/s]; bounds and meanings: :data:`FRICTION_KEYS`."""

    mu: float = 0.3
    slip_velocity: float = 0.05
    relaxation_length: float = 0.01
    min_speed: float = 0.1


@dataclass(frozen=True)
class NipPart:
    """``[[nip]]``: name; bodies ``a`` (the lower or supplying body) and ``b`` (names of
    two different bodies, not both with a fixed centre); contact and friction laws
    (:data:`KEYS`)."""

    name: str
    a: str
    b: str
    contact: ContactLaw = field(default_factory=ContactLaw)
    friction: FrictionLaw = field(default_factory=FrictionLaw)
