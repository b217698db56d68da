"""Simulation results: named channels over time, saved atomically as CSV or NPZ, and read
back without ever unpickling (a damaged or foreign file is an error naming the file)."""

from __future__ import annotations

import io
import json
import math
import struct
import warnings
import zipfile
import zlib
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from winder._errors import WinderError
from winder.io.files import atomic_write, atomic_write_all, csv_writer

__all__ = ["Result", "ResultFileError", "load_result"]

#: Most members an NPZ result may have (channels, ``__meta__`` and ``__units__``).
_MAX_MEMBERS = 1000


class ResultFileError(WinderError, ValueError):
    """A result file cannot be read: the message names the file and the problem."""


class Result(Mapping[str, np.ndarray]):
    """Channels of one run (spec §8): ``result.t``, ``result["radius"]`` …

    Attributes
    ----------
    meta: dict with scene name and source, method, rtol, atol, rhs evaluations, wall time.
    units: channel → unit (``{"t": "s", "drum_speed": "rad/s", ...}``, SI with ``rad``
        for angles; read-only); channels without a known unit are absent (a result read
        from a CSV, or from an NPZ written before results carried units, has none).
    """

    def __init__(self, channels: Mapping[str, np.ndarray],
                 meta: Mapping[str, Any] | None = None, *,
                 units: Mapping[str, str] | None = None) -> None:
        if "t" not in channels:
            raise WinderError("a result needs a 't' channel")
        n = len(channels["t"])
        self._channels = {k: np.asarray(v, dtype=float) for k, v in channels.items()}
        for k, v in self._channels.items():
            if v.shape != (n,):
                raise WinderError(f"channel {k!r} has shape {v.shape}, expected ({n},)")
        self.meta: dict[str, Any] = dict(meta or {})
        units = dict(units or {})
        for k, u in units.items():
            if k not in self._channels:
                raise WinderError(f"a unit for channel {k!r}, which this result does not "
                                  f"have; channels: {', '.join(self._channels)}"[:300])
            if not isinstance(u, str):
                raise WinderError(f"the unit of channel {k!r} must be a string, got {u!r}")
        self._units = MappingProxyType(units)

    @property
    def units(self) -> Mapping[str, str]:
        """Channel → unit [SI; read-only] (see the class docstring)."""
        return self._units

    @property
    def t(self) -> np.ndarray:
        """Output times [s]."""
        return self._channels["t"]

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._channels[name]
        except KeyError:
            raise KeyError(f"no channel {name!r}; channels: {', '.join(self._channels)}") \
                from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._channels)

    def __len__(self) -> int:
        return len(self._channels)

    def __repr__(self) -> str:
        t = self.t
        span = f"t = {t[0]:g} … {t[-1]:g} s" if len(t) else "empty"
        return f"Result({self.meta.get('scene', '?')!r}, {len(t)} samples, {span})"

    def _writer(self, path: str | Path) -> Callable[[Path], None]:
        """The function that writes this result to a (temporary) file, by ``path``'s
        suffix: ``.csv`` (header: channel names) or ``.npz`` (channels, ``__meta__`` and
        ``__units__``, JSON texts)."""
        suffix = Path(path).suffix.lower()
        if suffix == ".csv":
            return csv_writer(self._channels, fmt="%.15g")
        if suffix == ".npz":
            meta = np.array(json.dumps(self.meta, default=str))
            units = np.array(json.dumps(dict(self._units)))

            def write_npz(tmp: Path) -> None:
                with open(tmp, "wb") as fh:  # stored: 50× faster than deflate
                    np.savez(fh, __meta__=meta, __units__=units, **self._channels)
            return write_npz
        raise WinderError(f"{path}: unknown result format {suffix!r}; valid: .csv, .npz")

    def to_csv(self, path: str | Path) -> Path:
        """Write a CSV (header: channel names, first column ``t``), atomically."""
        return atomic_write(path, self._writer(Path(path).with_suffix(".csv")))

    def to_npz(self, path: str | Path) -> Path:
        """Write an NPZ (channels, ``__meta__`` and ``__units__`` JSON; stored, not
        compressed: writing the 700 s cycle takes 0.02 s instead of 1 s), atomically."""
        return atomic_write(path, self._writer(Path(path).with_suffix(".npz")))

    def save(self, path: str | Path, *more: str | Path) -> Path:
        """Write CSV or NPZ by the file's suffix; with ``more`` paths (e.g. the NPZ twin of
        a CSV), all the files are written or none is. Returns ``path``."""
        paths = [path, *more]
        return atomic_write_all([(p, self._writer(p)) for p in paths])[0]


def _bad(path: Path, problem: str) -> ResultFileError:
    return ResultFileError(f"{path}: {problem}")


def _read_npy(data: bytes) -> np.ndarray:
    """One ``.npy`` member, parsed without pickle and checked against its header."""
    fp = io.BytesIO(data)
    version = np.lib.format.read_magic(fp)
    if version == (1, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_1_0(fp)
    elif version == (2, 0):
        shape, fortran, dtype = np.lib.format.read_array_header_2_0(fp)
    else:
        raise ValueError(f"unsupported .npy format version {version}")
    if dtype.hasobject:
        raise ValueError("it holds Python objects (pickled data), which winder never loads")
    count = math.prod(shape)
    size = len(data) - fp.tell()
    if size != count * dtype.itemsize:
        raise ValueError(f"{size} bytes of data for an array of shape {shape} ({dtype})")
    array = np.frombuffer(data, dtype=dtype, count=count, offset=fp.tell())
    return array.reshape(shape, order="F" if fortran else "C")


def _json_member(p: Path, arrays: dict[str, np.ndarray], name: str) -> dict[str, Any]:
    """The JSON object of member ``name`` (popped from ``arrays``); ``{}`` without it."""
    if name not in arrays:
        return {}
    raw = arrays.pop(name)
    try:
        if raw.shape != () or raw.dtype.kind != "U":
            raise ValueError("not a text")
        value = json.loads(str(raw))
        if not isinstance(value, dict):
            raise ValueError("not a JSON object")
    except ValueError as exc:
        raise _bad(p, f"bad {'metadata' if name == '__meta__' else 'units'} ({name}: "
                      f"{exc})") from None
    return value


def _read_npz(p: Path) -> tuple[dict[str, np.ndarray], dict[str, Any], dict[str, Any]]:
    arrays: dict[str, np.ndarray] = {}
    try:
        with zipfile.ZipFile(p) as zf:
            infos = zf.infolist()
            if len(infos) > _MAX_MEMBERS:
                raise ValueError(f"{len(infos)} members (at most {_MAX_MEMBERS})")
            for info in infos:
                if not info.filename.endswith(".npy") or info.is_dir():
                    raise ValueError(f"unexpected member {info.filename!r}")
                name = info.filename[:-4]
                try:
                    arrays[name] = _read_npy(zf.read(info))
                except ValueError as exc:
                    raise ValueError(f"member {info.filename!r}: {exc}") from None
    except zipfile.BadZipFile as exc:
        raise _bad(p, f"not a readable .npz archive ({exc})") from None
    except (ValueError, EOFError, zlib.error, struct.error, NotImplementedError,
            RuntimeError, OverflowError, UnicodeError) as exc:
        raise _bad(p, f"damaged or not a winder result: {exc}") from None
    meta = _json_member(p, arrays, "__meta__")
    units = _json_member(p, arrays, "__units__")
    for k, u in units.items():
        if k not in arrays or not isinstance(u, str):
            raise _bad(p, f"bad units (__units__: {k!r}: {u!r} is not the unit text of one "
                          "of its channels)"[:300])
    return arrays, meta, units


def _read_csv(p: Path) -> dict[str, np.ndarray]:
    try:
        with open(p, encoding="utf-8") as fh:
            names = [n.strip() for n in fh.readline().strip().split(",")]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                table = np.loadtxt(fh, delimiter=",", ndmin=2)
    except UnicodeDecodeError as exc:
        raise _bad(p, f"not UTF-8 text (byte {exc.start})") from None
    except ValueError as exc:
        raise _bad(p, f"not a table of numbers: {exc}") from None
    if len(set(names)) != len(names) or not all(names):
        raise _bad(p, f"header must name each column once, got {','.join(names)!r}"[:300])
    if table.shape[0] == 0:
        raise _bad(p, "no data rows")
    if table.shape[1] != len(names):
        raise _bad(p, f"header has {len(names)} names, rows have {table.shape[1]} columns")
    return {n: table[:, i] for i, n in enumerate(names)}


def _check_channels(p: Path, arrays: dict[str, np.ndarray]) -> None:
    if "t" not in arrays:
        raise _bad(p, f"no time channel 't' (channels: {', '.join(arrays)[:200]})")
    n = arrays["t"].shape
    for k, v in arrays.items():
        if v.ndim != 1 or v.shape != n:
            raise _bad(p, f"channel {k!r} has shape {v.shape}, expected ({n[0]},)")
        if v.dtype.kind not in "biuf":
            raise _bad(p, f"channel {k!r} is not numeric ({v.dtype})")
    t = arrays["t"].astype(float)
    if len(t) == 0:
        raise _bad(p, "no samples")
    bad = np.flatnonzero(~np.isfinite(t))
    if len(bad):
        raise _bad(p, f"time t[{bad[0]}] = {float(t[bad[0]])!r} is not finite")
    back = np.flatnonzero(np.diff(t) <= 0)
    if len(back):
        i = back[0]
        raise _bad(p, f"time is not increasing: t[{i}] = {float(t[i])!r}, "
                      f"t[{i + 1}] = {float(t[i + 1])!r}")


def load_result(path: str | Path) -> Result:
    """Read a result written by :meth:`Result.to_csv` or :meth:`Result.to_npz`.

    Raises :class:`ResultFileError` (a ``ValueError``) naming the file when it is missing,
    damaged, not a winder result (NPZ members that need unpickling are refused, never
    loaded), or its time channel is not finite and increasing. The units of an NPZ come
    back in :attr:`Result.units` (none from a CSV, or an NPZ written before results
    carried units)."""
    p = Path(path)
    units: dict[str, Any] = {}
    try:
        if not p.is_file():
            raise _bad(p, "not a file" if p.exists() else "no such result file")
        suffix = p.suffix.lower()
        if suffix == ".npz":
            arrays, meta, units = _read_npz(p)
        elif suffix == ".csv":
            arrays, meta = _read_csv(p), {"scene": p.stem, "source": str(p)}
        else:
            raise _bad(p, f"unknown result format {suffix!r}; valid: .csv, .npz")
    except OSError as exc:
        raise _bad(p, f"cannot be read ({exc.strerror or exc})") from None
    _check_channels(p, arrays)
    return Result({k: np.array(v, dtype=float) for k, v in arrays.items()}, meta, units=units)
