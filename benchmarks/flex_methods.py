"""The integrators on the flexible two-drum winder against the rigid one (issue #33; writes
docs/flex_methods.md, .json and .png; run from ``benchmarks/flex_cycle.py --methods``).

1. **Cycle window, side by side**: the rigid machine (DOPRI5, its fastest) and the
   flexible one with each method over the first ``window`` seconds of the cycle at rtol
   1e-6, in one process, one after the other: CPU time of the integration
   (``time.thread_time``, which other processes do not disturb), wall time, evaluations,
   and the set's radius at the end of the window.
2. **Work–precision** per method: the flexible machine's first 0.5 s and the rigid
   machine's first 30 s, rtol 1e-3 … 1e-8 (``atol = rtol/100``), error = the largest
   deviation over the output grid of each channel scaled by its largest magnitude (the
   largest over the channels), against DOPRI5 at rtol 1e-11.
3. The rigid two-drum and paper cycles, whole, per method (events at scale).
4. What ``method="auto"`` picks for every shipped scene, and its probe's numbers.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

import numpy as np

import winder
from winder.io.files import atomic_write_all

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
METHODS = ("DOPRI5", "RODAS4", "RODAS3", "ROS34PW2")
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
CHANNELS = ("set_radius", "set_speed", "set_x", "set_z", "front_nip_normal_force",
            "rear_nip_normal_force", "rider_nip_normal_force")
PROBLEMS = {"flexible": ("two_drum_winder_flexible", 0.5, 0.005),
            "rigid": ("two_drum_winder", 30.0, 0.01)}


def _timed(scene: winder.Scene, **kw: Any) -> tuple[winder.Result, float]:
    c0 = time.thread_time()
    res = winder.simulate(scene, **kw)
    return res, time.thread_time() - c0


def side_by_side(window: float, methods: tuple[str, ...] = METHODS) -> dict[str, Any]:
    rigid = winder.load_scene(ROOT / "models" / "two_drum_winder.toml")
    flex = winder.load_scene(ROOT / "models" / "two_drum_winder_flexible.toml")
    out: dict[str, Any] = {"window": window, "rtol": 1e-6, "runs": []}
    for label, scene, meths in (("rigid", rigid, ("DOPRI5",)), ("flexible", flex, methods)):
        winder.simulate(scene, t_end=1e-3)  # build and balance outside the timing
        for m in meths:
            res, cpu = _timed(scene, t_end=window, rtol=1e-6, output_step=0.25, method=m)
            out["runs"].append({"machine": label, "method": m, "cpu": cpu,
                                "wall": res.meta["wall_time"],
                                "rhs": int(res.meta["rhs_evaluations"]),
                                "events": int(res.meta["events"]),
                                "set_radius": float(res["set_radius"][-1])})
            print(out["runs"][-1], flush=True)
    return out


def rigid_cycles(methods: tuple[str, ...] = ("DOPRI5", "RODAS4", "ROS34PW2")
                 ) -> list[dict[str, Any]]:
    """The rigid machines' whole cycles per method (rtol 1e-6): the located events at
    scale (11 943 on the two-drum cycle, 3 025 on the paper cycle with DOPRI5)."""
    rows = []
    for model, ch in (("two_drum_winder", "set_radius"), ("paper_winding", "radius")):
        scene = winder.load_scene(ROOT / "models" / f"{model}.toml")
        winder.simulate(scene, t_end=1e-3)
        for m in methods:
            res, cpu = _timed(scene, rtol=1e-6, output_step=0.25, method=m)
            rows.append({"scene": model, "method": m, "cpu": cpu,
                         "wall": res.meta["wall_time"],
                         "rhs": int(res.meta["rhs_evaluations"]),
                         "events": int(res.meta["events"]), "final": float(res[ch][-1]),
                         "channel": ch, "t_end": float(res.t[-1])})
            print(rows[-1], flush=True)
    return rows


def work_precision(methods: tuple[str, ...] = METHODS) -> dict[str, Any]:
    rows = []
    for prob, (model, t_end, dt) in PROBLEMS.items():
        scene = winder.load_scene(ROOT / "models" / f"{model}.toml")
        kw = {"t_end": t_end, "output_step": dt, "max_rhs": 10**10}
        ref = winder.simulate(scene, method="DOPRI5", rtol=1e-11, atol=1e-13, **kw)
        for m in methods:
            for rtol in TOLERANCES:
                try:
                    res, cpu = _timed(scene, method=m, rtol=rtol, atol=rtol * 1e-2, **kw)
                except (winder.SimulationError, winder.BudgetExceeded) as exc:
                    print(f"{prob} {m} {rtol:g}: {exc}"[:200], flush=True)
                    continue
                err = max(float(np.max(np.abs(res[c] - ref[c])) / np.max(np.abs(ref[c])))
                          for c in CHANNELS)
                rows.append({"problem": prob, "method": m, "rtol": rtol, "error": err,
                             "cpu": cpu, "wall": res.meta["wall_time"],
                             "rhs": int(res.meta["rhs_evaluations"])})
                print(rows[-1], flush=True)
    return {"rows": rows, "problems": {k: {"model": v[0], "t_end": v[1]}
                                       for k, v in PROBLEMS.items()}}


def auto_picks() -> list[dict[str, Any]]:
    from winder.solve.auto import choose_method
    from winder.solve.system import MachineSystem

    picks = []
    for f in sorted((ROOT / "models").glob("*.toml")):
        scene = winder.load_scene(f)
        sy = MachineSystem(scene)
        c = choose_method(sy, scene.solver.rtol, scene.solver.atol, 0.0, sy.initial_state(),
                          scene.scene.duration)
        picks.append({"scene": f.name, "states": sy.n_states, "method": c.method,
                      "reason": c.reason, "probe": c.probe})
        print(picks[-1]["scene"], c.method, c.reason, flush=True)
    return picks


def plot(wp: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, prob in zip(axes, PROBLEMS, strict=True):
        for m in METHODS:
            pts = [(r["wall"], r["error"]) for r in wp["rows"]
                   if r["problem"] == prob and r["method"] == m]
            if pts:
                ax.loglog(*zip(*pts, strict=True), "o-", label=m)
        model, t_end, _ = PROBLEMS[prob]
        ax.set_title(f"{prob} two-drum winder, 0–{t_end:g} s")
        ax.set_xlabel("wall time of the integration [s]")
        ax.set_ylabel("largest scaled error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")


def write(data: dict[str, Any]) -> None:
    s = data["side_by_side"]
    rig = next(r for r in s["runs"] if r["machine"] == "rigid")
    lines = [
        "# Integrators for the flexible two-drum winder", "",
        "`python benchmarks/flex_cycle.py --methods` (`benchmarks/flex_methods.py`). The "
        "flexible machine (`models/two_drum_winder_flexible.toml`, "
        f"{data.get('n_states', '?')} states) against the rigid one, on the shared 2-core "
        "machine: CPU times are this thread's (`time.thread_time`), which other processes "
        "do not disturb; wall times are given beside them. Methods: DOPRI5 (explicit), "
        "and the Rosenbrock methods of `src/winder/solve/c/rosenbrock.c` on the exact "
        "Jacobian factored on its sparsity (`sparse_lu.h`): RODAS4 (order 4, L-stable, a "
        "new Jacobian every step), RODAS3 (order 3), ROS34PW2 (a W-method of order 3, one "
        "Jacobian kept for up to 16 steps).", "",
        f"## The first {s['window']:g} s of the cycle, side by side (rtol 1e-6)", "",
        "| machine | method | CPU [s] | ÷ rigid | wall [s] | rhs evaluations | events | "
        "set radius at the end [m] |", "|---|---|---|---|---|---|---|---|"]
    for r in s["runs"]:
        lines.append(f"| {r['machine']} | {r['method']} | {r['cpu']:.2f} | "
                     f"{r['cpu'] / rig['cpu']:.1f} | {r['wall']:.2f} | {r['rhs']:,} | "
                     f"{r['events']} | {r['set_radius']:.7f} |")
    fd = next(r for r in s["runs"] if r["machine"] == "flexible" and r["method"] == "DOPRI5")
    lines += ["", "Set radius at the end of the window, each method minus DOPRI5: " + ", ".join(
        f"{r['method']} {r['set_radius'] - fd['set_radius']:+.2e} m" for r in s["runs"]
        if r["machine"] == "flexible" and r["method"] != "DOPRI5") + ".", ""]
    r4 = next((r for r in s["runs"] if r["machine"] == "flexible"
               and r["method"] == "RODAS4"), None)
    rows = data["work_precision"]["rows"]
    dfl = [r for r in rows if r["problem"] == "flexible" and r["method"] == "DOPRI5"]
    if r4 is not None and dfl:
        ev, cpu = fd["rhs"] / r4["rhs"], r4["cpu"] / fd["cpu"]
        probe = next((a["probe"].get("DOPRI5", {}) for a in data.get("auto", [])
                      if a["scene"] == "two_drum_winder_flexible.toml"), {})
        rho = ("the flexible machine's exact Jacobian's spectral radius at the start is "
               f"{probe['rho']:.2g} s⁻¹, DOPRI5's stable step 3.3/ρ = "
               f"{probe['h_stable']:.2g} s (auto's probe, below); " if "rho" in probe else "")
        lines += [
            "At rtol 1e-6 over the window RODAS4 takes "
            + (f"{ev:.1f} times fewer evaluations than DOPRI5" if ev >= 1 else
               f"{1 / ev:.1f} times more evaluations than DOPRI5")
            + f" and {cpu:.2f} times its CPU time: {rho}each RODAS4 step costs a Jacobian, a "
            "sparse factorisation and six solves, about a hundred evaluations' worth "
            "([c-integrators.md](c-integrators.md) gives the split). DOPRI5's evaluations "
            f"hardly change with the tolerance: over the work–precision window it takes "
            f"{min(r['rhs'] for r in dfl):,}–{max(r['rhs'] for r in dfl):,} evaluations and "
            f"reaches an error of {min(r['error'] for r in dfl):.0e}–"
            f"{max(r['error'] for r in dfl):.0e} from rtol 1e-3 to 1e-8 (its step held by "
            "stability, not accuracy), so a looser tolerance does not make it cheaper; the "
            "Rosenbrock methods win only where the fastest run per accuracy level below "
            "names them.", ""]
    lines += ["Fastest run per accuracy level (CPU time; error at most the level):", ""]
    for prob in PROBLEMS:
        for level in (1e-2, 1e-4, 1e-6, 1e-8):
            ok = [r for r in rows if r["problem"] == prob and r["error"] <= level]
            if ok:
                best = min(ok, key=lambda r: r["cpu"])
                dop = [r for r in ok if r["method"] == "DOPRI5"]
                vs = (f"; DOPRI5 {min(r['cpu'] for r in dop):.3g} s" if dop and
                      best["method"] != "DOPRI5" else "")
                lines.append(f"- {prob}, error ≤ {level:.0e}: {best['method']} (rtol "
                             f"{best['rtol']:.0e}) {best['cpu']:.3g} s{vs}")
    lines.append("")
    if data.get("rigid_cycles"):
        rc = data["rigid_cycles"]
        lines += ["## The rigid machines' whole cycles per method (rtol 1e-6)", "",
                  "| scene | method | CPU [s] | wall [s] | rhs evaluations | events | final "
                  "radius [m] | minus DOPRI5's [m] |", "|---|---|---|---|---|---|---|---|"]
        for r in rc:
            d0 = next(x for x in rc if x["scene"] == r["scene"] and x["method"] == "DOPRI5")
            lines.append(f"| {r['scene']} ({r['t_end']:g} s) | {r['method']} | "
                         f"{r['cpu']:.2f} | {r['wall']:.2f} | {r['rhs']:,} | {r['events']:,} "
                         f"| {r['final']:.7f} | {r['final'] - d0['final']:+.1e} |")
        lines.append("")
    lines += ["## Work–precision", "",
              "![work–precision](flex_methods.png)", "",
              "| problem | method | rtol | error | CPU [s] | wall [s] | rhs evaluations |",
              "|---|---|---|---|---|---|---|"]
    for r in data["work_precision"]["rows"]:
        lines.append(f"| {r['problem']} | {r['method']} | {r['rtol']:.0e} | "
                     f"{r['error']:.1e} | {r['cpu']:.3g} | {r['wall']:.3g} | {r['rhs']:,} |")
    lines += ["", "## What `method=\"auto\"` picks", "",
              "`winder.solve.auto.choose_method`: DOPRI5's mean step over a short probe "
              "against its stable step 3.3/ρ (ρ: the exact Jacobian's spectral radius at the "
              "start); where the step is held by stability, RODAS4 is probed on the same "
              "window and chosen where it takes less than 0.7 of DOPRI5's CPU time.", "",
              "| scene | states | picks | why |", "|---|---|---|---|"]
    for p in data["auto"]:
        lines.append(f"| {p['scene']} | {p['states']} | {p['method']} | {p['reason']} |")
    md = "\n".join(lines) + "\n"
    js = json.dumps(data, indent=1, default=float)
    atomic_write_all([(DOCS / "flex_methods.md", lambda p: Path(p).write_text(md)),
                      (DOCS / "flex_methods.json", lambda p: Path(p).write_text(js)),
                      (DOCS / "flex_methods.png",
                       lambda p: plot(data["work_precision"], Path(p)))])
    print(md)


def rewrite() -> None:
    """The page again from docs/flex_methods.json (no runs)."""
    write(json.loads((DOCS / "flex_methods.json").read_text()))


def main(window: float) -> None:
    from winder.solve.system import MachineSystem

    flex = winder.load_scene(ROOT / "models" / "two_drum_winder_flexible.toml")
    data = {"n_states": MachineSystem(flex).n_states,
            "side_by_side": side_by_side(window), "rigid_cycles": rigid_cycles(),
            "work_precision": work_precision(), "auto": auto_picks()}
    write(data)
