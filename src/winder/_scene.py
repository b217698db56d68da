"""Scene files (TOML, spec section 7): frozen dataclasses that validate on construction.

Every error names the file, the table and the key, and the offending value.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from ._errors import SceneError

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


def _fail(source: str, table: str, key: str, message: str) -> SceneError:
    return SceneError(f"{source}: [{table}] {key}: {message}")


def _check_number(source: str, table: str, key: str, value: Any, *, lo: float | None = None,
                  lo_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _fail(source, table, key, f"expected a number, got {value!r} "
                                         f"({type(value).__name__})")
    value = float(value)
    if not math.isfinite(value):
        raise _fail(source, table, key, f"must be finite, got {value!r}")
    if lo is not None and (value <= lo if lo_open else value < lo):
        raise _fail(source, table, key, f"must be {'>' if lo_open else '>='} {lo:g}, "
                                         f"got {value!r}")
    return value


# Lower bounds (value, open) of the table schemas in _SPEC.
_POS, _NONNEG = (0.0, True), (0.0, False)


@dataclass(frozen=True)
class SceneInfo:
    """``[scene]``: name, duration [s], output_step [s], gravity [m/s²]."""

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
    [m/s²] to ``web_speed`` [m/s]) or ``torque`` (drum free, driven by an input torque
    ``torque`` [N·m]; ``web_speed`` then is the initial web speed)."""

    kind: str = "speed_profile"
    web_acceleration: float = 0.0
    web_speed: float = 0.0
    torque: float = 0.0


@dataclass(frozen=True)
class Drum:
    """``[drum]``: radius [m], inertia (polar) [kg·m²], mass [kg]."""

    radius: float
    inertia: float
    mass: float
    drive: Drive = field(default_factory=Drive)


@dataclass(frozen=True)
class Roll:
    """``[roll]``: core_radius [m], core_mass [kg], core_inertia [kg·m²], width [m],
    initial_radius [m] (default: core_radius), initial_speed [rad/s], com_offset [m];
    winder's own key initial_height [m]: ``z`` at ``t = 0`` (default: static equilibrium on
    the contact, spec §6), e.g. to drop the roll onto the drum."""

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
    """``[paper]``: density [kg/m³], caliper [m] (thickness added per revolution)."""

    density: float
    caliper: float


@dataclass(frozen=True)
class Contact:
    """``[contact]``: law (``linear`` | ``hunt_crossley``), stiffness [N/m or N/m^p],
    damping [N·s/m] (linear), exponent ``p`` [-] and hc_damping ``α`` [s/m] (Hunt–Crossley)."""

    law: str = "linear"
    stiffness: float = 1e7
    damping: float = 0.0
    exponent: float = 1.5
    hc_damping: float = 0.0


@dataclass(frozen=True)
class Friction:
    """``[friction]``: mu [-], slip_velocity ``v_ref`` [m/s], relaxation_length ``σ`` [m],
    min_speed ``v_min`` [m/s]."""

    mu: float = 0.3
    slip_velocity: float = 0.05
    relaxation_length: float = 0.01
    min_speed: float = 0.1


@dataclass(frozen=True)
class Solver:
    """``[solver]``: method (one of :data:`METHODS`), rtol, atol, max_rhs and max_wall
    [s] (budgets), backend (one of :data:`BACKENDS`)."""

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

    def replace(self, **changes: dict[str, Any]) -> Scene:
        """A copy with some tables' keys changed: ``scene.replace(roll={"com_offset": 0})``.

        The result is validated like a file."""
        data = self.to_dict()
        for table, values in changes.items():
            if table not in data:
                raise SceneError(f"{self.source}: no table [{table}]; valid: "
                                 f"{', '.join(sorted(data))}")
            if table == "drum" and "drive" in values:
                data["drum"]["drive"].update(values["drive"])
                values = {k: v for k, v in values.items() if k != "drive"}
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
               "max_wall": ("num", False, _POS), "backend": ("str", False, None)},
}
_CHOICES = {("drum.drive", "kind"): DRIVE_KINDS, ("contact", "law"): CONTACT_LAWS,
            ("solver", "method"): METHODS, ("solver", "backend"): BACKENDS}
_REQUIRED_TABLES = ("scene", "drum", "roll", "paper")


def _parse_table(source: str, table: str, raw: Any) -> dict[str, Any]:
    spec = _SPEC[table]
    if not isinstance(raw, dict):
        raise SceneError(f"{source}: [{table}] must be a table, got {type(raw).__name__}")
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if table == "drum" and key == "drive":
            continue
        if key not in spec:
            raise _fail(source, table, key, f"unknown key; valid keys: {', '.join(spec)}")
        kind, _, bound = spec[key]
        if kind == "bool":
            if not isinstance(value, bool):
                raise _fail(source, table, key, f"expected true or false, got {value!r}")
            out[key] = value
        elif kind == "str":
            if not isinstance(value, str):
                raise _fail(source, table, key, f"expected a string, got {value!r}")
            choices = _CHOICES.get((table, key))
            if choices and value not in choices:
                raise _fail(source, table, key, f"{value!r} is not one of: "
                                                 f"{', '.join(repr(c) for c in choices)}")
            out[key] = value
        else:
            lo, lo_open = bound if bound else (None, False)
            out[key] = _check_number(source, table, key, value, lo=lo, lo_open=lo_open)
    for key, (_, required, _) in spec.items():
        if required and key not in out:
            raise _fail(source, table, key, "missing required key")
    return out


def scene_from_dict(data: dict[str, Any], *, source: str = "<scene>") -> Scene:
    """Validate nested dictionaries (as read from TOML) and build a :class:`Scene`."""
    if not isinstance(data, dict):
        raise SceneError(f"{source}: a scene is a set of TOML tables")
    for table in data:
        if table not in _SPEC or table == "drum.drive":
            valid = ", ".join(t for t in _SPEC if t != "drum.drive")
            raise SceneError(f"{source}: [{table}]: unknown table; valid tables: {valid}")
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
    roll_kw = dict(t["roll"])
    roll_kw.setdefault("initial_radius", roll_kw["core_radius"])
    roll = Roll(**roll_kw)
    if roll.initial_radius < roll.core_radius:
        raise _fail(source, "roll", "initial_radius",
                    f"{roll.initial_radius!r} m is below core_radius {roll.core_radius!r} m")
    if drive["kind"] == "speed_profile" and "web_speed" not in drive:
        raise _fail(source, "drum.drive", "web_speed", "missing required key "
                    "(kind = 'speed_profile')")
    solver_kw = dict(t["solver"])
    if "max_rhs" in solver_kw:
        solver_kw["max_rhs"] = int(solver_kw["max_rhs"])
    if effects.slip_relaxation and not effects.contact:
        raise SceneError(f"{source}: [effects] slip_relaxation: true requires contact = true "
                         "(the relaxed force is the nip friction)")
    contact = Contact(**t["contact"])
    if effects.contact and "contact" not in data:
        raise SceneError(f"{source}: [contact]: missing required table (effects.contact is on)")
    return Scene(scene=info, effects=effects,
                 drum=Drum(**t["drum"], drive=Drive(**drive)), roll=roll,
                 paper=Paper(**t["paper"]), contact=contact, friction=Friction(**t["friction"]),
                 solver=Solver(**solver_kw), source=source)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file (TOML, spec section 7).

    Raises
    ------
    SceneError
        If the file is missing, not TOML, or any key is unknown, missing, of the wrong
        type, non-finite or out of range (the message names the key and the file).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise SceneError(f"{p}: cannot read scene file: {exc.strerror or exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{p}: not valid TOML: {exc}") from None
    return scene_from_dict(data, source=str(p))
