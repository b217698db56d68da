"""Command-line interface: ``winder run|view|fmu|modes|sweep|linearise|fit`` (also ``python
-m winder``); ``winder sweep``, ``winder linearise`` and ``winder fit`` in their modules
(:mod:`winder.cli.sweep`, :mod:`winder.cli.linearise`, :mod:`winder.cli.fit`).

Exit status
-----------
- 0: done.
- 2: bad input or a failed run: one or a few lines on stderr naming the file, option or key,
  the bad value and what is valid; nothing is left on disk. Every output location is
  checked before a run starts.
- 128 + N when stopped by signal N: 130 for Ctrl-C (SIGINT), 143 for SIGTERM, 129 for
  SIGHUP; one line names it ("winder: terminated (SIGTERM); no partial file left").
  Temporary files are removed and child processes stopped; a set of files written together
  (a result and its NPZ twin, the figures) is complete or absent whenever the signal
  comes (files it would have replaced are put back); files a command had completed
  before the signal stay, and the line names them. A second signal during that clean-up
  stops at once, with a message. A signal after the command has finished (while Python
  shuts down) is ignored: the status is the command's own.
- 141 when the reader of stdout went away (``winder modes ... | head``), as for SIGPIPE.
- 1: an internal error of winder (a bug): the traceback and a line saying so; for
  ``winder sweep``, also: runs are missing (their workers died), listed on stderr.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import traceback
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from winder._args import ATOL_MAX, RTOL_MAX
from winder._errors import WinderError
from winder.io.interrupt import Interrupted, handling_signals

__all__ = ["main"]

EXIT_ERROR = 2
EXIT_INTERNAL = 1


# ---- option types: each names the valid range ---------------------------------------------
def _number(lo: float, hi: float = math.inf, *, lo_open: bool = True,
            hi_open: bool = False, integer: bool = False) -> Callable[[str], Any]:
    """An argparse type: a finite number (``integer``: a whole number) in the range."""
    left = "<" if lo_open else "<="
    right = "<" if hi_open else "<="
    valid = f"{lo:g} {left} x" + (f" {right} {hi:g}" if math.isfinite(hi) else "")
    valid = ("a whole number, " if integer else "a finite number, ") + valid

    def parse(text: str) -> float | int:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number; valid: {valid}") \
                from None
        ok = math.isfinite(value) and (value > lo if lo_open else value >= lo) and \
            (value < hi if hi_open else value <= hi)
        if ok and integer and value != int(value):
            ok = False
        if not ok:
            raise argparse.ArgumentTypeError(f"{text!r} is out of range; valid: {valid}")
        return int(value) if integer else value
    parse.__name__ = "number"
    return parse


_POSITIVE = _number(0.0)
_RTOL = _number(0.0, RTOL_MAX)
_ATOL = _number(0.0, ATOL_MAX)
_PLAYBACK = _number(0.0, 3600.0)
_POINTS = _number(2, 100_000, lo_open=False, integer=True)
_EVALS = _number(1, 1e15, lo_open=False, integer=True)
_COUNT = _number(1, 10_000, lo_open=False, integer=True)


class _Parser(argparse.ArgumentParser):
    """argparse with the project's error contract: one line naming the option, exit 2
    (raised as :class:`_UsageError`, so that :func:`main` returns the status)."""

    def error(self, message: str) -> NoReturn:
        raise _UsageError(f"{self.prog}: error: {message} (see {self.prog} --help)")

    def exit(self, status: int = 0, message: str | None = None) -> NoReturn:
        if message:
            sys.stderr.write(message)
        raise _Exit(status)


class _UsageError(Exception):
    pass


class _Exit(Exception):
    def __init__(self, status: int) -> None:
        super().__init__(status)
        self.status = status


# ---- commands -------------------------------------------------------------------------------
def _result_files(out: Path) -> list[Path]:
    """``--out`` and, for a CSV, its NPZ twin (the viewer reads it: it carries the scene)."""
    return [out, out.with_suffix(".npz")] if out.suffix.lower() == ".csv" else [out]


def _balance_text(residual: float, scale: float) -> str:
    """The line on the initial static balance (machines.md §7): its largest force
    residual ``residual`` [N] against the largest force ``scale`` [N] in it; with no force
    at all there is nothing to balance (no free coordinate rests on a nip)."""
    if scale == 0.0 and residual == 0.0:
        return ("initial static balance: nothing to solve (no free coordinate rests on a "
                "nip or carries a load)")
    return f"initial static balance: residual {residual:.1e} N of {scale:.1e} N"


def _tell(line: str) -> None:
    """What a long step is doing, on stderr where it is a terminal (as the progress bars):
    a log or a test's captured stderr keeps only the results and the errors."""
    if sys.stderr.isatty():
        print(line, file=sys.stderr, flush=True)


def _cmd_run(args: argparse.Namespace) -> int:
    from winder.io.files import check_output_dir, check_output_file

    out = check_output_file(args.out, "--out", suffixes=(".csv", ".npz"))
    files = _result_files(out)
    for twin in files[1:]:
        check_output_file(twin, "--out (its .npz twin)", suffixes=(".npz",))
    plots = check_output_dir(args.plots, "--plots") if args.plots is not None else None

    from winder.scene.load import load_scene

    scene = load_scene(args.scene)  # a bad scene stops here, before the solver is imported
    from winder._errors import BudgetExceeded
    from winder.solve.equilibrium import EquilibriumError
    from winder.solve.simulate import WebSlipWarning, simulate

    progress = sys.stderr.isatty() if args.progress is None else args.progress
    try:
        with warnings.catch_warnings():  # printed with the run's summary (meta slips)
            warnings.simplefilter("ignore", WebSlipWarning)
            result = simulate(scene, t_end=args.t_end, method=args.method, rtol=args.rtol,
                              atol=args.atol, max_step=args.max_step, progress=progress,
                              backend=args.backend,
                              max_rhs=args.max_evals, max_wall=args.max_wall)
    except EquilibriumError as exc:  # machines.md §7: no initial balance, a scene error
        raise WinderError(f"{args.scene}: {exc}") from None
    except BudgetExceeded as exc:
        partial = getattr(exc, "partial", None)
        if not args.keep_partial:
            raise WinderError(f"{exc}\n  (--keep-partial writes the result up to that time "
                              f"to {out}; --max-evals/--max-wall raise the budget)") from None
        if partial is None or len(partial.t) == 0:
            raise WinderError(f"{exc}\n  no partial result: no output sample was reached; "
                              f"{out} not written") from None
        partial.meta["partial"] = True
        partial.save(*files)
        raise WinderError(f"{exc}\n  partial result up to t = {partial.t[-1]:g} s written "
                          f"to {', '.join(map(str, files))}") from None
    figures: list[Path] = []
    items: list[tuple[Path, Callable[[Path], object]]] = [
        (f, result._writer(f)) for f in files]
    if plots is not None:  # rendered first, then written with the result: all or nothing
        from winder.plots.figures import CLOSEUP_STEP, closeup_end, collected
        from winder.plots.run import run_figures

        if progress:  # the figures of a large machine take several seconds: say so
            print(f"{scene.name}: drawing the figures into {plots} ...", file=sys.stderr,
                  flush=True)
        end = closeup_end(result)  # Fig. 8's close-up of the first lift-off, finely sampled
        closeup = None if end is None else simulate(scene, t_end=end, output_step=CLOSEUP_STEP)
        with collected() as pngs:
            figures = run_figures(result, plots, scene=scene, closeup=closeup)
        items += [(p, lambda tmp, data=data: tmp.write_bytes(data)) for p, data in pngs]
    from winder.io.files import atomic_write_all

    atomic_write_all(items)
    m = result.meta
    print(f"{scene.name}: {len(result.t)} samples to {out} ({m['method']}, rtol {m['rtol']:g}, "
          f"{m['rhs_evaluations']} RHS evaluations, {m['wall_time']:.2f} s integration)")
    if m.get("static_residual") is not None:
        print("  " + _balance_text(m["static_residual"], m["static_scale"]))
    if m.get("ended"):
        print(f"  {m['ended']}")
    for text in m.get("slips") or ():
        print(f"  warning: {text}")
    for p in figures:
        print(f"  figure {p}")
    return 0


def _load_for_view(path: str, check_span: Callable[[float], None]):
    """The scene and result to view; ``check_span(t_end)`` runs before a scene is simulated
    (and before a result file is used)."""
    from winder.io.files import _check_text
    from winder.io.result import load_result
    from winder.scene.load import load_scene, scene_from_dict

    p = _check_text("source", path)
    if p.suffix.lower() == ".toml":
        scene = load_scene(p)
        check_span(scene.scene.duration)
        from winder.solve.simulate import simulate

        print(f"simulating {p} for the view ...", file=sys.stderr)
        return scene, simulate(scene, progress=sys.stderr.isatty())
    if p.suffix.lower() not in (".npz", ".csv"):
        raise WinderError(f"{p}: unknown file type {p.suffix!r}; valid: .npz (from "
                          "'winder run') or .toml (a scene)")
    result = load_result(p)
    stored = result.meta.get("scene_dict")
    if not isinstance(stored, dict):
        raise WinderError(f"{p}: this result carries no scene (write it as .npz with "
                          "'winder run'), or pass the scene file instead")
    try:
        scene = scene_from_dict(stored, source=str(p))
    except WinderError as exc:
        raise WinderError(f"{p}: the scene stored in this result is invalid: {exc}") from None
    except (TypeError, ValueError, KeyError, AttributeError) as exc:
        raise WinderError(f"{p}: the scene stored in this result is invalid "
                          f"({type(exc).__name__}: {exc})") from None
    return scene, result


def _cmd_view(args: argparse.Namespace) -> int:
    from winder.io.files import check_output_dir, check_output_file

    html = check_output_file(args.html, "--html", suffixes=(".html", ".htm")) \
        if args.html is not None else None
    snaps = check_output_dir(args.snapshots, "--snapshots") \
        if args.snapshots is not None else None

    from winder.viewer import (
        WinderGraph,
        check_drawable,
        export_html,
        snapshot_names,
        snapshots,
    )

    def check_span(t_end: float) -> None:
        if snaps is not None:
            try:
                snapshot_names(t_end, args.every)
            except WinderError as exc:
                raise WinderError(f"--every: {exc}") from None

    scene, result = _load_for_view(args.source, check_span)
    check_drawable(result, args.source, scene=scene)
    check_span(float(result.t[-1]))
    graph = WinderGraph(scene)
    if html is not None:
        path = export_html(graph, result, html, playback=args.playback)
        print(f"animation ({args.playback:g} s playback) written to {path}")
    if snaps is not None:  # about 2 s a picture: say so before the first
        n = len(snapshot_names(float(result.t[-1]), args.every))
        _tell(f"taking {n} snapshot{'s' if n > 1 else ''} with headless Chromium into "
             f"{snaps} (about 2 s each) ...")
        for path in snapshots(graph, result, snaps, every=args.every):
            print(f"  snapshot {path}")
    if html is None and snaps is None:
        import time

        from winder.viewer import animate, plan_animation
        from winder.viewer._export import served

        with served(graph) as vis:
            animate(vis, graph, result, plan_animation(result, playback=args.playback,
                                                       scene=scene))
            print(f"live view at {vis.url()}  (Ctrl-C to stop)", flush=True)
            try:
                while True:
                    time.sleep(1.0)
            except Interrupted as exc:
                if exc.name != "SIGINT":
                    raise
                print("live view stopped", file=sys.stderr)
    return 0


def _check_fmu(path: Path) -> str:  # FMPy is optional: the check says so where missing
    try:
        from winder.fmu.host import check_fmu
    except ImportError:
        return "not run-checked: FMPy is not installed (pip install 'winder[fmu]')"
    return check_fmu(path)


def _cmd_fmu(args: argparse.Namespace) -> int:
    from winder.io.files import check_output_file

    out = check_output_file(args.out, "-o/--out", suffixes=(".fmu",))
    from winder.fmu.native import FMI_VERSIONS, build_fmu

    _tell(f"building the FMU of {args.scene} (its C code compiled; a few seconds) ...")
    out = build_fmu(args.scene, out, fmi_version=args.fmi_version,
                    speed_profile=args.speed_profile)
    print(f"FMI {args.fmi_version}.0 co-simulation and model-exchange FMU (native: no Python "
          f"inside) written to {out}\n  binaries/{FMI_VERSIONS[args.fmi_version][2]} from the "
          "system C compiler; sources/ rebuild it elsewhere (fmpy compile)")
    if args.check:
        print("  " + _check_fmu(out))
    return 0


def _cmd_modes(args: argparse.Namespace) -> int:
    from winder.cli.modes import cmd_modes

    return cmd_modes(args, _tell)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from winder.cli.sweep import cmd_sweep

    return cmd_sweep(args)


def _add_linearise(sub: Any) -> None:
    from winder.cli.linearise import add_parser

    add_parser(sub, _POSITIVE)


def _version() -> str:
    """The installed package's version."""
    from importlib import metadata

    try:
        return metadata.version("winder")
    except metadata.PackageNotFoundError:  # a source tree on sys.path, not installed
        return "(not installed)"


def _add_fit(sub: Any) -> None:
    from winder.cli.fit import add_parser

    add_parser(sub, _POSITIVE, _RTOL)


def _build_parser() -> argparse.ArgumentParser:
    from winder.scene.schema import BACKENDS, METHODS  # the scene's [solver] choices: one list

    parser = _Parser(prog="winder", description="Paper winder simulation.",
                     epilog="Exit status: 0 done; 2 bad input or failed run (a message names "
                     "the file, option or key); 128+N stopped by signal N (130 Ctrl-C, 143 "
                     "SIGTERM, 129 SIGHUP; no partial file left); 1 internal error.")
    parser.add_argument("--version", action="version", version=f"winder {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    run = sub.add_parser("run", help="simulate a scene file and write its result channels")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", required=True, help="result file (.csv or .npz; a .csv gets "
                     "an .npz twin)")
    run.add_argument("--t-end", type=_POSITIVE, help="end time [s] (default: scene duration)")
    run.add_argument("--method", help=f"integrator ({', '.join(METHODS)}; default: the "
                     "scene's [solver] method, else auto)")
    run.add_argument("--backend", help=f"right-hand side: {' or '.join(BACKENDS)} (default: "
                     "the scene's [solver] backend, else compiled)")
    run.add_argument("--rtol", type=_RTOL, help=f"relative tolerance (0 < rtol <= {RTOL_MAX:g})")
    run.add_argument("--atol", type=_ATOL,
                     help=f"absolute tolerance [state units] (0 < atol <= {ATOL_MAX:g})")
    run.add_argument("--max-step", type=_POSITIVE, metavar="SECONDS",
                     help="largest step [s] (the step of RK4, default 1e-3)")
    run.add_argument("--max-evals", type=_EVALS, metavar="N",
                     help="budget of right-hand side evaluations (default: [solver] max_rhs)")
    run.add_argument("--max-wall", type=_POSITIVE, metavar="SECONDS",
                     help="budget of wall-clock time of the integration [s]")
    run.add_argument("--keep-partial", action="store_true",
                     help="when a budget stops the run, write the result up to that time "
                     "to --out (the exit status stays 2)")
    run.add_argument("--plots", help="directory for the figures (PNG): the paper's for a "
                     "single-drum scene, drums, rolls, nips and positions for a scene of parts")
    run.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bar on stderr (default: when stderr is a terminal)")
    run.set_defaults(func=_cmd_run)
    view = sub.add_parser("view", help="meshcat view of a result (.npz) or scene (.toml)")
    view.add_argument("source", help="result file (.npz from 'winder run') or scene (.toml)")
    view.add_argument("--html", help="write a standalone HTML animation (no network)")
    view.add_argument("--snapshots", help="directory for PNG snapshots (headless Chromium)")
    view.add_argument("--every", type=_POSITIVE, default=100.0,
                      help="snapshot interval [s] (default 100)")
    view.add_argument("--playback", type=_PLAYBACK, default=30.0,
                      help="playback length of the whole run [s] (0 < x <= 3600, default 30)")
    view.set_defaults(func=_cmd_view)
    fmu = sub.add_parser("fmu", help="export a scene as a native FMU, FMI 2.0 or 3.0 "
                         "(co-simulation and model exchange)")
    fmu.add_argument("scene", help="scene file (TOML)")
    fmu.add_argument("-o", "--out", default="winder.fmu", help="FMU file (default winder.fmu)")
    fmu.add_argument("--check", action=argparse.BooleanOptionalAction, default=True,
                     help="load the built FMU with FMPy and step it (default on)")
    fmu.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                     help="FMI 2.0 (default) or FMI 3.0; both with co-simulation and model "
                          "exchange")
    fmu.add_argument("--native", action="store_true",
                     help="accepted for older scripts: every FMU is native (the compiled "
                          "machine and C integrators, no Python inside)")
    fmu.add_argument("--speed-profile", action=argparse.BooleanOptionalAction, default=None,
                     help="single-drum scenes: the drum on its speed profile, or freed on "
                          "the input drum_torque_command (fixed at build time; default: the "
                          "scene's drive)")
    fmu.set_defaults(func=_cmd_fmu)
    modes = sub.add_parser("modes", help="bounce modes against the wound roll's radius and "
                           "the rotation harmonics (resonance map); a machine without a "
                           "wound roll, or with [effects] contact = false: its modes at the "
                           "initial state (one row)")
    modes.add_argument("scene", help="scene file (TOML)")
    modes.add_argument("--plot", nargs="?", const="campbell.png",
                       help="write the resonance map (PNG; default name campbell.png)")
    modes.add_argument("--csv", help="write frequencies, damping and critical speeds (CSV)")
    modes.add_argument("--web-speed", type=_POSITIVE,
                       help="operating web speed [m/s] (default: the scene's)")
    modes.add_argument("--points", type=_POINTS, default=150,
                       help="radii (2 <= points <= 100000, default 150)")
    modes.add_argument("--radius-min", type=_POSITIVE, metavar="R",
                       help="smallest radius of the wound roll [m] (default: its initial "
                       "radius)")
    modes.add_argument("--radius-max", type=_POSITIVE, metavar="R",
                       help="largest radius of the wound roll [m] (default: its radius at "
                       "the end of the scene's run)")
    modes.add_argument("--roll", metavar="NAME",
                       help="the paper roll whose radius the map follows: the wound roll "
                       "(default) or a web's unwinding roll (the parent: its web line's "
                       "tension and dancer modes against the parent's radius, from its core "
                       "radius to its initial radius by default; the wound roll stays at "
                       "its initial radius)")
    modes.add_argument("--simulate", action=argparse.BooleanOptionalAction, default=True,
                       help="add the simulated normal-force envelope to the plot")
    modes.set_defaults(func=_cmd_modes)
    sweep = sub.add_parser("sweep", help="run a scene over a parameter grid on Dask "
                           "(runnability map)",
                           epilog="Exit status: 0 every run done (runs that failed are "
                           "listed on stderr with their values and message, and kept in the "
                           "table); 2 bad input, or every run failed (the table is kept); 1 "
                           "runs missing (their workers died: run again to retry them); "
                           "130 Ctrl-C (run again to resume).")
    sweep.add_argument("scene", help="scene file (TOML)")
    sweep.add_argument("--vary", action="append", required=True, metavar="KEY=SPEC",
                       help="scene key path and values: a range START:STOP:COUNT or a list "
                       "a,b,c (repeat for a grid), e.g. drum.drive.web_speed=15:45:16; tied "
                       "keys KEY1,KEY2=SPEC take the same value in each run, e.g. "
                       "drum.front.drive.web_speed,drum.rear.drive.web_speed=10:30:5")
    sweep.add_argument("--out", required=True, help="output directory (resumes a sweep "
                       "already there)")
    sweep.add_argument("--scheduler", help="address of a running Dask scheduler (default: "
                       "an embedded local cluster)")
    sweep.add_argument("--workers", type=_COUNT,
                       help="local workers (default: one per core)")
    sweep.add_argument("--plot", nargs="?", const=True, metavar="PNG",
                       help="draw the runnability map (default OUT/runnability_map.png)")
    sweep.add_argument("--trajectories", action="store_true",
                       help="also store each run's full result (OUT/trajectories/*.npz)")
    sweep.add_argument("--t-end", type=_POSITIVE, help="end time of each run [s]")
    sweep.add_argument("--rtol", type=_RTOL, help=f"relative tolerance of each run (0 < "
                       f"rtol <= {RTOL_MAX:g}; default: the scene's [solver] rtol)")
    sweep.add_argument("--output-step", type=_POSITIVE, help="sampling of the runs [s]")
    sweep.add_argument("--max-wall", type=_POSITIVE, help="wall-clock budget per run [s]")
    sweep.add_argument("--bands", type=_COUNT, default=24, help="radius bands (default 24)")
    sweep.add_argument("--vibration-threshold", type=_POSITIVE, default=0.5,
                       help="vibration level where vibration starts (default 0.5)")
    sweep.add_argument("--progress", action=argparse.BooleanOptionalAction, default=True,
                       help="progress bar and dashboard address on stderr (default on; "
                       "whole lines every 5 s on a log or pipe)")
    sweep.set_defaults(func=_cmd_sweep)
    _add_linearise(sub)
    _add_fit(sub)
    return parser


def _say(text: str) -> None:
    try:
        sys.stderr.write(text.rstrip("\n") + "\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # stderr closed: the exit status still tells
        pass


def _stopped(exc: Interrupted) -> str:
    """The line of a command stopped by a signal: which signal, and what is on disk."""
    from winder.io.interrupt import committed_files

    done = committed_files()
    if not done:
        return f"winder: {exc.describe()}; no partial file left"
    names = ", ".join(done[:4]) + (f" and {len(done) - 4} more" if len(done) > 4 else "")
    return f"winder: {exc.describe()} after writing {names} (complete); no partial file left"


def _command(argv: Sequence[str] | None) -> int:
    """Run one command inside the signal handling of :func:`main`; returns the status."""
    try:
        try:
            args = _build_parser().parse_args(argv)
        except _UsageError as exc:
            _say(str(exc))
            return EXIT_ERROR
        except _Exit as exc:
            return exc.status
        status = int(args.func(args) or 0)
        if argv is None:  # the process ends next: its output out before the handlers go
            sys.stdout.flush()
        return status
    except WinderError as exc:
        _say(f"winder: error: {exc}")
        return EXIT_ERROR
    except Interrupted as exc:
        _say(_stopped(exc))
        return exc.exit_status
    except KeyboardInterrupt:
        _say("winder: interrupted; no partial file left")
        return 130
    except BrokenPipeError:  # stdout closed by the reader (winder ... | head)
        if argv is None:  # keep Python's exit flush from failing on it too
            with contextlib.suppress(OSError):
                os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 128 + 13  # as if killed by SIGPIPE
    except MemoryError:
        _say("winder: error: not enough memory for this run (shorten it or sample it "
             "more coarsely)")
        return EXIT_ERROR
    except Exception:
        _say(traceback.format_exc())
        _say("winder: internal error: this is a bug in winder; please report it with "
             "the command line and the traceback above")
        return EXIT_INTERNAL


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns the exit status (see the module text). With ``argv``
    None (the ``winder`` program) the process is about to end: a signal after the command
    is ignored (the status stays)."""
    with handling_signals(exiting=argv is None):
        return _command(argv)


if __name__ == "__main__":
    sys.exit(main())
