"""The inputs of :func:`winder.fit`: the measured table (``t`` and channels with their
units) and the fitted parameters (scene key paths with optional bounds).

A table is a :class:`~winder.Result`, a mapping of column → values (``units``: column →
unit), or a file: CSV (header ``t,z [m],normal_force [N]``: each channel's unit in
brackets), NPZ (a winder result, or arrays with a ``__units__`` JSON member) or Parquet
(units in the columns' names as in CSV). Every fitted column must state its unit and it
must be the channel's; values must be finite; times increasing.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from winder._errors import ArgumentError, ArgumentTypeError

__all__ = ["Table", "read_table", "ParamSpec", "parse_params", "parse_param"]

_UNIT = re.compile(r"^\s*([^\[\]]+?)\s*\[([^\[\]]*)\]\s*$")


@dataclass(frozen=True)
class Table:
    """Measured columns: ``t`` [s] and ``columns`` (name → values), ``units`` (name →
    unit, ``None`` where the source gave none), ``source`` (for messages)."""

    t: np.ndarray
    columns: dict[str, np.ndarray]
    units: dict[str, str | None]
    source: str

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or len(t) < 2:
            raise ArgumentError(f"data ({self.source}): column 't' needs at least 2 samples")
        bad = np.flatnonzero(~np.isfinite(t))
        if len(bad):
            raise ArgumentError(f"data ({self.source}): column 't' row {bad[0]} is "
                                f"{float(t[bad[0]])!r}, not finite")
        back = np.flatnonzero(np.diff(t) <= 0)
        if len(back):
            raise ArgumentError(f"data ({self.source}): column 't' is not increasing at row "
                                f"{back[0] + 1} ({float(t[back[0]])!r}, {float(t[back[0] + 1])!r})")
        for name, v in self.columns.items():
            v = np.asarray(v, dtype=float)
            if v.shape != t.shape:
                raise ArgumentError(f"data ({self.source}): column {name!r} has {v.size} "
                                    f"values, 't' {t.size}")
            bad = np.flatnonzero(~np.isfinite(v))
            if len(bad):
                raise ArgumentError(f"data ({self.source}): column {name!r} row {bad[0]} "
                                    f"is {float(v[bad[0]])!r}, not finite")


def _split(name: str) -> tuple[str, str | None]:
    m = _UNIT.match(name)
    return (m.group(1), m.group(2).strip()) if m else (name.strip(), None)


def _from_columns(cols: Mapping[str, Any], units: Mapping[str, Any], source: str) -> Table:
    named: dict[str, np.ndarray] = {}
    unit: dict[str, str | None] = {}
    for raw, v in cols.items():
        name, u = _split(str(raw))
        if name in named:
            raise ArgumentError(f"data ({source}): column {name!r} is given twice")
        try:
            named[name] = np.asarray(v, dtype=float).ravel()
        except (TypeError, ValueError):
            raise ArgumentError(f"data ({source}): column {name!r} is not numbers") from None
        unit[name] = u if u is not None else (str(units[raw]) if raw in units
                                              and units[raw] is not None else None)
    if "t" not in named:
        raise ArgumentError(f"data ({source}): no time column 't' (columns: "
                            f"{', '.join(named) or 'none'})")
    t = named.pop("t")
    if unit.pop("t") not in (None, "s"):
        raise ArgumentError(f"data ({source}): column 't' must be in s")
    return Table(t, named, unit, source)


def read_table(data: Any, *, units: Mapping[str, str] | None = None) -> Table:
    """The measured table of ``data`` (module docstring). Raises ``ArgumentError`` naming
    the file or column."""
    from winder.io.result import Result

    if isinstance(data, Table):
        return data
    if isinstance(data, Result):
        return _from_columns(dict(data.items()), dict(data.units), "the result")
    if isinstance(data, Mapping):
        return _from_columns(data, dict(units or {}), "data")
    if not isinstance(data, str | os.PathLike):
        raise ArgumentTypeError(f"data: expected a Result, a mapping of columns or a file "
                                f"path, got {type(data).__name__}")
    path = Path(data)
    if not path.is_file():
        raise ArgumentError(f"data: {str(path)!r}: no such file")
    suffix = path.suffix.lower()
    src = str(path)
    try:
        if suffix == ".csv":
            with open(path, encoding="utf-8") as fh:
                header = [h.strip() for h in fh.readline().strip().split(",")]
                table = np.loadtxt(fh, delimiter=",", ndmin=2)
            if table.shape[1] != len(header):
                raise ArgumentError(f"data ({src}): the header names {len(header)} columns, "
                                    f"the rows have {table.shape[1]}")
            return _from_columns({h: table[:, i] for i, h in enumerate(header)}, {}, src)
        if suffix == ".npz":
            with np.load(path, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            u = json.loads(str(arrays.pop("__units__"))) if "__units__" in arrays else {}
            arrays.pop("__meta__", None)
            return _from_columns(arrays, u, src)
        if suffix in (".parquet", ".pq"):
            import pandas as pd

            frame = pd.read_parquet(path)
            return _from_columns({c: frame[c].to_numpy() for c in frame.columns}, {}, src)
    except ArgumentError:
        raise
    except (OSError, ValueError, UnicodeDecodeError, KeyError, ImportError) as exc:
        raise ArgumentError(f"data ({src}): cannot be read: {exc}"[:400]) from None
    raise ArgumentError(f"data: {src!r}: unknown format {suffix!r}; valid: .csv, .npz, "
                        ".parquet")


@dataclass(frozen=True)
class ParamSpec:
    """A fitted key path and its bounds [the key's unit] (``None``: the default, non-
    negative for a positive first guess, non-positive for a negative one, free at 0)."""

    key: str
    lo: float | None = None
    hi: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.key, str) or not self.key.strip():
            raise ArgumentError(f"params: a key path is dot-separated names, got {self.key!r}")
        for name in ("lo", "hi"):
            v = getattr(self, name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, int | float)
                                  or math.isnan(v)):
                raise ArgumentError(f"params: {self.key}: bound {v!r} is not a number")
        if self.lo is not None and self.hi is not None and not self.lo < self.hi:
            raise ArgumentError(f"params: {self.key}: bounds {self.lo!r}:{self.hi!r} need "
                                "LO < HI")


def parse_param(item: Any) -> ParamSpec:
    """``"KEY"``, ``"KEY=LO:HI"`` (either end may be empty), ``(KEY, LO, HI)`` or a
    :class:`ParamSpec`."""
    if isinstance(item, ParamSpec):
        return item
    if isinstance(item, tuple) and len(item) == 3:
        return ParamSpec(str(item[0]), item[1], item[2])
    if not isinstance(item, str):
        raise ArgumentTypeError(f"params: expected KEY or KEY=LO:HI, got {item!r}")
    key, sep, spec = item.partition("=")
    if not sep:
        return ParamSpec(key.strip())
    lo, colon, hi = spec.partition(":")
    if not colon:
        raise ArgumentError(f"params: {item!r}: bounds are KEY=LO:HI, e.g. "
                            "contact.stiffness=1e6:1e9")
    try:
        bounds = [float(v) if v.strip() else None for v in (lo, hi)]
    except ValueError:
        raise ArgumentError(f"params: {item!r}: LO and HI must be numbers") from None
    return ParamSpec(key.strip(), bounds[0], bounds[1])


def parse_params(params: Any) -> list[ParamSpec]:
    """The fitted parameters of ``params``: a key, or a sequence of keys, ``KEY=LO:HI``,
    ``(KEY, LO, HI)`` or a mapping key → ``(LO, HI)`` (or ``None``)."""
    if isinstance(params, str | ParamSpec):
        params = [params]
    if isinstance(params, Mapping):
        items = [ParamSpec(k, *(v if v is not None else (None, None)))
                 for k, v in params.items()]
    elif isinstance(params, Sequence):
        items = [parse_param(p) for p in params]
    else:
        raise ArgumentTypeError(f"params: expected key paths, got {type(params).__name__}")
    if not items:
        raise ArgumentError("params: give at least one key path, e.g. contact.stiffness")
    keys = [p.key for p in items]
    for k in keys:
        if keys.count(k) > 1:
            raise ArgumentError(f"params: {k!r} is given twice")
    return items
