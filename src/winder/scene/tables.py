"""The tables every scene has (``[scene]``, ``[effects]``, ``[solver]``) and ``[paper]``,
as frozen dataclasses; their keys, units and bounds are declared in
:mod:`winder.scene.schema`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from winder._args import number
from winder._errors import ArgumentError, ArgumentTypeError
from winder.forces import FORCES
from winder.scene.schema import effect_names, effect_settings

__all__ = ["SceneInfo", "Effects", "Paper", "Solver", "Settings"]

#: Settings of effects given in a scene: ``((effect, ((key, value), ...)), ...)``.
Settings = tuple[tuple[str, tuple[tuple[str, Any], ...]], ...]


@dataclass(frozen=True)
class SceneInfo:
    """``[scene]``: name, duration [s], output_step [s], gravity [m/s²]
    (:data:`~winder.scene.schema.SCENE_KEYS`)."""

    name: str = "scene"
    duration: float = 10.0
    output_step: float = 0.01
    gravity: float = 9.81


@dataclass(frozen=True, init=False, repr=False)
class Effects:
    """``[effects]``: which physical effects the scene simulates, and the settings of those
    that have their own (``[effects.NAME]``).

    The effects are the force elements registered in :data:`winder.forces.FORCES`; each
    is a keyword (``Effects(gravity=False)``) and an attribute (``effects.gravity``), on
    or off as given, else its force element's ``default`` (on). ``flags`` holds them all,
    ``((name, on), ...)`` in registration order. ``settings`` holds the settings given, a
    mapping ``{effect: {key: value}}`` or its tuple form :data:`Settings`; :meth:`setting`
    reads one, its declared default where not given.

    Raises
    ------
    ArgumentError: an unknown effect, or a setting that is not the effect's or out of
        its range.
    ArgumentTypeError: a flag that is not a bool, or settings that are not a mapping.
    """

    flags: tuple[tuple[str, bool], ...]
    settings: Settings

    def __init__(self, flags: Iterable[tuple[str, bool]] | Mapping[str, bool] = (),
                 settings: Settings | Mapping[str, Mapping[str, Any]] = (),
                 **named: bool) -> None:
        names = effect_names()
        given = dict(flags.items() if isinstance(flags, Mapping) else flags)
        given.update(named)
        for effect, on in given.items():
            if effect not in names:
                raise ArgumentError(f"Effects: {effect!r} is not an effect; valid: "
                                    f"{', '.join(names)}")
            if not isinstance(on, bool):
                raise ArgumentTypeError(f"Effects: {effect} must be true or false, got "
                                        f"{on!r} ({type(on).__name__})")
        object.__setattr__(self, "flags", tuple(
            (n, given.get(n, FORCES[n].default)) for n in names))
        object.__setattr__(self, "settings", _settings(settings, names))

    def __getattr__(self, name: str) -> bool:
        """``effects.NAME``: the effect ``NAME`` on (True) or off."""
        if not name.startswith("_"):
            for effect, on in self.__dict__.get("flags", ()):
                if effect == name:
                    return on
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __repr__(self) -> str:
        flags = ", ".join(f"{n}={on}" for n, on in self.flags)
        return f"Effects({flags}, settings={self.settings!r})"

    def enabled(self) -> tuple[str, ...]:
        """Names of the effects that are on, in registration (spec) order."""
        return tuple(n for n, on in self.flags if on)

    def setting(self, effect: str, key: str) -> Any:
        """The value of the setting ``key`` of ``effect``: as given in the scene, else the
        default its force element declares."""
        for name, values in self.settings:
            if name == effect:
                for k, v in values:
                    if k == key:
                        return v
        return effect_settings(effect)[key].default

    def to_dict(self) -> dict[str, Any]:
        """``[effects]`` as a TOML table: ``NAME = bool``, or ``[effects.NAME]`` with
        ``enabled`` and the settings given."""
        out: dict[str, Any] = dict(self.flags)
        for effect, values in self.settings:
            out[effect] = {"enabled": out[effect], **dict(values)}
        return out


def _settings(given: Any, names: tuple[str, ...]) -> Settings:
    """The settings of :class:`Effects`, checked against what each effect declares, in
    the tuple form (sorted)."""
    if isinstance(given, Mapping):
        given = tuple(given.items())
    if not isinstance(given, tuple | list):
        raise ArgumentTypeError(f"Effects: settings must be a mapping of effect names to "
                                f"mappings of their keys, got {type(given).__name__}")
    out = []
    for effect, values in given:
        if effect not in names:
            raise ArgumentError(f"Effects: settings of {effect!r}, not an effect; valid: "
                                f"{', '.join(names)}")
        items = tuple(values.items()) if isinstance(values, Mapping) else tuple(values)
        table = effect_settings(effect)
        for key, value in items:
            if key not in table or key == "enabled":
                valid = ", ".join(table.names()[1:]) or "(none)"
                raise ArgumentError(f"Effects: {key!r} is not a setting of {effect}; "
                                    f"valid: {valid}")
            k = table[key]
            if k.kind == "num":
                number(f"Effects: settings of {effect}", key, value, lo=k.lo,
                       lo_open=k.lo_open, hi=k.hi, unit=k.unit)
        if items:
            out.append((effect, tuple(sorted(items))))
    return tuple(sorted(out))


@dataclass(frozen=True)
class Paper:
    """``[paper]``: density [kg/m³], caliper [m] (thickness added per revolution)
    (:data:`~winder.scene.schema.PAPER_KEYS`)."""

    density: float
    caliper: float


@dataclass(frozen=True)
class Solver:
    """``[solver]``: method, rtol [-], atol [state units], max_rhs (guard: right-hand side
    evaluations), backend, max_wall (guard: wall-clock seconds) [s]
    (:data:`~winder.scene.schema.SOLVER_KEYS`)."""

    method: str = "auto"
    rtol: float = 1e-6
    atol: float = 1e-8
    max_rhs: int | None = None  # None: the path's own (winder.solve.budgets.default_max_rhs)
    max_wall: float = 600.0
    backend: str = "compiled"
