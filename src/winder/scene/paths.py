"""Key paths on a scene's nested tables (:meth:`~winder.scene.Scene.to_dict`):
``drum.front.drive.web_speed`` enters a table by key and an array of tables by the
element's ``name``, or, where its elements have no names (a web line's spans,
``[[web.span]]``), by the element's index from 0: ``web.span.1.length``. Sweeps
(:mod:`winder.analysis.sweep_grid`) and :func:`~winder.scene.keys.key_unit` read them."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from winder._errors import ArgumentError

__all__ = ["resolve", "get_path", "set_path"]


def _names(node: list) -> list[str]:
    """How the path names the elements of an array of tables: by ``name``, or, where none
    has one (a web line's spans), by index ``0, 1, …``."""
    named = [str(e.get("name")) for e in node if isinstance(e, Mapping) and "name" in e]
    if named or not all(isinstance(e, Mapping) for e in node):
        return named  # a list of numbers (a centre, a load schedule) has no elements here
    return [str(i) for i in range(len(node))]


def resolve(data: Any, key: str) -> tuple[Any, str | int]:
    """``(container, slot)`` of the value that ``key`` names in nested ``data``:
    ``container[slot]`` is the value (the slot may not exist yet: a key the scene leaves
    at its default). Dicts are entered by key; lists of tables by the element's ``name``
    (by its index where the elements have no names).

    Raises :class:`ArgumentError` naming the key path where a segment does not exist.
    """
    parts = key.split(".")
    if not key or any(p == "" for p in parts):
        raise ArgumentError(f"key {key!r}: a key path is dot-separated names, e.g. "
                            "drum.drive.web_speed")
    node = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        here = ".".join(parts[:i]) or "the scene"
        if isinstance(node, Mapping):
            if last:
                return node, part
            if part not in node:
                raise ArgumentError(f"key {key!r}: {here} has no table {part!r}; valid: "
                                    + ", ".join(k for k in node
                                                if isinstance(node[k], Mapping | list)))
            node = node[part]
        elif isinstance(node, list):
            names = _names(node)
            if part not in names:
                raise ArgumentError(f"key {key!r}: no element named {part!r} in {here}; "
                                    f"valid names: {', '.join(names) or '(none)'}")
            idx = names.index(part)
            if last:
                raise ArgumentError(f"key {key!r} selects a whole table ({here} named "
                                    f"{part!r}); name a value inside it")
            node = node[idx]
        else:
            raise ArgumentError(f"key {key!r}: {here} is a value ({node!r}), not a table")
    raise AssertionError("unreachable")  # pragma: no cover


def get_path(data: Any, key: str) -> Any:
    """The value at ``key`` in nested ``data`` (``KeyError`` when the key is absent)."""
    container, slot = resolve(data, key)
    if slot not in container:
        raise KeyError(key)
    return container[slot]


def set_path(data: Any, key: str, value: Any) -> None:
    """Set the value at ``key`` in nested ``data`` in place (the leaf may be new; tables
    and array elements must exist). Setting a whole table is refused."""
    container, slot = resolve(data, key)
    if isinstance(container.get(slot), Mapping | list):
        sub = container[slot]
        inner = ", ".join(sub) if isinstance(sub, Mapping) else ", ".join(_names(sub))
        raise ArgumentError(f"key {key!r} is a table, not a value; name one of its "
                            f"entries: {inner}")
    container[slot] = value
