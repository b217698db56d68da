"""A flexible body's ``flex`` sub-table (issue #25): the body becomes ``segments`` lumped
segments along its axis, joined by a beam's bending stiffness (Timoshenko or
Euler–Bernoulli, condensed onto the segment centres: :mod:`winder.model.beam`) and a
torsion spring between neighbours, held at its two ends by bearings.

``flex = { segments = N, EI = ..., kGA = ..., GJ = ... }`` on a ``[[drum]]`` or a
``[[rider]]`` (which then needs its ``length``), ``flex = { segments = N, core_EI = ...,
paper_E = ..., GJ = ... }`` on a wound ``[[roll]]`` (carried by its drums, or on chucks:
``support = "chucks"``); without it the body is rigid, exactly as before."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from winder._schema import Key, Table

__all__ = ["FlexPart", "FLEX_KEYS", "parse_flex", "MAX_SEGMENTS", "RollFlexPart",
           "ROLL_FLEX_KEYS", "parse_roll_flex", "ROLL_SUPPORTS"]

#: How a flexible wound roll is carried: ``drums`` (by its nips, no bearings) or ``chucks``
#: (bearings at its core's ends, on its ``centre``).
ROLL_SUPPORTS = ("drums", "chucks")

#: The most segments a flexible body may have.
MAX_SEGMENTS = 64

#: The keys of a body's ``flex`` sub-table: one declaration each.
FLEX_KEYS = Table((
    Key(name="segments", required=True, unit="-", lo=2.0, hi=float(MAX_SEGMENTS),
        valid=f"an integer, 2–{MAX_SEGMENTS}",
        doc="number N of segments along the axis, each of length L/N, mass m/N and polar "
            "inertia J/N; its channels are named NAME_s{i} (i = 0 at the drive end)"),
    Key(name="EI", required=True, unit="N·m²", lo=0.0, lo_open=True, hi=1e18,
        doc="bending stiffness E·I of the beam"),
    Key(name="shear", kind="bool",
        doc="true: Timoshenko beam (shear stiffness kGA); false: Euler–Bernoulli"),
    Key(name="rotary_inertia", kind="bool",
        doc="true: the sections' rotary inertia about the bending axes, J/(2N) per segment "
            "(half its polar inertia), on the section's rotation, a degree of freedom of "
            "its own (the full Timoshenko beam; with shear = false, Rayleigh's); false: "
            "the deflections alone carry mass"),
    Key(name="kGA", unit="N", lo=0.0, lo_open=True, hi=1e18,
        default_text="required when shear = true",
        doc="shear stiffness k·G·A of the beam (Timoshenko)"),
    Key(name="GJ", required=True, unit="N·m²", lo=0.0, lo_open=True, hi=1e18,
        doc="torsional stiffness G·J; neighbouring segments are joined by GJ/(L/N)"),
    Key(name="bearing_stiffness", unit="N/m", lo=0.0, hi=1e18,
        doc="stiffness of each of the two end bearings, per direction (x and z; a rider's "
            "arms: x only); a very large value: simply supported; 0: free–free"),
    Key(name="bearing_damping", unit="N·s/m", lo=0.0, hi=1e12,
        doc="damping of each end bearing, per direction"),
    Key(name="damping_ratio", unit="-", lo=0.0, hi=1.0,
        doc="damping ratio ζ of the first bending mode (Rayleigh, stiffness-proportional "
            "β = 2ζ/ω₁), of the first torsion mode (the chain's own β_t = 2ζ/ω_t1, ω_t1 "
            "the chain's first torsion frequency, held at the drive end under a speed "
            "profile, else free; a paper roll's from its J(r) at run time) and, with "
            "rotary_inertia, of the sections' rocking (β_φ = 2ζ/ω_φ from its lowest "
            "frequency ω_φ); higher modes of each grow with their frequency"),
))


@dataclass(frozen=True)
class FlexPart:
    """``flex = { ... }``: a body made of ``segments`` lumped segments; keys, units, bounds
    and meanings: :data:`FLEX_KEYS`."""

    segments: int
    EI: float
    GJ: float
    shear: bool = True
    kGA: float | None = None
    rotary_inertia: bool = True
    bearing_stiffness: float = 1e9
    bearing_damping: float = 0.0
    damping_ratio: float = 0.01


def parse_flex(reader: Any, label: str, raw: Any, length: float | None) -> FlexPart:
    """The ``flex`` sub-table ``raw`` of ``[label]`` (``drum 'front'``): its keys, an
    integer ``segments``, ``kGA`` where ``shear`` is on, and the body's ``length`` [m]
    given."""
    flabel = f"{label}.flex"
    kw = reader.keys(flabel, raw, FLEX_KEYS)
    n = kw["segments"]
    if float(n) != int(n):
        raise reader.fail(flabel, "segments", f"{n!r} is not an integer; valid: an integer, "
                                              f"2–{MAX_SEGMENTS}")
    kw["segments"] = int(n)
    if kw.get("shear", True) and "kGA" not in kw:
        raise reader.fail(flabel, "kGA", "missing required key (shear = true: a Timoshenko "
                                         "beam); valid: kGA [N] > 0, or shear = false")
    if length is None:
        raise reader.fail(label, "length", "missing required key (a flexible body, flex = "
                                           "{ ... }, needs its length along the axis [m])")
    return FlexPart(**kw)


#: The keys of a wound roll's ``flex`` sub-table (its length is its ``width``).
ROLL_FLEX_KEYS = Table((
    FLEX_KEYS["segments"],
    Key(name="core_EI", required=True, unit="N·m²", lo=0.0, lo_open=True, hi=1e18,
        doc="bending stiffness of the core; the roll's EI(r) = core_EI + paper_E·π(r⁴ − "
            "r_c⁴)/4 (Euler–Bernoulli)"),
    Key(name="paper_E", required=True, unit="Pa", lo=0.0, hi=1e18,
        doc="Young's modulus of the wound paper in bending"),
    Key(name="GJ", required=True, unit="N·m²", lo=0.0, lo_open=True, hi=1e18,
        doc="torsional stiffness G·J; neighbouring segments are joined by GJ/(L/N)"),
    Key(name="support", kind="str", choices=ROLL_SUPPORTS,
        doc="drums: carried by its nips, no bearings (free–free); chucks: held at its "
            "core's two ends by bearings on its centre, along its free axes"),
    Key(name="chuck_stiffness", unit="N/m", lo=0.0, lo_open=True, hi=1e18,
        default_text="1e9 with support = chucks",
        doc="stiffness of each of the two chucks, per free axis (support = chucks only)"),
    FLEX_KEYS["damping_ratio"],
))


#: [N/m] each chuck's stiffness where a roll on chucks does not give it
CHUCK_STIFFNESS = 1e9


@dataclass(frozen=True)
class RollFlexPart:
    """``flex = { ... }`` of a wound roll: ``segments`` lumped segments of its width, each
    with its share of ``m(r)``, ``J(r)``; keys, units, bounds and meanings:
    :data:`ROLL_FLEX_KEYS`."""

    segments: int
    core_EI: float
    paper_E: float
    GJ: float
    support: str = "drums"
    #: [N/m] on chucks (1e9 unless given); None on the drums (so a scene's dict omits it)
    chuck_stiffness: float | None = None
    damping_ratio: float = 0.01


def parse_roll_flex(reader: Any, label: str, raw: Any) -> RollFlexPart:
    """The ``flex`` sub-table ``raw`` of the wound roll ``[label]``: its keys and an
    integer ``segments``."""
    flabel = f"{label}.flex"
    kw = reader.keys(flabel, raw, ROLL_FLEX_KEYS)
    n = kw["segments"]
    if float(n) != int(n):
        raise reader.fail(flabel, "segments", f"{n!r} is not an integer; valid: an integer, "
                                              f"2–{MAX_SEGMENTS}")
    kw["segments"] = int(n)
    if "chuck_stiffness" in kw and kw.get("support", "drums") != "chucks":
        raise reader.fail(flabel, "chuck_stiffness", "given, but support is not 'chucks' "
                                                     "(a roll on its drums has no chucks); "
                                                     "valid: support = 'chucks', or no "
                                                     "chuck_stiffness")
    if kw.get("support") == "chucks":
        kw.setdefault("chuck_stiffness", CHUCK_STIFFNESS)
    return RollFlexPart(**kw)
