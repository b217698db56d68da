"""Command-line interface: ``winder run|view|bench|fmu|modes`` (also ``python -m winder``)."""

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
                      atol=args.atol, progress=progress)
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


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="winder", description="Paper winder simulation.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="simulate a scene file and write its result channels")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", required=True, help="result file (.csv or .npz)")
    run.add_argument("--t-end", type=_positive, help="end time [s] (default: scene duration)")
    run.add_argument("--method", help="integrator (auto, RK45, DOP853, Radau, BDF, LSODA, "
                     "RK23, RK4)")
    run.add_argument("--rtol", type=_positive)
    run.add_argument("--atol", type=_positive)
    run.add_argument("--plots", help="directory for the paper's figures (PNG)")
    run.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                     help="progress bar on stderr (default: when stderr is a terminal)")
    run.set_defaults(func=_cmd_run)
    for register in _EXTRA:
        register(sub)
    return parser


#: Further sub-commands register themselves here: ``f(subparsers)``.
_EXTRA: list = []


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
