"""A sweep's table and its files: one Parquet row per run, written atomically.

Layout of a sweep's output directory::

    DIR/runs/<run_id>.parquet          one row per finished run (the resume record)
    DIR/trajectories/<run_id>.npz      the run's full result (only when asked for)
    DIR/summary.parquet                all runs of the sweep, in grid order

A run counts as done when its row file exists (and, when trajectories are asked for, its
NPZ too): the row is written last, atomically, so an interrupted sweep never leaves a
half-written record and a re-run skips exactly the runs that finished.
The Parquet schema's metadata (key ``winder``) carries the swept keys, the radius band
edges, the base scene and the run settings, so :meth:`SweepTable.read` restores it all.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from winder._errors import WinderError
from winder.analysis.sweep_grid import Axis
from winder.analysis.sweep_summary import BAND_COLUMNS, SCALAR_COLUMNS, nip_columns, scene_nip_names
from winder.io.files import atomic_write
from winder.io.result import Result

__all__ = ["SweepTable", "RunStore", "row_schema", "table_meta", "RUN_COLUMNS",
           "SUMMARY_FILE"]

SUMMARY_FILE = "summary.parquet"
#: Columns of a row that describe the run rather than its physics.
RUN_COLUMNS = ("run_id", "scene_hash", "status", "message", "wall_time", "task_time",
               "worker")
_META_KEY = b"winder"


def _value_type(values: Sequence[Any]) -> pa.DataType:
    if all(isinstance(v, bool) for v in values):
        return pa.bool_()
    if all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return pa.int64()
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return pa.float64()
    return pa.string()


def table_meta(keys: Sequence[str], band_edges: np.ndarray, base_scene: Mapping[str, Any],
               settings: Mapping[str, Any], *,
               axes: Sequence[Sequence[str]] | None = None) -> dict[str, Any]:
    """What a sweep table's Parquet metadata stores (:meth:`SweepTable.read` restores it):
    ``axes`` groups ``keys`` into the grid's axes (tied keys share one; default: one axis
    per key)."""
    return {"keys": list(keys), "axes": [list(a) for a in (axes or [[k] for k in keys])],
            "band_edges": np.asarray(band_edges, dtype=float).tolist(),
            "base_scene": dict(base_scene), "settings": dict(settings)}


def row_schema(axes: Sequence[Axis], meta: Mapping[str, Any] | None = None) -> pa.Schema:
    """The Parquet schema of a sweep's rows: ``run`` (grid index), one column per swept
    key, the run columns (:data:`RUN_COLUMNS`), the scalar summary and the per-band lists."""
    fields = [pa.field("run", pa.int64())]
    fields += [pa.field(k, _value_type(a.values)) for a in axes for k in a.keys]
    fields += [pa.field(c, pa.float64() if c.endswith("_time") else pa.string())
               for c in RUN_COLUMNS]
    scalars, bands = nip_columns(scene_nip_names((meta or {}).get("base_scene", {})))
    fields += [pa.field(c, pa.float64()) for c in (*SCALAR_COLUMNS, *scalars)]
    fields += [pa.field(c, pa.list_(pa.float64())) for c in (*BAND_COLUMNS, *bands)]
    metadata = {_META_KEY: json.dumps(meta, allow_nan=True).encode()} if meta else None
    return pa.schema(fields, metadata=metadata)


def _cast(value: Any, kind: pa.DataType) -> Any:
    return str(value) if pa.types.is_string(kind) and not isinstance(value, str) else value


def _table(rows: Sequence[Mapping[str, Any]], schema: pa.Schema) -> pa.Table:
    data = [{f.name: _cast(r.get(f.name), f.type) for f in schema} for r in rows]
    return pa.Table.from_pylist(data, schema=schema)


class RunStore:
    """The per-run files of a sweep in ``out`` (module docstring)."""

    def __init__(self, out: str | Path) -> None:
        self.out = Path(out)
        self.runs = self.out / "runs"
        self.trajectories = self.out / "trajectories"

    def row_path(self, run_id: str) -> Path:
        return self.runs / f"{run_id}.parquet"

    def trajectory_path(self, run_id: str) -> Path:
        return self.trajectories / f"{run_id}.npz"

    def load_done(self, run_ids: Iterable[str], *, trajectories: bool = False
                  ) -> dict[str, dict[str, Any]]:
        """Rows of the runs among ``run_ids`` already done (an unreadable row file counts
        as not done: the run is done again)."""
        done = {}
        for rid in run_ids:
            path = self.row_path(rid)
            if not path.is_file() or (trajectories and not self.trajectory_path(rid).is_file()):
                continue
            try:
                rows = pq.read_table(path).to_pylist()
            except (OSError, pa.ArrowException):
                continue
            if len(rows) == 1 and rows[0].get("run_id") == rid:
                done[rid] = rows[0]
        return done

    def write_run(self, row: Mapping[str, Any], schema: pa.Schema,
                  trajectory: Result | None = None) -> Path:
        """Write one run's row (after its trajectory, if any), atomically."""
        rid = str(row["run_id"])
        if trajectory is not None:
            trajectory.to_npz(self.trajectory_path(rid))
        table = _table([row], schema.remove_metadata())  # the metadata lives in the summary
        return atomic_write(self.row_path(rid), lambda p: pq.write_table(table, p))

    def write_table(self, rows: Sequence[Mapping[str, Any]], schema: pa.Schema) -> Path:
        """Write all ``rows`` as ``DIR/summary.parquet``, atomically."""
        table = _table(sorted(rows, key=lambda r: r["run"]), schema)
        return atomic_write(self.out / SUMMARY_FILE, lambda p: pq.write_table(table, p))


@dataclass
class SweepTable:
    """The result of :func:`winder.sweep`: one row per run.

    Attributes
    ----------
    frame: the rows (pandas DataFrame, grid order): ``run`` (grid index), one column per
        swept key, ``run_id`` (hash of the run's scene and settings), ``scene_hash``,
        ``status`` (``ok``, ``failed`` or ``budget``), ``message``, ``wall_time`` [s]
        (integration), ``task_time`` [s] (the whole task on its worker), ``worker``, the
        scalar summary columns and per-band list columns (``winder.analysis.sweep_summary``; a
        scene of parts also has them per nip, ``NIP.column``).
    keys: the swept key paths (each tied key on its own, as the columns).
    axes: the grid's axes, each a tuple of its key paths (several: tied keys, equal in
        every row).
    band_edges: radius band edges [m] of the per-band columns.
    base_scene: the base scene as nested tables (:meth:`winder.Scene.to_dict`).
    settings: the run settings (``t_end``, ``rtol``, ``output_step`` …).
    path: the Parquet file (``DIR/summary.parquet``), or None.
    missing: runs that could not be done (their worker died too often): dicts with
        ``run``, ``run_id``, the swept values and ``reason``; a re-run retries them.
    computed: run ids simulated by this call; skipped: run ids found done on disk.
    dashboard: the Dask dashboard address of the sweep, when there was one.
    """

    frame: pd.DataFrame
    keys: tuple[str, ...]
    band_edges: np.ndarray
    base_scene: dict[str, Any]
    settings: dict[str, Any] = field(default_factory=dict)
    path: Path | None = None
    missing: list[dict[str, Any]] = field(default_factory=list)
    computed: tuple[str, ...] = ()
    skipped: tuple[str, ...] = ()
    dashboard: str | None = None
    axes: tuple[tuple[str, ...], ...] = ()

    def __post_init__(self) -> None:
        if not self.axes:
            self.axes = tuple((k,) for k in self.keys)

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def failed(self) -> pd.DataFrame:
        """The rows of runs that did not end normally (status other than ``ok``)."""
        return self.frame[self.frame["status"] != "ok"]

    def bands(self, column: str) -> np.ndarray:
        """A per-band column as an array ``(runs, bands)``."""
        per_band = (*BAND_COLUMNS, *nip_columns(scene_nip_names(self.base_scene))[1])
        if column not in per_band:
            raise WinderError(f"column {column!r} is not per band; per-band columns: "
                              + ", ".join(per_band))
        n = len(self.band_edges) - 1
        return np.array([np.asarray(v, dtype=float) if v is not None else np.full(n, np.nan)
                         for v in self.frame[column]]).reshape(len(self.frame), n)

    @classmethod
    def read(cls, path: str | Path) -> SweepTable:
        """Read a sweep's ``summary.parquet`` (or its directory)."""
        p = Path(path)
        if p.is_dir():
            p = p / SUMMARY_FILE
        if not p.is_file():
            raise WinderError(f"{p}: no sweep table (run 'winder sweep' first)")
        try:
            table = pq.read_table(p)
        except (OSError, pa.ArrowException) as exc:
            raise WinderError(f"{p}: not a readable Parquet file: {exc}") from None
        raw = (table.schema.metadata or {}).get(_META_KEY)
        if raw is None:
            raise WinderError(f"{p}: not a winder sweep table (no 'winder' metadata)")
        meta = json.loads(raw)
        return cls(frame=table.to_pandas(), keys=tuple(meta["keys"]),
                   axes=tuple(tuple(a) for a in meta.get("axes", [[k] for k in meta["keys"]])),
                   band_edges=np.asarray(meta["band_edges"], dtype=float),
                   base_scene=meta["base_scene"], settings=meta.get("settings", {}), path=p)
