"""The single-drum format (the old one: tables ``[drum]``, ``[drum.drive]``, ``[roll]``,
``[paper]``, ``[contact]``, ``[friction]``; spec section 7). The only module that knows
it: its tables of keys (read from the parts' declarations, plus ``[roll]
initial_height``), its dataclasses, its parsing and its translation into parts (machines
spec §8, last paragraph): drum "drum" at the origin, sense +1; roll "roll" free in ``z``
at ``(0, R + r0)``, sense −1; nip "nip" (a = drum, b = roll); web entering at "nip" with
tension 0; and its names (:class:`SingleDrumNaming`): the result columns of winder-model
§8 (:data:`COLUMNS`), its keys in messages, its FMU interface.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

from winder._errors import SceneError
from winder._schema import Channel, Key, Table
from winder.forces.web_momentum import WebMomentum
from winder.model.channels import BODY_CHANNELS, COORD_CHANNELS, NIP_CHANNELS, WEB_SPEED
from winder.model.paper_roll import paper_roll_mass
from winder.parts import (
    ContactLaw,
    DrumPart,
    FrictionLaw,
    NipPart,
    RollBody,
    RollPart,
    SpeedProfileDrive,
    TorqueDrive,
    WebPart,
)
from winder.parts import drum as _drum
from winder.parts import nip as _nip
from winder.parts import roll as _roll
from winder.scene.checks import check_roll_core
from winder.scene.naming import FmuNames, Naming
from winder.scene.parse import fail, parse_table
from winder.scene.schema import PAPER_KEYS, TABLES
from winder.scene.tables import Effects, Paper

__all__ = ["Drive", "Drum", "Roll", "LegacyContact", "LegacyFriction", "LEGACY_TABLES",
           "TABLE_NAMES", "OWN_TABLES", "is_legacy", "parse_tables", "build", "legacy_parts",
           "check_rest_on_nip", "COLUMNS", "CHANNELS", "EXTRA_CHANNELS", "SingleDrumNaming",
           "SINGLE_DRUM"]

#: ``[drum]``: a drum's body keys.
DRUM_KEYS = Table(_drum.KEYS.select("radius", "inertia", "mass"))
#: ``[drum.drive]``: a drum's drive keys but ``ratio``.
DRIVE_KEYS = Table(_drum.DRIVE_KEYS.select("kind", "web_acceleration", "web_speed", "torque"),
                   kinds={k: tuple(n for n in v if n != "ratio")
                          for k, v in _drum.DRIVE_KEYS.kinds.items()})
#: ``[roll]``: a roll's core and start keys, and the old format's own ``initial_height``.
ROLL_KEYS = Table((
    *_roll.KEYS.select("core_radius", "core_mass", "core_inertia", "width", "initial_radius",
                       "initial_speed", "com_offset"),
    Key(name="initial_height", unit="m", hi=1e3, default_text="static balance on the nip",
        doc="height z of the roll axis at t = 0, above the drum radius (e.g. to drop the "
            "roll onto the drum)"),
))
#: The tables of the single-drum format by schema name (those of both formats too).
LEGACY_TABLES: dict[str, Table] = {
    "scene": TABLES["scene"], "effects": TABLES["effects"], "drum": DRUM_KEYS,
    "drum.drive": DRIVE_KEYS, "roll": ROLL_KEYS, "paper": PAPER_KEYS,
    "contact": _nip.CONTACT_KEYS, "friction": _nip.FRICTION_KEYS, "solver": TABLES["solver"],
}
#: The top-level tables of a single-drum scene.
TABLE_NAMES = tuple(t for t in LEGACY_TABLES if t != "drum.drive")
#: The tables of a single-drum scene that a scene of parts does not have (its
#: :class:`~winder.scene.scene.Scene` fields).
OWN_TABLES = ("drum", "roll", "paper", "contact", "friction")
#: The tables a single-drum scene must have.
REQUIRED_TABLES = ("scene", "drum", "roll", "paper")

# ---- names -------------------------------------------------------------------------------
_DECLARED: dict[str, Channel] = {c.name: c for c in (
    *BODY_CHANNELS, *COORD_CHANNELS["z"], *NIP_CHANNELS, WEB_SPEED, *RollBody.CHANNELS,
    *WebMomentum.CHANNELS)}

#: The result columns of a single-drum scene after ``t``, in order (winder-model §8: the
#: standard 15, then winder's extras): column → (the channel's declaration, its owner: the
#: part's name, or ``""`` for the web), i.e. the machine's channel ``declaration.of(owner)``.
COLUMNS: dict[str, tuple[Channel, str]] = {column: (_DECLARED[pattern], owner) for
                                           column, (pattern, owner) in {
    "drum_speed": ("BODY_speed", "drum"), "drum_torque": ("BODY_torque", "drum"),
    "roll_speed": ("BODY_speed", "roll"), "roll_accel": ("BODY_accel", "roll"),
    "roll_angle": ("BODY_angle", "roll"), "radius": ("ROLL_radius", "roll"),
    "mass": ("ROLL_mass", "roll"), "inertia": ("ROLL_inertia", "roll"),
    "mass_rate": ("ROLL_mass_rate", "roll"), "inertia_rate": ("ROLL_inertia_rate", "roll"),
    "z": ("BODY_z", "roll"), "z_dot": ("BODY_z_dot", "roll"),
    "normal_force": ("NIP_normal_force", "nip"),
    "friction_force": ("NIP_friction_force", "nip"),
    "slip_velocity": ("NIP_slip_velocity", "nip"), "drum_angle": ("BODY_angle", "drum"),
    "web_speed": ("web_speed", ""), "z_accel": ("BODY_z_accel", "roll"),
    "web_force": ("web_force", ""), "penetration": ("NIP_penetration", "nip"),
}.items()}

#: Result channels of a single-drum scene (winder-model §8), in order (first column ``t``).
CHANNELS = ("t", *list(COLUMNS)[:15])
#: Its extra channels (winder's own): drum angle, web speed, roll vertical acceleration,
#: web momentum force, penetration.
EXTRA_CHANNELS = tuple(list(COLUMNS)[15:])

#: The resonance map's table of a single-drum scene (:meth:`winder.ModeMap.as_columns`).
MODE_MAP_COLUMNS = ("radius", "bounce_frequency", "bounce_damping", "slip_frequency",
                    "slip_damping", "rotation_1x", "rotation_2x", "critical_web_speed")

#: The keys that place the drum and the roll (their parts' ``centre``).
_PLACE_KEYS = {("drum", "centre"): "[drum] radius", ("roll", "centre"): "[roll] initial_radius"}


@dataclass(frozen=True)
class SingleDrumNaming(Naming):
    """The names of a single-drum scene: its result columns (:data:`COLUMNS`; a channel
    the machine lacks with an effect off, e.g. ``web_force``, is zeros in its declared
    unit), its keys in messages (``[drum.drive]``, ``[friction] mu``, the drum placed by
    ``[drum] radius``, the roll by ``[roll] initial_radius``), its FMU interface."""

    by_parts: ClassVar[bool] = False
    fmu: ClassVar[FmuNames | None] = FmuNames(
        parameters={
            "profile_web_speed": ("drum.drive", "web_speed"),
            "web_acceleration": ("drum.drive", "web_acceleration"),
            "com_offset": ("roll", "com_offset"),
            "contact_stiffness": ("contact", "stiffness"),
            "contact_damping": ("contact", "damping"),
            "mu": ("friction", "mu"),
            "slip_reference_velocity": ("friction", "slip_velocity"),
            "relaxation_length": ("friction", "relaxation_length"),
            "caliper": ("paper", "caliper"),
            "density": ("paper", "density"),
            "width": ("roll", "width"),
        },
        profile_switch="speed_profile", inputs={"drum_torque_command": "drum_torque"},
        profile_reference="web_speed_reference", acceleration="web_acceleration",
        speed="profile_web_speed",
        switch_doc="true: drum follows the web-speed profile; false: driven by")
    #: a result written before the drum angle was a channel draws the drum still
    optional: ClassVar[frozenset[str]] = frozenset({"drum_angle"})
    #: a result without its scene is one of this format (its drum and its roll, free in z)
    bodies_without_scene: ClassVar[Mapping[str, tuple[str, ...]]] = {
        "drum": ("angle", "speed"), "roll": ("z", "angle", "speed", "radius")}

    def outputs(self, units: Mapping[str, str]) -> dict[str, tuple[str, str]]:
        return {column: (decl.of(owner), decl.unit) for column, (decl, owner) in COLUMNS.items()}

    def output_name(self, channel: str) -> str:
        return _COLUMN_OF.get(channel, channel)

    def inputs(self, inputs: Mapping[str, str]) -> dict[str, str]:
        """``drum_torque``, the drum's torque (set only with drive kind ``torque``)."""
        return {"drum_torque": "drum.torque"}

    def key(self, table: str, part: str, *path: str) -> str:
        if (table, *path) in _PLACE_KEYS:
            return _PLACE_KEYS[(table, *path)]
        if table == "nip" and path:  # the nip's laws are tables of their own
            table, path = path[0], path[1:]
        elif table == "drum" and path[:1] == ("drive",):
            table, path = "drum.drive", path[1:]
        return " ".join((f"[{table}]", *path))

    def drive_changes(self, scene: Any, changes: dict[str, Any], speed_profile: bool) -> None:
        """Add the changes of ``[drum.drive]`` to ``changes`` for the FMU's
        :attr:`FmuNames.profile_switch`: true drives the drum along its profile, false
        frees it, started at the profile's initial speed, on the torque input."""
        drive = changes.setdefault("drum", {}).setdefault("drive", {})
        d = scene.drum.drive
        a = drive.get("web_acceleration", d.web_acceleration)
        v = drive.get("web_speed", d.web_speed)
        if speed_profile:
            drive.update(kind="speed_profile", web_acceleration=a, web_speed=v)
        else:  # free drum, started at the profile's initial speed
            drive.update(kind="torque", web_acceleration=a, web_speed=0.0 if a > 0 else v,
                         torque=0.0)

    def result_meta(self, scene: Any) -> dict[str, Any]:
        """``drum_radius`` [m]: the paper figures mark where the roll passes it."""
        return {"drum_radius": scene.drum.radius}

    def mode_map_columns(self, columns: Mapping[str, Any]) -> dict[str, Any]:
        """The historic columns only (:data:`MODE_MAP_COLUMNS`)."""
        return {k: v for k, v in columns.items() if k in MODE_MAP_COLUMNS}


_COLUMN_OF = {decl.of(owner): column for column, (decl, owner) in COLUMNS.items()}
#: The naming of every single-drum scene (and of a result without its scene).
SINGLE_DRUM = SingleDrumNaming()


@dataclass(frozen=True)
class Drive:
    """``[drum.drive]``: ``speed_profile`` (web speed ramps at ``web_acceleration``
    [m/s²] to ``web_speed`` [m/s]) or ``torque`` (drum free, driven by an input torque
    ``torque`` [N·m]; ``web_speed`` then is the initial web speed); bounds:
    :data:`DRIVE_KEYS`."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    torque: float = 0.0


@dataclass(frozen=True)
class Drum:
    """``[drum]``: radius [m], inertia (polar) [kg·m²], mass [kg]; bounds:
    :data:`DRUM_KEYS`."""

    radius: float
    inertia: float
    mass: float
    drive: Drive = field(default_factory=Drive)


@dataclass(frozen=True)
class Roll:
    """``[roll]``: core_radius [m], core_mass [kg], core_inertia [kg·m²], width [m],
    initial_radius [m] (at least core_radius; default: core_radius), initial_speed
    [rad/s], com_offset ``e`` [m] with ``0 <= e <``
    :func:`~winder.model.mass_law.max_com_offset` (inside the core, and the core's inertia
    about its centre of mass stays positive); winder's own key initial_height [m]: ``z``
    at ``t = 0`` (default: static equilibrium on the contact, spec §6), e.g. to drop the
    roll onto the drum; the roll axis must lie above the drum's surface. Bounds:
    :data:`ROLL_KEYS`."""

    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    initial_radius: float
    initial_speed: float = 0.0
    com_offset: float = 0.0
    initial_height: float | None = None


@dataclass(frozen=True)
class LegacyContact(ContactLaw):
    """``[contact]`` of the single-drum format: the nip's :class:`~winder.parts.ContactLaw`
    (law, stiffness, damping, exponent, hc_damping; same keys and bounds)."""


@dataclass(frozen=True)
class LegacyFriction(FrictionLaw):
    """``[friction]`` of the single-drum format: the nip's
    :class:`~winder.parts.FrictionLaw` (mu, slip_velocity, relaxation_length, min_speed;
    same keys and bounds)."""


def legacy_parts(drum: Drum, roll: Roll, paper: Paper, contact: LegacyContact,
                 friction: LegacyFriction) -> dict[str, Any]:
    """The parts of a single-drum scene from its tables (machines spec §8, last
    paragraph): the keyword arguments ``drums``, ``rolls``, ``riders``, ``nips``,
    ``webs`` of :class:`~winder.scene.scene.Scene`."""
    d = drum.drive
    drive: SpeedProfileDrive | TorqueDrive = (
        TorqueDrive(torque=d.torque, web_speed=d.web_speed) if d.kind == "torque" else
        SpeedProfileDrive(web_acceleration=d.web_acceleration, web_speed=d.web_speed))
    return {
        "drums": (DrumPart(name="drum", radius=drum.radius, inertia=drum.inertia,
                           mass=drum.mass, centre=(0.0, 0.0), sense=1, drive=drive),),
        "rolls": (RollPart(name="roll", kind="wound",
                           centre=(0.0, drum.radius + roll.initial_radius), free=("z",),
                           sense=-1, core_radius=roll.core_radius, core_mass=roll.core_mass,
                           core_inertia=roll.core_inertia, width=roll.width,
                           initial_radius=roll.initial_radius,
                           initial_speed=roll.initial_speed, com_offset=roll.com_offset,
                           density=paper.density, caliper=paper.caliper,
                           held_z=roll.initial_height),),
        "riders": (),
        "nips": (NipPart(name="nip", a="drum", b="roll",
                         contact=ContactLaw(**dataclasses.asdict(contact)),
                         friction=FrictionLaw(**dataclasses.asdict(friction))),),
        "webs": (WebPart(entry_nip="nip", tension=0.0),),
    }


def is_legacy(data: Mapping[str, Any]) -> bool:
    """Whether ``data`` is in the single-drum format: a single-table ``[drum]`` or
    ``[roll]``."""
    return any(isinstance(data.get(t), dict) for t in ("drum", "roll"))


def parse_tables(source: str, data: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The keys of a single-drum scene's own tables, each checked against its declaration
    (``[drum]`` without its sub-table ``drive``)."""
    for table in REQUIRED_TABLES:
        if table not in data:
            raise SceneError(f"{source}: [{table}]: missing required table")
    out = {}
    for name in ("drum", "roll", "paper", "contact", "friction"):
        raw = data.get(name, {})
        sub = ("drive",) if name == "drum" else ()
        if sub and isinstance(raw, dict):
            raw = {k: v for k, v in raw.items() if k not in sub}
        out[name] = parse_table(source, name, raw, LEGACY_TABLES[name], sub_tables=sub)
    return out


def build(source: str, data: Mapping[str, Any], tables: Mapping[str, dict[str, Any]],
          effects: Effects, gravity: float) -> dict[str, Any]:
    """The keyword arguments ``drum``, ``roll``, ``paper``, ``contact``, ``friction`` of
    :class:`~winder.scene.scene.Scene` from the parsed ``tables``
    (:func:`parse_tables`), with the checks across them (the roll resting on the nip:
    ``effects``, ``gravity`` [m/s²] of ``[scene]``)."""
    drum_raw = data["drum"]
    if "drive" not in drum_raw:
        raise SceneError(f"{source}: [drum.drive]: missing required table")
    drive = parse_table(source, "drum.drive", drum_raw["drive"], DRIVE_KEYS)
    roll_kw = dict(tables["roll"])
    roll_kw.setdefault("initial_radius", roll_kw["core_radius"])
    check_roll_core(source, "roll", roll_kw)
    roll = Roll(**roll_kw)
    radius = tables["drum"]["radius"]
    if roll.initial_height is not None and not roll.initial_height > radius:
        raise fail(source, "roll", "initial_height",
                   f"{roll.initial_height!r} m puts the roll axis inside the drum or below "
                   f"it; valid: > {radius!r} m (the drum radius, [drum] radius) and <= "
                   f"{ROLL_KEYS['initial_height'].hi:g} m")
    if drive["kind"] == "speed_profile" and "web_speed" not in drive:
        raise fail(source, "drum.drive", "web_speed", "missing required key "
                   "(kind = 'speed_profile')")
    contact = LegacyContact(**tables["contact"])
    if effects.contact and "contact" not in data:
        raise SceneError(f"{source}: [contact]: missing required table (effects.contact is on)")
    paper = Paper(**tables["paper"])
    check_rest_on_nip(source, effects, gravity, roll, paper, contact)
    return {"drum": Drum(**tables["drum"], drive=Drive(**drive)), "roll": roll,
            "paper": paper, "contact": contact,
            "friction": LegacyFriction(**tables["friction"])}


def check_rest_on_nip(source: str, effects: Effects, gravity: float, roll: Roll,
                      paper: Paper, contact: LegacyContact) -> None:
    """Spec §6 starts the roll at rest on the nip (``F_n = m g``): the nip must carry the
    roll's weight with a compression below the roll's radius, else the roll axis would
    start inside the drum."""
    if not effects.contact or roll.initial_height is not None:
        return
    from winder.forces.contact import rest_penetration

    r = roll.initial_radius
    mass = paper_roll_mass(r, roll.core_radius, roll.core_mass, roll.core_inertia,
                           math.pi * paper.density * roll.width)[0]
    weight = mass * (gravity if effects.gravity else 0.0)
    r_dot = paper.caliper / (2 * math.pi) * roll.initial_speed
    c = contact
    delta = rest_penetration(c.law, lambda k: getattr(c, k), weight, r_dot)
    if not delta < r:
        raise fail(source, "contact", "stiffness",
                    f"{c.stiffness!r} ({c.law}) is too soft for the roll's weight "
                    f"{weight:.4g} N: at rest the nip would be compressed by {delta:.3g} m, "
                    f"more than the roll's radius {r!r} m, with the roll axis inside the "
                    "drum (weight from [roll] core_mass, initial_radius, width, [paper] "
                    "density, [scene] gravity; compression from [contact] stiffness, "
                    "damping, exponent, hc_damping and [roll] initial_speed); valid: a "
                    "stiffer nip or a lighter roll, so that the compression stays below the "
                    "roll's radius")
