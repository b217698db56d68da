"""Drums (machines spec §1, §6, §8 ``[[drum]]``): bodies with a fixed centre and a
constant radius, driven by a speed profile or a torque; rigid, or flexible (issue #25:
``flex = { segments = N, ... }``, :mod:`winder.parts.flex`): then N segment bodies
(:class:`DrumSegment`) joined by the force element ``flex_beam``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from winder._schema import Key, Table
from winder.parts._base import Drawing, RigidDisc, Roles, SubTable, TableReader, segment_count
from winder.parts._keys import CENTRE, NAME
from winder.parts.flex import FLEX_KEYS, FlexPart, parse_flex

if TYPE_CHECKING:
    from winder.model.machine import BodyState, Evaluation, Machine

__all__ = ["DrumPart", "SpeedProfileDrive", "TorqueDrive", "DrumBody", "DrumSegment", "KEYS",
           "DRIVE_KEYS", "DRIVE_KINDS"]

#: Drive kinds of a drum.
DRIVE_KINDS = ("speed_profile", "torque")

#: The keys of ``[[drum]]``: one declaration each (units, bounds, meaning).
KEYS = Table((
    NAME,
    Key(name="radius", required=True, unit="m", lo=0.0, lo_open=True, hi=10.0,
        doc="drum radius R"),
    Key(name="inertia", required=True, unit="kg·m²", lo=0.0, lo_open=True, hi=1e7,
        doc="polar moment of inertia J_d about the drum axis"),
    Key(name="mass", required=True, unit="kg", lo=0.0, lo_open=True, hi=1e6,
        doc="drum mass"),
    CENTRE,
    Key(name="sense", kind="sense",
        doc="operation direction: +1 turns the top surface towards +x"),
    Key(name="drive", kind="table", required=True,
        doc="the drive, a sub-table: keys below"),
    Key(name="length", unit="m", lo=0.0, lo_open=True, hi=50.0,
        default_text="required with flex; else unused",
        doc="length L of the drum along its axis"),
    Key(name="flex", kind="table",
        default_text="none: a rigid drum",
        doc="a flexible drum, a sub-table: keys below (issue #25); its nips are sliced, one "
            "slice per segment"),
))

#: The keys of a drum's ``drive``; ``kinds``: the keys each drive kind takes.
DRIVE_KEYS = Table((
    Key(name="kind", kind="str", required=True, choices=DRIVE_KINDS,
        doc="speed_profile: the drum's speed is prescribed, its torque follows from inverse "
            "dynamics; torque: the drum is free and driven by an input torque"),
    Key(name="web_acceleration", unit="m/s²", fmu="web_acceleration", lo=0.0, hi=1e3,
        doc="ramp of the surface (web) speed a_w; 0: full speed from t = 0"),
    Key(name="web_speed", unit="m/s", lo=0.0, hi=1e3, fmu="web_speed",
        default_text="required (kind speed_profile); 0 (kind torque)",
        doc="speed_profile: the surface speed v_w the ramp reaches; torque: the initial "
            "surface speed"),
    Key(name="ratio", unit="-", lo=0.0, lo_open=True, hi=100.0,
        doc="kind speed_profile: the drum runs at ratio × the profile's surface speed"),
    Key(name="torque", unit="N·m", hi=1e8,
        doc="kind torque: the drive torque (operation sense), constant or an input"),
), kinds={"speed_profile": ("kind", "web_acceleration", "web_speed", "ratio"),
          "torque": ("kind", "torque", "web_speed")})


@dataclass(frozen=True)
class SpeedProfileDrive:
    """``drive = { kind = "speed_profile" }``: the drum's speed is prescribed,
    ``Ω(t) = ratio · min(web_acceleration · t, web_speed) / R`` [rad/s]; keys, units and
    bounds: :data:`DRIVE_KEYS`."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    ratio: float = 1.0


@dataclass(frozen=True)
class TorqueDrive:
    """``drive = { kind = "torque" }``: the drum turns freely under the input torque
    ``torque`` [N·m] (operation sense); ``web_speed`` [m/s] is its initial surface speed;
    bounds: :data:`DRIVE_KEYS`."""

    kind: str = "torque"
    torque: float = 0.0
    web_speed: float = 0.0


@dataclass(frozen=True)
class DrumPart:
    """``[[drum]]``: a drum of fixed centre and constant radius, mass and inertia, with its
    drive; keys, units, bounds and meanings: :data:`KEYS` (its drive: :data:`DRIVE_KEYS`)."""

    name: str
    radius: float
    inertia: float
    mass: float
    centre: tuple[float, float]
    sense: int = 1
    drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive()
    length: float | None = None
    flex: FlexPart | None = None


class DrumBody(RigidDisc):
    """A drum: fixed centre, constant radius, mass and inertia; driven by a speed profile
    (prescribed, machines.md §6: ``Ω = ratio · min(a_w t, v_w) / R`` [rad/s], no ``θ``
    state) or by an input torque ``NAME.torque`` [N·m]."""

    table = "drum"
    role = "drum"
    KEYS = KEYS
    SUB_TABLES = {"drive": SubTable(DRIVE_KEYS, (SpeedProfileDrive, TorqueDrive)),
                  "flex": SubTable(FLEX_KEYS, (FlexPart,))}
    part_cls = DrumPart

    @classmethod
    def parse(cls, reader: TableReader, label: str, raw: Any) -> DrumPart:
        """Its keys and its drive (machines spec §6)."""
        kw = reader.keys(label, raw, KEYS)
        dlabel = f"{label}.drive"
        d = reader.keys(dlabel, raw["drive"], DRIVE_KEYS)
        reader.kinds(dlabel, d, DRIVE_KEYS)
        if d["kind"] == "speed_profile":
            if "web_speed" not in d:
                raise reader.fail(dlabel, "web_speed",
                                  "missing required key (kind = 'speed_profile')")
            drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive(**d)
        else:
            drive = TorqueDrive(**d)
        if "flex" in raw:
            kw["flex"] = parse_flex(reader, label, raw["flex"], kw.get("length"))
        return DrumPart(**kw, drive=drive)

    @classmethod
    def elements(cls, part: Any, placed: Any) -> list[Any]:
        """A rigid drum: itself; a flexible one: its segments (:class:`DrumSegment`)."""
        if getattr(part, "flex", None) is None:
            return [cls(part, placed)]
        return [DrumSegment(part, i, placed) for i in range(part.flex.segments)]

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        """The web wraps it (an entry drum); fixed centre; sliced where flexible."""
        return Roles(web="wraps", nip="fixed",
                     segments=segment_count(part))

    def drawing(self) -> Drawing:
        return Drawing(colour="drum")

    def __init__(self, part: Any, placed: Any = None) -> None:
        super().__init__(part)
        self.centre = tuple(part.centre)
        self.prescribed = part.drive.kind == "speed_profile"
        self.torque_inputs = () if self.prescribed else (f"{self.name}.torque",)

    def declare(self, machine: Machine) -> None:
        super().declare(machine)
        self._declare_drive(machine)

    def _declare_drive(self, machine: Machine) -> None:
        n, dr = self.name, self.part.drive
        if self.prescribed:
            aw, vw = dr.web_acceleration, dr.web_speed
            machine.parameter(f"{n}.web_acceleration", aw)
            machine.parameter(f"{n}.web_speed", vw)
            machine.parameter(f"{n}.ratio", dr.ratio)
            machine.parameter(f"{n}.ramp_time", vw / aw if aw > 0 else 0.0)
        else:  # named by its input: a flexible drum's is the drum's, not its segment's
            machine.parameter(self.torque_inputs[0], dr.torque)

    def initial_rate(self, coord: str) -> float:
        """Spec §7: ``θ̇ = s · web_speed / R`` (a torque drive's initial web speed)."""
        if coord != "theta":
            return 0.0
        return self.sense * self.part.drive.web_speed / self.part.radius

    def breakpoints(self) -> tuple[float, ...]:
        """The end of the speed ramp ``v_w / a_w`` [s] (a kink of the prescribed speed)."""
        dr = self.part.drive
        return (dr.web_speed / dr.web_acceleration,) \
            if self.prescribed and dr.web_acceleration > 0 else ()

    def operating_speed(self, web_speed: float) -> float:
        """``ratio · v / R`` [rad/s]."""
        return self.part.drive.ratio * web_speed / self.part.radius

    def hold_operating_speed(self, machine: Machine, params: Any, web_speed: float) -> None:
        """No ramp: ``ramp_time = 0``, ``web_speed = v``."""
        if self.prescribed:
            params[machine.param_index(f"{self.name}.ramp_time")] = 0.0
            params[machine.param_index(f"{self.name}.web_speed")] = web_speed

    def kinematics(self, ev: Evaluation, bs: BodyState) -> None:
        n, mathns, t = self.name, ev.mathns, ev.t
        if self.prescribed:  # machines.md §6: Ω = ratio·min(a_w t, v_w)/R
            R, k = ev.p(f"{n}.radius"), ev.p(f"{n}.ratio")
            aw, vw, tr = (ev.p(f"{n}.web_acceleration"), ev.p(f"{n}.web_speed"),
                          ev.p(f"{n}.ramp_time"))
            ramp = t < tr
            s = self.sense
            bs.theta = s * k / R * mathns.if_else(ramp, 0.5 * aw * t * t,
                                                  0.5 * aw * tr * tr + vw * (t - tr))
            bs.omega = s * k / R * mathns.if_else(ramp, aw * t, vw)
            bs.alpha_prescribed = s * k / R * mathns.if_else(ramp, aw, 0.0)
        super().kinematics(ev, bs)

    def drive_torque(self, ev: Evaluation) -> Any:
        return None if self.prescribed else ev.p(self.torque_inputs[0])

    # ---- for the analyses ---------------------------------------------------------------
    def drive_web_speed(self) -> float | None:
        """Its drive's ``web_speed`` [m/s]."""
        return float(self.part.drive.web_speed)

    def surface_speed(self, web_speed: float) -> float:
        """``ratio · v`` [m/s] (a speed profile's ``ratio``; a torque drive: ``v``)."""
        return getattr(self.part.drive, "ratio", 1.0) * web_speed

    def web_length(self, duration: float, web_speed: float) -> float:
        """Web [m] over ``duration`` ``T`` [s] at ``web_speed`` ``v`` [m/s] along its
        profile: the ramp at ``web_acceleration`` ``a_w`` to ``v`` (none: ``v`` from the
        start), ``a_w T²/2`` within the ramp, else ``v T − v t_r/2`` with ``t_r = v/a_w``."""
        a, v, T = getattr(self.part.drive, "web_acceleration", 0.0), web_speed, duration
        if a > 0.0 and v > 0.0:
            tr = v / a
            return a * T * T / 2 if T <= tr else v * T - v * tr / 2
        return v * T


class DrumSegment(DrumBody):
    """Segment ``i`` of a flexible drum (issue #25): a body ``NAME_s{i}`` free along ``x``
    and ``z`` (its deflection from the drum's ``centre``, the line of its bearings) that
    turns about ``+y``, of mass ``m/N`` [kg], polar inertia ``J/N`` [kg·m²] and the drum's
    radius [m]; segment 0 is the drive end and carries the drive (a speed profile
    prescribes its rotation alone; a torque drive acts on it alone, its input the drum's
    ``NAME.torque`` as the rigid drum's). The beam and the torsion between the segments
    are the force element ``flex_beam``, which every segment calls for (:attr:`drives`)."""

    #: the axes its bearings hold (the beam's supports)
    bearing_axes = ("x", "z")

    def __init__(self, part: Any, index: int, placed: Any = None) -> None:
        super().__init__(part, placed)
        flex = part.flex
        #: the drum's name, its segment index (0: drive end) and count
        self.drum, self.index, self.segments = part.name, index, flex.segments
        #: the flexible body's data for the force element ``flex_beam``
        self.flex, self.length = flex, float(part.length)
        self.name = f"{part.name}_s{index}"
        self.segment_of = part.name
        self.whole_free = self.free  # the rigid drum's: none
        self.free = ("x", "z")
        self.prescribed = index == 0 and part.drive.kind == "speed_profile"
        # the drum's input, as the rigid drum's: DRUM.torque (the FMU's DRUM_torque)
        self.torque_inputs = (f"{part.name}.torque",) \
            if index == 0 and part.drive.kind == "torque" else ()
        self.drives = ("flex_beam",)

    def drawing(self) -> Drawing:
        h = self.length / self.segments
        return Drawing(colour="drum", width=h, y=(self.index + 0.5) * h - self.length / 2)

    def declare(self, machine: Machine) -> None:
        n, part, N = self.name, self.part, self.segments
        machine.parameter(f"{n}.radius", part.radius)
        machine.parameter(f"{n}.inertia", part.inertia / N)
        machine.parameter(f"{n}.mass", part.mass / N)
        if self.index == 0:
            self._declare_drive(machine)

    def drive_torque(self, ev: Evaluation) -> Any:
        return ev.p(self.torque_inputs[0]) if self.torque_inputs else None

    def drive_web_speed(self) -> float | None:
        """Its drive's ``web_speed`` [m/s] (segment 0 only)."""
        return super().drive_web_speed() if self.index == 0 else None

    def structure_tag(self) -> str:
        return f"{super().structure_tag()}:{self.index}/{self.segments}"

    def initial_rate(self, coord: str) -> float:
        """Spec §7 for every segment: a torque drive's ``s · web_speed / R``, a speed
        profile's ``Ω(0)`` [rad/s]; translational rates 0."""
        dr = self.part.drive
        if coord != "theta" or dr.kind == "torque":
            return super().initial_rate(coord)
        return self.sense * dr.ratio * (dr.web_speed if dr.web_acceleration == 0 else 0.0) \
            / self.part.radius
