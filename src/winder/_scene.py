"""Scene files (TOML, spec section 7): frozen dataclasses that validate on construction.

Every error names the file, the table and the key, and the offending value.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from ._args import RTOL_MAX, check_real, show
from ._errors import ArgumentError, ArgumentTypeError, SceneError

__all__ = ["Scene", "SceneInfo", "Effects", "Drum", "Drive", "Roll", "Paper", "Contact",
           "Friction", "Solver", "load_scene", "scene_from_dict", "EFFECT_NAMES",
           "DRIVE_KINDS", "CONTACT_LAWS", "METHODS", "BACKENDS"]

EFFECT_NAMES = ("variable_mass", "web_momentum", "gravity", "imbalance", "contact",
                "slip_relaxation")
DRIVE_KINDS = ("speed_profile", "torque")
CONTACT_LAWS = ("linear", "hunt_crossley")
METHODS = ("auto", "DOPRI5", "RK4", "RK45", "DOP853", "Radau", "BDF", "LSODA", "RK23")
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
    gravity: bool = True
    imbalance: bool = True
    contact: bool = True
    slip_relaxation: bool = True

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
class Contact:
    """``[contact]``: law (``linear`` | ``hunt_crossley``), stiffness (0, 1e18] [N/m or
    N/m^p], damping [0, 1e12] [N·s/m] (linear), exponent ``p`` [1, 3] [-] and hc_damping
    ``α`` [0, 1e4] [s/m] (Hunt–Crossley)."""

    law: str = "linear"
    stiffness: float = 1e7
    damping: float = 0.0
    exponent: float = 1.5
    hc_damping: float = 0.0


@dataclass(frozen=True)
class Friction:
    """``[friction]``: mu [0, 10] [-], slip_velocity ``v_ref`` (0, 1000] [m/s],
    relaxation_length ``σ`` (0, 1000] [m], min_speed ``v_min`` (0, 1000] [m/s]."""

    mu: float = 0.3
    slip_velocity: float = 0.05
    relaxation_length: float = 0.01
    min_speed: float = 0.1


@dataclass(frozen=True)
class Solver:
    """``[solver]``: method (one of :data:`METHODS`), rtol (0, 0.1] [-], atol (0, 1]
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
    """A complete winder scene. Build one with :func:`load_scene` or :func:`scene_from_dict`."""

    scene: SceneInfo
    effects: Effects
    drum: Drum
    roll: Roll
    paper: Paper
    contact: Contact
    friction: Friction
    solver: Solver
    source: str = "<scene>"

    @property
    def name(self) -> str:
        return self.scene.name

    def replace(self, **changes: Mapping[str, Any]) -> Scene:
        """A copy with some tables' keys changed: ``scene.replace(roll={"com_offset": 0})``.

        Each keyword is a table (``drum={"drive": {...}}`` reaches ``[drum.drive]``) and
        its value a mapping of that table's keys to new values. The result is validated
        like a file (:class:`SceneError` naming the key).

        Raises
        ------
        ArgumentError: a keyword that is not a table of the scene.
        ArgumentTypeError: a table given as something other than a mapping of keys.
        """
        data = self.to_dict()
        for table, values in changes.items():
            if table not in data:
                raise ArgumentError(f"Scene.replace: {table} is not a table of the scene; "
                                    f"valid tables: {', '.join(data)}")
            if not isinstance(values, Mapping):
                raise ArgumentTypeError(
                    f"Scene.replace: {table} must be a mapping of [{table}] keys to values, "
                    f"e.g. {table}={{{next(iter(data[table]))!r}: ...}}; got {show(values)} "
                    f"({type(values).__name__})")
            values = dict(values)
            if table == "drum" and "drive" in values:
                drive = values.pop("drive")
                if not isinstance(drive, Mapping):
                    raise ArgumentTypeError(
                        f"Scene.replace: drum['drive'] must be a mapping of [drum.drive] keys "
                        f"to values, e.g. drum={{'drive': {{'web_speed': 5.0}}}}; got "
                        f"{show(drive)} ({type(drive).__name__})")
                data["drum"]["drive"].update(drive)
            data[table].update(values)
        return scene_from_dict(data, source=self.source)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """The scene as nested dictionaries (TOML tables)."""
        out: dict[str, dict[str, Any]] = {}
        for f in fields(self):
            if f.name == "source":
                continue
            table = dataclasses.asdict(getattr(self, f.name))
            if f.name == "drum":
                table["drive"] = {k: v for k, v in table["drive"].items() if v is not None}
            out[f.name] = {k: v for k, v in table.items() if v is not None}
        return out


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
#: Upper bounds of the numeric keys (far beyond any real winder, well inside the float
#: range so that masses, inertias and forces cannot overflow); units as in the tables'
#: docstrings. Keys without a lower bound are bounded in magnitude.
_MAX: dict[tuple[str, str], float] = {
    ("scene", "duration"): 1e6, ("scene", "gravity"): 1e3,
    ("drum", "radius"): 10.0, ("drum", "inertia"): 1e7, ("drum", "mass"): 1e6,
    ("drum.drive", "web_acceleration"): 1e3, ("drum.drive", "web_speed"): 1e3,
    ("drum.drive", "torque"): 1e8,
    ("roll", "core_radius"): 10.0, ("roll", "core_mass"): 1e6, ("roll", "core_inertia"): 1e7,
    ("roll", "width"): 100.0, ("roll", "initial_radius"): 10.0,
    ("roll", "initial_speed"): 1e5, ("roll", "com_offset"): 10.0,
    ("roll", "initial_height"): 1e3,
    ("paper", "density"): 1e5, ("paper", "caliper"): 0.1,
    ("contact", "stiffness"): 1e18, ("contact", "damping"): 1e12,
    ("contact", "exponent"): 3.0, ("contact", "hc_damping"): 1e4,
    ("friction", "mu"): 10.0, ("friction", "slip_velocity"): 1e3,
    ("friction", "relaxation_length"): 1e3, ("friction", "min_speed"): 1e3,
    ("solver", "rtol"): RTOL_MAX, ("solver", "atol"): 1.0, ("solver", "max_rhs"): 1e12,
}
_CHOICES = {("drum.drive", "kind"): DRIVE_KINDS, ("contact", "law"): CONTACT_LAWS,
            ("solver", "method"): METHODS, ("solver", "backend"): BACKENDS}
_REQUIRED_TABLES = ("scene", "drum", "roll", "paper")


def _check_name(source: str, value: str) -> str:
    if not value or len(value) > MAX_NAME or not value.isprintable():
        raise _fail(source, "scene", "name", f"{show(value)} is not a plain name; valid: 1 to "
                                              f"{MAX_NAME} printable characters")
    return value


def _parse_table(source: str, table: str, raw: Any) -> dict[str, Any]:
    spec = _SPEC[table]
    if not isinstance(raw, dict):
        raise SceneError(f"{source}: [{table}] must be a table of keys, got {show(raw)} "
                         f"({type(raw).__name__})")
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if table == "drum" and key == "drive":
            continue
        if key not in spec:
            raise _fail(source, table, key, f"unknown key; valid keys: {', '.join(spec)}")
        kind, _, bound = spec[key]
        if kind == "bool":
            if not isinstance(value, bool):
                raise _fail(source, table, key, f"expected true or false, got {show(value)}")
            out[key] = value
        elif kind == "str":
            if not isinstance(value, str):
                raise _fail(source, table, key, f"expected a string, got {show(value)} "
                                                 f"({type(value).__name__})")
            choices = _CHOICES.get((table, key))
            if choices and value not in choices:
                raise _fail(source, table, key, f"{show(value)} is not one of: "
                                                 f"{', '.join(repr(c) for c in choices)}")
            out[key] = _check_name(source, value) if (table, key) == ("scene", "name") \
                else value
        else:
            lo, lo_open = bound if bound else (None, False)
            out[key] = _check_number(source, table, key, value, lo=lo, lo_open=lo_open,
                                     hi=_MAX.get((table, key)))
    for key, (_, required, _) in spec.items():
        if required and key not in out:
            raise _fail(source, table, key, "missing required key")
    return out


def max_com_offset(core_radius: float, core_mass: float, core_inertia: float) -> float:
    """Bound ``e_max`` [m] of a roll's centre-of-mass offset, ``0 <= e < e_max``.

    The centre of mass lies inside the core (``e < r_c``) and the core's inertia about it,
    ``J_core − m_core e²``, is positive (``e < √(J_core/m_core)``). Then the roll's inertia
    about its centre of mass ``J(r) − m(r) e²`` stays positive at every radius: the paper
    adds ``b(r)(½(r² + r_c²) − e²) > 0`` with ``b`` its mass."""
    return min(core_radius, math.sqrt(core_inertia / core_mass))


def scene_from_dict(data: dict[str, Any], *, source: str = "<scene>") -> Scene:
    """Validate nested dictionaries (as read from TOML) and build a :class:`Scene`."""
    if not isinstance(data, dict):
        raise SceneError(f"{source}: a scene is a set of TOML tables, got {show(data)} "
                         f"({type(data).__name__})")
    valid = ", ".join(t for t in _SPEC if t != "drum.drive")
    for table in data:
        if table not in _SPEC or table == "drum.drive":
            raise SceneError(f"{source}: [{_name(table)}]: unknown table; valid "
                             f"tables: {valid}")
    for table in _REQUIRED_TABLES:
        if table not in data:
            raise SceneError(f"{source}: [{table}]: missing required table")
    t = {name: _parse_table(source, name, data.get(name, {})) for name in _SPEC
         if name != "drum.drive"}
    drum_raw = data["drum"]
    if "drive" not in drum_raw:
        raise SceneError(f"{source}: [drum.drive]: missing required table")
    drive = _parse_table(source, "drum.drive", drum_raw["drive"])

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
    roll_kw = dict(t["roll"])
    roll_kw.setdefault("initial_radius", roll_kw["core_radius"])
    roll = Roll(**roll_kw)
    if roll.initial_radius < roll.core_radius:
        raise _fail(source, "roll", "initial_radius",
                    f"{roll.initial_radius!r} m is below core_radius {roll.core_radius!r} m; "
                    f"valid: >= core_radius")
    e_max = max_com_offset(roll.core_radius, roll.core_mass, roll.core_inertia)
    if not roll.com_offset < e_max:
        raise _fail(source, "roll", "com_offset",
                    f"{roll.com_offset!r} m puts the centre of mass outside the core or "
                    f"makes the core's inertia about it, core_inertia − core_mass "
                    f"com_offset², non-positive (core_radius {roll.core_radius!r} m, "
                    f"core_inertia {roll.core_inertia!r} kg·m², core_mass "
                    f"{roll.core_mass!r} kg); valid: com_offset < min(core_radius, "
                    f"√(core_inertia/core_mass)) = {e_max:.6g} m")
    radius = t["drum"]["radius"]
    if roll.initial_height is not None and not roll.initial_height > radius:
        raise _fail(source, "roll", "initial_height",
                    f"{roll.initial_height!r} m puts the roll axis inside the drum or below "
                    f"it; valid: > {radius!r} m (the drum radius, [drum] radius) and <= "
                    f"{_MAX[('roll', 'initial_height')]:g} m")
    if drive["kind"] == "speed_profile" and "web_speed" not in drive:
        raise _fail(source, "drum.drive", "web_speed", "missing required key "
                    "(kind = 'speed_profile')")
    solver_kw = dict(t["solver"])
    if "max_rhs" in solver_kw:
        if solver_kw["max_rhs"] != int(solver_kw["max_rhs"]):
            raise _fail(source, "solver", "max_rhs", f"{solver_kw['max_rhs']!r} is not a whole "
                        "number of evaluations; valid: an integer 1 … 1e12")
        solver_kw["max_rhs"] = int(solver_kw["max_rhs"])
    if effects.slip_relaxation and not effects.contact:
        raise SceneError(f"{source}: [effects] slip_relaxation: true requires contact = true "
                         "(the relaxed force is the nip friction)")
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


def _check_rest_on_nip(scene: Scene) -> None:
    """Spec §6 starts the roll at rest on the nip (``F_n = m g``): the nip must carry the
    roll's weight with a compression below the roll's radius, else the roll axis would
    start inside the drum."""
    if not scene.effects.contact or scene.roll.initial_height is not None:
        return
    from ._mass_law import PaperRollLaw
    from .effects.contact import make_contact_law

    roll = scene.roll
    r = roll.initial_radius
    weight = PaperRollLaw(roll.core_radius, roll.core_mass, roll.core_inertia, roll.width,
                          scene.paper.density).mass(r) \
        * (scene.scene.gravity if scene.effects.gravity else 0.0)
    r_dot = scene.paper.caliper / (2 * math.pi) * roll.initial_speed
    try:
        delta = make_contact_law(scene).static_penetration(weight, r_dot)
    except ValueError:
        delta = math.inf
    if not delta < r:
        c = scene.contact
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
