"""``winder modes``: a scene's resonance map (or its web line's modes against the unwinding
roll's radius), its summary, table and figure."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable

__all__ = ["cmd_modes"]


def cmd_modes(args: argparse.Namespace, tell: Callable[[str], None]) -> int:
    """``winder modes``: the map, its summary, the CSV and the figure; ``tell`` says what a
    long step is doing (on a terminal)."""
    from winder.io.files import check_output_file

    csv = check_output_file(args.csv, "--csv", suffixes=(".csv",)) \
        if args.csv is not None else None
    plot = check_output_file(args.plot, "--plot", suffixes=(".png",)) \
        if args.plot is not None else None

    from winder.scene.load import load_scene

    scene = load_scene(args.scene)
    from winder.analysis.modes import mode_map
    from winder.io.files import atomic_write, csv_writer

    bar: list = []  # on a terminal: a bar over the map's radii (a flexible machine's take a minute)

    def progress(done: int, total: int) -> None:
        if not bar:
            from winder.io.progress import CountProgress

            bar.append(CountProgress(total, f"{scene.name} modes", units="radii"))
        if done:
            bar[0].update()

    try:
        mm = mode_map(scene, web_speed=args.web_speed, n=args.points,
                      radius_min=args.radius_min, radius_max=args.radius_max, roll=args.roll,
                      progress=progress if sys.stderr.isatty() else None,
                      _names=("--radius-min", "--radius-max"))
    finally:
        for b in bar:
            b.close()
    if mm.initial_state:  # no wound roll, or contact off: one row
        where = "" if math.isnan(mm.radius[0]) else \
            f", the wound roll at r = {mm.radius[0]:.3f} m"
        print(f"{scene.name}: modes at the initial state ({mm.initial_reason}: no map over "
              f"a wound roll's radius{where})")
    elif mm.unwinding:
        print(f"{scene.name}: the web line's modes at {len(mm.radius)} radii of the "
              f"unwinding roll {mm.roll!r}, {mm.radius[0]:.3f}-{mm.radius[-1]:.3f} m, web "
              f"speed {mm.web_speed:g} m/s")
    else:
        print(f"{scene.name}: modes at {len(mm.radius)} radii, {mm.radius[0]:.3f}-"
              f"{mm.radius[-1]:.3f} m, web speed {mm.web_speed:g} m/s")
    for line in mm.summary():
        print(f"  {line}")
    if csv is not None:
        atomic_write(csv, csv_writer(mm.as_columns(), fmt="%.10g"))
        print(f"  table written to {csv}")
    if plot is not None:
        tell(f"  drawing the resonance map into {plot} ...")
        from winder.plots.campbell import campbell_figure
        from winder.plots.figures import nip_colours
        from winder.solve.simulate import simulate

        result = None
        if args.simulate and mm.unwinding:
            print("  (the normal-force envelope follows the wound roll's radius: not "
                  "simulated for a map over the unwinding roll's)", file=sys.stderr)
        elif args.simulate and mm.initial_state:
            print("  (the normal-force envelope needs a map over a wound roll's radius: not "
                  "simulated)", file=sys.stderr)
        elif args.simulate:
            print("  simulating the scene for the normal-force envelope ...", file=sys.stderr)
            result = simulate(scene, progress=sys.stderr.isatty())
        out = scene.naming.output_name  # the result's channels as the scene names them
        nips = {n.name: (out(f"{n.name}_normal_force"), out(f"{mm.roll}_radius"))
                for n in scene.nips if mm.roll in (n.a, n.b)}
        title = f"Line modes of {scene.name} against the parent's radius" \
            if mm.unwinding else f"Resonance map of {scene.name}"
        path = campbell_figure(mm, plot, result=result, envelopes=nips or None, title=title,
                               colours=nip_colours(scene))
        print(f"  figure written to {path}")
    return 0
