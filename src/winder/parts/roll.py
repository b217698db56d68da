"""Paper rolls (machines spec §1, §6, §8 ``[[roll]]``): bodies whose radius, mass and
inertia grow as paper is wound on (``wound``) or shrink as it is paid off
(``unwinding``), and the drives of an unwinding roll. A wound roll may be flexible (issue
#25: ``flex = { segments = N, ... }``, :mod:`winder.parts.flex`): then N segment bodies
(:class:`RollSegment`) that share one radius state, joined by the force element
``flex_beam``."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from winder._args import show
from winder._schema import Channel, Key, Table
from winder.model.locked_modes import AT_CORE, CORE_AUTO, ModeKind
from winder.model.paper_roll import max_com_offset, paper_roll_mass
from winder.parts._base import (
    BodyElement,
    Drawing,
    Roles,
    SubTable,
    TableReader,
    segment_count,
)
from winder.parts._keys import CENTRE, NAME
from winder.parts.flex import ROLL_FLEX_KEYS, RollFlexPart, parse_roll_flex

if TYPE_CHECKING:
    from winder.model.machine import BodyState, Evaluation, Machine

__all__ = ["RollPart", "RollBody", "RollSegment", "ROLL_KINDS", "AXES", "UnwindTorqueDrive",
           "TensionControl", "DancerControl", "UNWIND_DRIVE_KINDS", "KEYS", "DRIVE_KEYS",
           "check_core", "winding_rate"]

#: Kinds of paper roll: ``wound`` (radius grows) and ``unwinding`` (radius shrinks; fixed
#: centre, the start of a web span).
ROLL_KINDS = ("wound", "unwinding")
#: Drive kinds of an unwinding roll (no drive: it turns freely).
UNWIND_DRIVE_KINDS = ("torque", "tension_control", "dancer_control")
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
    Key(name="width", required=True, unit="m", fmu="width", **_POS, hi=100.0,
        doc="roll width L (cross-machine)"),
    Key(name="initial_radius", unit="m", **_POS, hi=10.0, default_text="core_radius",
        doc="radius at t = 0; at least core_radius"),
    Key(name="initial_speed", unit="rad/s", hi=1e5, doc="speed at t = 0 (operation sense)"),
    Key(name="com_offset", unit="m", lo=0.0, hi=10.0, fmu="com_offset",
        doc="distance e of the centre of mass from the roll axis (imbalance); below "
            "min(core_radius, √(core_inertia / core_mass))"),
    Key(name="density", unit="kg/m³", lo=0.0, hi=1e5, fmu="density", default_text="[paper] density",
        doc="paper density ρ"),
    Key(name="caliper", unit="m", **_POS, hi=0.1, fmu="caliper", default_text="[paper] caliper",
        doc="paper thickness h, added to the radius once per revolution"),
    Key(name="drive", kind="table", default_text="none (free)",
        doc="unwinding rolls only: the unwind drive, a sub-table: keys below"),
    Key(name="flex", kind="table", default_text="none: a rigid roll",
        doc="wound rolls only: a flexible roll along its width, a sub-table: keys below "
            "(issue #25); its nips are sliced, one slice per segment"),
))

#: The keys of an unwinding roll's ``drive``; ``kinds``: the keys each drive kind takes.
DRIVE_KEYS = Table((
    Key(name="kind", kind="str", required=True, choices=UNWIND_DRIVE_KINDS,
        doc="torque: a torque (negative brakes); tension_control: the unwind holds the "
            "span tension by PI with inertia feed-forward, gains from bandwidth; "
            "dancer_control: the unwind holds a dancer at its centre (d = 0) likewise"),
    Key(name="torque", unit="N·m", hi=1e8,
        doc="kind torque: the unwind torque (operation sense), constant or an input"),
    Key(name="tension", unit="N", **_POS, hi=1e7,
        default_text="required (kind tension_control)",
        doc="kind tension_control: the tension set-point T*"),
    Key(name="bandwidth", unit="rad/s", **_POS, hi=1e4, fmu="bandwidth",
        doc="kinds tension_control, dancer_control: the closed loop's bandwidth ω_c (its "
            "three poles at −ω_c)"),
    Key(name="dancer", kind="ref", default_text="required (kind dancer_control)",
        doc="kind dancer_control: the idler on a dancer carriage it holds at d = 0"),
    Key(name="span", unit="-", lo=0.0, hi=1e3,
        doc="kind tension_control: the index of the span whose tension it holds (0: the "
            "first, from the unwinding roll; on a web line the load cell's span)"),
), kinds={"torque": ("kind", "torque"),
          "tension_control": ("kind", "tension", "bandwidth", "span"),
          "dancer_control": ("kind", "dancer", "bandwidth")})


def winding_rate(ev: Evaluation, n: str, r: Any, rc: Any, speed: Any, *,
                 switches: bool = True) -> Any:
    """Spec §2: the radius rate ``ṙ = h·speed/2π`` [m/s] of the winding roll ``n``, held at
    0 at its core (``r <= r_c``) while it turns backwards (its core mode); with
    ``switches``, the switching functions ``n.unwound = r_c − r`` and ``n.forward =
    speed`` the core events are located on. ``speed`` [rad/s] in the roll's sense."""
    mathns = ev.mathns
    core = ev.mode(f"{n}.core")
    at_core = mathns.logic_or(core == AT_CORE, mathns.logic_and(
        core == CORE_AUTO, mathns.logic_and(r <= rc, speed < 0.0)))
    if switches:
        ev.switches[f"{n}.unwound"] = rc - r
        ev.switches[f"{n}.forward"] = speed
    return mathns.if_else(at_core, 0.0, ev.p(f"{n}.caliper") / (2.0 * math.pi) * speed)


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
    holds the tension of span ``span`` (an index from the unwinding roll, machines.md §11)
    at ``tension`` [N]; ``bandwidth`` ω_c [rad/s] is the closed loop's bandwidth, from
    which the engine derives the gains by its rule; bounds: :data:`DRIVE_KEYS`."""

    kind: str = "tension_control"
    tension: float
    bandwidth: float = 10.0
    span: int = 0

    def __post_init__(self) -> None:
        if isinstance(self.span, bool) or not float(self.span).is_integer():
            raise ValueError(f"tension_control: span must be a whole number (a span's "
                             f"index), got {self.span!r}")
        object.__setattr__(self, "span", int(self.span))


@dataclass(frozen=True, kw_only=True)
class DancerControl:
    """``drive = { kind = "dancer_control" }`` of an unwinding roll: the unwind torque
    holds the carriage of the idler ``dancer`` at its centre (``d = 0``); ``bandwidth``
    ω_c [rad/s] is the closed loop's bandwidth (:mod:`winder.forces.dancer_control`);
    bounds: :data:`DRIVE_KEYS`."""

    kind: str = "dancer_control"
    dancer: str
    bandwidth: float = 10.0


@dataclass(frozen=True, kw_only=True)
class RollPart:
    """``[[roll]]``: a paper roll; keys, units, bounds and meanings: :data:`KEYS` (an
    unwinding roll's drive: :data:`DRIVE_KEYS`, None for a free one). density and caliper
    come from ``[paper]`` unless given. held_z [m]: a given initial centre ``z`` that the
    static balance leaves as it is (no scene key of a roll sets it; None: solved).
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
    held_z: float | None = None
    drive: UnwindTorqueDrive | TensionControl | DancerControl | None = None
    flex: RollFlexPart | None = None


def check_core(fail: Callable[[str, str, str], Exception], table: str,
               roll: Mapping[str, Any]) -> None:
    """A roll's initial radius (>= core) and centre-of-mass offset (inside the core, core
    inertia about it positive); ``roll`` holds its parsed keys with initial_radius,
    ``fail(table, key, message)`` the error to raise."""
    r0, rc = roll["initial_radius"], roll["core_radius"]
    if r0 < rc:
        raise fail(table, "initial_radius",
                   f"{r0!r} m is below core_radius {rc!r} m; valid: >= core_radius")
    e, mc, jc = roll.get("com_offset", 0.0), roll["core_mass"], roll["core_inertia"]
    e_max = max_com_offset(rc, mc, jc)
    if not e < e_max:
        raise fail(table, "com_offset",
                   f"{e!r} m puts the centre of mass outside the core or "
                   f"makes the core's inertia about it, core_inertia − core_mass "
                   f"com_offset², non-positive (core_radius {rc!r} m, "
                   f"core_inertia {jc!r} kg·m², core_mass "
                   f"{mc!r} kg); valid: com_offset < min(core_radius, "
                   f"√(core_inertia/core_mass)) = {e_max:.6g} m")


def _parse_drive(reader: TableReader, label: str, kw: Mapping[str, Any],
                 raw: Mapping[str, Any]
                 ) -> UnwindTorqueDrive | TensionControl | DancerControl | None:
    """The drive of a roll (spec §6): only an unwinding roll may have one."""
    if "drive" not in raw:
        return None
    if kw["kind"] != "unwinding":
        raise reader.fail(label, "drive",
                          f"{show(raw['drive'])}: a drive on a {kw['kind']} roll; only "
                          "unwinding rolls (kind = 'unwinding') have a drive; a wound roll "
                          "is turned by its nips; valid: remove drive")
    dlabel = f"{label}.drive"
    d = reader.keys(dlabel, raw["drive"], DRIVE_KEYS)
    reader.kinds(dlabel, d, DRIVE_KEYS)
    if d["kind"] == "torque":
        return UnwindTorqueDrive(**d)
    if d["kind"] == "dancer_control":
        if "dancer" not in d:
            raise reader.fail(dlabel, "dancer", "missing required key (kind = "
                                                "'dancer_control': the idler it holds)")
        return DancerControl(**d)
    if "tension" not in d:
        raise reader.fail(dlabel, "tension",
                          "missing required key (kind = 'tension_control': the set-point [N])")
    if not float(d.get("span", 0)).is_integer():
        raise reader.fail(dlabel, "span", f"{show(d['span'])}: not a whole number; valid: a "
                                          "span's index 0, 1, … from the unwinding roll")
    return TensionControl(**d)


# ---- behaviour (the part protocol, :class:`~winder.parts._base.BodyElement`) -------------
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
    KEYS = KEYS
    SUB_TABLES = {"drive": SubTable(DRIVE_KEYS, (UnwindTorqueDrive, TensionControl,
                                                 DancerControl),
                                    heading="drive (unwinding rolls)"),
                  "flex": SubTable(ROLL_FLEX_KEYS, (RollFlexPart,),
                                   heading="flex (wound rolls)")}
    part_cls = RollPart
    CHANNELS = (
        Channel(name="ROLL_radius", unit="m", doc="radius r of a paper roll", whole="shared"),
        Channel(name="ROLL_mass", unit="kg", doc="mass m(r)", whole="sum"),
        Channel(name="ROLL_inertia", unit="kg·m²", doc="polar inertia J(r) about its axis",
                whole="sum"),
        Channel(name="ROLL_mass_rate", unit="kg/s", doc="ṁ (negative for an unwinding roll)",
                whole="sum"),
        Channel(name="ROLL_inertia_rate", unit="kg·m²/s", doc="J̇", whole="sum"),
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
        self.drives = (kind,) if kind in ("tension_control", "dancer_control") else ()
        self.setpoint_inputs = (f"{n}.tension_setpoint",) \
            if kind == "tension_control" else ()
        self.com_offset = part.com_offset

    @classmethod
    def parse(cls, reader: TableReader, label: str, raw: Any) -> RollPart:
        """Its keys, paper defaults, core and drive (spec §1, §8)."""
        kw = reader.keys(label, raw, KEYS)
        kw.setdefault("kind", "wound")
        if kw["kind"] == "unwinding":
            kw.setdefault("free", ())
            if kw["free"]:
                raise reader.fail(label, "free",
                                  f"{show(list(kw['free']))}: an unwinding roll's centre is "
                                  "fixed (docs/model.md §1); valid: [] (or leave free out)")
        kw["drive"] = _parse_drive(reader, label, kw, raw)
        kw.setdefault("initial_radius", kw["core_radius"])
        for key in ("density", "caliper"):
            if key not in kw:
                if reader.paper is None:
                    raise reader.fail(label, key, "missing required key (the scene has no "
                                                  f"[paper] {key} to default to)")
                kw[key] = getattr(reader.paper, key)
        check_core(reader.fail, label, kw)
        if "flex" in raw:
            if kw["kind"] != "wound":
                raise reader.fail(label, "flex", "a flexible roll must be wound (kind = "
                                                 "'wound'); valid: no flex on an unwinding "
                                                 "roll")
            kw["flex"] = parse_roll_flex(reader, label, raw["flex"])
        return RollPart(**kw)

    @classmethod
    def elements(cls, part: Any, placed: Any) -> list[Any]:
        """A rigid roll: itself; a flexible one: its segments (:class:`RollSegment`)."""
        if getattr(part, "flex", None) is None:
            return [cls(part, placed)]
        return [RollSegment(part, i, placed) for i in range(part.flex.segments)]

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        """A paper roll that winds its web on (``wound``) or pays it off (``unwinding``),
        free to move where it has ``free`` axes; sliced where flexible."""
        return Roles(web="unwinds" if part.kind == "unwinding" else "winds",
                     nip="free" if tuple(part.free) else "fixed", paper=True,
                     segments=segment_count(part))

    @classmethod
    def initial_circle(cls, part: Any) -> tuple[tuple[float, float], float]:
        return tuple(part.centre), part.initial_radius

    def drawing(self) -> Drawing:
        """Its core, and its paper scaled by its radius; the centre-of-mass marker."""
        return Drawing(colour="paper", width=self.part.width,
                       core_radius=self.part.core_radius, com_offset=self.part.com_offset)

    @property
    def initial_radius(self) -> float:
        return float(self.part.initial_radius)

    @property
    def roll_key(self) -> str:
        """The prefix of its radius state, parameters and core mode: its name."""
        return self.name

    def declare(self, machine: Machine) -> None:
        n, part = self.roll_key, self.part
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
        """A given initial centre ``z`` (:attr:`RollPart.held_z`), held out of the balance."""
        h = getattr(self.part, "held_z", None)
        return {} if h is None else {"z": h}

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        n = self.name
        r = ev.x(f"{n}.radius")
        rc = ev.p(f"{n}.core_radius")
        k = math.pi * ev.p(f"{n}.density") * ev.p(f"{n}.width")
        bs.mass, bs.inertia, bs.dm_dr, bs.dJ_dr = paper_roll_mass(
            r, rc, ev.p(f"{n}.core_mass"), ev.p(f"{n}.core_inertia"), k)
        speed = bs.speed
        bs.r = r
        if self.unwinding:  # machines.md §1: ṙ = −h·speed/2π, down to the core
            bs.r_dot = -(ev.p(f"{n}.caliper") / (2.0 * math.pi)) * speed
            ev.switches[f"{n}.exhausted"] = rc - r
        else:
            bs.r_dot = winding_rate(ev, n, r, rc, speed)
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



class RollSegment(RollBody):
    """Segment ``i`` of a flexible wound roll (issue #25): a body ``NAME_s{i}`` free along
    the roll's ``free`` axes, with its share ``1/N`` of ``m(r)``, ``J(r)`` (a roll of width
    ``L/N`` on ``1/N`` of the core) and so of the ``−Ẏv`` terms. All segments share one
    radius state ``NAME.radius`` and the parameters ``NAME.core_radius``, ``NAME.width``,
    ... (declared by segment 0); the radius grows with their mean speed,
    ``ṙ = h · mean(speed_i) / 2π``, and segment 0 holds the core mode ``NAME.core``.
    Bending (``EI(r)``; no bearings, or chucks at the core's ends) and torsion: the force
    element ``flex_beam``."""

    @property
    def bearing_axes(self) -> tuple[str, ...]:
        """The axes its chucks hold (``support = "chucks"``: its free axes), else none:
        carried by its nips."""
        return tuple(self.free) if self.flex.support == "chucks" else ()

    def __init__(self, part: Any, index: int, placed: Any = None) -> None:
        super().__init__(part, placed)
        flex = part.flex
        self.index, self.segments, self.flex = index, flex.segments, flex
        self.length = float(part.width)
        self.roll = part.name
        self.name = f"{part.name}_s{index}"
        self.segment_of = part.name
        self.drives = ("flex_beam",)

    def drawing(self) -> Drawing:
        h = self.length / self.segments
        return replace(super().drawing(), width=h, y=(self.index + 0.5) * h - self.length / 2)

    @property
    def roll_key(self) -> str:
        """The roll's name: its segments share its radius state and parameters."""
        return self.roll

    def declare(self, machine: Machine) -> None:
        if self.index == 0:  # the roll's radius, parameters and core mode, once
            super().declare(machine)

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        n, N = self.roll, self.segments
        r = ev.x(f"{n}.radius")
        rc = ev.p(f"{n}.core_radius")
        k = math.pi * ev.p(f"{n}.density") * ev.p(f"{n}.width") / N
        bs.mass, bs.inertia, bs.dm_dr, bs.dJ_dr = paper_roll_mass(
            r, rc, ev.p(f"{n}.core_mass") / N, ev.p(f"{n}.core_inertia") / N, k)
        rates = [ev.x(f"{n}_s{j}.theta_dot") for j in range(N)]
        speed = self.sense * sum(rates[1:], rates[0]) / N
        bs.r = r
        bs.r_dot = winding_rate(ev, n, r, rc, speed, switches=self.index == 0)
        if self.index == 0:
            ev.set_rate(f"{n}.radius", bs.r_dot)

    def radius_of(self, y: Any, machine: Machine) -> float:
        """The roll's shared radius [m] in state ``y``."""
        return float(y[machine.index(f"{self.roll}.radius")])

    def transverse_inertia(self, ev: Evaluation, mass: Any, inertia: Any) -> Any:
        """A cylinder of width ``L/N``."""
        h = ev.p(f"{self.roll}.width") / self.segments
        return 0.5 * inertia + mass * h * h / 12.0

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{self.index}/{self.segments}"
