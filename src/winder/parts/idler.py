"""Idler rollers (machines spec §11 ``[[idler]]``): rigid rollers on a fixed centre that
carry a web line between its spans, with wrap angle, bearing drag (viscous and Coulomb)
and, optionally, a drive as a drum's (a pull roll).

Its motion (operation sense, the one in which its surface carries the web forward)::

    J ω̇ = R (T_down − T_up) − c_v ω − τ_c tanh(ω / 0.1 rad/s) + τ_drive

The span tensions' torque is the web line's (force element ``web_tension``), the bearing
drag the force element ``bearing_friction`` (called for where ``c_v`` or ``τ_c`` is not
zero), the drive as a drum's. Channels (besides ``NAME_speed``, ``NAME_angle``,
``NAME_torque``): ``NAME_load_cell`` [N], the bearing force of the two tensions over the
wrap, and ``NAME_traction`` [-], the share of the capstan limit ``exp(μ β) − 1`` used."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from winder._schema import Channel, Key, Table
from winder.model.locked_modes import ModeKind
from winder.parts._base import Drawing, Roles, SubTable, TableReader
from winder.parts._keys import CENTRE, NAME
from winder.parts.drum import DRIVE_KEYS, DrumBody, SpeedProfileDrive, TorqueDrive

if TYPE_CHECKING:
    from winder.model.machine import BodyState, Evaluation, Machine

__all__ = ["IdlerPart", "IdlerBody", "KEYS", "TRACTION_FLOOR", "roller_channels",
           "DancerPart", "DancerBody", "DANCER_KEYS"]

#: [N] the smallest tension the traction divides by
TRACTION_FLOOR = 1e-9

#: The keys of ``[[idler]]``: one declaration each (units, bounds, meaning).
KEYS = Table((
    NAME,
    Key(name="radius", required=True, unit="m", lo=0.0, lo_open=True, hi=10.0,
        doc="roller radius R"),
    Key(name="inertia", required=True, unit="kg·m²", lo=0.0, lo_open=True, hi=1e7,
        doc="polar moment of inertia J of the roller about its axis"),
    Key(name="mass", unit="kg", lo=0.0, hi=1e6, doc="roller mass"),
    CENTRE,
    Key(name="sense", kind="sense",
        doc="the rotation (+1: top surface towards +x) in which its surface carries the "
            "web forward"),
    Key(name="initial_speed", unit="rad/s", lo=-1e4, hi=1e4,
        default_text="0 (a driven roller: its drive's)",
        doc="speed at t = 0 (operation sense)"),
    Key(name="wrap", unit="rad", lo=0.0, lo_open=True, hi=2.0 * math.pi, fmu="wrap",
        default_text="required where a web wraps it",
        doc="the web's wrap angle β on the roller"),
    Key(name="bearing_viscous", unit="N·m·s/rad", lo=0.0, hi=1e6, fmu="bearing_viscous",
        doc="viscous bearing drag c_v (torque −c_v ω)"),
    Key(name="bearing_coulomb", unit="N·m", lo=0.0, hi=1e6, fmu="bearing_coulomb",
        doc="Coulomb bearing drag τ_c (torque −τ_c tanh(ω / 0.1 rad/s))"),
    Key(name="drive", kind="table", default_text="none: an idler",
        doc="a pull roll's drive, a sub-table: the keys of a drum's drive"),
    Key(name="dancer", kind="table", default_text="none: a fixed roller",
        doc="a dancer's carriage, a sub-table: keys below (then wrap = π)"),
))

#: The keys of an idler's ``dancer`` sub-table (machines.md §11).
DANCER_KEYS = Table((
    Key(name="stiffness", required=True, unit="N/m", lo=0.0, lo_open=True, hi=1e10,
        doc="spring stiffness k of the carriage"),
    Key(name="damping", unit="N·s/m", lo=0.0, hi=1e9, fmu="dancer_damping",
        doc="damping c of the carriage"),
    Key(name="load", required=True, unit="N", hi=1e8,
        doc="net load F_load pushing the carriage out (both spans lengthen), its weight "
            "included"),
    Key(name="mass", required=True, unit="kg", lo=0.0, hi=1e6,
        doc="carriage mass m_d (the roller's own mass rides with it and adds to it)"),
    Key(name="travel", kind="pair", required=True, doc_unit="m",
        doc="the carriage's travel [lo, hi] (d = 0 at the centre); the run ends where d "
            "reaches an end",
        items=(Key(name="lo", doc="lower end", unit="m", hi=1e3),
               Key(name="hi", doc="upper end", unit="m", hi=1e3))),
))


@dataclass(frozen=True)
class DancerPart:
    """``dancer = { ... }``: an idler's sprung, damped, loaded carriage; keys, units,
    bounds and meanings: :data:`DANCER_KEYS`."""

    stiffness: float
    load: float
    mass: float
    travel: tuple[float, float]
    damping: float = 0.0

    def position(self, t_up: float, t_down: float) -> float:
        """Its static position ``d`` [m] under the tensions ``t_up``, ``t_down`` [N]:
        ``(F_load − T_up − T_down) / k`` (their ``max(T, 0)``)."""
        return (self.load - max(t_up, 0.0) - max(t_down, 0.0)) / self.stiffness


@dataclass(frozen=True)
class IdlerPart:
    """``[[idler]]``: a roller on a fixed centre; keys, units, bounds and meanings:
    :data:`KEYS` (its drive: :data:`~winder.parts.drum.DRIVE_KEYS`, None: undriven)."""

    name: str
    radius: float
    inertia: float
    centre: tuple[float, float]
    mass: float = 0.0
    sense: int = 1
    initial_speed: float = 0.0
    wrap: float | None = None
    bearing_viscous: float = 0.0
    bearing_coulomb: float = 0.0
    drive: SpeedProfileDrive | TorqueDrive | None = None
    dancer: DancerPart | None = None
    #: no flex: a rigid roller (the drum's machinery reads it)
    length: None = None
    flex: None = None


#: Its own channels (``BODY`` its name).
ROLLER_CHANNELS = (
    Channel(name="BODY_load_cell", unit="N",
            doc="bearing force of the two span tensions over the wrap, "
                "sqrt(T_up² + T_down² − 2 T_up T_down cos β)"),
    Channel(name="BODY_traction", unit="-",
            doc="share of the capstan limit used, |T_down − T_up| / ((exp(μ β) − 1) "
                "min(T_up, T_down)); 1 or more: the web slips"),
)


def roller_channels(mathns: Any, t_up: Any, t_down: Any, wrap: Any, mu: Any
                    ) -> tuple[Any, Any]:
    """``(load cell [N], traction [-])`` of a roller under ``t_up``, ``t_down`` [N] (already
    ``max(T, 0)``) over ``wrap`` [rad] with the web's ``mu`` (machines.md §11)."""
    load = mathns.sqrt(mathns.fmax(t_up * t_up + t_down * t_down
                                   - 2.0 * t_up * t_down * mathns.cos(wrap), 0.0))
    least = mathns.fmax(mathns.fmin(t_up, t_down), TRACTION_FLOOR)
    diff = t_down - t_up
    traction = mathns.fabs(diff) / ((mathns.power_abs(math.e, mu * wrap) - 1.0) * least)
    return load, traction


class IdlerBody(DrumBody):
    """An idler roller: fixed centre, constant radius, mass and inertia; turned by its web
    (the spans' tensions), slowed by its bearings, optionally driven as a drum."""

    table = "idler"
    role = "drum"
    KEYS = KEYS
    SUB_TABLES = {"drive": SubTable(DRIVE_KEYS, (SpeedProfileDrive, TorqueDrive),
                                    heading="drive (pull rolls)"),
                  "dancer": SubTable(DANCER_KEYS, (DancerPart,), heading="dancer")}
    part_cls = IdlerPart
    CHANNELS = ROLLER_CHANNELS

    @classmethod
    def parse(cls, reader: TableReader, label: str, raw: Any) -> IdlerPart:
        """Its keys and its optional drive (a drum's)."""
        kw = reader.keys(label, raw, KEYS)
        if "drive" in raw:
            dlabel = f"{label}.drive"
            d = reader.keys(dlabel, raw["drive"], DRIVE_KEYS)
            reader.kinds(dlabel, d, DRIVE_KEYS)
            if d["kind"] == "speed_profile" and "web_speed" not in d:
                raise reader.fail(dlabel, "web_speed",
                                  "missing required key (kind = 'speed_profile')")
            kw["drive"] = SpeedProfileDrive(**d) if d["kind"] == "speed_profile" \
                else TorqueDrive(**d)
        if "dancer" in raw:
            kw["dancer"] = _parse_dancer(reader, label, raw["dancer"], kw.get("wrap"))
        return IdlerPart(**kw)

    @classmethod
    def elements(cls, part: Any, placed: Any) -> list[Any]:
        return [(DancerBody if part.dancer is not None else cls)(part, placed)]

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        """The web wraps it as a roller of its line; fixed centre; bearing drag; a
        dancer's carriage; paced by a speed-profile drive (a pull roll)."""
        drive = getattr(part, "drive", None)
        return Roles(web="wraps", nip="fixed", roller=True, wrap=part.wrap,
                     bearing_torques=True, dancer=getattr(part, "dancer", None),
                     paced=getattr(drive, "kind", None) == "speed_profile")

    def drawing(self) -> Drawing:
        return Drawing(colour="idler")

    def __init__(self, part: Any, placed: Any = None) -> None:
        super(DrumBody, self).__init__(part)
        self.centre = tuple(part.centre)
        kind = part.drive.kind if part.drive is not None else None
        self.prescribed = kind == "speed_profile"
        self.torque_inputs = (f"{self.name}.torque",) if kind == "torque" else ()
        drag = part.bearing_viscous != 0.0 or part.bearing_coulomb != 0.0
        self.drives = ("bearing_friction",) if drag else ()

    def declare(self, machine: Machine) -> None:
        n, part = self.name, self.part
        machine.parameter(f"{n}.radius", part.radius)
        machine.parameter(f"{n}.inertia", part.inertia)
        machine.parameter(f"{n}.mass", part.mass)
        machine.parameter(f"{n}.wrap", part.wrap if part.wrap is not None else math.pi)
        machine.parameter(f"{n}.bearing_viscous", part.bearing_viscous)
        machine.parameter(f"{n}.bearing_coulomb", part.bearing_coulomb)
        if part.drive is not None:
            self._declare_drive(machine)

    def initial_rate(self, coord: str) -> float:
        """Spec §11: ``θ̇ = s · initial_speed``, a driven roller as a drum (§7)."""
        if coord != "theta":
            return 0.0
        if self.part.drive is None:
            return self.sense * self.part.initial_speed
        if self.prescribed:
            dr = self.part.drive
            return self.sense * dr.ratio * (dr.web_speed if dr.web_acceleration == 0
                                            else 0.0) / self.part.radius
        return super().initial_rate(coord)

    def breakpoints(self) -> tuple[float, ...]:
        return super().breakpoints() if self.part.drive is not None else ()

    def drive_torque(self, ev: Evaluation) -> Any:
        return ev.p(f"{self.name}.torque") if self.torque_inputs else None

    def outputs(self, ev: Evaluation, bs: BodyState) -> None:
        """Its load cell and traction from the tensions its web line provides (none: 0)."""
        up, down, mu = ev.provided("roller_tensions", self.name, (0.0, 0.0, 0.3))
        load, traction = roller_channels(ev.mathns, up, down, ev.p(f"{self.name}.wrap"), mu)
        ev.output(ROLLER_CHANNELS[0], self.name, load)
        ev.output(ROLLER_CHANNELS[1], self.name, traction)

    def drive_web_speed(self) -> float | None:
        return None if self.part.drive is None else super().drive_web_speed()

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{self.part.drive is not None}"


def _parse_dancer(reader: TableReader, label: str, raw: Any, wrap: float | None
                  ) -> DancerPart:
    """The ``dancer`` sub-table of ``[label]``: its keys, ``lo < hi``, and the roller's
    wrap π (machines.md §11: both spans pull the carriage back)."""
    dlabel = f"{label}.dancer"
    kw = reader.keys(dlabel, raw, DANCER_KEYS)
    lo, hi = kw["travel"]
    if not lo < hi:
        raise reader.fail(dlabel, "travel", f"[{lo!r}, {hi!r}]: valid: [lo, hi] with lo < hi "
                                            "[m]")
    if wrap is None or abs(wrap - math.pi) > 1e-9:
        raise reader.fail(label, "wrap", f"{'missing required key' if wrap is None else wrap!r}"
                                         f": a dancer's roller is wrapped by π (both spans pull "
                                         f"its carriage back); valid: wrap = {math.pi!r}")
    return DancerPart(**kw)


class DancerBody(IdlerBody):
    """An idler on a dancer's carriage (machines.md §11): states ``NAME.position`` [m]
    and ``NAME.position_dot`` [m/s] (their rates: its own and the web line's,
    ``m_d d̈ = F_load − k d − c ḋ − (T_up + T_down)``), both adjacent spans ``length + d``
    long; the run ends where ``d`` reaches an end of its travel (modes ``NAME.travel_lo``,
    ``NAME.travel_hi``). Its channels ``NAME_position``, ``NAME_position_dot`` are the web
    line's (``web_tension``), which moves the carriage."""

    def declare(self, machine: Machine) -> None:
        super().declare(machine)
        n, d = self.name, self.part.dancer
        machine.parameter(f"{n}.dancer_stiffness", d.stiffness)
        machine.parameter(f"{n}.dancer_damping", d.damping)
        machine.parameter(f"{n}.dancer_load", d.load)
        machine.parameter(f"{n}.dancer_mass", d.mass + self.part.mass)
        machine.parameter(f"{n}.travel_lo", d.travel[0])
        machine.parameter(f"{n}.travel_hi", d.travel[1])
        machine.state(f"{n}.position", d.position(*self.initial_tensions(machine)))
        machine.state(f"{n}.position_dot", 0.0)
        for end in ("lo", "hi"):
            machine.mode(f"{n}.travel_{end}", (f"{n}.beyond_{end}",), ModeKind.END, owner=n,
                         state=f"{n}.position", param=f"{n}.travel_{end}")

    def initial_tensions(self, machine: Machine) -> tuple[float, float]:
        """The initial tensions [N] of the spans arriving at it and leaving it."""
        for w in machine.webs:
            for s in w.spans[1:]:
                if s.upstream is self:
                    up = w.spans[s.index - 1].part
                    t_in = w.spans[0].part.T_in
                    return tuple(t_in if p.initial_tension is None else p.initial_tension
                                 for p in (up, s.part))  # type: ignore[return-value]
        return (0.0, 0.0)

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        super().kinematics(ev, bs)
        n = self.name
        d = ev.x(f"{n}.position")
        ev.set_rate(f"{n}.position", ev.x(f"{n}.position_dot"))
        ev.switches[f"{n}.beyond_lo"] = ev.p(f"{n}.travel_lo") - d
        ev.switches[f"{n}.beyond_hi"] = d - ev.p(f"{n}.travel_hi")
