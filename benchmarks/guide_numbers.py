"""The numbers of the user guide's web-line page (docs/guide/idlers-dancers-spans.md) and
of docs/control.md from the computations of their tests and examples, written to
``docs/guide_numbers.json`` (raw, SI units), from which ``benchmarks/doc_numbers.py``
fills the pages' blocks.

- ``tension_span``: the unwind holding span 1 behind a guide roller
  (``tests/test_tension_span.py``'s ``span_loop``: the linearised machine's closed-loop
  poles nearest ``−ω_c``, the loop's margins broken at the torque) at a full and an empty
  parent, 5 m/s and the scene's web speed; its 10 N set-point step's settling time
  (``span_step``);
- ``dancer_control``: the shipped dancer line's loop margins
  (``examples/dancer_loop_margins.py``'s ``margins``) and the dancer error's decay rate
  from 20 mm out (``tests/test_idler_line.py``'s ``dancer_decay``);
- ``line_modes``: the shipped dancer line's mode map over the parent's radius
  (:func:`winder.mode_map`, ``roll="parent"``) at a full and an empty parent, under
  ``dancer_control`` and under the brake of ``tests/test_line_modes.py``;

and of docs/control.md: ``casadi_model``'s build times, ``tension_mpc``: the MPC example's
closed loops (``examples/tension_mpc.py``'s ``run``, three of them: a minute or two).

A few minutes (the machines' builds cached). A slow test
(``tests/test_doc_numbers.py``) compares the file with a fresh run.

Run:  python benchmarks/guide_numbers.py [--json docs/guide_numbers.json]
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
JSON = ROOT / "docs" / "guide_numbers.json"

#: The tension_control loop's cases: label -> (parent radius [m], web speed [m/s] or None:
#: the scene's).
SPAN_CASES = {"full_5": (1.25, 5.0), "empty_5": (0.45, 5.0), "full": (1.25, None),
              "empty": (0.45, None)}
PARENTS = {"full": 1.25, "empty": 0.45}  #: the parent's radii of the tables [m]


def _module(folder: str, name: str):  # noqa: ANN202 - the module
    """A test's or an example's module (tests/ on the path: the tests import each other)."""
    for p in (ROOT / "tests", ROOT / folder):
        if str(p) not in sys.path:
            sys.path.insert(0, str(p))
    return importlib.import_module(name)


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def tension_span_values() -> dict:
    """Per case the parent's radius [m], J [kg·m²], web speed [m/s] (None: the scene's),
    the three closed-loop poles nearest ``−ω_c`` ([re, im], rad/s), the phase margin [°]
    at its crossover [rad/s], the gain margin [-] at its frequency [rad/s] (None: the
    phase never reaches −180°); and the step's settling times [s] (the run, the design)."""
    ts = _module("tests", "test_tension_span")
    out: dict = {"bandwidth": ts.WC, "cases": {}}
    for label, (r, v) in SPAN_CASES.items():
        loop = ts.span_loop(r, v)
        near = sorted(np.asarray(loop["closed"]), key=lambda s: abs(s + ts.WC))[:3]
        near = sorted((p for p in near if p.imag >= 0.0), key=lambda p: (p.imag, p.real))
        out["cases"][label] = {
            "radius": r, "web_speed": v, "inertia": float(loop["J"]),
            "poles": [[float(p.real), float(p.imag)] for p in near],
            "phase_margin": float(loop["pm"]), "crossover": float(loop["crossover"]),
            "gain_margin": _finite(loop["gm"]),
            "gain_crossover": _finite(loop["w_gm"]) if np.isfinite(loop["gm"]) else None}
    step = ts.span_step()
    out["step"] = {"settled": step["settled"], "settled_design": step["settled_ref"]}
    return out


def dancer_values() -> dict:
    """The shipped dancer loop's margins per parent (gain margin [-] at its frequency
    [rad/s], phase margin [°] at its crossover [rad/s], J [kg·m²]) and the dancer
    error's decay rate [1/s] from 20 mm out at ω_c = 5 rad/s."""
    import winder
    from winder.model.paper_roll import paper_roll_mass

    ex = _module("examples", "dancer_loop_margins")
    parent = next(r for r in winder.load_scene(ex.MODEL).rolls if r.name == "parent")
    out: dict = {"parents": {}}
    for label, r in PARENTS.items():
        gm, pm, w_gm, w_pm = ex.margins(r)
        _, J, _, _ = paper_roll_mass(r, parent.core_radius, parent.core_mass,
                                     parent.core_inertia,
                                     math.pi * parent.density * parent.width)
        out["parents"][label] = {"radius": r, "inertia": float(J), "gain_margin": gm,
                                 "gain_crossover": w_gm, "phase_margin": pm,
                                 "crossover": w_pm}
    _, rate = _module("tests", "test_idler_line").dancer_decay(0.02, 5.0)
    out["decay"] = {"offset": 0.02, "bandwidth": 5.0, "rate": rate}
    return out


def line_mode_values() -> dict:
    """The shipped dancer line's line modes (frequency [Hz], damping ratio) at the full
    and the empty parent, under ``dancer_control`` and under the tests' brake
    (``drive = { kind = "torque", torque = -1000.0 }``)."""
    import winder

    tl = _module("tests", "test_line_modes")
    radii = np.array([PARENTS["empty"], PARENTS["full"]])
    out: dict = {}
    for label, brake in (("dancer_control", False), ("brake", True)):
        _, scene = tl._shipped(brake)
        mm = winder.mode_map(scene, radii, roll="parent")
        out[label] = {c: {p: [float(mm.line[c][i]), float(mm.line_damping[c][i])]
                          for i, p in enumerate(("empty", "full"))}
                      for c in mm.line_shown}
    return out


def mpc_values() -> dict:
    """``examples/tension_mpc.py``'s closed loops over the whole ramp (23 s): with the
    default move scale (300 N·m) the largest and rms tension errors [N] of the MPC and the
    built-in controller over the ramp and at its end, the built-in torque's fall where the
    ramp ends [N·m] (±0.05 s), the MPC steps and their wall time [s]; with move scales 10
    and 1000 N·m the MPC's largest error at the ramp's end [N]."""
    ex = _module("examples", "tension_mpc")
    out: dict = {"move_scales": {}}
    for scale in (300.0, 10.0, 1000.0):
        r = ex.run(23.0, 0.01, 20, scale)
        ramp, end = ex.windows(r["t"], 23.0).values()
        out["move_scales"][f"{scale:g}"] = {"end_max": float(np.max(np.abs(r["err_mpc"][end])))}
        if scale != 300.0:
            continue
        ref = r["ref"]
        drop = (np.interp(ex.RAMP_END - 0.05, ref.t, ref["parent_torque"])
                - np.interp(ex.RAMP_END + 0.05, ref.t, ref["parent_torque"]))
        out.update({
            "ramp_end": ex.RAMP_END, "torque_drop": float(drop), "steps": r["steps"],
            "loop_wall_time": r["t_loop"], "loop_cpu_time": r["cpu_loop"],
            "load_average": os.getloadavg()[0],
            **{f"{who}_{where}_{what}": float(f(r[key][w]))
               for who, key in (("mpc", "err_mpc"), ("builtin", "err_ref"))
               for where, w in (("ramp", ramp), ("end", end))
               for what, f in (("max", lambda e: np.max(np.abs(e))),
                               ("rms", lambda e: np.sqrt(np.mean(e ** 2))))}})
    return out


def casadi_build_values() -> dict:
    """The CPU and wall times [s] of ``winder.casadi_model`` on the winder line in a fresh
    process: the first call (the machine's compiled code from the disk cache, the CasADi
    expressions built) and a second one (the machine cached in the process); the load
    average."""
    import json
    import subprocess

    import winder

    code = ("import json, time, winder\n"
            "m = 'models/winder_line.toml'\n"
            "t = []\n"
            "for _ in range(2):\n"
            "    t0, c0 = time.perf_counter(), time.process_time(); winder.casadi_model(m)\n"
            "    t += [time.perf_counter() - t0, time.process_time() - c0]\n"
            "print(json.dumps(t))\n")
    winder.casadi_model(ROOT / "models" / "winder_line.toml")  # its code built and cached
    res = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, check=True)
    first, first_cpu, again, again_cpu = json.loads(res.stdout.strip().splitlines()[-1])
    return {"first_wall_time": first, "cached_wall_time": again, "first_cpu_time": first_cpu,
            "cached_cpu_time": again_cpu, "load_average": os.getloadavg()[0]}


def guide_numbers() -> dict:
    return {"generated_by": "benchmarks/guide_numbers.py",
            "tension_span": tension_span_values(), "dancer_control": dancer_values(),
            "line_modes": line_mode_values(), "casadi_model": casadi_build_values(),
            "tension_mpc": mpc_values()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, default=JSON,
                    help="where to write (default docs/guide_numbers.json)")
    args = ap.parse_args(argv)
    rn = _module("benchmarks", "readme_numbers")
    rn.write_json(guide_numbers(), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
