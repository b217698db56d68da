"""Validating a whole scene (nested dictionaries, as read from TOML) into the keyword
arguments of :class:`~winder.scene.scene.Scene`: which format it is, the tables both
formats have, then the parts (:mod:`winder.scene.parts`) or the single-drum tables
(:mod:`winder.scene.legacy`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import winder.scene.legacy as legacy
from winder._args import show
from winder._errors import SceneError
from winder._schema import format_number
from winder.scene.parse import fail, name_text, parse_effects, parse_table
from winder.scene.parts import parse_parts
from winder.scene.schema import (
    ARRAYS,
    MAX_SAMPLES,
    PAPER_KEYS,
    SCENE_KEYS,
    SOLVER_KEYS,
)
from winder.scene.tables import Effects, Paper, SceneInfo, Solver

__all__ = ["scene_kwargs", "part_table_names"]


def part_table_names() -> tuple[str, ...]:
    """The top-level tables of a scene of parts (a body type's from the registry)."""
    return ("scene", "effects", "paper", *ARRAYS, "web", "solver")


def _is_parts(source: str, data: Mapping[str, Any]) -> bool:
    """Whether ``data`` is a scene of parts, else the single-drum format
    (:func:`winder.scene.legacy.is_legacy`); else any ``[[drum]]``, ``[[roll]]``,
    ``[[rider]]``, ``[[nip]]`` or ``[web]`` makes it of parts. A table of the other format
    is an error."""
    old = legacy.is_legacy(data)
    parts = not old and (any(isinstance(data.get(a), list) for a in ARRAYS)
                         or any(t in data for t in (*ARRAYS, "web")
                                if t not in legacy.TABLE_NAMES))
    for table in data:
        if old and table not in legacy.TABLE_NAMES:
            raise SceneError(
                f"{source}: [{table}]: a table of scenes of parts in a scene of the "
                f"single-drum format ([drum] or [roll] is a single table); build a machine "
                f"from parts with [[drum]] and [[roll]] (arrays of tables, each with a "
                f"name); valid tables here: {', '.join(legacy.TABLE_NAMES)}")
        if parts and table not in part_table_names():
            raise SceneError(
                f"{source}: [{table}]: a table of the single-drum format in a scene of "
                f"parts; each [[nip]] has its own contact and friction; valid tables: "
                f"{', '.join(part_table_names())}")
    return parts


def scene_kwargs(data: Any, *, source: str = "<scene>") -> dict[str, Any]:
    """The keyword arguments of :class:`~winder.scene.scene.Scene` from nested
    dictionaries; every key checked against its declaration (a
    :class:`~winder.SceneError` naming the file, the table, the key and the value)."""
    if not isinstance(data, dict):
        raise SceneError(f"{source}: a scene is a set of TOML tables, got {show(data)} "
                         f"({type(data).__name__})")
    valid = ", ".join(dict.fromkeys((*legacy.TABLE_NAMES, *part_table_names())))
    for table in data:
        if table not in legacy.TABLE_NAMES and table not in part_table_names():
            raise SceneError(f"{source}: [{name_text(table)}]: unknown table; valid "
                             f"tables: {valid}")
    parts = _is_parts(source, data)
    scene_raw = data.get("scene", {})
    if not parts:  # the old format's required tables, before any key is read
        for table in legacy.REQUIRED_TABLES:
            if table not in data:
                raise SceneError(f"{source}: [{table}]: missing required table")
    info_kw = parse_table(source, "scene", scene_raw, SCENE_KEYS)
    effects = Effects(**parse_effects(source, data.get("effects", {})))
    solver_kw = parse_table(source, "solver", data.get("solver", {}), SOLVER_KEYS)
    old_tables = {} if parts else legacy.parse_tables(source, data)
    info = SceneInfo(**{"name": Path(source).stem if source != "<scene>" else "scene",
                        **info_kw})
    if info.output_step > info.duration:
        raise fail(source, "scene", "output_step",
                   f"{info.output_step!r} is longer than duration {info.duration!r}")
    samples = info.duration / info.output_step + 1.0  # both ends, as simulate counts
    if samples > MAX_SAMPLES:
        raise fail(source, "scene", "output_step",
                   f"{info.output_step!r} s over duration {info.duration!r} s gives "
                   f"{samples:.3g} samples; valid: at most {MAX_SAMPLES:.0e} samples "
                   f"(output_step >= {info.duration / MAX_SAMPLES:.3g} s)")
    if "max_rhs" in solver_kw:
        if solver_kw["max_rhs"] != int(solver_kw["max_rhs"]):
            hi = format_number(SOLVER_KEYS["max_rhs"].hi)
            raise fail(source, "solver", "max_rhs", f"{solver_kw['max_rhs']!r} is not a whole "
                       f"number of evaluations; valid: an integer 1 … {hi}")
        solver_kw["max_rhs"] = int(solver_kw["max_rhs"])
    if effects.slip_relaxation and not effects.contact:
        raise SceneError(f"{source}: [effects] slip_relaxation: true requires contact = true "
                         "(the relaxed force is the nip friction)")
    common = {"scene": info, "effects": effects, "solver": Solver(**solver_kw),
              "source": source}
    if not parts:
        return {**common, **legacy.build(source, data, old_tables, effects, info.gravity)}
    paper = Paper(**parse_table(source, "paper", data["paper"], PAPER_KEYS)) \
        if "paper" in data else None
    return {**common, "drum": None, "roll": None, "paper": paper, "contact": None,
            "friction": None, **parse_parts(source, data, effects, paper)}
