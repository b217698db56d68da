"""``winder fit``: calibrate scene keys to a mill's measurements (:func:`winder.fit`),
progress on stderr, the estimates with their intervals printed as a table, ``FIT.json``
(and the figure, the fitted scene) written together: all or none."""

from __future__ import annotations

import argparse
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from winder._errors import ArgumentError, WinderError

__all__ = ["add_parser", "cmd_fit"]

#: The API's argument names in messages → the command's options.
_OPTIONS = {"params": "--param", "channels": "--channel", "sigma": "--channel NAME:STD",
            "data": "--data", "t_start": "--t-start", "t_end": "--t-end", "rtol": "--rtol",
            "t_start, t_end": "--t-start, --t-end"}


def _time(text: str) -> float:
    """An argparse type: a time [s], finite and >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number; valid: a finite time "
                                         ">= 0 s") from None
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"{text!r} is out of range; valid: a finite time "
                                         ">= 0 s")
    return value


def add_parser(sub: Any, positive: Callable[[str], Any], rtol: Callable[[str], Any]) -> None:
    """Add ``winder fit`` to the subcommands ``sub`` (``positive``: the option type of a
    finite number > 0; ``rtol``: of a relative tolerance)."""
    p = sub.add_parser("fit", help="calibrate scene keys (nip stiffness, damping, ...) to "
                       "measured channels by least squares on exact sensitivities")
    p.add_argument("scene", help="scene file (TOML); its values are the first guesses")
    p.add_argument("--data", required=True, metavar="FILE",
                   help="the measurements: CSV (header t,NAME [unit],...), NPZ or Parquet; "
                   "columns t [s] and result channels in their units")
    p.add_argument("--param", action="append", required=True, metavar="KEY[=LO:HI]",
                   help="a scene key path to fit (repeat), as in winder sweep, e.g. "
                   "contact.stiffness=1e6:1e9 or nip.front_nip.contact.damping")
    p.add_argument("--channel", action="append", metavar="NAME[:STD]",
                   help="a channel to fit (repeat; default every data column), with its "
                   "measurement noise STD in its unit (default: estimated)")
    p.add_argument("--t-start", type=_time, metavar="T", help="start of the window [s]")
    p.add_argument("--t-end", type=_time, metavar="T", help="end of the window [s]")
    p.add_argument("--rtol", type=rtol, help="the integrator's relative tolerance "
                   "(default 1e-8)")
    p.add_argument("--out", required=True, metavar="FIT.json",
                   help="write the estimates, intervals, correlation, residuals and "
                   "identifiability (JSON)")
    p.add_argument("--plot", metavar="FIT.png", help="write measured against fitted "
                   "channels and the residuals")
    p.add_argument("--scene-out", metavar="FITTED.toml", help="write the scene with the "
                   "estimates")
    p.set_defaults(func=cmd_fit)


def _option_text(message: str) -> str:
    """An API message with its argument names as the command's options."""
    text = message.removeprefix("fit: ")
    for name in sorted(_OPTIONS, key=len, reverse=True):
        if text.startswith(name + ":") or text.startswith(name + " "):
            return _OPTIONS[name] + text[len(name):]
    return re.sub(r"^data \(", "--data (", text)


def _channels(items: list[str] | None) -> tuple[list[str] | None, dict[str, float] | None]:
    if not items:
        return None, None
    names, sigma = [], {}
    for item in items:
        name, sep, std = item.partition(":")
        name = name.strip()
        if not name:
            raise ArgumentError(f"--channel {item!r}: expected NAME or NAME:STD")
        names.append(name)
        if sep:
            try:
                value = float(std)
            except ValueError:
                raise ArgumentError(f"--channel {item!r}: STD {std!r} is not a number") \
                    from None
            if not (value > 0 and value < float("inf")):
                raise ArgumentError(f"--channel {item!r}: STD must be finite and > 0")
            sigma[name] = value
    return names, sigma or None


def cmd_fit(args: argparse.Namespace) -> int:
    """Fit, print the table, write ``--out`` (``--plot``, ``--scene-out``) together."""
    from winder.analysis.fit import fit
    from winder.io.files import atomic_write_all, check_output_file
    from winder.scene.load import load_scene
    from winder.scene.write import scene_toml

    out = check_output_file(args.out, "--out", suffixes=(".json",))
    plot = check_output_file(args.plot, "--plot", suffixes=(".png", ".pdf", ".svg")) \
        if args.plot else None
    scene_out = check_output_file(args.scene_out, "--scene-out", suffixes=(".toml",)) \
        if args.scene_out else None
    targets = [p for p in (out, plot, scene_out) if p is not None]
    if len({p.resolve() for p in targets}) != len(targets):
        raise WinderError("--out, --plot, --scene-out: give each file once")
    scene = load_scene(args.scene)
    channels, sigma = _channels(args.channel)

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    try:
        res = fit(scene, args.data, list(args.param), channels=channels, sigma=sigma,
                  t_start=args.t_start, t_end=args.t_end, rtol=args.rtol, progress=say)
    except ArgumentError as exc:
        raise WinderError(_option_text(str(exc))) from None
    print(f"{scene.name}: fit of {len(res.keys)} parameters to {len(res.channels)} "
          f"channels ({', '.join(res.channels)}), {len(res.t)} samples from "
          f"{res.t[0]:g} to {res.t[-1]:g} s, {res.wall_time:.1f} s")
    print(res.table())
    for c in res.channels:
        how = "estimated" if res.sigma_estimated[c] else "given"
        print(f"  {c}: sigma {res.sigma[c]:.4g} {res.channel_units[c]} ({how}), rms "
              f"residual {res.rms_residuals[c]:.4g}")
    import json

    text = json.dumps(res.to_dict(), indent=2, allow_nan=False) + "\n"
    items: list[tuple[Path, Any]] = [(out, lambda tmp: Path(tmp).write_text(text,
                                                                            encoding="utf-8"))]
    if plot is not None:
        fig = res.plot()
        items.append((plot, lambda tmp: fig.savefig(tmp, format=plot.suffix.lstrip("."),
                                                    dpi=110)))
    if scene_out is not None:
        toml = f"# {scene.name} fitted by winder fit to {args.data}\n" + \
            scene_toml(res.fitted_scene())
        items.append((scene_out, lambda tmp: Path(tmp).write_text(toml, encoding="utf-8")))
    for p in atomic_write_all(items):
        print(f"  written {p}")
    return 0
