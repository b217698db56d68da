"""The scene's tables of keys (spec section 7; machines spec §8), each key declared once.

A part's keys are declared in its module under ``winder/parts/`` (``KEYS``), an effect's
flag, meaning, default and settings on its force element (``[effects]`` is read from the
registry :data:`winder.forces.FORCES`); this module declares the tables that are no
part's (``[scene]``, ``[paper]``, ``[solver]``) and gathers every table of
a scene of parts by its schema name (``drum[]``, ``drum[].drive``, ..., :data:`TABLES`):
the body types' from the registry :data:`winder.parts.PARTS` (a type registered later is
a table at once).
The single-drum format's tables are :data:`winder.scene.legacy.LEGACY_TABLES`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence

from winder._args import ATOL_MAX, COMPILED_MAX_RHS, RTOL_MAX, STEPWISE_MAX_RHS, STEPWISE_STATES
from winder._schema import Key, Table
from winder.forces import FORCES
from winder.parts import PARTS, drum, nip, roll, web

__all__ = ["EFFECT_NAMES", "METHODS", "BACKENDS", "DRIVE_KINDS", "MAX_SAMPLES", "MAX_NAME",
           "SCENE_KEYS", "EFFECTS_KEYS", "PAPER_KEYS", "SOLVER_KEYS", "TABLES", "ARRAYS",
           "EffectsTable", "effect_names", "effect_settings", "Live", "body_tables"]

#: The built-in effects of ``[effects]``, in spec order: the force elements of
#: :data:`winder.forces.FORCES` (:func:`effect_names` also those registered later).
EFFECT_NAMES = tuple(FORCES)
#: Integrators of ``[solver] method``.
METHODS = ("auto", "DOPRI5", "RK4", "ROS2", "RODAS3", "RODAS4", "ROS34PW2", "DOP853C", "RK45",
           "DOP853", "Radau", "BDF", "LSODA", "RK23")
#: Right-hand side backends: the compiled planar equations, or Pinocchio's ABA.
BACKENDS = ("compiled", "pinocchio")
#: Drive kinds of a drum.
DRIVE_KINDS = drum.DRIVE_KINDS
#: Most output samples a scene may ask for (``duration / output_step``); each sample holds
#: some twenty channels of 8 bytes.
MAX_SAMPLES = 10_000_000
#: Longest scene name [characters].
MAX_NAME = 200

_POS = {"lo": 0.0, "lo_open": True}  # a positive number

#: ``[scene]``.
SCENE_KEYS = Table((
    Key(name="name", kind="str", default_text="the file name without .toml",
        valid=f"1–{MAX_NAME} printable characters",
        doc="the scene's name, in titles, messages and the result"),
    Key(name="duration", required=True, unit="s", **_POS, hi=1e6,
        doc="simulated time of a run"),
    Key(name="output_step", unit="s", **_POS,
        doc="time between result samples; at most duration, and at most 1e7 samples per "
            "run"),
    Key(name="gravity", unit="m/s²", lo=0.0, hi=1e3,
        doc="gravitational acceleration g, along −z"),
))

class EffectsTable(Table):
    """``[effects]``: one flag per effect registered in :data:`winder.forces.FORCES`, in
    registration order, its meaning and default from its force element (``summary()``,
    ``default``). Read from the registry each time (an effect registered later is a key at
    once); an effect with settings of its own may also be a table ``[effects.NAME]`` of
    ``enabled`` and its settings (:func:`effect_settings`)."""

    def __init__(self) -> None:  # no keys of its own: they are the registry's
        object.__setattr__(self, "kinds", {})

    @property  # type: ignore[override]
    def keys(self) -> tuple[Key, ...]:
        return tuple(Key(name=n, kind="bool", default=cls.default, doc=cls.summary())
                     for n, cls in FORCES.items())

    def __repr__(self) -> str:
        return f"EffectsTable({', '.join(effect_names())})"


def effect_names() -> tuple[str, ...]:
    """The effects of ``[effects]`` now registered (:data:`winder.forces.FORCES`), in
    registration order."""
    return tuple(FORCES)


#: ``[effects]`` (:class:`EffectsTable`, from the force elements).
EFFECTS_KEYS: Table = EffectsTable()

#: ``[paper]``: the default paper of every roll (a roll's own keys, required here).
PAPER_KEYS = Table(roll.KEYS.select("density", "caliper", required=True, default_text=None))

#: ``[solver]``.
SOLVER_KEYS = Table((
    Key(name="method", kind="str", choices=METHODS,
        doc="integrator; auto: DOPRI5, or RODAS4 where a short probe finds it faster "
        "(docs/work_precision.md)"),
    Key(name="rtol", unit="-", **_POS, hi=RTOL_MAX, doc="relative tolerance"),
    Key(name="atol", unit="", doc_unit="state units", **_POS, hi=ATOL_MAX,
        doc="absolute tolerance"),
    Key(name="max_rhs", unit="-", **_POS, hi=1e12,
        default_text=f"{COMPILED_MAX_RHS:,} on the compiled methods, "
                     f"{STEPWISE_MAX_RHS['compiled']:,} on scipy's, "
                     f"{STEPWISE_MAX_RHS['pinocchio']:,} on the pinocchio backend (times "
                     f"{STEPWISE_STATES} / states above {STEPWISE_STATES} states)",
        doc="budget: most right-hand side evaluations of a run (a whole number); each "
            "default stops a run within about a minute"),
    Key(name="backend", kind="str", choices=BACKENDS,
        doc="compiled: the generated code; pinocchio: the numeric Pinocchio path (the "
            "cross-check)"),
    Key(name="max_wall", unit="s", **_POS, doc="budget: most wall-clock time of a run"),
))

class Live(Mapping[str, Table]):
    """A mapping computed each time it is read (from the registries, so that a body type
    or an effect registered later is in it at once)."""

    def __init__(self, build: Callable[[], dict[str, Table]]) -> None:
        self._build = build

    def __getitem__(self, name: str) -> Table:
        return self._build()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._build())

    def __len__(self) -> int:
        return len(self._build())

    def __repr__(self) -> str:
        return f"Live({', '.join(self)})"


def body_tables() -> dict[str, Table]:
    """The tables of the registered body types (:data:`winder.parts.PARTS`) by schema
    name: ``TABLE[]`` and each sub-table ``TABLE[].KEY``, in registration order."""
    out: dict[str, Table] = {}
    for cls in PARTS.values():
        out[f"{cls.table}[]"] = cls.KEYS
        for key, sub in cls.SUB_TABLES.items():
            out[f"{cls.table}[].{key}"] = sub.keys
    return out


def _tables() -> dict[str, Table]:
    return {"scene": SCENE_KEYS, "effects": EFFECTS_KEYS, "paper": PAPER_KEYS,
            "solver": SOLVER_KEYS, **body_tables(),
            "nip[]": nip.KEYS, "nip[].contact": nip.CONTACT_KEYS,
            "nip[].friction": nip.FRICTION_KEYS, "web": web.KEYS, "web.span": web.SPAN_KEYS}


#: Every table of a scene of parts by its schema name: ``NAME[]`` an element of the array
#: of tables ``[[NAME]]``, ``.SUB`` its sub-table (live: from the body registry).
TABLES: Mapping[str, Table] = Live(_tables)


class _Arrays(Sequence[str]):
    """The arrays of tables of a scene of parts: each body type's table (registration
    order), then ``nip`` (live, like :data:`TABLES`)."""

    def _names(self) -> tuple[str, ...]:
        return (*(cls.table for cls in PARTS.values()), "nip")

    def __getitem__(self, i):  # type: ignore[no-untyped-def]
        return self._names()[i]

    def __len__(self) -> int:
        return len(self._names())

    def __repr__(self) -> str:
        return repr(self._names())


#: Arrays of tables of a scene of parts (``drum``, ``roll``, ``rider``, ..., ``nip``).
ARRAYS: Sequence[str] = _Arrays()


def effect_settings(effect: str) -> Table:
    """The table ``[effects.NAME]`` of an effect: ``enabled``, then the settings its force
    element declares (:attr:`winder.forces.ForceElement.settings`)."""
    cls = FORCES[effect]
    enabled = Key(name="enabled", kind="bool", default=True, doc=f"the effect {effect} on")
    return Table((enabled, *cls.settings))
