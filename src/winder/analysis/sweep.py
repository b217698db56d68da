"""Parameter sweeps on Dask distributed: every grid point a full simulation, summarised.

:func:`sweep` builds the grid (:mod:`winder.analysis.sweep_grid`, every point validated before
anything is submitted), skips the runs already done in the output directory, submits the
rest as independent tasks to a Dask cluster (an embedded ``LocalCluster`` with one
single-threaded worker process per core, or an existing scheduler), and writes each
finished run's summary row as soon as it arrives (:mod:`winder.analysis.sweep_table`). A run that
fails records its status and message; a task whose worker died more often than the
scheduler allows (``distributed.scheduler.allowed-failures``) is reported as missing and
retried by the next call.
"""

from __future__ import annotations

import math
import os
import socket
import sys
import time
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from winder._args import RTOL_MAX
from winder._errors import ArgumentError, ArgumentTypeError, BudgetExceeded, WinderError
from winder.analysis.sweep_grid import Grid, Value, build_grid, parse_spec, scene_hash, split_keys
from winder.analysis.sweep_summary import default_band_edges, empty_summary, summarise
from winder.analysis.sweep_table import RunStore, SweepTable, row_schema, table_meta
from winder.io.progress import SweepProgress
from winder.io.result import Result
from winder.scene.load import Scene, load_scene
from winder.solve.simulate import simulate

__all__ = ["sweep", "run_one", "run_settings", "run_id"]

#: Radius bands of the summaries when not given.
DEFAULT_BANDS = 24


def run_settings(*, t_end: float | None = None, rtol: float | None = None,
                 output_step: float | None = None, max_wall: float | None = None,
                 window: float = 0.5, threshold: float = 0.5) -> dict[str, Any]:
    """The checked settings of every run of a sweep (``None``: the scene's own value).

    ``t_end`` [s], ``rtol`` [-], ``output_step`` [s], ``max_wall`` [s] (wall-clock budget
    per run) go to :func:`winder.simulate`; ``window`` [s] and ``threshold`` [-] to
    :func:`winder.analysis.sweep_summary.summarise`."""
    out: dict[str, Any] = {}
    for name, value, optional in (("t_end", t_end, True), ("rtol", rtol, True),
                                  ("output_step", output_step, True),
                                  ("max_wall", max_wall, True), ("window", window, False),
                                  ("threshold", threshold, False)):
        if value is None and optional:
            out[name] = None
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ArgumentTypeError(f"{name}: expected a number, got {value!r} "
                                    f"({type(value).__name__})")
        if not (math.isfinite(value) and value > 0):
            raise ArgumentError(f"{name}: must be finite and > 0, got {value!r}")
        if name == "rtol" and value > RTOL_MAX:
            raise ArgumentError(f"rtol: must be > 0 and <= {RTOL_MAX:g}, got {value!r}")
        out[name] = float(value)
    return out


def run_id(scene: Scene, settings: Mapping[str, Any], edges: Sequence[float]) -> str:
    """Identity of one run: the hash of its scene, its settings and its band edges."""
    return scene_hash({"scene": scene.to_dict(), "settings": dict(settings),
                       "band_edges": [float(e) for e in edges]})


def run_one(scene: Scene, settings: Mapping[str, Any], edges: Sequence[float],
            trajectory: bool = False) -> tuple[dict[str, Any], Result | None]:
    """Simulate one grid point and summarise it (the task a worker runs).

    Never raises for a failed simulation: the row's ``status`` is ``ok``, ``budget``
    (:class:`~winder.BudgetExceeded`; the summary covers the partial result) or
    ``failed`` (any other error; ``message`` says what). Returns ``(row, result)`` with the
    full result only when ``trajectory`` is true."""
    start = time.perf_counter()
    result: Result | None = None
    status, message = "ok", ""
    try:
        result = simulate(scene, t_end=settings.get("t_end"), rtol=settings.get("rtol"),
                          output_step=settings.get("output_step"),
                          max_wall=settings.get("max_wall"))
    except BudgetExceeded as exc:
        status, message = "budget", str(exc)
        result = exc.partial if isinstance(exc.partial, Result) else None
    except WinderError as exc:
        status, message = "failed", str(exc)
    except Exception as exc:  # a run must not stop the sweep: record what happened
        status, message = "failed", f"{type(exc).__name__}: {exc}"
    if result is not None:
        summary = summarise(result, np.asarray(edges), window=settings["window"],
                            threshold=settings["threshold"])
    else:
        summary = empty_summary(len(edges) - 1)
    row = {"status": status, "message": message,
           "wall_time": float(result.meta.get("wall_time", math.nan)) if result else math.nan,
           "worker": f"{socket.gethostname()}:{os.getpid()}", **summary}
    row["task_time"] = time.perf_counter() - start
    return row, (result if trajectory else None)


def _edges(bands: int | Sequence[float], grid: Grid, t_end: float | None) -> np.ndarray:
    if isinstance(bands, bool):
        raise ArgumentTypeError(f"bands: expected a count or band edges [m], got {bands!r}")
    if isinstance(bands, int):
        if bands < 1:
            raise ArgumentError(f"bands: must be >= 1, got {bands}")
        return default_band_edges(grid.scenes, t_end, bands)
    edges = np.asarray(bands, dtype=float)
    if edges.ndim != 1 or len(edges) < 2 or not np.all(np.isfinite(edges)) \
            or np.any(np.diff(edges) <= 0):
        raise ArgumentError(f"bands: edges must be at least two finite, increasing radii "
                            f"[m], got {bands!r}")
    return edges


def _why_missing(future: Any) -> str:
    """One line on why a task gave no row (its worker died, it was cancelled, ...)."""
    if future.status == "cancelled":
        return "cancelled"
    exc = future.exception()
    last = getattr(exc, "last_worker", None)
    if last is not None:  # distributed's KilledWorker
        return (f"{type(exc).__name__}: the worker running it died "
                f"{exc.allowed_failures + 1} time(s), last {last.address}")
    return f"{type(exc).__name__}: {exc}"


@contextmanager
def _client(scheduler: Any, workers: int | None) -> Iterator[Any]:
    """A Dask client: the one given, one attached to ``scheduler`` (an address), or one
    on an embedded ``LocalCluster`` with ``workers`` single-threaded processes."""
    from distributed import Client, LocalCluster

    if isinstance(scheduler, Client):
        yield scheduler
        return
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ArgumentError(f"scheduler {scheduler!r}: cannot connect ({exc}); start "
                                "one with 'dask scheduler' and 'dask worker ADDRESS'") \
                from None
        try:
            yield client
        finally:
            client.close()
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True)
    try:
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


def sweep(scene: Scene | str | Path,
          vary: Mapping[str | tuple[str, ...], str | Sequence[Value]],
          out: str | Path, *, scheduler: Any = None, workers: int | None = None,
          t_end: float | None = None, rtol: float | None = None,
          output_step: float | None = None, max_wall: float | None = None,
          bands: int | Sequence[float] = DEFAULT_BANDS, window: float = 0.5,
          threshold: float = 0.5, trajectories: bool = False, progress: bool = False,
          callback: Callable[[dict[str, Any]], None] | None = None) -> SweepTable:
    """Run a scene over the full grid of ``vary`` on Dask and return the summary table.

    Parameters
    ----------
    scene: the base scene (a :class:`~winder.Scene` or a scene file).
    vary: ``{key path: values}``; values are a list or a spec string (``"15:45:16"``:
        16 values from 15 to 45; ``"1e7,2e7"``); see :mod:`winder.analysis.sweep_grid`. Tied keys
        share one axis (each run sets them all to the same value): the key
        ``"drum.front.drive.web_speed,drum.rear.drive.web_speed"`` or a tuple of key
        paths.
    out: output directory (``runs/``, ``summary.parquet``, ``trajectories/``). Runs
        already done there are skipped: an interrupted sweep resumes.
    scheduler: ``None`` (an embedded ``LocalCluster`` with ``workers`` processes, default
        one per core), a scheduler address (``"tcp://host:8786"``) or a
        ``distributed.Client``.
    t_end [s], rtol [-], output_step [s], max_wall [s]: per-run settings of
        :func:`winder.simulate` (default: the scene's).
    bands: number of equal radius bands (from the smallest initial radius to the largest
        end radius of the grid) or the band edges [m].
    window [s], threshold [-]: windows of bounce amplitude and vibration level; the
        vibration level at which vibration counts as started.
    trajectories: also store every run's full result (``trajectories/<run_id>.npz``).
    progress: a progress bar and the Dask dashboard address on stderr.
    callback: called with each new row as soon as it is written.

    Raises
    ------
    ArgumentError: a bad key, spec, value (the scene rejects it) or setting; raised before
        anything is submitted or written.
    """
    base = scene if isinstance(scene, Scene) else load_scene(scene)
    if not isinstance(vary, Mapping) or not vary:
        raise ArgumentError(f"vary: give at least one {{key: values}}, got {vary!r}")
    # keyed as given: build_grid refuses a key on two axes ("a,b" and ("a", "b") too)
    values = {k: parse_spec(",".join(split_keys(k)), v) if isinstance(v, str)
              else [x.item() if isinstance(x, np.generic) else x for x in v]
              for k, v in vary.items()}
    grid = build_grid(base, values)
    settings = run_settings(t_end=t_end, rtol=rtol, output_step=output_step,
                            max_wall=max_wall, window=window, threshold=threshold)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int)
                                or workers < 1):
        raise ArgumentError(f"workers: must be a whole number >= 1, got {workers!r}")
    if workers is not None and scheduler is not None:
        raise ArgumentError("workers: only for the embedded cluster; an existing scheduler "
                            "brings its own workers")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ArgumentError(f"out {out}: exists and is not a directory")
    edges = _edges(bands, grid, settings["t_end"])
    ids = [run_id(s, settings, edges) for s in grid.scenes]
    hashes = [scene_hash(s.to_dict()) for s in grid.scenes]
    schema = row_schema(grid.axes, table_meta(grid.keys, edges, base.to_dict(), settings,
                                              axes=[a.keys for a in grid.axes]))
    store = RunStore(out)

    def row_of(i: int, fields: Mapping[str, Any]) -> dict[str, Any]:
        return {**fields, "run": i, **grid.points[i], "run_id": ids[i], "scene_hash": hashes[i]}

    done = store.load_done(ids, trajectories=trajectories)
    rows = {i: row_of(i, done[rid]) for i, rid in enumerate(ids) if rid in done}
    todo = [i for i in range(len(ids)) if i not in rows]
    computed: list[str] = []
    missing: list[dict[str, Any]] = []
    dashboard = None
    if todo:
        from distributed import as_completed

        with _client(scheduler, workers) as client:
            dashboard = client.dashboard_link
            bar = None
            if progress:
                print(f"winder sweep: {len(grid)} runs ({len(rows)} already done in {out}), "
                      f"Dask dashboard: {dashboard}", file=sys.stderr, flush=True)
                bar = SweepProgress(len(grid), done=len(rows), label=base.name)
            token = uuid.uuid4().hex[:8]
            futures = {client.submit(run_one, grid.scenes[i], settings, edges, trajectories,
                                     key=f"winder-run-{i}-{ids[i]}-{token}", pure=False): i
                       for i in todo}
            try:
                for fut in as_completed(list(futures)):
                    i = futures.pop(fut)
                    try:  # a result lost with its worker is computed again: wait for it
                        fields, result = fut.result()
                    except Exception:  # noqa: BLE001 - the run's worker died: missing
                        fields = None
                    if fields is not None:
                        row = row_of(i, fields)
                        store.write_run(row, schema, result if trajectories else None)
                        rows[i] = row
                        computed.append(ids[i])
                        failed = row["status"] != "ok"
                        if callback is not None:
                            callback(row)
                    else:
                        missing.append({"run": i, **grid.points[i], "run_id": ids[i],
                                        "reason": _why_missing(fut)})
                        failed = True
                    fut.release()
                    if bar is not None:
                        bar.update(failed=failed)
            finally:
                if futures:
                    client.cancel(list(futures))
                if bar is not None:
                    bar.close()
    path = store.write_table(list(rows.values()), schema)
    table = SweepTable.read(path)
    table.missing = sorted(missing, key=lambda m: m["run"])
    table.computed = tuple(computed)
    table.skipped = tuple(done)
    table.dashboard = dashboard
    return table
