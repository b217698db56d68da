"""The grid of a parameter sweep: scene key paths, value specs, and the scenes they make.

A key path names one value in a scene's nested tables, dot-separated, e.g.
``drum.drive.web_speed`` or ``roll.com_offset``. Where a level is an array of tables (TOML
``[[nip]]``), the next segment selects the element by its ``name``: ``nip.rear.contact.
stiffness`` is ``stiffness`` in table ``contact`` of the ``[[nip]]`` element whose
``name = "rear"``. Resolution works on any nested ``dict``/``list`` structure
(:meth:`Scene.to_dict`), so new scene formats need no change here.

Several keys can share one axis (tied keys): ``drum.front.drive.web_speed,drum.rear.
drive.web_speed`` (comma-separated, no spaces needed) gives every key the same value in
each run, e.g. both drums' web speed. The axis is named by its keys joined with commas;
the table has one column per key.

A value spec is a range ``START:STOP:COUNT`` (``COUNT`` values from ``START`` to ``STOP``
inclusive, evenly spaced) or a comma-separated list (numbers, ``true``/``false``, or
words such as ``linear,hunt_crossley``).

Every grid point is built into a validated :class:`~winder.Scene` before anything runs:
an unknown key, an empty range or a value the scene rejects raises
:class:`~winder.ArgumentError` naming the key.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from winder._errors import ArgumentError, SceneError
from winder.scene.load import Scene, scene_from_dict
from winder.scene.paths import get_path, resolve, set_path

__all__ = ["Axis", "Grid", "parse_spec", "parse_vary", "split_keys", "axis_keys", "resolve",
           "get_path", "set_path", "scene_hash", "build_grid"]

Value = float | int | bool | str


# ---- value specs -----------------------------------------------------------------------

def _word(text: str) -> Value:
    t = text.strip()
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    try:
        return int(t)
    except ValueError:
        pass
    try:
        return float(t)
    except ValueError:
        return t


def parse_spec(key: str, spec: str) -> list[Value]:
    """Values of one ``--vary`` spec: ``START:STOP:COUNT`` or ``a,b,c``."""
    text = spec.strip()
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ArgumentError(f"--vary {key}={spec}: a range is START:STOP:COUNT, "
                                "e.g. 15:45:16")
        try:
            start, stop = float(parts[0]), float(parts[1])
            count = int(parts[2])
        except ValueError:
            raise ArgumentError(f"--vary {key}={spec}: a range is START:STOP:COUNT with "
                                "numbers START, STOP and a whole COUNT, e.g. 15:45:16") \
                from None
        if not (math.isfinite(start) and math.isfinite(stop)):
            raise ArgumentError(f"--vary {key}={spec}: range ends must be finite")
        if count < 1:
            raise ArgumentError(f"--vary {key}={spec}: empty range (COUNT = {count}); "
                                "COUNT must be >= 1")
        if count > 1 and start == stop:
            raise ArgumentError(f"--vary {key}={spec}: empty range ({count} copies of "
                                f"{start:g}); give START != STOP or COUNT = 1")
        return [float(v) for v in np.linspace(start, stop, count)]
    items = [s for s in text.split(",")]
    if not text or any(not s.strip() for s in items):
        raise ArgumentError(f"--vary {key}={spec}: empty value list; give a range "
                            "START:STOP:COUNT or values a,b,c")
    values = [_word(s) for s in items]
    seen = set()
    for v in values:
        if (type(v), v) in seen:
            raise ArgumentError(f"--vary {key}={spec}: value {v!r} is listed twice")
        seen.add((type(v), v))
    return values


def split_keys(name: str | Sequence[str]) -> tuple[str, ...]:
    """The keys of one axis: ``"a.b,c.d"`` (tied keys, comma-separated) or a sequence of
    key paths → ``("a.b", "c.d")``. Raises :class:`ArgumentError` for an empty key or a
    key listed twice."""
    if isinstance(name, str):
        keys = tuple(k.strip() for k in name.split(","))
    elif isinstance(name, Sequence) and all(isinstance(k, str) for k in name):
        keys = tuple(k.strip() for k in name)
    else:
        raise ArgumentError(f"vary: a key is a key path or a tuple of key paths, got "
                            f"{name!r}")
    shown = name if isinstance(name, str) else ",".join(name)
    if not keys or any(not k for k in keys):
        raise ArgumentError(f"--vary {shown!r}: empty key; tied keys are key paths "
                            "separated by commas, e.g. drum.front.drive.web_speed,"
                            "drum.rear.drive.web_speed=10:30:5")
    for k in keys:
        if keys.count(k) > 1:
            raise ArgumentError(f"--vary {shown}: key {k} is listed twice")
    return keys


def axis_keys(names: Iterable[str | Sequence[str]]) -> list[tuple[str, ...]]:
    """The keys of each axis named in ``names`` (:func:`split_keys`); raises
    :class:`ArgumentError` for a key on two axes."""
    out: list[tuple[str, ...]] = []
    seen: set[str] = set()
    for name in names:
        keys = split_keys(name)
        for k in keys:
            if k in seen:
                raise ArgumentError(f"--vary {k}: the key is given twice")
            seen.add(k)
        out.append(keys)
    return out


def parse_vary(items: Sequence[str]) -> dict[str, list[Value]]:
    """``["KEY=SPEC", ...]`` (the ``--vary`` options) → ``{key: values}`` in order. KEY may
    be tied keys ``KEY1,KEY2`` sharing the values (the result's key is then
    ``"KEY1,KEY2"``)."""
    pairs = []
    for item in items:
        key, sep, spec = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ArgumentError(f"--vary {item!r}: expected KEY=SPEC or KEY1,KEY2=SPEC, e.g. "
                                "drum.drive.web_speed=15:45:16")
        pairs.append((key, spec))
    if not pairs:
        raise ArgumentError("--vary: give at least one KEY=SPEC")
    names = [",".join(keys) for keys in axis_keys(key for key, _ in pairs)]
    return {name: parse_spec(name, spec) for name, (_, spec) in zip(names, pairs, strict=True)}


# ---- the grid --------------------------------------------------------------------------

def scene_hash(data: Mapping[str, Any]) -> str:
    """Hex digest (16 characters) of a scene's nested tables: equal scenes, equal hash."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Axis:
    """One axis of the grid: its key paths (several: tied keys, all set to the same value
    in a run) and its values."""

    keys: tuple[str, ...]
    values: tuple[Value, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "keys", split_keys(self.keys))
        object.__setattr__(self, "values", tuple(self.values))

    @property
    def key(self) -> str:
        """The axis's name: its keys joined with commas."""
        return ",".join(self.keys)


@dataclass(frozen=True)
class Grid:
    """The full factorial grid of a sweep: ``points[i]`` maps each key (each tied key on
    its own) to its value in run ``i`` (first axis outermost), ``scenes[i]`` is that run's
    validated scene."""

    base: Scene
    axes: tuple[Axis, ...]
    points: tuple[dict[str, Value], ...]
    scenes: tuple[Scene, ...]

    @property
    def keys(self) -> tuple[str, ...]:
        """Every swept key path (tied keys each on their own), in axis order."""
        return tuple(k for a in self.axes for k in a.keys)

    def __len__(self) -> int:
        return len(self.points)


def _apply(base: dict[str, Any], point: Mapping[str, Value]) -> dict[str, Any]:
    data = copy.deepcopy(base)
    for key, value in point.items():
        set_path(data, key, value)
    return data


def _build(base: Scene, data: dict[str, Any], keys: Sequence[str]) -> Scene:
    try:
        return scene_from_dict(data, source=base.source)
    except SceneError as exc:
        raise ArgumentError(f"--vary {', '.join(keys)}: {exc}") from None


def build_grid(base: Scene, vary: Mapping[str | tuple[str, ...], Sequence[Value]]) -> Grid:
    """Resolve every key, check every value of an axis alone against the base scene (tied
    keys together; the error names the keys and the value), then build and validate every
    grid point. A key of ``vary`` is one key path, tied key paths ``"k1,k2"`` or a tuple
    of key paths."""
    data = base.to_dict()
    axes: list[Axis] = []
    for keys, values in zip(axis_keys(vary), vary.values(), strict=True):
        key = ",".join(keys)
        values = tuple(values)
        if not values:
            raise ArgumentError(f"--vary {key}: no values")
        for k in keys:
            container, slot = resolve(data, k)
            if slot not in container:  # a key the scene leaves at its default, or a typo
                try:
                    scene_from_dict(_apply(data, dict.fromkeys(keys, values[0])),
                                    source=base.source)
                except SceneError as exc:
                    raise ArgumentError(f"--vary {k}: unknown key or bad value ({exc})") \
                        from None
        for v in values:
            try:
                scene_from_dict(_apply(data, dict.fromkeys(keys, v)), source=base.source)
            except SceneError as exc:
                raise ArgumentError(f"--vary {key}: value {v!r} fails scene validation: "
                                    f"{exc}") from None
        axes.append(Axis(keys, values))
    points, scenes = [], []
    for combo in itertools.product(*(a.values for a in axes)):
        point = {k: v for a, v in zip(axes, combo, strict=True) for k in a.keys}
        points.append(point)
        scenes.append(_build(base, _apply(data, point), list(point)))
    return Grid(base, tuple(axes), tuple(points), tuple(scenes))
