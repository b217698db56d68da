"""Paper rolls (machines spec §1, §6, §8 ``[[roll]]``): bodies whose radius, mass and
inertia grow as paper is wound on (``wound``) or shrink as it is paid off
(``unwinding``), and the drives of an unwinding roll."""

from __future__ import annotations

from dataclasses import dataclass, replace

from winder._schema import Key, Table
from winder.parts.drum import CENTRE, NAME

__all__ = ["RollPart", "ROLL_KINDS", "AXES", "UnwindTorqueDrive", "TensionControl",
           "UNWIND_DRIVE_KINDS", "KEYS", "DRIVE_KEYS"]

#: Kinds of paper roll: ``wound`` (radius grows) and ``unwinding`` (radius shrinks; fixed
#: centre, the start of a web span).
ROLL_KINDS = ("wound", "unwinding")
#: Drive kinds of an unwinding roll (no drive: it turns freely).
UNWIND_DRIVE_KINDS = ("torque", "tension_control")
#: Translational axes a body can be free along, in this order.
AXES = ("x", "z")

_POS = {"lo": 0.0, "lo_open": True}  # a positive number

#: The keys of ``[[roll]]`` (its ``drive``: :data:`DRIVE_KEYS`).
KEYS = Table((
    NAME,
    Key(name="kind", kind="str", choices=ROLL_KINDS,
        doc="wound: grows, ṙ = +h·speed/2π; unwinding: shrinks, ṙ = −h·speed/2π, fixed "
            "centre, feeds [web.span]; the run ends where it reaches its core"),
    replace(CENTRE, doc="axis position [x, z]: the initial guess of the free coordinates "
                        "(static balance), the value of the fixed ones"),
    Key(name="free", kind="axes", default_text='["z"] (wound), [] (unwinding)',
        doc="the axes its centre moves along"),
    Key(name="sense", kind="sense",
        doc="operation direction: −1 turns the bottom surface towards +x (a roll on a "
            "drum)"),
    Key(name="core_radius", required=True, unit="m", **_POS, hi=10.0,
        doc="outer radius r_c of the empty core"),
    Key(name="core_mass", required=True, unit="kg", **_POS, hi=1e6, doc="mass of the core"),
    Key(name="core_inertia", required=True, unit="kg·m²", **_POS, hi=1e7,
        doc="polar inertia of the core about its axis"),
    Key(name="width", required=True, unit="m", **_POS, hi=100.0,
        doc="roll width L (cross-machine)"),
    Key(name="initial_radius", unit="m", **_POS, hi=10.0, default_text="core_radius",
        doc="radius at t = 0; at least core_radius"),
    Key(name="initial_speed", unit="rad/s", hi=1e5, doc="speed at t = 0 (operation sense)"),
    Key(name="com_offset", unit="m", lo=0.0, hi=10.0,
        doc="distance e of the centre of mass from the roll axis (imbalance); below "
            "min(core_radius, √(core_inertia / core_mass))"),
    Key(name="density", unit="kg/m³", lo=0.0, hi=1e5, default_text="[paper] density",
        doc="paper density ρ"),
    Key(name="caliper", unit="m", **_POS, hi=0.1, default_text="[paper] caliper",
        doc="paper thickness h, added to the radius once per revolution"),
    Key(name="drive", kind="table", default_text="none (free)",
        doc="unwinding rolls only: the unwind drive, a sub-table: keys below"),
))

#: The keys of an unwinding roll's ``drive``; ``kinds``: the keys each drive kind takes.
DRIVE_KEYS = Table((
    Key(name="kind", kind="str", required=True, choices=UNWIND_DRIVE_KINDS,
        doc="torque: a torque (negative brakes); tension_control: the unwind holds the "
            "span tension by PI with inertia feed-forward, gains from bandwidth"),
    Key(name="torque", unit="N·m", hi=1e8,
        doc="kind torque: the unwind torque (operation sense), constant or an input"),
    Key(name="tension", unit="N", **_POS, hi=1e7,
        default_text="required (kind tension_control)",
        doc="kind tension_control: the tension set-point T*"),
    Key(name="bandwidth", unit="rad/s", **_POS, hi=1e4,
        doc="kind tension_control: the closed loop's bandwidth ω_c (its three poles at "
            "−ω_c)"),
), kinds={"torque": ("kind", "torque"), "tension_control": ("kind", "tension", "bandwidth")})


@dataclass(frozen=True)
class UnwindTorqueDrive:
    """``drive = { kind = "torque" }`` of an unwinding roll: a torque ``torque`` [N·m]
    (operation sense: negative brakes), constant or an input; bounds:
    :data:`DRIVE_KEYS`."""

    kind: str = "torque"
    torque: float = 0.0


@dataclass(frozen=True, kw_only=True)
class TensionControl:
    """``drive = { kind = "tension_control" }`` of an unwinding roll: the unwind torque
    holds the span tension at ``tension`` [N]; ``bandwidth`` ω_c [rad/s] is the closed
    loop's bandwidth, from which the engine derives the gains by its rule; bounds:
    :data:`DRIVE_KEYS`."""

    kind: str = "tension_control"
    tension: float
    bandwidth: float = 10.0


@dataclass(frozen=True, kw_only=True)
class RollPart:
    """``[[roll]]``: a paper roll.

    name; kind ``"wound"`` or ``"unwinding"``; centre ``(x, z)`` [m] (initial guess of
    the free coordinates, value of the fixed ones); free: the axes among ``("x", "z")``
    (in that order) its centre moves along (an unwinding roll: none); sense ±1 (default
    −1); core_radius [m], core_mass [kg], core_inertia [kg·m²], width [m],
    initial_radius [m] (at least core_radius), initial_speed [rad/s] (operation sense),
    com_offset ``0 <= e < min(r_c, √(J_c/m_c))`` [m], density [kg/m³] and caliper [m]
    (from ``[paper]`` unless given; bounds and meanings of every key:
    :data:`KEYS`); initial_height [m]: only from the
    single-drum format's ``[roll] initial_height`` (a fixed initial centre ``z``, no
    static solve), else None; drive: an unwinding roll's :class:`UnwindTorqueDrive` or
    :class:`TensionControl`, None for a free one (a wound roll has none).
    """

    name: str
    kind: str = "wound"
    centre: tuple[float, float]
    free: tuple[str, ...] = ("z",)
    sense: int = -1
    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    initial_radius: float
    initial_speed: float = 0.0
    com_offset: float = 0.0
    density: float
    caliper: float
    initial_height: float | None = None
    drive: UnwindTorqueDrive | TensionControl | None = None
