"""Simulation results: named channels over time, saved atomically as CSV or NPZ."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ._errors import WinderError

__all__ = ["Result", "load_result", "atomic_write"]


def atomic_write(path: str | Path, write: Any, *, suffix: str = "") -> Path:
    """Call ``write(tmp_path)`` then move the file into place: no partial ``path`` on
    error or Ctrl-C."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix or target.suffix,
                               dir=target.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; results are ordinary files
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


class Result(Mapping[str, np.ndarray]):
    """Channels of one run (spec §8): ``result.t``, ``result["radius"]`` …

    Attributes
    ----------
    meta: dict with scene name and source, method, rtol, atol, rhs evaluations, wall time.
    """

    def __init__(self, channels: Mapping[str, np.ndarray],
                 meta: Mapping[str, Any] | None = None) -> None:
        if "t" not in channels:
            raise WinderError("a result needs a 't' channel")
        n = len(channels["t"])
        self._channels = {k: np.asarray(v, dtype=float) for k, v in channels.items()}
        for k, v in self._channels.items():
            if v.shape != (n,):
                raise WinderError(f"channel {k!r} has shape {v.shape}, expected ({n},)")
        self.meta: dict[str, Any] = dict(meta or {})

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

    def to_csv(self, path: str | Path) -> Path:
        """Write a CSV (header: channel names, first column ``t``), atomically."""
        names = list(self._channels)
        table = np.column_stack([self._channels[n] for n in names])

        def write(tmp: Path) -> None:
            np.savetxt(tmp, table, delimiter=",", header=",".join(names), comments="",
                       fmt="%.15g")
        return atomic_write(path, write)

    def to_npz(self, path: str | Path) -> Path:
        """Write a compressed NPZ (channels + ``__meta__`` JSON), atomically."""
        def write(tmp: Path) -> None:
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, __meta__=np.array(json.dumps(self.meta, default=str)),
                                    **self._channels)
        return atomic_write(path, write)

    def save(self, path: str | Path) -> Path:
        """Write CSV or NPZ by the file's suffix."""
        suffix = Path(path).suffix.lower()
        if suffix == ".csv":
            return self.to_csv(path)
        if suffix == ".npz":
            return self.to_npz(path)
        raise WinderError(f"{path}: unknown result format {suffix!r}; valid: .csv, .npz")


def load_result(path: str | Path) -> Result:
    """Read a result written by :meth:`Result.to_csv` or :meth:`Result.to_npz`."""
    p = Path(path)
    if not p.is_file():
        raise WinderError(f"{p}: no such result file")
    suffix = p.suffix.lower()
    if suffix == ".npz":
        with np.load(p, allow_pickle=False) as z:
            meta = json.loads(str(z["__meta__"])) if "__meta__" in z else {}
            return Result({k: z[k] for k in z.files if k != "__meta__"}, meta)
    if suffix == ".csv":
        with open(p, encoding="utf-8") as fh:
            names = fh.readline().strip().split(",")
        table = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2)
        if table.shape[1] != len(names):
            raise WinderError(f"{p}: header has {len(names)} names, rows have "
                              f"{table.shape[1]} columns")
        return Result({n: table[:, i] for i, n in enumerate(names)},
                      {"scene": p.stem, "source": str(p)})
    raise WinderError(f"{p}: unknown result format {suffix!r}; valid: .csv, .npz")
