"""DOP853 in C against DOPRI5 on the shipped cycles (issue #33; writes
docs/dop853_cycle.md and .json).

For the rigid two-drum winder (``models/two_drum_winder.toml``, 414.5 s) and the paper
cycle (``models/paper_winding.toml``, 700 s), each method (``DOPRI5``, ``DOP853C``) with
``atol = rtol/100`` (as the scenes and ``work_precision.py``), on the scene's output grid:

- **a window** (the two-drum winder's first 30 s, the smooth paper scene's first 120 s,
  ``models/paper_winding_smooth.toml``: as ``work_precision.py``), rtol 1e-4 … 1e-8.
  Error: as ``work_precision.py``, the largest deviation over the output grid scaled by
  the channel's largest magnitude, the largest over its channels, against DOP853C at rtol
  1e-10 (DOPRI5 at rtol 1e-10 gives the reference's spread). The verdict: at the error of
  DOPRI5 at rtol 1e-6 (the scenes' tolerance), DOP853C's evaluations and CPU time
  (log–log interpolation between its tolerances) relative to DOPRI5's.
- **the whole cycle**, rtol 1e-5 … 1e-7: evaluations, CPU time, events and the final
  radius' deviation from DOP853C at rtol 1e-10. The whole cycles are not well conditioned
  (thousands of contact events: the trajectories' phase drifts; DOPRI5 and DOP853C at rtol
  1e-10 end 4e-6 apart in the set's radius), so no pointwise error is compared there.

Cost: right-hand side evaluations (a count no other process disturbs) and this thread's
CPU time of the ``simulate`` call (``time.thread_time``, the build excluded by a warm-up),
one run each.

Run:  python benchmarks/dop853_cycle.py [--quick] [--scene NAME]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

import winder
from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: scene file, the window's scene file and length [s], the channels of the error
#: (``work_precision.py``'s), the radius
SCENES = {"two-drum winder": ("two_drum_winder.toml", "two_drum_winder.toml", 30.0,
                              ("set_radius", "set_speed", "set_x", "set_z",
                               "rear_nip_normal_force", "rider_nip_normal_force"),
                              "set_radius"),
          "paper cycle": ("paper_winding.toml", "paper_winding_smooth.toml", 120.0,
                          ("radius", "roll_speed", "z", "normal_force"), "radius")}
METHODS = ("DOPRI5", "DOP853C")
TOLERANCES = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
CYCLE_TOLERANCES = (1e-5, 1e-6, 1e-7)
REFERENCE = 1e-10


def run(scene: winder.Scene, method: str, rtol: float, t_end: float | None = None
        ) -> tuple[winder.Result, float]:
    """A run to ``t_end`` [s] (the whole cycle: None) and this thread's CPU time [s]."""
    c0 = time.thread_time()
    res = winder.simulate(scene, method=method, rtol=rtol, atol=rtol * 1e-2, t_end=t_end,
                          max_rhs=10**10)
    return res, time.thread_time() - c0


def error(res: winder.Result, ref: winder.Result, channels: tuple[str, ...]) -> float:
    """The largest deviation over the grid / the channel's largest magnitude, over
    ``channels``."""
    return max(float(np.max(np.abs(res[c] - ref[c])) / np.max(np.abs(ref[c])))
               for c in channels)


def at_error(rows: list[dict[str, Any]], target: float, key: str) -> float:
    """``key`` (evaluations, CPU) at error ``target``: log–log interpolation between the
    two tolerances whose errors bracket it (nan outside)."""
    pts = sorted((r["error"], r[key]) for r in rows)
    for (e0, v0), (e1, v1) in zip(pts, pts[1:], strict=False):
        if e0 <= target <= e1 and e0 > 0.0:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(v0) + w * (math.log(v1) - math.log(v0)))
    return math.nan


def study(name: str, quick: bool) -> dict[str, Any]:
    file, window_file, window, channels, radius = SCENES[name]
    scene = winder.load_scene(ROOT / "models" / file)
    wscene = winder.load_scene(ROOT / "models" / window_file)
    for m in METHODS:  # build or load the machines outside the timed runs
        run(scene, m, 1e-6, t_end=0.5)
        run(wscene, m, 1e-6, t_end=0.5)
    ref, _ = run(wscene, "DOP853C", REFERENCE, window)
    alt, _ = run(wscene, "DOPRI5", REFERENCE, window)
    out: dict[str, Any] = {"scene": file, "window_scene": window_file, "window": window,
                           "channels": channels,
                           "reference_spread": error(alt, ref, channels), "rows": [],
                           "cycle": []}
    for m in METHODS:
        for tol in TOLERANCES:
            res, cpu = run(wscene, m, tol, window)
            out["rows"].append({"method": m, "rtol": tol, "error": error(res, ref, channels),
                                "nfev": res.meta["rhs_evaluations"], "cpu": cpu,
                                "events": res.meta["events"]})
            print(name, out["rows"][-1], flush=True)
    base = next(r for r in out["rows"] if r["method"] == "DOPRI5" and r["rtol"] == 1e-6)
    d8 = [r for r in out["rows"] if r["method"] == "DOP853C"]
    out["at_dopri5_1e-6"] = {
        "error": base["error"], "dopri5_nfev": base["nfev"], "dopri5_cpu": base["cpu"],
        "dop853_nfev": at_error(d8, base["error"], "nfev"),
        "dop853_cpu": at_error(d8, base["error"], "cpu")}
    if quick:
        return out
    ref, _ = run(scene, "DOP853C", REFERENCE)
    r_end = float(ref[radius][-1])
    out["t_end"], out["radius"], out["radius_end"] = float(ref.meta["t_end"]), radius, r_end
    for m, tol in [(m, t) for m in METHODS for t in CYCLE_TOLERANCES] + [("DOPRI5", REFERENCE)]:
        res, cpu = run(scene, m, tol)
        out["cycle"].append({"method": m, "rtol": tol, "nfev": res.meta["rhs_evaluations"],
                             "cpu": cpu, "events": res.meta["events"],
                             "radius_error": abs(float(res[radius][-1]) - r_end)})
        print(name, "cycle", out["cycle"][-1], flush=True)
    return out


def report(results: list[dict[str, Any]]) -> str:
    lines = ["# DOP853 (C) against DOPRI5 on the shipped cycles", "",
             "Written by `benchmarks/dop853_cycle.py` (its docstring gives the method). "
             "Error: the largest deviation over the output grid / the channel's largest "
             f"magnitude, against DOP853C at rtol {REFERENCE:g}; CPU: this thread's, of the "
             "`simulate` call, one run each on a shared 2-core machine (the evaluation "
             "counts are exact, the CPU times ±10 %).", ""]
    for res in results:
        a = res["at_dopri5_1e-6"]
        lines += [f"## {res['window_scene']}: the first {res['window']:g} s", "",
                  f"Reference spread (DOPRI5 at rtol {REFERENCE:g}): "
                  f"{res['reference_spread']:.1e}.", "",
                  "| method | rtol | error | RHS evals | CPU [s] | events |",
                  "|---|---|---|---|---|---|"]
        for r in res["rows"]:
            lines.append(f"| {r['method']} | {r['rtol']:.0e} | {r['error']:.1e} | "
                         f"{r['nfev']:,} | {r['cpu']:.3f} | {r['events']:,} |")
        lines += ["", f"At DOPRI5's error at rtol 1e-6 ({a['error']:.1e}): DOP853C needs "
                  f"{a['dop853_nfev'] / a['dopri5_nfev']:.2f} of DOPRI5's evaluations "
                  f"({a['dop853_nfev']:,.0f} against {a['dopri5_nfev']:,}) and "
                  f"{a['dop853_cpu'] / a['dopri5_cpu']:.2f} of its CPU time "
                  f"({a['dop853_cpu']:.3f} s against {a['dopri5_cpu']:.3f} s; interpolated "
                  "between DOP853C's tolerances).", ""]
        if res["cycle"]:
            lines += [f"## {res['scene']}: the whole cycle ({res['t_end']:g} s)", "",
                      f"Final {res['radius']} of DOP853C at rtol {REFERENCE:g}: "
                      f"{res['radius_end']:.9f} m.", "",
                      f"| method | rtol | RHS evals | CPU [s] | events | final "
                      f"{res['radius']} − reference [m] |", "|---|---|---|---|---|---|"]
            for r in res["cycle"]:
                lines.append(f"| {r['method']} | {r['rtol']:.0e} | {r['nfev']:,} | "
                             f"{r['cpu']:.2f} | {r['events']:,} | {r['radius_error']:.1e} |")
            lines.append("")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the windows only (no docs written)")
    ap.add_argument("--scene", choices=sorted(SCENES), action="append",
                    help="only this scene (repeatable)")
    args = ap.parse_args()
    results = [study(name, args.quick) for name in (args.scene or SCENES)]
    text = report(results)
    print(text)
    if not args.quick:
        atomic_write(DOCS / "dop853_cycle.md", lambda p: p.write_text(text + "\n"))
        js = json.dumps(results, indent=1) + "\n"
        atomic_write(DOCS / "dop853_cycle.json", lambda p: p.write_text(js))


if __name__ == "__main__":
    main()
