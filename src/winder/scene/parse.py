"""Parsing one scene table against its declared keys (:class:`~winder._schema.Table`).

Every error is a :class:`~winder.SceneError` naming the file, the table (an element of an
array by its name, ``[drum 'front']``), the key, the offending value and what is valid,
all read from the key's declaration: its kind, bounds and choices.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from winder._args import check_real, show
from winder._errors import SceneError
from winder._schema import Key, Table
from winder.parts import AXES
from winder.scene.schema import EFFECTS_KEYS, MAX_NAME, effect_names, effect_settings

__all__ = ["fail", "name_text", "parse_table", "parse_effects", "check_part_name",
           "check_drive_keys"]

#: A part's name: a letter or underscore, then letters, digits, ``_`` or ``-`` (it names
#: result channels and sweep key paths, so no dots or spaces).
_PART_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]{0,39}")


def name_text(key: Any) -> str:
    """A table or key name for a message: as is if short and printable, else its repr."""
    plain = isinstance(key, str) and 0 < len(key) <= 40 and key.isprintable()
    return key if plain else show(key, 40)


def fail(source: str, table: str, key: str, message: str) -> SceneError:
    """The error of ``key`` of ``[table]`` in the file ``source``."""
    return SceneError(f"{source}: [{table}] {name_text(key)}: {message}")


def check_scene_name(source: str, value: str) -> str:
    if not value or len(value) > MAX_NAME or not value.isprintable():
        raise fail(source, "scene", "name", f"{show(value)} is not a plain name; valid: 1 to "
                                            f"{MAX_NAME} printable characters")
    return value


def check_part_name(source: str, table: str, value: Any) -> str:
    """A part's name (:data:`_PART_NAME`), else the error naming ``[table] name``."""
    if not isinstance(value, str) or not _PART_NAME.fullmatch(value):
        raise fail(source, table, "name", f"{show(value)} is not a part name; valid: 1 to 40 "
                   "letters, digits, '_' or '-', starting with a letter or '_' (names make "
                   "channel names and sweep key paths)")
    return value


def _number(source: str, table: str, key: str, value: Any, spec: Key) -> float:
    """A finite number within the bounds of ``spec``."""
    number, problem, _ = check_real(value, lo=spec.lo, lo_open=spec.lo_open, hi=spec.hi)
    if problem is not None:
        raise fail(source, table, key, problem)
    return number


def _pair(source: str, table: str, key: str, value: Any, spec: Key) -> tuple[float, float]:
    """Two numbers ``[u, v]``, each within the bounds of its item of ``spec``."""
    form = f"[{', '.join(i.name for i in spec.items)}]"
    if not isinstance(value, list | tuple) or len(value) != 2:
        raise fail(source, table, key, f"expected a list of two numbers {form}, got "
                                        f"{show(value)} ({type(value).__name__})")
    out = []
    for item, x in zip(spec.items, value, strict=True):
        number, problem, _ = check_real(x, lo=item.lo, lo_open=item.lo_open, hi=item.hi)
        if problem is not None:
            raise fail(source, table, key, f"{item.name} {problem}")
        out.append(number)
    return out[0], out[1]


def _axes(source: str, table: str, key: str, value: Any) -> tuple[str, ...]:
    valid = "[], [\"z\"], [\"x\"] or [\"x\", \"z\"]"
    if not isinstance(value, list | tuple) or any(a not in AXES for a in value) \
            or len(set(value)) != len(value):
        raise fail(source, table, key, f"{show(value)} is not a set of axes; valid: {valid}")
    return tuple(a for a in AXES if a in value)


def _load(source: str, table: str, key: str, value: Any, spec: Key
          ) -> tuple[tuple[float, float], ...]:
    """A rider's line-load schedule: ``[[radius, line_load], ...]``, radii strictly
    increasing."""
    if not isinstance(value, list | tuple):
        units = ", ".join(i.unit for i in spec.items)
        raise fail(source, table, key, f"expected a list of [radius, line_load] pairs "
                                        f"[{units}], got {show(value)} ({type(value).__name__})")
    points = [_pair(source, table, f"{key}[{i}]", p, spec) for i, p in enumerate(value)]
    for i in range(1, len(points)):
        if not points[i][0] > points[i - 1][0]:
            raise fail(source, table, f"{key}[{i}]",
                       f"radius {points[i][0]!r} m does not follow {points[i - 1][0]!r} m; "
                       "valid: strictly increasing radii")
    return tuple(points)


def parse_value(source: str, table: str, key: str, value: Any, spec: Key) -> Any:
    """One key's value, checked against its declaration ``spec``."""
    kind = spec.kind
    if kind == "bool":
        if not isinstance(value, bool):
            raise fail(source, table, key, f"expected true or false, got {show(value)}")
        return value
    if kind in ("str", "ref", "name"):
        if not isinstance(value, str):
            raise fail(source, table, key, f"expected a string, got {show(value)} "
                                           f"({type(value).__name__})")
        if spec.choices and value not in spec.choices:
            raise fail(source, table, key, f"{show(value)} is not one of: "
                                           f"{', '.join(repr(c) for c in spec.choices)}")
        if kind == "name":
            check_part_name(source, table, value)
        return check_scene_name(source, value) if (table, key) == ("scene", "name") else value
    if kind == "pair":
        return _pair(source, table, key, value, spec)
    if kind == "sense":
        if isinstance(value, bool) or value not in (1, -1):
            raise fail(source, table, key, f"{show(value)} is not a sense; valid: 1 or -1 "
                                           "(the operation direction, docs/model.md §1)")
        return int(value)
    if kind == "axes":
        return _axes(source, table, key, value)
    if kind == "load":
        return _load(source, table, key, value, spec)
    return _number(source, table, key, value, spec)


def parse_table(source: str, table: str, raw: Any, keys: Table, *,
                sub_tables: tuple[str, ...] = ()) -> dict[str, Any]:
    """The keys of one table, each checked against its declaration in ``keys`` (type,
    finiteness, bounds, choices); ``table`` names it in messages (``drum 'front'``).
    Sub-tables (kind ``table``) are left out: the caller parses them with their own;
    ``sub_tables`` names those the caller took out of ``raw`` (listed as valid keys)."""
    if not isinstance(raw, dict):
        raise SceneError(f"{source}: [{table}] must be a table of keys, got {show(raw)} "
                         f"({type(raw).__name__})")
    out: dict[str, Any] = {}
    for key, value in raw.items():
        if key not in keys:
            raise fail(source, table, key, "unknown key; valid keys: "
                       + ", ".join((*keys.names(), *sub_tables)))
        spec = keys[key]
        if spec.kind != "table":
            out[key] = parse_value(source, table, key, value, spec)
    for spec in keys:
        if spec.required and spec.name not in raw:
            raise fail(source, table, spec.name, "missing required key")
    return out


def parse_effects(source: str, raw: Any) -> dict[str, Any]:
    """``[effects]``: each effect ``NAME = true/false``, or a table ``[effects.NAME]`` of
    ``enabled`` and the settings its force element declares; the keyword arguments of
    :class:`~winder.scene.tables.Effects` (``settings`` those given)."""
    if not isinstance(raw, dict):
        raise SceneError(f"{source}: [effects] must be a table of keys, got {show(raw)} "
                         f"({type(raw).__name__})")
    out: dict[str, Any] = {}
    settings: dict[str, dict[str, Any]] = {}
    for key, value in raw.items():
        if key not in EFFECTS_KEYS:
            raise fail(source, "effects", key,
                       f"unknown key; valid keys: {', '.join(EFFECTS_KEYS.names())}")
        if isinstance(value, dict):
            table = effect_settings(key)
            values = parse_table(source, f"effects.{key}", value, table)
            out[key] = values.pop("enabled", True)
            if values:
                settings[key] = values
        elif isinstance(value, bool):
            out[key] = value
        else:
            table = effect_settings(key) if key in effect_names() else None
            extra = (f" or a table [effects.{key}] of enabled and its settings "
                     f"({', '.join(table.names()[1:])})" if table and len(table) > 1 else "")
            raise fail(source, "effects", key, f"expected true or false{extra}, got "
                                               f"{show(value)}")
    if settings:
        out["settings"] = settings
    return out


def check_drive_keys(source: str, table: str, drive: Mapping[str, Any], keys: Table) -> None:
    """Every key of a parsed drive belongs to its kind (``keys.kinds``)."""
    valid = keys.kinds[drive["kind"]]
    for key in drive:
        if key not in valid:
            raise fail(source, table, key, f"not a key of kind {drive['kind']!r}; valid "
                                           f"keys: {', '.join(valid)}")
