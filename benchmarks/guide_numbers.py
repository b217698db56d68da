"""The numbers of the user guide's web-line page (docs/guide/idlers-dancers-spans.md) from
the computations of its tests and example, written to ``docs/guide_numbers.json`` (raw,
SI units), from which ``benchmarks/doc_numbers.py`` fills the page's blocks.

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
  ``dancer_control`` and under the brake of ``tests/test_line_modes.py``.

About a minute (the machines' builds cached). A slow test
(``tests/test_doc_numbers.py``) compares the file with a fresh run.

Run:  python benchmarks/guide_numbers.py [--json docs/guide_numbers.json]
"""

from __future__ import annotations

import argparse
import importlib
import math
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


def guide_numbers() -> dict:
    return {"generated_by": "benchmarks/guide_numbers.py",
            "tension_span": tension_span_values(), "dancer_control": dancer_values(),
            "line_modes": line_mode_values()}


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
