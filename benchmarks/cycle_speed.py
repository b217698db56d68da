"""Whole-cycle wall times per method (writes docs/cycle_speed.md and .json).

- ``paper``: the 700 s paper cycle (``models/paper_winding.toml`` and
  ``paper_winding_smooth.toml``) with the compiled DOPRI5 at rtol 1e-6 — against the old
  engine's 0.50 s (the hand-written planar kernel, quiet machine).
- ``two_drum``: the two-drum winder's full cycle (``models/two_drum_winder.toml``,
  414.5 s) at rtol 1e-6 with the compiled DOPRI5 and ROS2 and scipy's Radau, BDF and LSODA
  on the exact generated Jacobian.
- ``stiff``: the paper scene with nip stiffness 1e12 N/m (the hard case the old engine
  took ~28 min for with LSODA on the Pinocchio backend) with the implicit methods on the
  exact Jacobian: ROS2, Radau, BDF, LSODA; each attempt capped at ``max_wall``.

Integration wall time is ``result.meta["wall_time"]`` (the integrator alone, after a warm-up
run that compiles and links the machine's library); best of N where a run is short.

Run:  python benchmarks/cycle_speed.py [paper] [two_drum] [stiff] [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import time
from pathlib import Path
from typing import Any

import winder
from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
DOCS = ROOT / "docs"
OLD_ENGINE_PAPER = 0.50  # [s] the old engine's 700 s paper cycle, DOPRI5 rtol 1e-6, quiet
OLD_ENGINE_STIFF = "about 28 min (LSODA, Pinocchio backend, finite-difference Jacobian)"
IMPLICIT = ("Radau", "BDF", "LSODA")
#: No evaluation budget: each attempt is capped by its wall clock alone (the step-wise
#: paths' default budget would stop them first).
MAX_RHS = 10**12


def run(scene: winder.Scene, method: str, *, repeats: int, max_wall: float,
        **kw: Any) -> dict[str, Any]:
    """Best of ``repeats`` runs (stops repeating once a run takes over 20 s)."""
    best: dict[str, Any] | None = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            res = winder.simulate(scene, method=method, rtol=1e-6, max_wall=max_wall,
                                  max_rhs=MAX_RHS, **kw)
        except winder.SimulationError as exc:
            msg = str(exc)
            need = re.search(r"needs about ([0-9.e+]+) evaluations and ([0-9.e+]+) s", msg)
            return {"method": method, "status": "wall limit" if "max_wall" in msg else "failed",
                    "message": msg[:400], "elapsed": time.perf_counter() - t0,
                    "reached": getattr(exc, "time", None),
                    "projected": float(need.group(2)) if need else None}
        row = {"method": method, "status": "ok", "wall": res.meta["wall_time"],
               "total": time.perf_counter() - t0, "cpu": time.process_time() - c0,
               "nfev": res.meta["rhs_evaluations"],
               "events": res.meta["events"], "samples": len(res.t)}
        if best is None or row["wall"] < best["wall"]:
            best = row
        if row["wall"] > 20.0:
            break
    assert best is not None
    return best


def warm(scene: winder.Scene) -> None:
    """Compile and link the machine's library, and run every method once, before timing."""
    for m in ("DOPRI5", "ROS2"):
        winder.simulate(scene, t_end=0.05, method=m, output_step=0.01)


def paper(quick: bool) -> list[dict[str, Any]]:
    rows = []
    for name in ("paper_winding", "paper_winding_smooth"):
        scene = winder.load_scene(MODELS / f"{name}.toml")
        warm(scene)
        for m in ("DOPRI5", "ROS2"):
            r = run(scene, m, repeats=2 if quick else 5, max_wall=120.0)
            r["scene"] = name
            rows.append(r)
            print(f"{name} {m}: {r.get('wall', float('nan')):.3f} s", file=sys.stderr,
                  flush=True)
    return rows


def two_drum(quick: bool) -> list[dict[str, Any]]:
    scene = winder.load_scene(MODELS / "two_drum_winder.toml")
    warm(scene)
    rows = []
    for m in ("DOPRI5", "ROS2", *IMPLICIT):
        r = run(scene, m, repeats=1 if quick or m in IMPLICIT else 3,
                max_wall=60.0 if quick or m in IMPLICIT else 300.0, jacobian="exact")
        r["scene"] = "two_drum_winder"
        rows.append(r)
        print(f"two_drum {m}: {r['status']} {r.get('wall', float('nan')):.3f} s",
              file=sys.stderr, flush=True)
    return rows


def stiff(quick: bool) -> list[dict[str, Any]]:
    scene = winder.load_scene(MODELS / "paper_winding.toml").replace(
        contact={"stiffness": 1e12})
    warm(scene)
    rows = []
    for m in ("ROS2", *IMPLICIT):
        r = run(scene, m, repeats=1, max_wall=60.0 if quick else 300.0, jacobian="exact")
        r["scene"] = "paper_winding, nip stiffness 1e12 N/m"
        rows.append(r)
        print(f"stiff {m}: {r['status']} {r.get('wall', r.get('elapsed')):.3f} s",
              file=sys.stderr, flush=True)
    return rows


SECTIONS = {"paper": paper, "two_drum": two_drum, "stiff": stiff}


def write_docs(data: dict[str, Any]) -> None:
    lines = ["# Whole cycles: wall time per method", "",
             "Regenerate with `python benchmarks/cycle_speed.py` (each section can be run "
             "alone: `paper`, `two_drum`, `stiff`). rtol 1e-6, atol 1e-8 (the scenes' "
             "`[solver]`), output grids of the scenes. *wall*: `result.meta[\"wall_time\"]`, the "
             "integration alone, after a warm-up that compiled the machine's library"
             "; *total*: the `simulate()` call with the static balance and the output "
             "channels; *CPU*: the process time of that call (what the process itself got "
             "of a core: on a loaded machine closer to a quiet machine's wall time than the "
             "wall time is). Shared 2-core machine: the load average at the start of each "
             "section is given; short runs are the best of several.", ""]
    titles = {"paper": "The 700 s paper cycle",
              "two_drum": "The two-drum winder, full cycle (414.5 s; target < 2 s)",
              "stiff": "Stiff hard case: paper scene with nip stiffness 1e12 N/m (700 s)"}
    notes = {"paper": f"Old engine (hand-written planar kernel, DOPRI5): {OLD_ENGINE_PAPER:.2f} s "
                      "integration on a quiet machine.",
             "two_drum": "Radau, BDF, LSODA: scipy on the generated right-hand side and the "
                         "exact generated Jacobian (`jacobian=\"exact\"`), capped at "
                         "`max_wall = 60 s` (the projection to the end is the budget "
                         "error's own).",
             "stiff": f"Old engine: {OLD_ENGINE_STIFF}. Each attempt is capped at "
                      "`max_wall = 300 s`; scipy's methods with `jacobian=\"exact\"`."}
    for key, sec in data["sections"].items():
        lines += [f"## {titles[key]}", "", notes[key],
                  f"Load average at the start: {sec['load'][0]:.1f} "
                  f"(1 min), {sec['load'][1]:.1f} (5 min).", "",
                  "| scene | method | status | wall [s] | total [s] | CPU [s] | evaluations | "
                  "events | µs per evaluation (wall) |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for r in sec["rows"]:
            if r["status"] != "ok":
                at = re.search(r"at t = ([0-9.e+-]+) s", r["message"])
                reached = r.get("reached") or (float(at.group(1)) if at else None)
                where = f" at t = {reached:.4g} s" if reached is not None else ""
                proj = (f"; ~{r['projected']:.3g} s to finish at that rate"
                        if r.get("projected") else "")
                lines.append(f"| {r['scene']} | {r['method']} | {r['status']} after "
                             f"{r['elapsed']:.0f} s{where}{proj} | | | | | | |")
                continue
            cpu = f"{r['cpu']:.3f}" if "cpu" in r else "–"
            lines.append(f"| {r['scene']} | {r['method']} | ok | {r['wall']:.3f} | "
                         f"{r['total']:.3f} | {cpu} | {r['nfev']:,} | {r['events']} | "
                         f"{1e6 * r['wall'] / r['nfev']:.3f} |")
        lines.append("")
    text = "\n".join(lines)
    atomic_write(DOCS / "cycle_speed.md", lambda tmp: tmp.write_text(text, encoding="utf-8"))


def main(sections: list[str], quick: bool) -> dict[str, Any]:
    path = DOCS / "cycle_speed.json"
    data: dict[str, Any] = {"sections": {}}
    if path.exists():  # sections not re-run keep their last numbers
        data = json.loads(path.read_text(encoding="utf-8"))
    for key in sections:
        load = os.getloadavg()
        data["sections"][key] = {"load": load, "rows": SECTIONS[key](quick)}
    data["sections"] = {k: data["sections"][k] for k in SECTIONS if k in data["sections"]}
    js = json.dumps(data, indent=1)
    atomic_write(path, lambda tmp: tmp.write_text(js, encoding="utf-8"))
    write_docs(data)
    return data


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("sections", nargs="*", help=f"any of {', '.join(SECTIONS)} (default: all)")
    ap.add_argument("--quick", action="store_true", help="fewer repeats, 60 s caps")
    a = ap.parse_args()
    bad = [s for s in a.sections if s not in SECTIONS]
    if bad:
        ap.error(f"unknown section(s) {', '.join(bad)}; valid: {', '.join(SECTIONS)}")
    main(a.sections or list(SECTIONS), a.quick)
