"""Command-line interface: ``winder run|view|fmu|modes|sweep`` (also ``python -m winder``)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from ._errors import WinderError

__all__ = ["main"]


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be > 0")
    return value


def _cmd_run(args: argparse.Namespace) -> int:
    from ._plots import paper_figures
    from ._scene import load_scene
    from ._simulate import simulate

    scene = load_scene(args.scene)
    out = Path(args.out)
    if out.suffix.lower() not in (".csv", ".npz"):
        raise WinderError(f"--out {out}: unknown result format {out.suffix!r}; valid: .csv, .npz")
    progress = sys.stderr.isatty() if args.progress is None else args.progress
    result = simulate(scene, t_end=args.t_end, method=args.method, rtol=args.rtol,
                      atol=args.atol, progress=progress, backend=args.backend)
    result.save(out)
    if out.suffix.lower() == ".csv":  # the viewer and later tools read the NPZ twin
        result.to_npz(out.with_suffix(".npz"))
    m = result.meta
    print(f"{scene.name}: {len(result.t)} samples to {out} ({m['method']}, rtol {m['rtol']:g}, "
          f"{m['rhs_evaluations']} RHS evaluations, {m['wall_time']:.2f} s integration)")
    if args.plots:
        for p in paper_figures(result, args.plots, scene=scene):
            print(f"  figure {p}")
    return 0


def _load_for_view(path: str):
    from ._result import load_result
    from ._scene import load_scene, scene_from_dict
    from ._simulate import simulate

    p = Path(path)
    if p.suffix.lower() == ".toml":
        scene = load_scene(p)
        print(f"simulating {p} for the view ...", file=sys.stderr)
        return scene, simulate(scene, progress=sys.stderr.isatty())
    result = load_result(p)
    if "scene_dict" not in result.meta:
        raise WinderError(f"{p}: this result carries no scene (write it as .npz with "
                          "'winder run'), or pass the scene file instead")
    scene = scene_from_dict(result.meta["scene_dict"], source=str(result.meta.get("source", p)))
    return scene, result


def _cmd_view(args: argparse.Namespace) -> int:
    from winder.viewer import WinderGraph, export_html, snapshots

    scene, result = _load_for_view(args.source)
    graph = WinderGraph(scene)
    if args.html:
        path = export_html(graph, result, args.html, playback=args.playback)
        print(f"animation ({args.playback:g} s playback) written to {path}")
    if args.snapshots:
        for path in snapshots(graph, result, args.snapshots, every=args.every):
            print(f"  snapshot {path}")
    if not args.html and not args.snapshots:
        import meshcat

        from winder.viewer import animate, plan_animation

        vis = meshcat.Visualizer()
        graph.build(vis)
        animate(vis, graph, result, plan_animation(result, playback=args.playback))
        print(f"live view at {vis.url()}  (Ctrl-C to stop)")
        try:
            import time
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            return 0
    return 0


def _check_fmu(path: Path) -> str:
    """Load the FMU in FMPy in this process and run ten 1 ms steps; a one-line report."""
    try:
        import fmpy
    except ImportError:
        return "not run-checked: FMPy is not installed (pip install 'winder[fmu]')"
    from ._fmpy_host import loaded_fmu, start_fmu

    with loaded_fmu(path, instance_name="check") as (fmu, refs, _):
        try:
            start_fmu(fmu, refs)
            for i in range(10):
                fmu.doStep(currentCommunicationPoint=i * 1e-3, communicationStepSize=1e-3)
            radius = fmu.getReal([refs["radius"]])[0]
            fmu.terminate()
        except Exception as exc:  # FMPy raises plain exceptions with the FMI status
            raise WinderError(f"{path} was built but does not run in this Python "
                              f"({sys.executable}): {exc}") from exc
        finally:
            fmu.freeInstance()
    return f"run-checked with FMPy {fmpy.__version__}: 10 steps of 1 ms, radius {radius:.6g} m"


def _cmd_fmu(args: argparse.Namespace) -> int:
    from ._fmu import build_fmu

    out = build_fmu(args.scene, args.out)
    print(f"FMI 2.0 co-simulation FMU written to {out}")
    print(f"  runs inside the host's Python: needs winder installed there (built with "
          f"{sys.executable})")
    if args.check:
        print("  " + _check_fmu(out))
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    import numpy as np

    from ._modes import mode_map
    from ._result import atomic_write
    from ._scene import load_scene

    scene = load_scene(args.scene)
    mm = mode_map(scene, web_speed=args.web_speed, n=args.points)
    print(f"{scene.name}: modes at {len(mm.radius)} radii, {mm.radius[0]:.3f}-"
          f"{mm.radius[-1]:.3f} m, web speed {mm.web_speed:g} m/s")
    print(f"  bounce mode {mm.bounce_frequency[0]:.1f} -> {mm.bounce_frequency[-1]:.1f} Hz, "
          f"damping ratio {mm.bounce_damping[0]:.3f} -> {mm.bounce_damping[-1]:.3f}")
    for k in (1, 2, 3):
        crit = mm.critical_radii(k)
        print(f"  {k}x rotation meets the bounce mode at r = "
              + (", ".join(f"{c:.4f} m" for c in crit) if crit else "(no crossing)"))
    if args.csv:
        cols = mm.as_columns()
        header = ",".join(cols)
        table = np.column_stack(list(cols.values()))
        atomic_write(args.csv, lambda p: np.savetxt(p, table, delimiter=",", header=header,
                                                    comments="", fmt="%.10g"))
        print(f"  table written to {args.csv}")
    if args.plot:
        from ._plots import campbell_figure
        from ._simulate import simulate

        result = None
        if args.simulate:
            print("  simulating the scene for the normal-force envelope ...", file=sys.stderr)
            result = simulate(scene, progress=sys.stderr.isatty())
        path = campbell_figure(mm, args.plot, result=result,
                               title=f"Resonance map of {scene.name}")
        print(f"  figure written to {path}")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    """``winder sweep``: the grid on Dask, the summary table, optionally the map. Exit 0
    when every run is done (failed runs are recorded in the table), 1 when runs are
    missing (workers died), 130 on Ctrl-C (finished runs are kept: re-run to resume)."""
    from ._scene import load_scene
    from ._sweep import sweep
    from ._sweep_grid import parse_vary

    scene = load_scene(args.scene)
    vary = parse_vary(args.vary)
    if args.plot:
        from ._sweep_plot import map_layout

        map_layout(vary)  # a map that cannot be drawn stops the sweep before it runs
    try:
        table = sweep(scene, vary, args.out, scheduler=args.scheduler, workers=args.workers,
                      t_end=args.t_end, rtol=args.rtol, output_step=args.output_step,
                      max_wall=args.max_wall, bands=args.bands,
                      threshold=args.vibration_threshold, trajectories=args.trajectories,
                      progress=args.progress)
    except KeyboardInterrupt:
        print(f"winder: interrupted; finished runs are kept in {args.out}/runs; run the same "
              "command again to resume", file=sys.stderr)
        return 130
    n_bad = int((table.frame["status"] != "ok").sum())
    print(f"{scene.name}: {len(table)} runs in {table.path} ({len(table.computed)} run now, "
          f"{len(table.skipped)} already done, {n_bad} failed)")
    if args.plot:
        from ._sweep_plot import runnability_map

        png = Path(args.out) / "runnability_map.png" if args.plot is True else args.plot
        print(f"  runnability map written to "
              f"{runnability_map(table, png, title=f'Runnability map of {scene.name}')}")
    if table.missing:
        print(f"winder: {len(table.missing)} runs missing (their workers died); run the same "
              "command again to retry them:", file=sys.stderr)
        for m in table.missing:
            values = ", ".join(f"{k} = {m[k]!r}" for k in table.keys)
            print(f"  run {m['run']} ({values}): {m['reason']}", file=sys.stderr)
        return 1
    return 0


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="winder", description="Paper winder simulation.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="simulate a scene file and write its result channels")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", required=True, help="result file (.csv or .npz)")
    run.add_argument("--t-end", type=_positive, help="end time [s] (default: scene duration)")
    run.add_argument("--method", help="integrator (auto, DOPRI5, RK4, RK45, DOP853, Radau, "
                     "BDF, LSODA, RK23)")
    run.add_argument("--backend", help="right-hand side: compiled (default) or pinocchio")
    run.add_argument("--rtol", type=_positive)
    run.add_argument("--atol", type=_positive)
    run.add_argument("--plots", help="directory for the paper's figures (PNG)")
    run.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bar on stderr (default: when stderr is a terminal)")
    run.set_defaults(func=_cmd_run)
    view = sub.add_parser("view", help="meshcat view of a result (.npz) or scene (.toml)")
    view.add_argument("source", help="result file (.npz from 'winder run') or scene (.toml)")
    view.add_argument("--html", help="write a standalone HTML animation (no network)")
    view.add_argument("--snapshots", help="directory for PNG snapshots (headless Chromium)")
    view.add_argument("--every", type=_positive, default=100.0,
                      help="snapshot interval [s] (default 100)")
    view.add_argument("--playback", type=_positive, default=30.0,
                      help="playback length of the whole run [s] (default 30)")
    view.set_defaults(func=_cmd_view)
    fmu = sub.add_parser("fmu", help="export a scene as an FMI 2.0 co-simulation FMU")
    fmu.add_argument("scene", help="scene file (TOML)")
    fmu.add_argument("-o", "--out", default="winder.fmu", help="FMU file (default winder.fmu)")
    fmu.add_argument("--check", action=argparse.BooleanOptionalAction, default=True,
                     help="load the built FMU with FMPy and step it (default on)")
    fmu.set_defaults(func=_cmd_fmu)
    modes = sub.add_parser("modes", help="nip modes against roll radius (resonance map)")
    modes.add_argument("scene", help="scene file (TOML)")
    modes.add_argument("--plot", nargs="?", const="campbell.png",
                       help="write the Campbell chart (PNG; default name campbell.png)")
    modes.add_argument("--csv", help="write frequencies, damping and critical speeds (CSV)")
    modes.add_argument("--web-speed", type=_positive,
                       help="operating web speed [m/s] (default: the scene's)")
    modes.add_argument("--points", type=int, default=150, help="radii (default 150)")
    modes.add_argument("--simulate", action=argparse.BooleanOptionalAction, default=True,
                       help="add the simulated normal-force envelope to the plot")
    modes.set_defaults(func=_cmd_modes)
    sweep = sub.add_parser("sweep", help="run a scene over a parameter grid on Dask "
                           "(runnability map)")
    sweep.add_argument("scene", help="scene file (TOML)")
    sweep.add_argument("--vary", action="append", required=True, metavar="KEY=SPEC",
                       help="scene key path and values: a range START:STOP:COUNT or a list "
                       "a,b,c (repeat for a grid), e.g. drum.drive.web_speed=15:45:16")
    sweep.add_argument("--out", required=True, help="output directory (resumes a sweep "
                       "already there)")
    sweep.add_argument("--scheduler", help="address of a running Dask scheduler (default: "
                       "an embedded local cluster)")
    sweep.add_argument("--workers", type=int, help="local workers (default: one per core)")
    sweep.add_argument("--plot", nargs="?", const=True, metavar="PNG",
                       help="draw the runnability map (default OUT/runnability_map.png)")
    sweep.add_argument("--trajectories", action="store_true",
                       help="also store each run's full result (OUT/trajectories/*.npz)")
    sweep.add_argument("--t-end", type=_positive, help="end time of each run [s]")
    sweep.add_argument("--rtol", type=_positive)
    sweep.add_argument("--output-step", type=_positive, help="sampling of the runs [s]")
    sweep.add_argument("--max-wall", type=_positive, help="wall-clock budget per run [s]")
    sweep.add_argument("--bands", type=int, default=24, help="radius bands (default 24)")
    sweep.add_argument("--vibration-threshold", type=_positive, default=0.5,
                       help="vibration level where vibration starts (default 0.5)")
    sweep.add_argument("--progress", action=argparse.BooleanOptionalAction, default=True,
                       help="progress bar and dashboard address on stderr (default on; "
                       "whole lines every 5 s on a log or pipe)")
    sweep.set_defaults(func=_cmd_sweep)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except WinderError as exc:
        print(f"winder: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("winder: interrupted (no partial output written)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
