"""Scene files (TOML, spec section 7; machines spec §8): frozen dataclasses that validate
on construction.

Two formats load: the single-drum format (tables ``[drum]``, ``[roll]``, ``[contact]``,
``[friction]``; :attr:`Scene.legacy`) and scenes of parts (arrays of tables ``[[drum]]``,
``[[roll]]``, ``[[rider]]``, ``[[nip]]``, and ``[web]`` (or ``[[web]]``, one per wound
roll) with its optional ``[web.span]`` from an unwinding roll). A single-drum scene is also
converted to parts (drum "drum", roll "roll", nip "nip", web entering at "nip"), so code
written for parts reads both.

Every error names the file, the table (an element of an array by its name, ``[drum
'front']``) and the key, and the offending value.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from winder._args import ATOL_MAX, RTOL_MAX, check_real, show
from winder._errors import ArgumentError, ArgumentTypeError, SceneError
from winder.parts import (
    AXES,
    CONTACT_LAWS,
    ROLL_KINDS,
    UNWIND_DRIVE_KINDS,
    ContactLaw,
    DrumPart,
    FrictionLaw,
    NipPart,
    RiderPart,
    RollPart,
    SpanPart,
    SpeedProfileDrive,
    TensionControl,
    TorqueDrive,
    UnwindTorqueDrive,
    WebPart,
)

__all__ = ["Scene", "SceneInfo", "Effects", "Drum", "Drive", "Roll", "Paper", "Contact",
           "Friction", "Solver", "load_scene", "scene_from_dict", "EFFECT_NAMES",
           "DRIVE_KINDS", "CONTACT_LAWS", "METHODS", "BACKENDS"]

EFFECT_NAMES = ("variable_mass", "web_momentum", "web_tension", "gravity", "imbalance",
                "contact", "slip_relaxation", "rider_load")
DRIVE_KINDS = ("speed_profile", "torque")
METHODS = ("auto", "DOPRI5", "RK4", "ROS2", "RK45", "DOP853", "Radau", "BDF", "LSODA",
           "RK23")
#: Right-hand side backends: the compiled planar equations, or Pinocchio's ABA.
BACKENDS = ("compiled", "pinocchio")


#: Most output samples a scene may ask for (``duration / output_step``); each sample holds
#: some twenty channels of 8 bytes.
MAX_SAMPLES = 10_000_000
#: Longest scene name [characters].
MAX_NAME = 200


def _name(key: Any) -> str:
    """A table or key name for a message: as is if short and printable, else its repr."""
    plain = isinstance(key, str) and 0 < len(key) <= 40 and key.isprintable()
    return key if plain else show(key, 40)


def _fail(source: str, table: str, key: str, message: str) -> SceneError:
    return SceneError(f"{source}: [{table}] {_name(key)}: {message}")


def _check_number(source: str, table: str, key: str, value: Any, *, lo: float | None = None,
                  lo_open: bool = False, hi: float | None = None) -> float:
    """A finite number in ``[lo, hi]`` (``(lo, hi]`` when ``lo_open``); with ``lo`` None
    the bound ``hi`` applies to ``|value|``."""
    number, problem, _ = check_real(value, lo=lo, lo_open=lo_open, hi=hi)
    if problem is not None:
        raise _fail(source, table, key, problem)
    return number


# Lower bounds (value, open) of the table schemas in _SPEC.
_POS, _NONNEG = (0.0, True), (0.0, False)


@dataclass(frozen=True)
class SceneInfo:
    """``[scene]``: name (1 to 200 printable characters), duration (0, 1e6] [s],
    output_step (0, duration] [s] with at most :data:`MAX_SAMPLES` samples, gravity
    [0, 1000] [m/s²]."""

    name: str = "scene"
    duration: float = 10.0
    output_step: float = 0.01
    gravity: float = 9.81


@dataclass(frozen=True)
class Effects:
    """``[effects]``: which physical effects the scene simulates (all on by default)."""

    variable_mass: bool = True
    web_momentum: bool = True
    web_tension: bool = True
    gravity: bool = True
    imbalance: bool = True
    contact: bool = True
    slip_relaxation: bool = True
    rider_load: bool = True

    def enabled(self) -> tuple[str, ...]:
        """Names of the effects that are on, in spec order."""
        return tuple(n for n in EFFECT_NAMES if getattr(self, n))


@dataclass(frozen=True)
class Drive:
    """``[drum.drive]``: ``speed_profile`` (web speed ramps at ``web_acceleration``
    [0, 1000] [m/s²] to ``web_speed`` [0, 1000] [m/s]) or ``torque`` (drum free, driven by
    an input torque ``torque``, ``|torque| <= 1e8`` [N·m]; ``web_speed`` then is the
    initial web speed)."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    torque: float = 0.0


@dataclass(frozen=True)
class Drum:
    """``[drum]``: radius (0, 10] [m], inertia (polar) (0, 1e7] [kg·m²], mass (0, 1e6]
    [kg]."""

    radius: float
    inertia: float
    mass: float
    drive: Drive = field(default_factory=Drive)


@dataclass(frozen=True)
class Roll:
    """``[roll]``: core_radius (0, 10] [m], core_mass (0, 1e6] [kg], core_inertia
    (0, 1e7] [kg·m²], width (0, 100] [m], initial_radius [core_radius, 10] [m] (default:
    core_radius), initial_speed ``|ω| <= 1e5`` [rad/s], com_offset ``e`` [m] with
    ``0 <= e <`` :func:`max_com_offset` (inside the core, and the core's inertia about
    its centre of mass stays positive); winder's own key initial_height
    (drum radius, 1000] [m]: ``z`` at ``t = 0`` (default: static equilibrium on the
    contact, spec §6), e.g. to drop the roll onto the drum; the roll axis must lie above
    the drum's surface."""

    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    initial_radius: float
    initial_speed: float = 0.0
    com_offset: float = 0.0
    initial_height: float | None = None


@dataclass(frozen=True)
class Paper:
    """``[paper]``: density [0, 1e5] [kg/m³], caliper (0, 0.1] [m] (thickness added per
    revolution)."""

    density: float
    caliper: float


@dataclass(frozen=True)
class Contact(ContactLaw):
    """``[contact]`` of the single-drum format: the nip's :class:`~winder.parts.ContactLaw`
    (law, stiffness, damping, exponent, hc_damping; same keys and bounds)."""


@dataclass(frozen=True)
class Friction(FrictionLaw):
    """``[friction]`` of the single-drum format: the nip's
    :class:`~winder.parts.FrictionLaw` (mu, slip_velocity, relaxation_length, min_speed;
    same keys and bounds)."""


@dataclass(frozen=True)
class Solver:
    """``[solver]``: method (one of :data:`METHODS`), rtol (0, 0.1] [-], atol (0, 1e-3]
    [state units], max_rhs (guard: an integer 1 … 1e12 of right-hand side evaluations),
    backend (one of :data:`BACKENDS`), max_wall (guard: wall-clock seconds, > 0) [s]."""

    method: str = "auto"
    rtol: float = 1e-6
    atol: float = 1e-8
    max_rhs: int = 50_000_000
    max_wall: float = 600.0
    backend: str = "compiled"


@dataclass(frozen=True)
class Scene:
    """A complete winder scene. Build one with :func:`load_scene` or :func:`scene_from_dict`.

    The parts (``drums``, ``rolls``, ``riders``, ``nips``, ``webs``) describe every scene;
    ``web`` is the first (or only) web, or None.
    A scene in the single-drum format (``legacy``) also has ``drum``, ``roll``,
    ``contact`` and ``friction``, and its parts are derived from them (machines spec §8):
    drum "drum" at the origin, sense +1; roll "roll" free in ``z`` at ``(0, R + r0)``,
    sense −1; nip "nip" (a = drum, b = roll); web entering at "nip" with tension 0. In a
    scene of parts those four are None, and ``paper`` is None unless ``[paper]`` is given.
    Every wound roll is fed by exactly one web (``webs``, one per wound roll, machines spec
    §3); a winder line has an unwinding roll (``rolls``, kind ``"unwinding"``) feeding the
    span of a web (``web.span``, machines spec §5).
    """

    scene: SceneInfo
    effects: Effects
    drum: Drum | None
    roll: Roll | None
    paper: Paper | None
    contact: Contact | None
    friction: Friction | None
    solver: Solver
    source: str = "<scene>"
    drums: tuple[DrumPart, ...] = ()
    rolls: tuple[RollPart, ...] = ()
    riders: tuple[RiderPart, ...] = ()
    nips: tuple[NipPart, ...] = ()
    web: WebPart | None = None
    webs: tuple[WebPart, ...] = ()
    legacy: bool = field(init=False)

    def __post_init__(self) -> None:
        legacy = self.drum is not None
        object.__setattr__(self, "legacy", legacy)
        if legacy:  # the parts always follow the single-drum tables
            for name, value in _legacy_parts(self).items():
                object.__setattr__(self, name, value)
        # ``webs`` is every web; ``web`` the first (or only) one, kept for code that reads a
        # single web; given only ``web``, ``webs`` is that one
        webs = tuple(self.webs) or ((self.web,) if self.web is not None else ())
        object.__setattr__(self, "webs", webs)
        object.__setattr__(self, "web", webs[0] if webs else None)

    @property
    def name(self) -> str:
        return self.scene.name

    def replace(self, **changes: Mapping[str, Any]) -> Scene:
        """A copy with some tables' keys changed: ``scene.replace(roll={"com_offset": 0})``.

        Each keyword is a table (``drum={"drive": {...}}`` reaches ``[drum.drive]``) and
        its value a mapping of that table's keys to new values; sub-tables merge the same
        way. For an array of tables (a scene of parts) the mapping selects elements by
        name: ``nip={"front": {"contact": {"stiffness": 1e8}}}``. The result is validated
        like a file (:class:`SceneError` naming the key).

        Raises
        ------
        ArgumentError: a keyword that is not a table of the scene, or an element name
            that is not in the array.
        ArgumentTypeError: a table given as something other than a mapping of keys.
        """
        data = self.to_dict()
        for table, values in changes.items():
            if table not in data:
                raise ArgumentError(f"Scene.replace: {table} is not a table of the scene; "
                                    f"valid tables: {', '.join(data)}")
            _merge(data[table], values, table, ())
        return scene_from_dict(data, source=self.source)

    def to_dict(self) -> dict[str, Any]:
        """The scene as nested dictionaries (TOML tables; arrays of tables as lists of
        dictionaries with their ``name``). A roll's density or caliper equal to
        ``[paper]``'s is left to ``[paper]``; tuples become lists."""
        if self.legacy:
            names = ("scene", "effects", "drum", "roll", "paper", "contact", "friction",
                     "solver")
            return {n: _table_dict(getattr(self, n)) for n in names}
        out: dict[str, Any] = {"scene": _table_dict(self.scene),
                               "effects": _table_dict(self.effects)}
        if self.paper is not None:
            out["paper"] = _table_dict(self.paper)
        for key, parts in (("drum", self.drums), ("roll", self.rolls), ("rider", self.riders),
                           ("nip", self.nips)):
            if parts:
                out[key] = [_table_dict(p) for p in parts]
        for roll in out.get("roll", ()):
            for key in ("density", "caliper"):
                if self.paper is not None and roll[key] == getattr(self.paper, key):
                    del roll[key]
        if len(self.webs) == 1:
            out["web"] = _web_dict(self.webs[0])
        elif self.webs:  # [[web]], one table per wound roll
            out["web"] = [_web_dict(w, named=True) for w in self.webs]
        out["solver"] = _table_dict(self.solver)
        return out

    def elements(self) -> tuple[list[Any], list[Any]]:
        """What :class:`~winder.model.machine.Machine` assembles: the body elements of the
        parts (:func:`winder.parts.body_elements`) and the force elements of the effects
        and drives (:func:`winder.forces.force_elements`)."""
        from winder.forces import force_elements
        from winder.parts import body_elements

        bodies = body_elements(self)
        return bodies, force_elements(self.effects, bodies)


def _web_dict(web: WebPart, *, named: bool = False) -> dict[str, Any]:
    """``[web]`` as a TOML table: with a span, ``[web.span]`` (its roll under the key
    ``from``) and no ``tension`` (the span's state); its name only if ``named`` or not the
    default (its entry nip's)."""
    out = _table_dict(web)
    if not named and web.name == web.entry_nip:
        del out["name"]
    if web.span is not None:
        del out["tension"]
        out["span"] = {"from": out["span"].pop("source"), **out["span"]}
    return out


def _table_dict(obj: Any) -> dict[str, Any]:
    """A dataclass as a TOML table: None values left out, tuples as lists."""
    def plain(v: Any) -> Any:
        if isinstance(v, tuple | list):
            return [plain(x) for x in v]
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items() if x is not None}
        return v
    return plain(dataclasses.asdict(obj))


def _merge(node: Any, values: Any, table: str, path: tuple[str, ...]) -> None:
    """Merge ``values`` into ``node`` (a table or an array of named tables) in place, for
    :meth:`Scene.replace`; ``table`` and ``path`` place it in messages."""
    where = table + "".join(f"[{p!r}]" for p in path)
    dotted = ".".join((table, *path))
    if not isinstance(values, Mapping):
        inner = (f"{next(iter(node))!r}: ..." if isinstance(node, dict) and node else "...")
        if isinstance(node, list):
            names = [str(e.get("name")) for e in node]
            inner = f"{names[0]!r}: {{...}}" if names else "..."
        example = "{" + inner + "}"
        for p in reversed(path):
            example = f"{{{p!r}: {example}}}"
        what = (f"[[{dotted}]] names to mappings of keys" if isinstance(node, list)
                else f"[{dotted}] keys")
        raise ArgumentTypeError(
            f"Scene.replace: {where} must be a mapping of {what} to values, e.g. "
            f"{table}={example}; got {show(values)} ({type(values).__name__})")
    if isinstance(node, list):
        names = [str(e.get("name")) for e in node]
        for name, sub in values.items():
            if name not in names:
                raise ArgumentError(f"Scene.replace: {where} has no element named "
                                    f"{show(name)}; valid names: {', '.join(names)}")
            _merge(node[names.index(name)], sub, table, (*path, name))
        return
    for key, value in values.items():
        old = node.get(key)
        tables = isinstance(old, dict) or (
            isinstance(old, list) and bool(old) and all(isinstance(e, dict) for e in old))
        if tables:  # a sub-table or an array of named tables: merge into it
            _merge(node[key], value, table, (*path, key))
        else:  # a value, or a list of values (a rider's load schedule): replace it
            node[key] = value


def _legacy_parts(scene: Scene) -> dict[str, Any]:
    """The parts of a single-drum scene (machines spec §8, last paragraph)."""
    drum, roll, paper = scene.drum, scene.roll, scene.paper
    assert drum is not None and roll is not None and paper is not None
    assert scene.contact is not None and scene.friction is not None
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
                           initial_height=roll.initial_height),),
        "riders": (),
        "nips": (NipPart(name="nip", a="drum", b="roll",
                         contact=ContactLaw(**dataclasses.asdict(scene.contact)),
                         friction=FrictionLaw(**dataclasses.asdict(scene.friction))),),
        "webs": (WebPart(entry_nip="nip", tension=0.0),),
    }


# ---- parsing --------------------------------------------------------------------------

_SPEC: dict[str, dict[str, tuple]] = {
    # key: (kind, required, bound); kind "num", "bool" or "str" (choices in _CHOICES);
    # bound = (lo, open) or None
    "scene": {"name": ("str", False, None), "duration": ("num", True, _POS),
              "output_step": ("num", False, _POS), "gravity": ("num", False, _NONNEG)},
    "effects": {n: ("bool", False, None) for n in EFFECT_NAMES},
    "drum": {"radius": ("num", True, _POS), "inertia": ("num", True, _POS),
             "mass": ("num", True, _POS)},
    "drum.drive": {"kind": ("str", True, None), "web_acceleration": ("num", False, _NONNEG),
                   "web_speed": ("num", False, _NONNEG), "torque": ("num", False, None)},
    "roll": {"core_radius": ("num", True, _POS), "core_mass": ("num", True, _POS),
             "core_inertia": ("num", True, _POS), "width": ("num", True, _POS),
             "initial_radius": ("num", False, _POS), "initial_speed": ("num", False, None),
             "com_offset": ("num", False, _NONNEG),
             "initial_height": ("num", False, None)},
    "paper": {"density": ("num", True, _NONNEG), "caliper": ("num", True, _POS)},
    "contact": {"law": ("str", False, None), "stiffness": ("num", False, _POS),
                "damping": ("num", False, _NONNEG), "exponent": ("num", False, (1.0, False)),
                "hc_damping": ("num", False, _NONNEG)},
    "friction": {"mu": ("num", False, _NONNEG), "slip_velocity": ("num", False, _POS),
                 "relaxation_length": ("num", False, _POS),
                 "min_speed": ("num", False, _POS)},
    "solver": {"method": ("str", False, None), "rtol": ("num", False, _POS),
               "atol": ("num", False, _POS), "max_rhs": ("num", False, _POS),
               "backend": ("str", False, None), "max_wall": ("num", False, _POS)},
}
#: The numeric keys, by table: ``(upper bound, unit)``. The bound is far beyond any real
#: winder, well inside the float range so that masses, inertias and forces cannot overflow
#: (None: bounded otherwise, or not at all); keys without a lower bound are bounded in
#: magnitude. The unit labels sweep axes and plots ("-": dimensionless, "": none in
#: common). :data:`_MAX` and :data:`_UNITS` are read from it; a new numeric key needs an
#: entry here (tests/test_sweep.py checks).
_NUMBERS: dict[tuple[str, str], tuple[float | None, str]] = {
    ("scene", "duration"): (1e6, "s"), ("scene", "output_step"): (None, "s"),
    ("scene", "gravity"): (1e3, "m/s²"),
    ("drum", "radius"): (10.0, "m"), ("drum", "inertia"): (1e7, "kg·m²"),
    ("drum", "mass"): (1e6, "kg"),
    ("drum.drive", "web_acceleration"): (1e3, "m/s²"),
    ("drum.drive", "web_speed"): (1e3, "m/s"), ("drum.drive", "torque"): (1e8, "N·m"),
    ("roll", "core_radius"): (10.0, "m"), ("roll", "core_mass"): (1e6, "kg"),
    ("roll", "core_inertia"): (1e7, "kg·m²"), ("roll", "width"): (100.0, "m"),
    ("roll", "initial_radius"): (10.0, "m"), ("roll", "initial_speed"): (1e5, "rad/s"),
    ("roll", "com_offset"): (10.0, "m"), ("roll", "initial_height"): (1e3, "m"),
    ("paper", "density"): (1e5, "kg/m³"), ("paper", "caliper"): (0.1, "m"),
    ("contact", "stiffness"): (1e18, "N/m"), ("contact", "damping"): (1e12, "N·s/m"),
    ("contact", "exponent"): (3.0, "-"), ("contact", "hc_damping"): (1e4, "s/m"),
    ("friction", "mu"): (10.0, "-"), ("friction", "slip_velocity"): (1e3, "m/s"),
    ("friction", "relaxation_length"): (1e3, "m"), ("friction", "min_speed"): (1e3, "m/s"),
    ("solver", "rtol"): (RTOL_MAX, "-"),
    ("solver", "atol"): (ATOL_MAX, ""),  # in each state's own unit: none in common
    ("solver", "max_rhs"): (1e12, "-"), ("solver", "max_wall"): (None, "s"),
}
_CHOICES = {("drum.drive", "kind"): DRIVE_KINDS, ("contact", "law"): CONTACT_LAWS,
            ("solver", "method"): METHODS, ("solver", "backend"): BACKENDS}
_REQUIRED_TABLES = ("scene", "drum", "roll", "paper")

# Scenes of parts (machines spec §8). Extra kinds: "name" (a part's name), "ref" (the name
# of another part, checked once all are read), "pair" (centre [x, z]), "sense" (±1),
# "axes" (free), "load" (rider schedule), "table" (a sub-table, parsed on its own).
#: Largest coordinate of a centre or a rider's x [m].
MAX_COORD = 1e3
_PART_SPEC: dict[str, dict[str, tuple]] = {
    "drum[]": {"name": ("name", True, None), **_SPEC["drum"],
               "centre": ("pair", True, None), "sense": ("sense", False, None),
               "drive": ("table", True, None)},
    "drum[].drive": {"kind": ("str", True, None),
                     "web_acceleration": ("num", False, _NONNEG),
                     "web_speed": ("num", False, _NONNEG), "ratio": ("num", False, _POS),
                     "torque": ("num", False, None)},
    "roll[]": {"name": ("name", True, None), "kind": ("str", False, None),
               "centre": ("pair", True, None), "free": ("axes", False, None),
               "sense": ("sense", False, None),
               **{k: v for k, v in _SPEC["roll"].items() if k != "initial_height"},
               **_SPEC["paper"], "drive": ("table", False, None)},
    "rider[]": {"name": ("name", True, None), "rides": ("ref", True, None),
                "radius": ("num", True, _POS), "mass": ("num", True, _POS),
                "inertia": ("num", True, _POS), "x": ("num", True, None),
                "load": ("load", False, None)},
    "nip[]": {"name": ("name", True, None), "a": ("ref", True, None),
              "b": ("ref", True, None), "contact": ("table", False, None),
              "friction": ("table", False, None)},
    "nip[].contact": _SPEC["contact"],
    "nip[].friction": _SPEC["friction"],
    "roll[].drive": {"kind": ("str", True, None), "torque": ("num", False, None),
                     "tension": ("num", False, _POS), "bandwidth": ("num", False, _POS)},
    "web": {"name": ("name", False, None), "entry_nip": ("ref", True, None),
            "tension": ("num", False, _NONNEG), "span": ("table", False, None)},
    "web.span": {"from": ("ref", True, None), "length": ("num", True, _POS),
                 "EA": ("num", True, _POS), "T_in": ("num", False, _NONNEG),
                 "initial_tension": ("num", False, _NONNEG)},
}
_PART_SPEC["roll[]"]["density"] = ("num", False, _NONNEG)  # default: [paper]
_PART_SPEC["roll[]"]["caliper"] = ("num", False, _POS)
#: Keys of each drive kind of a drum.
_DRIVE_KEYS = {"speed_profile": ("kind", "web_acceleration", "web_speed", "ratio"),
               "torque": ("kind", "torque", "web_speed")}
#: Keys of each drive kind of an unwinding roll.
_UNWIND_DRIVE_KEYS = {"torque": ("kind", "torque"),
                      "tension_control": ("kind", "tension", "bandwidth")}
_NUMBERS.update({("drum[]", k): _NUMBERS[("drum", k)] for k in _SPEC["drum"]})
_NUMBERS.update({("drum[].drive", k): v for (t, k), v in _NUMBERS.items()
                 if t == "drum.drive"})
_NUMBERS.update({("roll[]", k): v for (t, k), v in _NUMBERS.items()
                 if t in ("roll", "paper")})
_NUMBERS.update({("nip[]." + t, k): v for (t, k), v in _NUMBERS.items()
                 if t in ("contact", "friction")})
_NUMBERS.update({("drum[].drive", "ratio"): (100.0, "-"), ("rider[]", "radius"): (10.0, "m"),
                 ("rider[]", "mass"): (1e6, "kg"), ("rider[]", "inertia"): (1e7, "kg·m²"),
                 ("rider[]", "x"): (MAX_COORD, "m"), ("web", "tension"): (1e7, "N"),
                 ("roll[].drive", "torque"): (1e8, "N·m"),
                 ("roll[].drive", "tension"): (1e7, "N"),
                 ("roll[].drive", "bandwidth"): (1e4, "rad/s"),
                 ("web.span", "length"): (1e3, "m"), ("web.span", "EA"): (1e12, "N"),
                 ("web.span", "T_in"): (1e7, "N"), ("web.span", "initial_tension"): (1e7, "N")})
#: Upper bounds of the numeric keys that have one (:data:`_NUMBERS`).
_MAX = {key: hi for key, (hi, _) in _NUMBERS.items() if hi is not None}
#: Units of the numeric keys (:data:`_NUMBERS`); keys absent here (words, flags, pairs)
#: have no unit.
_UNITS = {key: unit for key, (_, unit) in _NUMBERS.items()}
_CHOICES.update({("drum[].drive", "kind"): DRIVE_KINDS, ("roll[]", "kind"): ROLL_KINDS,
                 ("roll[].drive", "kind"): UNWIND_DRIVE_KINDS,
                 ("nip[].contact", "law"): CONTACT_LAWS})
#: Arrays of tables of a scene of parts, and the tables of each format.
_ARRAYS = ("drum", "roll", "rider", "nip")
_PART_TABLES = ("scene", "effects", "paper", *_ARRAYS, "web", "solver")
_LEGACY_TABLES = tuple(t for t in _SPEC if t != "drum.drive")
#: A part's name: a letter or underscore, then letters, digits, ``_`` or ``-`` (it names
#: result channels and sweep key paths, so no dots or spaces).
_PART_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]{0,39}")
#: Bounds of a rider's load schedule: radius (0, 10] [m], line load [0, 1e7] [N/m].
MAX_LOAD_RADIUS, MAX_LINE_LOAD = 10.0, 1e7

def key_unit(path: str, data: Mapping[str, Any] | None = None) -> str:
    """The unit of the scene key at dotted ``path`` (``drum.drive.web_speed``: ``"m/s"``;
    ``nip.front.contact.stiffness``: ``"N/m"``), ``"-"`` for a dimensionless number and
    ``""`` for a key without a unit (a word, a flag) or an unknown path. ``data`` (the
    scene's nested tables, :meth:`Scene.to_dict`) tells an array of tables (whose next
    segment is an element's name) from a table, and a Hunt–Crossley nip's stiffness
    (``N/m^p``) from a linear one's; without it, the first segment is an array when the
    path does not fit the single-drum tables."""
    parts = path.split(".")
    if len(parts) < 2:
        return ""
    head, rest = parts[0], parts[1:]
    if data is not None:
        array = isinstance(data.get(head), list)
    else:
        array = head in _ARRAYS and ".".join([head, *rest[:-1]]) not in _SPEC
    if array:
        head, rest = head + "[]", rest[1:]  # skip the element's name
    if not rest:
        return ""
    unit = _UNITS.get((".".join([head, *rest[:-1]]), rest[-1]), "")
    if unit == "N/m" and rest[-1] == "stiffness" and data is not None:
        from winder.analysis.sweep_grid import get_path  # its law's: k δ^p of a Hunt–Crossley nip

        try:
            law = get_path(data, path[:-len("stiffness")] + "law")
        except (KeyError, ArgumentError):
            law = "linear"
        if law == "hunt_crossley":
            return "N/m^p"
    return unit


def _check_name(source: str, value: str) -> str:
    if not value or len(value) > MAX_NAME or not value.isprintable():
        raise _fail(source, "scene", "name", f"{show(value)} is not a plain name; valid: 1 to "
                                              f"{MAX_NAME} printable characters")
    return value


def _check_part_name(source: str, table: str, value: Any) -> str:
    if not isinstance(value, str) or not _PART_NAME.fullmatch(value):
        raise _fail(source, table, "name", f"{show(value)} is not a part name; valid: 1 to 40 "
                    "letters, digits, '_' or '-', starting with a letter or '_' (names make "
                    "channel names and sweep key paths)")
    return value


def _parse_table(source: str, table: str, raw: Any, *, spec_name: str | None = None,
                 specs: Mapping[str, Mapping[str, tuple]] = _SPEC) -> dict[str, Any]:
    """The keys of one table, each checked for type, finiteness and bounds; ``table``
    names it in messages (``drum 'front'``), ``spec_name`` selects its schema in
    ``specs`` (default: ``table``). Sub-tables (kind "table") are left out."""
    spec_name = spec_name or table
    spec = specs[spec_name]
    if not isinstance(raw, dict):
        raise SceneError(f"{source}: [{table}] must be a table of keys, got {show(raw)} "
                         f"({type(raw).__name__})")
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if spec_name == "drum" and key == "drive":
            continue
        if key not in spec:
            raise _fail(source, table, key, f"unknown key; valid keys: {', '.join(spec)}")
        kind, _, bound = spec[key]
        if kind == "table":
            continue
        if kind == "bool":
            if not isinstance(value, bool):
                raise _fail(source, table, key, f"expected true or false, got {show(value)}")
            out[key] = value
        elif kind in ("str", "ref", "name"):
            if not isinstance(value, str):
                raise _fail(source, table, key, f"expected a string, got {show(value)} "
                                                 f"({type(value).__name__})")
            choices = _CHOICES.get((spec_name, key))
            if choices and value not in choices:
                raise _fail(source, table, key, f"{show(value)} is not one of: "
                                                 f"{', '.join(repr(c) for c in choices)}")
            if kind == "name":
                _check_part_name(source, table, value)
            out[key] = _check_name(source, value) if (table, key) == ("scene", "name") \
                else value
        elif kind == "pair":
            out[key] = _parse_pair(source, table, key, value, ("x", "z"),
                                   ((None, False, MAX_COORD),) * 2)
        elif kind == "sense":
            if isinstance(value, bool) or value not in (1, -1):
                raise _fail(source, table, key, f"{show(value)} is not a sense; valid: 1 or "
                                                 "-1 (the operation direction, docs/model.md §1)")
            out[key] = int(value)
        elif kind == "axes":
            out[key] = _parse_axes(source, table, key, value)
        elif kind == "load":
            out[key] = _parse_load(source, table, key, value)
        else:
            lo, lo_open = bound if bound else (None, False)
            out[key] = _check_number(source, table, key, value, lo=lo, lo_open=lo_open,
                                     hi=_MAX.get((spec_name, key)))
    for key, (_, required, _) in spec.items():
        if required and key not in raw:
            raise _fail(source, table, key, "missing required key")
    return out


def _parse_pair(source: str, table: str, key: str, value: Any, names: tuple[str, str],
                bounds: tuple[tuple[float | None, bool, float], ...]) -> tuple[float, float]:
    """Two numbers ``[u, v]`` named ``names``, each within its ``(lo, lo_open, hi)`` of
    ``bounds`` (as :func:`check_real`)."""
    form = f"[{', '.join(names)}]"
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise _fail(source, table, key, f"expected a list of two numbers {form}, got "
                                         f"{show(value)} ({type(value).__name__})")
    out = []
    for part, item, (lo, lo_open, hi) in zip(names, value, bounds, strict=True):
        x, problem, _ = check_real(item, lo=lo, lo_open=lo_open, hi=hi)
        if problem is not None:
            raise _fail(source, table, key, f"{part} {problem}")
        out.append(x)
    return out[0], out[1]


def _parse_axes(source: str, table: str, key: str, value: Any) -> tuple[str, ...]:
    valid = "[], [\"z\"], [\"x\"] or [\"x\", \"z\"]"
    if not isinstance(value, list | tuple) or any(a not in AXES for a in value) \
            or len(set(value)) != len(value):
        raise _fail(source, table, key, f"{show(value)} is not a set of axes; valid: {valid}")
    return tuple(a for a in AXES if a in value)


def _parse_load(source: str, table: str, key: str, value: Any
                ) -> tuple[tuple[float, float], ...]:
    """A rider's line-load schedule: ``[[radius, line_load], ...]``, radii strictly
    increasing."""
    if not isinstance(value, list | tuple):
        raise _fail(source, table, key, f"expected a list of [radius, line_load] pairs "
                                         f"[m, N/m], got {show(value)} ({type(value).__name__})")
    points = [_parse_pair(source, table, f"{key}[{i}]", p, ("radius", "line_load"),
                          ((0.0, True, MAX_LOAD_RADIUS), (0.0, False, MAX_LINE_LOAD)))
              for i, p in enumerate(value)]
    for i in range(1, len(points)):
        if not points[i][0] > points[i - 1][0]:
            raise _fail(source, table, f"{key}[{i}]",
                        f"radius {points[i][0]!r} m does not follow {points[i - 1][0]!r} m; "
                        "valid: strictly increasing radii")
    return tuple(points)


def max_com_offset(core_radius: float, core_mass: float, core_inertia: float) -> float:
    """Bound ``e_max`` [m] of a roll's centre-of-mass offset, ``0 <= e < e_max``.

    The centre of mass lies inside the core (``e < r_c``) and the core's inertia about it,
    ``J_core − m_core e²``, is positive (``e < √(J_core/m_core)``). Then the roll's inertia
    about its centre of mass ``J(r) − m(r) e²`` stays positive at every radius: the paper
    adds ``b(r)(½(r² + r_c²) − e²) > 0`` with ``b`` its mass."""
    return min(core_radius, math.sqrt(core_inertia / core_mass))


def _check_roll_core(source: str, table: str, roll: dict[str, Any]) -> None:
    """A roll's initial radius (>= core) and centre-of-mass offset (inside the core, core
    inertia about it positive); ``roll`` holds its parsed keys with initial_radius."""
    r0, rc = roll["initial_radius"], roll["core_radius"]
    if r0 < rc:
        raise _fail(source, table, "initial_radius",
                    f"{r0!r} m is below core_radius {rc!r} m; valid: >= core_radius")
    e, mc, jc = roll.get("com_offset", 0.0), roll["core_mass"], roll["core_inertia"]
    e_max = max_com_offset(rc, mc, jc)
    if not e < e_max:
        raise _fail(source, table, "com_offset",
                    f"{e!r} m puts the centre of mass outside the core or "
                    f"makes the core's inertia about it, core_inertia − core_mass "
                    f"com_offset², non-positive (core_radius {rc!r} m, "
                    f"core_inertia {jc!r} kg·m², core_mass "
                    f"{mc!r} kg); valid: com_offset < min(core_radius, "
                    f"√(core_inertia/core_mass)) = {e_max:.6g} m")


def _is_parts(source: str, data: Mapping[str, Any]) -> bool:
    """Whether ``data`` is a scene of parts, else the single-drum format: a single-table
    ``[drum]`` or ``[roll]`` makes it single-drum, else any ``[[drum]]``, ``[[roll]]``,
    ``[[rider]]``, ``[[nip]]`` or ``[web]`` makes it of parts. A table of the other format
    is an error."""
    legacy = any(isinstance(data.get(t), dict) for t in ("drum", "roll"))
    parts = not legacy and (any(isinstance(data.get(a), list) for a in ("drum", "roll"))
                            or any(t in data for t in ("rider", "nip", "web")))
    for table in data:
        if legacy and table not in _LEGACY_TABLES:
            raise SceneError(
                f"{source}: [{table}]: a table of scenes of parts in a scene of the "
                f"single-drum format ([drum] or [roll] is a single table); build a machine "
                f"from parts with [[drum]] and [[roll]] (arrays of tables, each with a "
                f"name); valid tables here: {', '.join(_LEGACY_TABLES)}")
        if parts and table not in _PART_TABLES:
            raise SceneError(
                f"{source}: [{table}]: a table of the single-drum format in a scene of "
                f"parts; each [[nip]] has its own contact and friction; valid tables: "
                f"{', '.join(_PART_TABLES)}")
    return parts


def scene_from_dict(data: dict[str, Any], *, source: str = "<scene>") -> Scene:
    """Validate nested dictionaries (as read from TOML) and build a :class:`Scene`: the
    single-drum format or a scene of parts (machines spec §8)."""
    if not isinstance(data, dict):
        raise SceneError(f"{source}: a scene is a set of TOML tables, got {show(data)} "
                         f"({type(data).__name__})")
    valid = ", ".join(dict.fromkeys((*_LEGACY_TABLES, *_PART_TABLES)))
    for table in data:
        if table not in _LEGACY_TABLES and table not in _PART_TABLES:
            raise SceneError(f"{source}: [{_name(table)}]: unknown table; valid "
                             f"tables: {valid}")
    parts = _is_parts(source, data)
    if not parts:
        for table in _REQUIRED_TABLES:
            if table not in data:
                raise SceneError(f"{source}: [{table}]: missing required table")
    common = ("scene", "effects", "solver") + (() if parts else _LEGACY_TABLES)
    t = {name: _parse_table(source, name, data.get(name, {}))
         for name in dict.fromkeys(common)}
    effects = Effects(**t["effects"])
    info = SceneInfo(**{"name": Path(source).stem if source != "<scene>" else "scene",
                        **t["scene"]})
    if info.output_step > info.duration:
        raise _fail(source, "scene", "output_step",
                    f"{info.output_step!r} is longer than duration {info.duration!r}")
    samples = info.duration / info.output_step + 1.0  # both ends, as simulate counts
    if samples > MAX_SAMPLES:
        raise _fail(source, "scene", "output_step",
                    f"{info.output_step!r} s over duration {info.duration!r} s gives "
                    f"{samples:.3g} samples; valid: at most {MAX_SAMPLES:.0e} samples "
                    f"(output_step >= {info.duration / MAX_SAMPLES:.3g} s)")
    solver_kw = dict(t["solver"])
    if "max_rhs" in solver_kw:
        if solver_kw["max_rhs"] != int(solver_kw["max_rhs"]):
            raise _fail(source, "solver", "max_rhs", f"{solver_kw['max_rhs']!r} is not a whole "
                        "number of evaluations; valid: an integer 1 … 1e12")
        solver_kw["max_rhs"] = int(solver_kw["max_rhs"])
    if effects.slip_relaxation and not effects.contact:
        raise SceneError(f"{source}: [effects] slip_relaxation: true requires contact = true "
                         "(the relaxed force is the nip friction)")
    if parts:
        paper = Paper(**_parse_table(source, "paper", data["paper"])) \
            if "paper" in data else None
        return Scene(scene=info, effects=effects, drum=None, roll=None, paper=paper,
                     contact=None, friction=None, solver=Solver(**solver_kw), source=source,
                     **_parse_parts(source, data, effects, paper))

    drum_raw = data["drum"]
    if "drive" not in drum_raw:
        raise SceneError(f"{source}: [drum.drive]: missing required table")
    drive = _parse_table(source, "drum.drive", drum_raw["drive"])
    roll_kw = dict(t["roll"])
    roll_kw.setdefault("initial_radius", roll_kw["core_radius"])
    _check_roll_core(source, "roll", roll_kw)
    roll = Roll(**roll_kw)
    radius = t["drum"]["radius"]
    if roll.initial_height is not None and not roll.initial_height > radius:
        raise _fail(source, "roll", "initial_height",
                    f"{roll.initial_height!r} m puts the roll axis inside the drum or below "
                    f"it; valid: > {radius!r} m (the drum radius, [drum] radius) and <= "
                    f"{_MAX[('roll', 'initial_height')]:g} m")
    if drive["kind"] == "speed_profile" and "web_speed" not in drive:
        raise _fail(source, "drum.drive", "web_speed", "missing required key "
                    "(kind = 'speed_profile')")
    contact = Contact(**t["contact"])
    if effects.contact and "contact" not in data:
        raise SceneError(f"{source}: [contact]: missing required table (effects.contact is on)")
    scene = Scene(scene=info, effects=effects,
                  drum=Drum(**t["drum"], drive=Drive(**drive)), roll=roll,
                  paper=Paper(**t["paper"]), contact=contact,
                  friction=Friction(**t["friction"]), solver=Solver(**solver_kw),
                  source=source)
    _check_rest_on_nip(scene)
    return scene


# ---- scenes of parts -------------------------------------------------------------------

def _elements(source: str, data: Mapping[str, Any], array: str, *, named: bool = True
              ) -> list[tuple[str, dict[str, Any]]]:
    """``(label, raw table)`` of each element of ``[[array]]``; the label names it in
    messages (``drum 'front'``, or ``drum #2`` while its name is not valid, or absent
    where ``named`` is false: the name is optional)."""
    raw = data.get(array, [])
    if not isinstance(raw, list):
        raise SceneError(f"{source}: [{array}] must be an array of tables ([[{array}]], one "
                         f"per {array}, each with a name), got {show(raw)} "
                         f"({type(raw).__name__})")
    out = []
    for i, element in enumerate(raw):
        label = f"{array} #{i + 1}"
        if not isinstance(element, dict):
            raise SceneError(f"{source}: [{label}] must be a table of keys, got "
                             f"{show(element)} ({type(element).__name__})")
        if "name" not in element:
            if not named:
                out.append((label, element))
                continue
            raise _fail(source, label, "name", "missing required key")
        name = _check_part_name(source, label, element["name"])
        out.append((f"{array} {name!r}", element))
    return out


def _parse_drive_keys(source: str, table: str, drive: dict[str, Any],
                      keys: Mapping[str, tuple[str, ...]]) -> None:
    """Every key of a parsed drive belongs to its kind (``keys[kind]``)."""
    for key in drive:
        if key not in keys[drive["kind"]]:
            raise _fail(source, table, key, f"not a key of kind {drive['kind']!r}; valid "
                                            f"keys: {', '.join(keys[drive['kind']])}")


def _parse_roll_drive(source: str, label: str, kw: dict[str, Any], raw: Mapping[str, Any]
                      ) -> UnwindTorqueDrive | TensionControl | None:
    """The drive of a roll (spec §6): only an unwinding roll may have one."""
    if "drive" not in raw:
        return None
    if kw["kind"] != "unwinding":
        raise _fail(source, label, "drive",
                    f"{show(raw['drive'])}: a drive on a {kw['kind']} roll; only unwinding "
                    "rolls (kind = 'unwinding') have a drive; a wound roll is turned by its "
                    "nips; valid: remove drive")
    dlabel = f"{label}.drive"
    d = _parse_table(source, dlabel, raw["drive"], spec_name="roll[].drive",
                     specs=_PART_SPEC)
    _parse_drive_keys(source, dlabel, d, _UNWIND_DRIVE_KEYS)
    if d["kind"] == "torque":
        return UnwindTorqueDrive(**d)
    if "tension" not in d:
        raise _fail(source, dlabel, "tension",
                    "missing required key (kind = 'tension_control': the set-point [N])")
    return TensionControl(**d)


def _parse_roll(source: str, label: str, raw: Mapping[str, Any], paper: Paper | None
                ) -> RollPart:
    """One ``[[roll]]`` element: its keys, paper defaults, core and drive (spec §1, §8)."""
    kw = _parse_table(source, label, raw, spec_name="roll[]", specs=_PART_SPEC)
    kw.setdefault("kind", "wound")
    if kw["kind"] == "unwinding":
        kw.setdefault("free", ())
        if kw["free"]:
            raise _fail(source, label, "free",
                        f"{show(list(kw['free']))}: an unwinding roll's centre is fixed "
                        "(docs/model.md §1); valid: [] (or leave free out)")
    kw["drive"] = _parse_roll_drive(source, label, kw, raw)
    kw.setdefault("initial_radius", kw["core_radius"])
    for key in ("density", "caliper"):
        if key not in kw:
            if paper is None:
                raise _fail(source, label, key, "missing required key (the scene has no "
                                                f"[paper] {key} to default to)")
            kw[key] = getattr(paper, key)
    _check_roll_core(source, label, kw)
    return RollPart(**kw)


def _parse_webs(source: str, data: Mapping[str, Any]) -> list[tuple[str, WebPart]]:
    """``[web]`` (one table) or ``[[web]]`` (an array of tables, one per wound roll), each
    with its optional ``[web.span]`` (spec §3, §5, §8): ``(label, web)`` pairs, the label
    naming the table in messages (``web``; ``web 'name'`` or ``web #2`` in an array)."""
    web_raw = data.get("web")
    if web_raw is None:
        return []
    if isinstance(web_raw, list):
        if not web_raw:
            raise SceneError(f"{source}: [[web]]: an empty array of webs; give one [[web]] "
                             "table per wound roll, each with entry_nip, or leave web out "
                             "(a scene without wound rolls)")
        elements = _elements(source, data, "web", named=False)
    else:
        elements = [("web", web_raw)]
    webs = []
    for label, raw in elements:
        kw = _parse_table(source, label, raw, spec_name="web", specs=_PART_SPEC)
        if "span" in raw:
            if "tension" in raw:
                raise _fail(source, label, "tension",
                            f"{show(raw['tension'])}: with [web.span] the tension is the "
                            "span's state, docs/model.md §6; valid: remove tension (the span's "
                            "initial_tension sets where it starts)")
            slabel = f"{label}.span"
            sp = _parse_table(source, slabel, raw["span"], spec_name="web.span",
                              specs=_PART_SPEC)
            kw["span"] = SpanPart(source=sp.pop("from"), **sp)
        webs.append((label, WebPart(**kw)))
    return webs


def _parse_parts(source: str, data: Mapping[str, Any], effects: Effects,
                 paper: Paper | None) -> dict[str, Any]:
    """The parts of a scene (machines spec §8): each element's keys, then names and
    references."""
    spec = _PART_SPEC
    drums = []
    for label, raw in _elements(source, data, "drum"):
        kw = _parse_table(source, label, raw, spec_name="drum[]", specs=spec)
        dlabel = f"{label}.drive"
        d = _parse_table(source, dlabel, raw["drive"], spec_name="drum[].drive", specs=spec)
        _parse_drive_keys(source, dlabel, d, _DRIVE_KEYS)
        if d["kind"] == "speed_profile":
            if "web_speed" not in d:
                raise _fail(source, dlabel, "web_speed",
                            "missing required key (kind = 'speed_profile')")
            drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive(**d)
        else:
            drive = TorqueDrive(**d)
        drums.append(DrumPart(**kw, drive=drive))
    rolls = [_parse_roll(source, label, raw, paper)
             for label, raw in _elements(source, data, "roll")]
    riders = [RiderPart(**_parse_table(source, label, raw, spec_name="rider[]", specs=spec))
              for label, raw in _elements(source, data, "rider")]
    nips = []
    for label, raw in _elements(source, data, "nip"):
        kw = _parse_table(source, label, raw, spec_name="nip[]", specs=spec)
        if effects.contact and "contact" not in raw:
            raise _fail(source, label, "contact",
                        "missing required table (effects.contact is on)")
        for key, law in (("contact", ContactLaw), ("friction", FrictionLaw)):
            kw[key] = law(**_parse_table(source, f"{label}.{key}", raw.get(key, {}),
                                         spec_name=f"nip[].{key}", specs=spec))
        nips.append(NipPart(**kw))
    webs = _parse_webs(source, data)
    _check_references(source, drums, rolls, riders, nips, webs)
    _check_overlaps(source, drums, rolls, nips)
    return {"drums": tuple(drums), "rolls": tuple(rolls), "riders": tuple(riders),
            "nips": tuple(nips), "webs": tuple(w for _, w in webs)}


def _check_references(source: str, drums: list[DrumPart], rolls: list[RollPart],
                      riders: list[RiderPart], nips: list[NipPart],
                      webs: list[tuple[str, WebPart]]) -> None:
    """Unique names, and every ``a``, ``b``, ``rides``, ``entry_nip``, ``from`` naming a
    part of the right kind; nips that can be assembled; every wound roll fed by exactly
    one web (``webs``: ``(label, web)``), one span per unwinding roll (machines spec
    §3, §8)."""
    kinds: dict[str, str] = {}
    for kind, parts in (("drum", drums), ("roll", rolls), ("rider", riders), ("nip", nips)):
        for i, p in enumerate(parts):
            if p.name in kinds:
                raise _fail(source, f"{kind} #{i + 1}", "name",
                            f"{p.name!r} is already the name of {kinds[p.name]} {p.name!r}; "
                            f"every part needs its own name (taken: {', '.join(kinds)})")
            kinds[p.name] = kind
    bodies = [n for n, k in kinds.items() if k != "nip"]
    if not bodies:
        raise SceneError(f"{source}: a scene of parts needs at least one body: a [[drum]], "
                         "[[roll]] or [[rider]]")
    fixed = {d.name for d in drums} | {r.name for r in rolls if not r.free}
    pairs: dict[frozenset[str], str] = {}
    for nip in nips:
        label = f"nip {nip.name!r}"
        for key in ("a", "b"):
            ref = getattr(nip, key)
            if kinds.get(ref) not in ("drum", "roll", "rider"):
                what = f"is {kinds[ref]} {ref!r}, not a body" if ref in kinds else \
                    "is not a body of the scene"
                raise _fail(source, label, key, f"{show(ref)} {what}; a nip joins two "
                                                f"bodies; valid names: {', '.join(bodies)}")
        if nip.a == nip.b:
            raise _fail(source, label, "b",
                        f"{nip.b!r} is also a: a nip joins two different bodies; valid "
                        f"names: {', '.join(n for n in bodies if n != nip.a) or '(none)'}")
        if nip.a in fixed and nip.b in fixed:
            raise _fail(source, label, "b",
                        f"{nip.b!r}: a nip between two bodies with fixed centres "
                        f"({kinds[nip.a]} {nip.a!r} and {kinds[nip.b]} {nip.b!r}) cannot be "
                        "assembled: neither can move to carry its normal force; valid "
                        "names: a roll free to move or a rider: "
                        f"{', '.join(n for n in bodies if n not in fixed) or '(none)'}")
        pair = frozenset((nip.a, nip.b))
        if pair in pairs:
            raise _fail(source, label, "b", f"{nip.b!r}: nip {pairs[pair]!r} already joins "
                                            f"{nip.a!r} and {nip.b!r}; one nip per pair of "
                                            "bodies")
        pairs[pair] = nip.name
    roll_names = [r.name for r in rolls]
    for rider in riders:
        label = f"rider {rider.name!r}"
        if rider.rides not in roll_names:
            what = f"is {kinds[rider.rides]} {rider.rides!r}, not a roll; a rider rides a " \
                "paper roll" if rider.rides in kinds else "is not a roll of the scene"
            raise _fail(source, label, "rides", f"{show(rider.rides)} {what}; valid names: "
                                                f"{', '.join(roll_names) or '(none)'}")
        if not any(n.a == rider.rides and n.b == rider.name for n in nips):
            raise _fail(source, label, "rides",
                        f"{rider.rides!r}: no [[nip]] with a = {rider.rides!r} and b = "
                        f"{rider.name!r} (the rider rests on its roll through a nip); "
                        "declare one; nips: "
                        f"{', '.join(f'{n.name} ({n.a}, {n.b})' for n in nips) or '(none)'}")
    wound = [r.name for r in rolls if r.kind == "wound"]
    entries = [n.name for n in nips if kinds[n.a] == "drum" and n.b in wound]
    if not webs and wound:
        valid = ", ".join(entries) or "(none: no nip joins a drum, a, to the roll, b)"
        raise SceneError(f"{source}: [web]: missing required table: the scene has the "
                         f"wound roll {wound[0]!r}; add [web] with entry_nip = the nip "
                         f"where the web enters it; valid names: {valid}")
    fed: dict[str, str] = {}  # wound roll -> the label of the web that feeds it
    names: dict[str, str] = {}  # web name -> its label
    for label, web in webs:
        ref = web.entry_nip
        if ref not in entries:
            if kinds.get(ref) == "nip":
                nip = next(n for n in nips if n.name == ref)
                what = (f"is nip {ref!r} joining {kinds[nip.a]} {nip.a!r} (a) and "
                        f"{kinds[nip.b]} {nip.b!r} (b); the web enters a wound roll (b) "
                        "from the drum it wraps (a)")
            else:
                what = f"is {kinds[ref]} {ref!r}, not a nip" if ref in kinds else \
                    "is not a nip of the scene"
            raise _fail(source, label, "entry_nip", f"{show(ref)} {what}; valid names: "
                                                    f"{', '.join(entries) or '(none)'}")
        roll = next(n.b for n in nips if n.name == ref)
        if roll in fed:
            free = [e for e in entries if next(n.b for n in nips if n.name == e) not in fed]
            raise _fail(source, label, "entry_nip",
                        f"{ref!r} enters wound roll {roll!r}, which [{fed[roll]}] already "
                        "feeds: two webs into one roll; every wound roll is fed by exactly "
                        "one web; valid names: nips into the other wound rolls: "
                        f"{', '.join(free) or '(none)'}")
        fed[roll] = label
        if web.name in names:
            raise _fail(source, label, "name",
                        f"{web.name!r} is already the name of [{names[web.name]}]; every "
                        "web needs its own name (default: its entry_nip); valid: a name "
                        f"not taken ({', '.join(names)})")
        if web.name != ref and web.name in kinds:
            raise _fail(source, label, "name",
                        f"{web.name!r} is already the name of {kinds[web.name]} "
                        f"{web.name!r}; a web's name is its entry nip's or one no part "
                        f"has (taken: {', '.join(kinds)})")
        names[web.name] = label
    _check_span(source, kinds, rolls, webs)
    for roll in wound:
        if roll not in fed:
            valid = [n.name for n in nips if n.b == roll and kinds[n.a] == "drum"]
            raise _fail(source, f"roll {roll!r}", "kind",
                        "'wound': no web feeds this wound roll, so its paper would come "
                        "from nowhere (every wound roll is fed by exactly one "
                        "web); add a [[web]] with entry_nip = the nip where its web enters "
                        "it; valid names: "
                        f"{', '.join(valid) or '(none: no nip joins a drum, a, to it, b)'}"
                        ", or make it kind = 'unwinding' with its own span")


def _check_span(source: str, kinds: Mapping[str, str], rolls: list[RollPart],
                webs: list[tuple[str, WebPart]]) -> None:
    """Every unwinding roll feeds exactly one web's span, and every span starts at an
    unwinding roll (spec §5); ``kinds`` maps every part's name to its kind."""
    unwinding = [r.name for r in rolls if r.kind == "unwinding"]
    spans = [(label, w.span) for label, w in webs if w.span is not None]
    source_of: dict[str, str] = {}
    for label, span in spans:
        ref = span.source
        if ref not in unwinding:
            if kinds.get(ref) == "roll":
                what = f"is roll {ref!r} of kind 'wound', not an unwinding roll"
            elif ref in kinds:
                what = f"is {kinds[ref]} {ref!r}, not an unwinding roll"
            else:
                what = "is not a roll of the scene"
            raise _fail(source, f"{label}.span", "from",
                        f"{show(ref)} {what}; the span starts at the unwinding roll that "
                        "feeds it; valid names: "
                        f"{', '.join(unwinding) or '(none: no roll has kind = unwinding)'}")
        if ref in source_of:
            raise _fail(source, f"{label}.span", "from",
                        f"{ref!r} already feeds the span of [{source_of[ref]}]: an "
                        "unwinding roll pays off one web; valid names: unwinding rolls "
                        "feeding no span: "
                        f"{', '.join(u for u in unwinding if u not in source_of) or '(none)'}")
        source_of[ref] = label
    for name in unwinding:
        if name not in source_of:
            first = not spans and len(webs) <= 1
            raise _fail(source, f"roll {name!r}", "kind",
                        "'unwinding': an unwinding roll feeds a web span, and "
                        + ("the scene has no [web.span]; add [web.span] with from = "
                           f"{name!r} (and [web] entry_nip, where the web enters the wound "
                           "roll)" if first else
                           f"no [web.span] has from = {name!r}; add one to the web it "
                           "feeds, or make it kind = 'wound' with a web of its own"))


def _check_overlaps(source: str, drums: list[DrumPart], rolls: list[RollPart],
                    nips: list[NipPart]) -> None:
    """No two drums or rolls whose circles overlap at the start (their ``centre`` and
    initial radius) without a nip between them (spec §8): nothing would carry the force
    between them. Riders are left out: the machine places a rider on top of the roll it
    rides, and the twin-drum winder of spec §10 starts its rider inside the drums'
    circles (a small set in the valley), a contact it does not model."""
    circles: list[tuple[str, str, float, float, float]] = []  # kind, name, x, z, radius
    for d in drums:
        circles.append(("drum", d.name, *d.centre, d.radius))
    for r in rolls:
        circles.append(("roll", r.name, *r.centre, r.initial_radius))
    joined = {frozenset((n.a, n.b)) for n in nips}
    for i, (ka, a, xa, za, ra) in enumerate(circles):
        for kb, b, xb, zb, rb in circles[i + 1:]:
            gap = math.hypot(xb - xa, zb - za) - (ra + rb)
            if gap < -1e-9 * (ra + rb) and frozenset((a, b)) not in joined:
                raise _fail(source, f"{kb} {b!r}", "centre",
                            f"{kb} {b!r} (radius {rb:.6g} m at ({xb:.6g}, {zb:.6g}) m) "
                            f"overlaps {ka} {a!r} (radius {ra:.6g} m at ({xa:.6g}, "
                            f"{za:.6g}) m) by {-gap:.4g} m at the start, and no [[nip]] "
                            "joins them, so nothing carries the force between them; valid: "
                            "centres at least the sum of the radii apart, or a [[nip]] with "
                            f"a = {a!r}, b = {b!r}")


def _check_rest_on_nip(scene: Scene) -> None:
    """Spec §6 starts the roll at rest on the nip (``F_n = m g``): the nip must carry the
    roll's weight with a compression below the roll's radius, else the roll axis would
    start inside the drum."""
    if not scene.effects.contact or scene.roll.initial_height is not None:
        return
    from winder.forces.contact import rest_penetration
    from winder.model.mass_law import PaperRollLaw

    roll = scene.roll
    r = roll.initial_radius
    weight = PaperRollLaw(roll.core_radius, roll.core_mass, roll.core_inertia, roll.width,
                          scene.paper.density).mass(r) \
        * (scene.scene.gravity if scene.effects.gravity else 0.0)
    r_dot = scene.paper.caliper / (2 * math.pi) * roll.initial_speed
    c = scene.contact
    delta = rest_penetration(c.law, lambda k: getattr(c, k), weight, r_dot)
    if not delta < r:
        raise _fail(scene.source, "contact", "stiffness",
                    f"{c.stiffness!r} ({c.law}) is too soft for the roll's weight "
                    f"{weight:.4g} N: at rest the nip would be compressed by {delta:.3g} m, "
                    f"more than the roll's radius {r!r} m, with the roll axis inside the "
                    "drum (weight from [roll] core_mass, initial_radius, width, [paper] "
                    "density, [scene] gravity; compression from [contact] stiffness, "
                    "damping, exponent, hc_damping and [roll] initial_speed); valid: a "
                    "stiffer nip or a lighter roll, so that the compression stays below the "
                    "roll's radius")


#: Largest scene file read [bytes] (scenes are a few kB; this stops a device or a huge
#: file given by mistake from being read into memory).
MAX_SCENE_BYTES = 1 << 20


def _scene_text(p: Path) -> str:
    """The text of a scene file, or a :class:`SceneError` saying why it is not one."""
    try:
        with p.open("rb") as fh:
            raw = fh.read(MAX_SCENE_BYTES + 1)
    except IsADirectoryError:
        raise SceneError(f"{p}: is a directory, not a scene file (give a .toml file)") from None
    except OSError as exc:
        raise SceneError(f"{p}: cannot read scene file: {exc.strerror or exc}") from None
    if len(raw) > MAX_SCENE_BYTES:
        raise SceneError(f"{p}: larger than {MAX_SCENE_BYTES} bytes: not a scene file "
                         "(a scene is a small TOML text file)")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise SceneError(f"{p}: UTF-16 text; a scene file must be UTF-8 (save it as UTF-8)")
    if raw.startswith(b"PK\x03\x04"):
        raise SceneError(f"{p}: a zip archive (a .npz result?), not a TOML scene file")
    if b"\x00" in raw:
        raise SceneError(f"{p}: a binary file (NUL byte at offset {raw.index(0)}), not a "
                         "TOML scene file")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise SceneError(f"{p}: not UTF-8 text: byte 0x{raw[exc.start]:02x} at line {line} "
                         f"(offset {exc.start}); a scene file must be UTF-8 (save it as "
                         "UTF-8)") from None


def load_scene(path: str | os.PathLike[str]) -> Scene:
    """Read and validate a scene file (TOML, UTF-8, spec section 7).

    Raises
    ------
    SceneError
        If the file is missing, a directory, not UTF-8 text, not TOML, or any key is
        unknown, missing, of the wrong type, non-finite or out of range (the message names
        the key and the file).
    ArgumentTypeError
        If ``path`` is not a string or path.
    """
    if not isinstance(path, str | os.PathLike):
        raise ArgumentTypeError(f"load_scene: path must be a str or os.PathLike naming a "
                                f"scene file, got {show(path)} ({type(path).__name__})")
    name = os.fspath(path)
    if not isinstance(name, str):
        raise ArgumentTypeError(f"load_scene: path must name the file as text, got "
                                f"{show(name)} ({type(name).__name__})")
    if "\x00" in name:
        raise SceneError(f"{show(name)}: a file name cannot contain a NUL byte")
    p = Path(path)
    text = _scene_text(p)
    try:
        data = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, ValueError) as exc:  # ValueError: 5000-digit integers
        raise SceneError(f"{p}: not valid TOML: {show(str(exc), 200)[1:-1]}") from None
    except RecursionError:
        raise SceneError(f"{p}: not a scene: arrays or tables nested too deeply for TOML "
                         "parsing (a scene is a few flat tables)") from None
    return scene_from_dict(data, source=str(p))


# ---- key documentation (docs/scene-reference.md) ---------------------------------------
# A self-contained block: the unit and meaning of every scene key, and the default where
# it is not a plain dataclass default. ``winder.scene.reference`` joins it with _SPEC,
# _PART_SPEC, _MAX and _CHOICES (type, range, required) into docs/scene-reference.md; a
# test regenerates that file and fails when it is stale, and fails on a key of the
# schemas missing here. Keys of a scene of parts that repeat a single-drum key
# (``drum[] radius`` is ``drum radius``) fall back to it through _KEY_DOC_ALIAS.

#: (table of _SPEC/_PART_SPEC, key) -> (unit, meaning, default text or None: the
#: dataclass default, or "required"). The unit of a numeric key is None here: it is
#: declared once, in :data:`_NUMBERS`, and :func:`key_doc` reads it from there; only
#: where the reference says more than one axis label can (a stiffness whose unit
#: follows the law, atol in each state's unit) is it written here.
_KEY_DOC: dict[tuple[str, str], tuple[str | None, str, str | None]] = {
    ("scene", "name"): ("-", "the scene's name, in titles, messages and the result",
                        "the file name without .toml"),
    ("scene", "duration"): (None, "simulated time of a run", None),
    ("scene", "output_step"): (None, "time between result samples; at most duration, and "
                               "at most 1e7 samples per run", None),
    ("scene", "gravity"): (None, "gravitational acceleration g, along −z", None),
    ("effects", "variable_mass"): ("-", "the −Ẏv force of mass that joins a body from "
                                   "rest; off: m(r) and J(r) still follow the radius, the "
                                   "term is dropped (the naive overwrite)", None),
    ("effects", "web_momentum"): ("-", "the momentum flux ṁ u the web brings into a wound "
                                  "roll (and the leaving paper takes out of an unwinding "
                                  "one)", None),
    ("effects", "web_tension"): ("-", "the web tension's pull on the wound roll at its "
                                 "entry nip (and on the unwinding roll)", None),
    ("effects", "gravity"): ("-", "gravity; off: g = 0", None),
    ("effects", "imbalance"): ("-", "the centre-of-mass offset com_offset; off: e = 0",
                               None),
    ("effects", "contact"): ("-", "the nips' normal and friction forces", None),
    ("effects", "slip_relaxation"): ("-", "the friction force relaxes towards the "
                                     "steady slip force over relaxation_length (a state "
                                     "per nip); off: F_t = F_ss; needs contact", None),
    ("effects", "rider_load"): ("-", "the riders' applied line load; off: only their "
                                "weight", None),
    ("drum", "radius"): (None, "drum radius R", None),
    ("drum", "inertia"): (None, "polar moment of inertia J_d about the drum axis", None),
    ("drum", "mass"): (None, "drum mass", None),
    ("drum.drive", "kind"): ("-", "speed_profile: the drum's speed is prescribed, its "
                             "torque follows from inverse dynamics; torque: the drum is "
                             "free and driven by an input torque", None),
    ("drum.drive", "web_acceleration"): (None, "ramp of the surface (web) speed a_w; "
                                         "0: full speed from t = 0", None),
    ("drum.drive", "web_speed"): (None, "speed_profile: the surface speed v_w the ramp "
                                  "reaches; torque: the initial surface speed",
                                  "required (kind speed_profile); 0 (kind torque)"),
    ("drum.drive", "torque"): (None, "kind torque: the drive torque (operation sense), "
                               "constant or an input", None),
    ("roll", "core_radius"): (None, "outer radius r_c of the empty core", None),
    ("roll", "core_mass"): (None, "mass of the core", None),
    ("roll", "core_inertia"): (None, "polar inertia of the core about its axis", None),
    ("roll", "width"): (None, "roll width L (cross-machine)", None),
    ("roll", "initial_radius"): (None, "radius at t = 0; at least core_radius",
                                 "core_radius"),
    ("roll", "initial_speed"): (None, "speed at t = 0 (operation sense)", None),
    ("roll", "com_offset"): (None, "distance e of the centre of mass from the roll axis "
                             "(imbalance); below min(core_radius, √(core_inertia / "
                             "core_mass))", None),
    ("roll", "initial_height"): (None, "height z of the roll axis at t = 0, above the drum "
                                 "radius (e.g. to drop the roll onto the drum)",
                                 "static balance on the nip"),
    ("paper", "density"): (None, "paper density ρ", None),
    ("paper", "caliper"): (None, "paper thickness h, added to the radius once per "
                           "revolution", None),
    ("contact", "law"): ("-", "linear: F_n = max(0, k δ + c δ̇); hunt_crossley: F_n = "
                         "max(0, k δ^p (1 + α δ̇))", None),
    ("contact", "stiffness"): ("N/m (N/m^p)", "stiffness k of the nip", None),
    ("contact", "damping"): (None, "damping c of the linear law", None),
    ("contact", "exponent"): (None, "exponent p of the Hunt–Crossley law", None),
    ("contact", "hc_damping"): (None, "damping α of the Hunt–Crossley law", None),
    ("friction", "mu"): (None, "friction coefficient μ: F_ss = μ F_n tanh(v_s / v_ref)",
                         None),
    ("friction", "slip_velocity"): (None, "slip velocity scale v_ref of the tanh law",
                                    None),
    ("friction", "relaxation_length"): (None, "relaxation length σ: dF_t/dt = (|u_a| + "
                                        "v_min)/σ (F_ss − F_t)", None),
    ("friction", "min_speed"): (None, "speed v_min added in the relaxation rate (keeps it "
                                "finite at standstill)", None),
    ("solver", "method"): ("-", "integrator; auto is DOPRI5", None),
    ("solver", "rtol"): (None, "relative tolerance", None),
    ("solver", "atol"): ("state units", "absolute tolerance", None),
    ("solver", "max_rhs"): (None, "budget: most right-hand side evaluations of a run (a "
                            "whole number)", None),
    ("solver", "backend"): ("-", "compiled: the generated code; pinocchio: the numeric "
                            "Pinocchio path (the cross-check)", None),
    ("solver", "max_wall"): (None, "budget: most wall-clock time of a run", None),
    ("drum[]", "name"): ("-", "the part's name (unique; names its channels)", "required"),
    ("drum[]", "centre"): ("m", "axis position [x, z]", None),
    ("drum[]", "sense"): ("-", "operation direction: +1 turns the top surface towards +x",
                          None),
    ("drum[]", "drive"): ("-", "the drive, a sub-table: keys below", None),
    ("drum[].drive", "ratio"): (None, "kind speed_profile: the drum runs at ratio × the "
                                "profile's surface speed", None),
    ("roll[]", "name"): ("-", "the part's name (unique; names its channels)", None),
    ("roll[]", "kind"): ("-", "wound: grows, ṙ = +h·speed/2π; unwinding: shrinks, ṙ = "
                         "−h·speed/2π, fixed centre, feeds [web.span]; the run ends where "
                         "it reaches its core", None),
    ("roll[]", "centre"): ("m", "axis position [x, z]: the initial guess of the free "
                           "coordinates (static balance), the value of the fixed ones", None),
    ("roll[]", "free"): ("-", "the axes its centre moves along", '["z"] (wound), [] '
                         "(unwinding)"),
    ("roll[]", "sense"): ("-", "operation direction: −1 turns the bottom surface towards "
                          "+x (a roll on a drum)", None),
    ("roll[]", "density"): (None, "paper density ρ", "[paper] density"),
    ("roll[]", "caliper"): (None, "paper thickness h", "[paper] caliper"),
    ("roll[]", "drive"): ("-", "unwinding rolls only: the unwind drive, a sub-table: keys "
                          "below", "none (free)"),
    ("roll[].drive", "kind"): ("-", "torque: a torque (negative brakes); tension_control: "
                               "the unwind holds the span tension by PI with inertia "
                               "feed-forward, gains from bandwidth", None),
    ("roll[].drive", "torque"): (None, "kind torque: the unwind torque (operation sense), "
                                 "constant or an input", None),
    ("roll[].drive", "tension"): (None, "kind tension_control: the tension set-point T*",
                                  "required (kind tension_control)"),
    ("roll[].drive", "bandwidth"): (None, "kind tension_control: the closed loop's "
                                    "bandwidth ω_c (its three poles at −ω_c)", None),
    ("rider[]", "name"): ("-", "the part's name (unique; names its channels)", None),
    ("rider[]", "rides"): ("-", "name of the paper roll it rests on (through a [[nip]] "
                           "with a = that roll, b = the rider)", None),
    ("rider[]", "radius"): (None, "rider radius (constant)", None),
    ("rider[]", "mass"): (None, "rider mass", None),
    ("rider[]", "inertia"): (None, "polar inertia of the rider", None),
    ("rider[]", "x"): (None, "horizontal position of its axis (fixed; it moves along z)",
                       None),
    ("rider[]", "load"): ("m, N/m", "line-load schedule [[radius of the ridden roll, line "
                          "load], ...], radii strictly increasing, interpolated linearly, "
                          "held beyond the ends; the force is −width × load along z",
                          "[] (no load)"),
    ("nip[]", "name"): ("-", "the part's name (unique; names its channels)", None),
    ("nip[]", "a"): ("-", "the lower or supplying body (the drum under a roll, the roll "
                     "under a rider)", None),
    ("nip[]", "b"): ("-", "the other body", None),
    ("nip[]", "contact"): ("-", "the contact law, a sub-table: the keys of [contact]",
                           "required while effects.contact is on"),
    ("nip[]", "friction"): ("-", "the friction law, a sub-table: the keys of [friction]",
                            None),
    ("web", "name"): ("-", "the web's name, in its channels and messages where a scene has "
                      "several webs ([[web]], one per wound roll)", "its entry_nip"),
    ("web", "entry_nip"): ("-", "the nip where the web enters the wound roll (a: the drum "
                           "it wraps, b: the roll)", None),
    ("web", "tension"): (None, "constant web tension (not with [web.span])", None),
    ("web", "span"): ("-", "an elastic span from an unwinding roll, a sub-table: keys "
                      "below", "none"),
    ("web.span", "from"): ("-", "the unwinding roll that feeds the span", None),
    ("web.span", "length"): (None, "span length L_s", None),
    ("web.span", "EA"): (None, "axial stiffness EA of the web", None),
    ("web.span", "T_in"): (None, "tension wound into the unwinding roll", None),
    ("web.span", "initial_tension"): (None, "span tension at t = 0", "T_in"),
}
#: Tables of a scene of parts whose keys, where not in _KEY_DOC, are those of a
#: single-drum table.
_KEY_DOC_ALIAS = {"drum[]": "drum", "drum[].drive": "drum.drive", "roll[]": "roll",
                  "nip[].contact": "contact", "nip[].friction": "friction"}


def key_doc(table: str, key: str) -> tuple[str, str, str | None]:
    """``(unit, meaning, default text or None)`` of ``key`` of the schema table ``table``
    (a table of ``_SPEC`` or ``_PART_SPEC``); KeyError where it is not documented."""
    doc = _KEY_DOC.get((table, key))
    if doc is None and table in _KEY_DOC_ALIAS:
        alias = _KEY_DOC_ALIAS[table]
        doc = _KEY_DOC.get((alias, key)) or (
            _KEY_DOC.get(("paper", key)) if table == "roll[]" else None)
    if doc is None:
        raise KeyError((table, key))
    unit, meaning, default = doc
    return (_UNITS[(table, key)] if unit is None else unit), meaning, default
