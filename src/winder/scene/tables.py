"""The tables every scene has (``[scene]``, ``[effects]``, ``[solver]``) and ``[paper]``,
as frozen dataclasses; their keys, units and bounds are declared in
:mod:`winder.scene.schema`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from winder._args import number
from winder._errors import ArgumentError, ArgumentTypeError
from winder.scene.schema import EFFECT_NAMES, effect_settings

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


@dataclass(frozen=True)
class Effects:
    """``[effects]``: which physical effects the scene simulates (all on by default), and
    the settings of those that have their own (``[effects.NAME]``; ``settings`` holds the
    ones given, a mapping ``{effect: {key: value}}`` or its tuple form :data:`Settings`;
    :meth:`setting` reads one, its declared default where not given)."""

    variable_mass: bool = True
    web_momentum: bool = True
    web_tension: bool = True
    gravity: bool = True
    imbalance: bool = True
    contact: bool = True
    slip_relaxation: bool = True
    rider_load: bool = True
    settings: Settings = ()

    def __post_init__(self) -> None:
        given = self.settings
        if isinstance(given, Mapping):
            given = tuple(given.items())
        if not isinstance(given, tuple | list):
            raise ArgumentTypeError(f"Effects: settings must be a mapping of effect names to "
                                    f"mappings of their keys, got {type(given).__name__}")
        out = []
        for effect, values in given:
            if effect not in EFFECT_NAMES:
                raise ArgumentError(f"Effects: settings of {effect!r}, not an effect; valid: "
                                    f"{', '.join(EFFECT_NAMES)}")
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
        object.__setattr__(self, "settings", tuple(sorted(out)))

    def enabled(self) -> tuple[str, ...]:
        """Names of the effects that are on, in spec order."""
        return tuple(n for n in EFFECT_NAMES if getattr(self, n))

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
        out: dict[str, Any] = {n: getattr(self, n) for n in EFFECT_NAMES}
        for effect, values in self.settings:
            out[effect] = {"enabled": out[effect], **dict(values)}
        return out


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
    max_rhs: int = 50_000_000
    max_wall: float = 600.0
    backend: str = "compiled"
