"""``winder linearise``: the linear plant of a scene at a radius of its wound roll
(:func:`winder.linearise`), written for MATLAB (``.mat``) or NumPy (``.npz``), its poles
printed with their damping."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from typing import Any

from winder._errors import ArgumentError, WinderError

__all__ = ["add_parser", "cmd_linearise"]

#: The API's argument names in messages → the command's options.
_OPTIONS = {"radius": "--radius", "web_speed": "--web-speed", "inputs": "--input",
            "outputs": "--output"}


def add_parser(sub: Any, positive: Callable[[str], Any]) -> None:
    """Add ``winder linearise`` to the subcommands ``sub`` (``positive``: the option type
    of a finite number > 0)."""
    p = sub.add_parser("linearise", help="the linear plant (A, B, C, D) at a radius of the "
                       "wound roll, for control design (.mat for MATLAB, or .npz)")
    p.add_argument("scene", help="scene file (TOML)")
    p.add_argument("--radius", type=positive, required=True, metavar="R",
                   help="radius of the wound roll [m] (>= its core radius)")
    p.add_argument("--web-speed", type=positive, metavar="V",
                   help="operating web speed [m/s] (default: the scene's)")
    p.add_argument("--input", action="append", metavar="NAME",
                   help="an input (repeat; default all): ROLL_torque (an unwind's), "
                   "ROLL_tension_setpoint, DRUM_web_speed")
    p.add_argument("--output", action="append", metavar="NAME",
                   help="an output: a result channel (repeat; default all)")
    p.add_argument("--out", metavar="FILE", help="write the plant (.mat: MATLAB, scipy's "
                   "savemat; .npz: NumPy): A, B, C, D, names, units, poles, operating point")
    p.set_defaults(func=cmd_linearise)


def _option_text(message: str) -> str:
    """An API message with its argument names as the command's options."""
    text = message.removeprefix("linearise: ")
    return re.sub(r"^(\w+)", lambda m: _OPTIONS.get(m.group(1), m.group(1)), text)


def cmd_linearise(args: argparse.Namespace) -> int:
    """Linearise, print the poles with their damping, write ``--out``."""
    from winder.analysis.plant import PLANT_SUFFIXES, poles_with_damping, save_plant
    from winder.io.files import check_output_file
    from winder.scene.load import load_scene

    out = check_output_file(args.out, "--out", suffixes=PLANT_SUFFIXES) \
        if args.out is not None else None
    scene = load_scene(args.scene)
    from winder.analysis.plant import linearise

    try:
        plant = linearise(scene, args.radius, web_speed=args.web_speed, inputs=args.input,
                          outputs=args.output)
    except ArgumentError as exc:
        raise WinderError(_option_text(str(exc))) from None
    op = plant.operating_point
    print(f"{scene.name}: linear plant at r = {op['radius']:g} m, web speed "
          f"{op['web_speed']:g} m/s: {plant.nstates} states, {plant.ninputs} inputs "
          f"({', '.join(plant.input_labels) or 'none'}), {plant.noutputs} outputs")
    print(f"  states: {', '.join(f'{n} [{plant.units[n]}]' for n in plant.state_labels)}")
    print("  poles (one of each pair):      natural frequency   damping ratio")
    for pole, fn, zeta in poles_with_damping(plant):
        text = f"{pole.real:.6g}" + (f" ± {pole.imag:.6g}j" if pole.imag > 0 else "")
        print(f"  {text:<30s} {fn:>10.4g} Hz   {zeta:>10.4f}")
    if out is not None:
        print(f"  plant written to {save_plant(plant, out)}")
    return 0
