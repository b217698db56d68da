"""Paper rolls (machines spec §1, §6, §8 ``[[roll]]``): bodies whose radius, mass and
inertia grow as paper is wound on (``wound``) or shrink as it is paid off
(``unwinding``), and the drives of an unwinding roll."""

from __future__ import annotations

from dataclasses import dataclass, replace

from winder._schema import Channel, Key, Table
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


# ---- behaviour (the part protocol, :class:`~winder.parts._base.BodyElement`) -------------
import math  # noqa: E402
from collections.abc import Mapping  # noqa: E402
from typing import TYPE_CHECKING, Any  # noqa: E402

from winder.model.locked_modes import AT_CORE, CORE_AUTO, ModeKind  # noqa: E402
from winder.model.mass_law import paper_roll_mass  # noqa: E402
from winder.parts._base import BodyElement  # noqa: E402

if TYPE_CHECKING:
    from winder.model.machine import BodyState, Evaluation, Machine


class RollBody(BodyElement):
    """A paper roll: its radius is a state that grows (``wound``) or shrinks
    (``unwinding``) as paper is wound on or paid off, ``ṙ = ±h · speed / 2π`` [m/s]
    (machines.md §1), its mass and inertia follow the mass law of winder-model §2.

    A wound roll has the core mode of spec §2 (``ROLL.core``: at the core its radius
    stops shrinking); an unwinding roll the end mode (``ROLL.end``: the run ends where it
    reaches its core). Its drive: an input torque ``ROLL.torque`` [N·m] or the
    ``tension_control`` force element.
    """

    table = "roll"
    role = "roll"
    CHANNELS = (
        Channel(name="ROLL_radius", unit="m", doc="radius r of a paper roll"),
        Channel(name="ROLL_mass", unit="kg", doc="mass m(r)"),
        Channel(name="ROLL_inertia", unit="kg·m²", doc="polar inertia J(r) about its axis"),
        Channel(name="ROLL_mass_rate", unit="kg/s", doc="ṁ (negative for an unwinding roll)"),
        Channel(name="ROLL_inertia_rate", unit="kg·m²/s", doc="J̇"),
    )
    radius_state = True
    variable_mass = True

    def __init__(self, part: Any, placed: Any = None) -> None:
        super().__init__(part)
        self.free = tuple(part.free)
        self.centre = tuple(part.centre)
        drive = getattr(part, "drive", None)
        kind = drive.kind if drive is not None else None
        n = self.name
        #: it pays off its web (machines.md §1): fixed centre, shrinking radius
        self.unwinding = part.kind == "unwinding"
        self.winds = not self.unwinding
        self.torque_inputs = (f"{n}.torque",) if kind == "torque" else ()
        self.drives = ("tension_control",) if kind == "tension_control" else ()
        self.setpoint_inputs = (f"{n}.tension_setpoint",) if self.drives else ()
        self.com_offset = part.com_offset

    @property
    def initial_radius(self) -> float:
        return float(self.part.initial_radius)

    def declare(self, machine: Machine) -> None:
        n, part = self.name, self.part
        machine.state(f"{n}.radius", part.initial_radius)
        machine.parameter(f"{n}.core_radius", part.core_radius)
        machine.parameter(f"{n}.core_mass", part.core_mass)
        machine.parameter(f"{n}.core_inertia", part.core_inertia)
        machine.parameter(f"{n}.width", part.width)
        machine.parameter(f"{n}.density", part.density)
        machine.parameter(f"{n}.caliper", part.caliper)
        if self.unwinding:  # the run ends where it reaches its core
            machine.mode(f"{n}.end", (f"{n}.exhausted",), ModeKind.END, owner=n,
                         state=f"{n}.radius", param=f"{n}.core_radius")
        else:
            machine.mode(f"{n}.core", (f"{n}.unwound", f"{n}.forward"), ModeKind.CORE,
                         owner=n, state=f"{n}.radius", param=f"{n}.core_radius")
        if self.torque_inputs:
            machine.parameter(f"{n}.torque", part.drive.torque)

    def initial_rate(self, coord: str) -> float:
        """Spec §7: ``θ̇ = s · initial_speed``; the centre at rest."""
        return self.sense * self.part.initial_speed if coord == "theta" else 0.0

    def fixed_at_rest(self) -> Mapping[str, float]:
        """The single-drum format's ``[roll] initial_height``: a given centre ``z``."""
        h = getattr(self.part, "initial_height", None)
        return {} if h is None else {"z": h}

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        n, mathns = self.name, ev.mathns
        r = ev.x(f"{n}.radius")
        rc = ev.p(f"{n}.core_radius")
        k = math.pi * ev.p(f"{n}.density") * ev.p(f"{n}.width")
        bs.mass, bs.inertia, bs.dm_dr, bs.dJ_dr = paper_roll_mass(
            r, rc, ev.p(f"{n}.core_mass"), ev.p(f"{n}.core_inertia"), k)
        h2pi = ev.p(f"{n}.caliper") / (2.0 * math.pi)
        speed = bs.speed
        bs.r = r
        if self.unwinding:  # machines.md §1: ṙ = −h·speed/2π, down to the core
            bs.r_dot = -h2pi * speed
            ev.switches[f"{n}.exhausted"] = rc - r
        else:
            core = ev.mode(f"{n}.core")
            at_core = mathns.logic_or(core == AT_CORE, mathns.logic_and(
                core == CORE_AUTO, mathns.logic_and(r <= rc, speed < 0.0)))
            bs.r_dot = mathns.if_else(at_core, 0.0, h2pi * speed)
            ev.switches[f"{n}.unwound"] = rc - r
            ev.switches[f"{n}.forward"] = speed
        ev.set_rate(f"{n}.radius", bs.r_dot)

    def transverse_inertia(self, ev: Evaluation, mass: Any, inertia: Any) -> Any:
        """A cylinder of width ``L``: ``J/2 + m L²/12`` [kg·m²]."""
        L = ev.p(f"{self.name}.width")
        return 0.5 * inertia + mass * L * L / 12.0

    def drive_torque(self, ev: Evaluation) -> Any:
        return ev.p(f"{self.name}.torque") if self.torque_inputs else None

    def outputs(self, ev: Evaluation, bs: BodyState) -> None:
        values = (bs.r, bs.mass, bs.inertia, bs.mass_rate, bs.inertia_rate)
        for declared, value in zip(self.CHANNELS, values, strict=True):
            ev.output(declared, self.name, value)

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{self.unwinding}"

    # ---- for the analyses ---------------------------------------------------------------
    least_radius_key = "core_radius"

    @property
    def least_radius(self) -> float:
        """Its core radius ``r_c`` [m]."""
        return float(self.part.core_radius)

    def radius_after(self, length: float) -> float:
        """The growth law (machines.md §1, one caliper ``h`` per revolution) integrated:
        ``r² = r₀² + h L/π`` [m] once ``L`` = ``length`` [m] of paper is wound on."""
        part = self.part
        return math.sqrt(part.initial_radius**2 + part.caliper * length / math.pi)
