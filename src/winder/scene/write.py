"""A scene as TOML text (:func:`scene_toml`): its nested tables
(:meth:`~winder.scene.Scene.to_dict`) written back, so that ``load_scene`` reads the same
scene (``winder fit --scene-out``)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

from winder._errors import ArgumentError

__all__ = ["scene_toml", "toml_text"]


def _key(k: str) -> str:
    return k if k and all(c.isalnum() or c in "_-" for c in k) else json.dumps(k)


def _value(v: Any, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            return "inf" if v > 0 else "-inf" if v < 0 else "nan"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list | tuple) and not any(isinstance(e, Mapping) for e in v):
        return "[" + ", ".join(_value(e, where) for e in v) + "]"
    raise ArgumentError(f"scene_toml: {where}: cannot write {type(v).__name__} {v!r}")


def _table(data: Mapping[str, Any], path: list[str], out: list[str]) -> None:
    simple = {k: v for k, v in data.items() if v is not None and not isinstance(v, Mapping)
              and not (isinstance(v, list) and v and all(isinstance(e, Mapping) for e in v))}
    for k, v in simple.items():
        out.append(f"{_key(k)} = {_value(v, '.'.join([*path, k]))}")
    for k, v in data.items():
        if isinstance(v, Mapping):
            out.append("")
            out.append("[" + ".".join(_key(p) for p in [*path, k]) + "]")
            _table(v, [*path, k], out)
        elif isinstance(v, list) and v and all(isinstance(e, Mapping) for e in v):
            for e in v:
                out.append("")
                out.append("[[" + ".".join(_key(p) for p in [*path, k]) + "]]")
                _table(e, [*path, k], out)


def toml_text(data: Mapping[str, Any]) -> str:
    """Nested tables (dicts, lists of dicts, numbers, booleans, strings; ``None`` left
    out) as TOML text."""
    out: list[str] = []
    _table(data, [], out)
    return "\n".join(out).lstrip("\n") + "\n"


def scene_toml(scene: Any) -> str:
    """The TOML text of ``scene`` (a :class:`~winder.Scene`): read back by
    :func:`winder.load_scene`, the same scene."""
    return toml_text(scene.to_dict())
