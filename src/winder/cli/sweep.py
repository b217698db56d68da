"""``winder sweep``: a scene over a parameter grid on Dask, its summary table and the
runnability map."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from winder.io.interrupt import Interrupted

__all__ = ["cmd_sweep"]

EXIT_ERROR = 2

#: Failed runs listed by ``winder sweep`` (the rest are counted; the table holds them all).
_MAX_FAILED_LISTED = 20


def _axis_values(table: Any, row: Any) -> str:
    """``k1, k2 = 20.0, k3 = 1e-3``: a run's swept values, tied keys once."""
    return ", ".join(f"{', '.join(a)} = {row[a[0]]!r}" for a in table.axes)


def _failed_runs(table: Any) -> list[str]:
    """Lines listing the runs of ``table`` that did not end normally: run index, swept
    values, status and message (its first line, cut to 200 characters)."""
    bad = table.failed
    lines = []
    for row in bad.head(_MAX_FAILED_LISTED).to_dict("records"):
        message = " ".join(str(row["message"]).split()) or "(no message)"
        if len(message) > 200:
            message = message[:197] + "..."
        lines.append(f"  run {row['run']} ({_axis_values(table, row)}): {row['status']}: "
                     f"{message}")
    if len(bad) > _MAX_FAILED_LISTED:
        lines.append(f"  ... and {len(bad) - _MAX_FAILED_LISTED} more (column 'status' of "
                     f"{table.path})")
    return lines


def cmd_sweep(args: argparse.Namespace) -> int:
    """``winder sweep``: the grid on Dask, the summary table, optionally the map. Exit 0
    when every run is done and at least one ended normally (failed runs are listed on
    stderr and recorded in the table), 2 when every run failed (listed; the table is kept,
    no map is drawn), 1 when runs are missing (workers died), 128 + N on signal N (130
    Ctrl-C; finished runs are kept: re-run to resume)."""
    from winder.io.files import check_output_dir, check_output_file
    from winder.scene.load import load_scene

    check_output_dir(args.out, "--out")  # every output location, before anything runs
    if args.plot not in (None, True):
        check_output_file(args.plot, "--plot", suffixes=(".png",))
    scene = load_scene(args.scene)
    from winder.analysis.sweep_grid import parse_vary

    vary = parse_vary(args.vary)
    if args.plot:
        from winder.plots.sweep import map_layout

        map_layout(vary)  # a map that cannot be drawn stops the sweep before it runs
    from winder.analysis.sweep import sweep  # Dask, pandas, pyarrow

    try:
        table = sweep(scene, vary, args.out, scheduler=args.scheduler, workers=args.workers,
                      t_end=args.t_end, rtol=args.rtol, output_step=args.output_step,
                      max_wall=args.max_wall, bands=args.bands,
                      threshold=args.vibration_threshold, trajectories=args.trajectories,
                      progress=args.progress)
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM/SIGHUP as Interrupted
        what = exc.describe() if isinstance(exc, Interrupted) else "interrupted (SIGINT)"
        print(f"winder: {what}; finished runs are kept in {args.out}/runs; run the same "
              "command again to resume", file=sys.stderr)
        return exc.exit_status if isinstance(exc, Interrupted) else 130
    n_bad = len(table.failed)
    print(f"{scene.name}: {len(table)} runs in {table.path} ({len(table.computed)} run now, "
          f"{len(table.skipped)} already done, {n_bad} failed)")
    all_failed = n_bad == len(table) > 0
    if n_bad:
        head = (f"every run failed ({n_bad})" if all_failed
                else f"{n_bad} of {len(table)} runs failed")
        print(f"winder: {head}:", file=sys.stderr)
        for line in _failed_runs(table):
            print(line, file=sys.stderr)
    if args.plot and all_failed:
        print("  no runnability map: no run ended normally", file=sys.stderr)
    elif args.plot:
        from winder.plots.sweep import runnability_map

        png = Path(args.out) / "runnability_map.png" if args.plot is True else args.plot
        print(f"  runnability map written to "
              f"{runnability_map(table, png, title=f'Runnability map of {scene.name}')}")
    if table.missing:
        print(f"winder: {len(table.missing)} runs missing (their workers died); run the same "
              "command again to retry them:", file=sys.stderr)
        for m in table.missing:
            print(f"  run {m['run']} ({_axis_values(table, m)}): {m['reason']}",
                  file=sys.stderr)
        return 1
    return EXIT_ERROR if all_failed else 0
