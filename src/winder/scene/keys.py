"""Looking up a scene key's declaration: its unit (:func:`key_unit`, which labels sweep
axes and plots) and its documentation (:func:`key_doc`), for both scene formats."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from winder._errors import ArgumentError
from winder._schema import Key, Table
from winder.scene.legacy import LEGACY_TABLES
from winder.scene.paths import get_path
from winder.scene.schema import ARRAYS, TABLES, Live, effect_settings

__all__ = ["ALL_TABLES", "find_key", "key_unit", "key_doc"]

#: Every table of both formats by schema name (``drum`` the single-drum table, ``drum[]``
#: an element of ``[[drum]]``; live, like :data:`~winder.scene.schema.TABLES`).
ALL_TABLES: Mapping[str, Table] = Live(lambda: {**LEGACY_TABLES, **TABLES})


def find_key(table: str, key: str) -> Key:
    """The declaration of ``key`` of the schema table ``table`` (a name of
    :data:`ALL_TABLES`, or ``effects.NAME`` for an effect's settings); KeyError where
    there is none."""
    if table.startswith("effects."):
        effect = table[len("effects."):]
        if effect not in TABLES["effects"]:
            raise KeyError((table, key))
        settings = effect_settings(effect)
        if key not in settings:
            raise KeyError((table, key))
        return settings[key]
    keys = ALL_TABLES.get(table)
    if keys is None or key not in keys:
        raise KeyError((table, key))
    return keys[key]


def key_doc(table: str, key: str) -> tuple[str, str, str | None]:
    """``(unit, meaning, default text or None)`` of ``key`` of the schema table ``table``
    (:func:`find_key`); the default text is None where the default is a plain value (the
    dataclass field's, or the key's own). KeyError where the key is not declared."""
    k = find_key(table, key)
    return k.shown_unit, k.doc, k.default_text


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
        array = head in ARRAYS and ".".join([head, *rest[:-1]]) not in LEGACY_TABLES
    if array:
        head, rest = head + "[]", rest[1:]  # skip the element's name
    elif data is not None and len(rest) > 2 and isinstance(data.get(head), Mapping) and \
            isinstance(data[head].get(rest[0]), list):  # a web line's span by its index
        head, rest = f"{head}.{rest[0]}", rest[2:]
    if not rest:
        return ""
    try:
        k = find_key(".".join([head, *rest[:-1]]), rest[-1])
    except KeyError:
        return ""
    unit = k.unit if k.kind == "num" else ""
    if unit == "N/m" and rest[-1] == "stiffness" and data is not None:
        try:  # its law's: k δ^p of a Hunt–Crossley nip
            law = get_path(data, path[:-len("stiffness")] + "law")
        except (KeyError, ArgumentError):
            law = "linear"
        if law == "hunt_crossley":
            return "N/m^p"
    return unit
