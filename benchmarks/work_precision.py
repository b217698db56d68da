"""Work–precision study: error against wall time per method (writes docs/work_precision.*).

Problems: the smooth paper scene (first 120 s), 0.5 s of the bouncing phase of the paper
scene (from t = 25 s), free spin (closed form) and the two-drum winder's first 30 s (the
speed ramp, the set settling into the valley under the rider). Methods: the compiled
DOPRI5, DOP853C (DOP853 in C), ROS2 (Rosenbrock, exact Jacobian) and fixed-step RK4, and
scipy's RK45, DOP853, Radau, BDF and LSODA on the generated right-hand side (the implicit
ones with the exact generated Jacobian, and Radau/BDF also with their finite differences),
plus LSODA on the numeric Pinocchio backend. Errors are the largest deviation over the
output grid, scaled by the channel's largest magnitude, against the compiled DOPRI5 at rtol
1e-12 (the closed form for free spin); the spread to a second tight solution is reported
with each problem.
Each point's wall time is the median of ``--repeats`` runs (runs longer than
``--repeat-below`` seconds are timed once); the RHS evaluation and event counts of every
run are kept, so that the error can be read against a count that no other process on the
machine can disturb (the sixth panel, and the section on DOPRI5's curves).

Run:  make bench      (or  python benchmarks/work_precision.py [--quick])
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import brentq

import winder
from winder.io.files import atomic_write

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
DOCS = ROOT / "docs"
PAPER_CHANNELS = ("radius", "roll_speed", "z", "normal_force")
TWO_DRUM_CHANNELS = ("set_radius", "set_speed", "set_x", "set_z", "rear_nip_normal_force",
                     "rider_nip_normal_force")
LINE_CHANNELS = (*TWO_DRUM_CHANNELS, "span_tension", "parent_speed", "parent_torque")
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
RK4_STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5)
COMPILED = ("DOPRI5", "DOP853C", "ROS2")
SCIPY = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


#: Why DOPRI5's curves zigzagged in the bouncing and two-drum panels (written from the
#: measurements of this study: see each problem's "DOPRI5 from rtol ..." line).
ZIGZAG = [
    "## Why the DOPRI5 curves zigzagged (a record of 2026-11-25, 040f03b)", "",
    "This section records a study of 2026-11-25 at commit 040f03b, with the numba "
    "integrators of then: its numbers are that study's, not the tables' below, which "
    "this script writes from today's run.", "",
    "The previous version of this figure (one timing per point) showed DOPRI5's curves in the "
    "bouncing and two-drum panels going back and forth. Measured, not guessed:", "",
    "- **The error is monotone in the tolerance** on every problem: see each problem's "
    "\"DOPRI5 from rtol …\" line below, and the sixth panel, which plots DOPRI5's error "
    "against its right-hand side evaluations, a count no other process can disturb: every "
    "curve there falls (with a plateau of the bouncing phase's normal-force error, "
    "4.6e-5 at rtol 1e-5 and 1e-6).",
    "- **Located events do not cause it**: the number of located lift-offs and touch-downs "
    "is the same at every tolerance (17 in the bouncing phase, 1 on the two-drum winder and "
    "the line, 0 in free spin), and the evaluation counts grow monotonically as the "
    "tolerance tightens.",
    "- **The timings did.** On the two-drum winder rtol 1e-3, 1e-4 and 1e-5 take the same "
    "345 000–347 000 evaluations (the step is held by the stiff nips' stability limit, not "
    "by the tolerance, so the error falls 50× at one cost): a vertical line, which single "
    "timings of 0.43, 0.47 and 0.20 s had turned into a Z; their medians now are 0.10, "
    "0.13 and 0.13 s. The bouncing phase integrates 0.5 s in 0.4–5 ms, and a run on a "
    "machine with more runnable processes than cores that is descheduled loses whole "
    "scheduler ticks: the repeats below are bimodal (e.g. 0.5 ms or 12.7 ms at rtol 1e-3; "
    "a separate probe at load 3 gave rtol 1e-9 2.9 ms or 7.05 ms, rtol 1e-10 4.5 ms or "
    "8.5 ms, a step of 4.1 ms: one tick of this kernel's 250 Hz). The single timing of "
    "the old figure (8.5 ms at rtol 1e-8 against 2.6 ms at 1e-9 with 55 % more "
    "evaluations) was one such descheduled run.",
    "- **And the plot joined the points in the order of their wall times**, not of their "
    "tolerances: where three tolerances cost the same, any timing noise reordered them "
    "into a zigzag. The lines now join the points from the loosest tolerance to the "
    "tightest.",
    "- Each point is now the median of repeated runs, and the compiled integrators are "
    "compiled (numba) before any timed run: in a fresh checkout the first ROS2 run included "
    "that compilation and, on the smooth scene, hit the 15 s budget at rtol 1e-3 (0.26 s "
    "once compiled). Where the load stays above the core count for a whole point, even "
    "the median of 11 is a descheduled value (the bouncing phase at rtol 1e-9 and 1e-10: "
    "11 and 13 ms here, against 2.9 and 4.5 ms in the probe): on this shared machine the "
    "wall-time axis of runs of a few ms measures the machine as much as the method, and "
    "the sixth panel is the comparison free of it. Runs of 2 s or more are timed once "
    "(the two-drum winder at rtol 1e-9: 2.04 s, against a median of 1.71 s at 1e-10).",
]


@dataclass
class Problem:
    name: str
    scene: winder.Scene
    t_end: float
    output_step: float
    channels: tuple[str, ...] = PAPER_CHANNELS
    t_start: float = 0.0
    y0: np.ndarray | None = None
    reference: dict[str, np.ndarray] | None = field(default=None, repr=False)
    note: str = ""

    def run(self, method: str, rtol: float, *, backend: str = "compiled",
            max_step: float | None = None, max_wall: float | None = None,
            jacobian: str = "exact", t_end: float | None = None) -> winder.Result:
        return winder.simulate(self.scene, t_end=t_end or self.t_end, method=method, rtol=rtol,
                               atol=rtol * 1e-2, output_step=self.output_step,
                               backend=backend, max_step=max_step, max_wall=max_wall,
                               max_rhs=10**12,  # capped by max_wall alone
                               t_start=self.t_start, initial_state=self.y0,
                               jacobian=jacobian)


def free_spin_closed_form(scene: winder.Scene, t: np.ndarray) -> dict[str, np.ndarray]:
    """``J(r) ω = J₀ ω₀`` and ``ṙ = h ω/2π`` give ``t(r) = 2π/(h L₀) ∫ J dr``; inverted.
    ``J(r) = J_c + k (r⁴ − r_c⁴)``, ``k = ρ π w / 2`` (winder-model §2)."""
    r0, w0, h = scene.roll.initial_radius, scene.roll.initial_speed, scene.paper.caliper
    k = 0.5 * scene.paper.density * math.pi * scene.roll.width
    rc, Jc = scene.roll.core_radius, scene.roll.core_inertia

    def J(r: float) -> float:
        return Jc + k * (r**4 - rc**4)

    def integral(r: float) -> float:
        return Jc * (r - r0) + k * ((r**5 - r0**5) / 5 - rc**4 * (r - r0))

    L0 = J(r0) * w0
    r = np.array([brentq(lambda x, ti=ti: 2 * math.pi / (h * L0) * integral(x) - ti, r0,
                         r0 + 10.0, xtol=1e-15, rtol=1e-15) if ti > 0 else r0 for ti in t])
    return {"radius": r, "roll_speed": L0 / np.array([J(x) for x in r])}


def build_problems(quick: bool) -> list[Problem]:
    smooth = winder.load_scene(MODELS / "paper_winding_smooth.toml")
    paper = winder.load_scene(MODELS / "paper_winding.toml")
    spin = winder.load_scene(MODELS / "free_spin.toml")
    two = winder.load_scene(MODELS / "two_drum_winder.toml")
    line = winder.load_scene(MODELS / "winder_line.toml")
    start = winder.Stepper(paper, rtol=1e-12, atol=1e-14)
    start.step(25.0)
    probs = [
        Problem("smooth paper scene, 0-120 s", smooth, 120.0, 1.0,
                note="com_offset 0.5 mm: the roll stays on the drum"),
        Problem("bouncing phase, 25-25.5 s", paper, 25.5, 0.005, t_start=25.0,
                y0=np.array(start.y), note="paper scene; the nip opens every turn"),
        Problem("free spin, 0-300 s", spin, 300.0, 1.0, channels=("radius", "roll_speed"),
                note="closed form reference"),
        Problem("two-drum winder, 0-30 s", two, 30.0 if not quick else 10.0, 0.01,
                channels=TWO_DRUM_CHANNELS,
                note="speed ramp; the set settles in the valley under the rider"),
        Problem(f"winder line, 0-{30 if not quick else 10} s", line,
                30.0 if not quick else 10.0, 0.01,
                channels=LINE_CHANNELS,
                note="the two-drum winder fed through the web span (EA/L_s = 4.7e5 N/m), "
                     "its tension held by the unwind's controller"),
    ]
    return probs


def errors(res: winder.Result, ref: dict[str, np.ndarray]) -> dict[str, float]:
    out = {}
    for ch, r in ref.items():
        if np.max(np.abs(r)) > 0:
            out[ch] = float(np.max(np.abs(res[ch] - r)) / np.max(np.abs(r)))
    return out


#: Runs shorter than this [s] are repeated SHORT_REPEATS times: on a machine with more
#: runnable processes than cores, a run of a few ms is either not preempted or preempted
#: for a whole scheduler time slice (several ms), and three repeats do not out-vote that.
SHORT_RUN, SHORT_REPEATS = 0.05, 11


def timed(prob: Problem, method: str, rtol: float, *, repeats: int, repeat_below: float,
          **kw: Any) -> tuple[winder.Result, list[float]]:
    """The run and the wall times [s] of its repeats: ``repeats`` runs
    (:data:`SHORT_REPEATS` where the first is shorter than :data:`SHORT_RUN`), or one where
    the first takes ``repeat_below`` or longer. Every repeat must take the same steps."""
    res = prob.run(method, rtol, **kw)
    walls = [res.meta["wall_time"]]
    if walls[0] < SHORT_RUN:
        repeats = max(repeats, SHORT_REPEATS)
    while len(walls) < repeats and walls[0] < repeat_below:
        again = prob.run(method, rtol, **kw)
        assert again.meta["rhs_evaluations"] == res.meta["rhs_evaluations"]
        walls.append(again.meta["wall_time"])
    return res, walls


def study(problems: list[Problem], *, max_wall: float, quick: bool, repeats: int = 3,
          repeat_below: float = 2.0, log: Any = sys.stderr) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    tols = TOLERANCES[::3] if quick else TOLERANCES
    for prob in problems:
        t0 = time.perf_counter()
        if prob.name.startswith("free spin"):
            res = prob.run("DOPRI5", 1e-6)
            prob.reference = free_spin_closed_form(prob.scene, res.t)
            ref_note = "closed form"
        else:
            ref = prob.run("DOPRI5", 1e-12)
            chk = prob.run("DOPRI5", 1e-11)
            prob.reference = {ch: ref[ch] for ch in prob.channels}
            spread = max(errors(chk, prob.reference).values())
            ref_note = f"DOPRI5 1e-12 (DOPRI5 1e-11 differs by {spread:.1e})"
        prob.note += f"; reference: {ref_note}"
        print(f"{prob.name}: reference in {time.perf_counter() - t0:.1f} s ({ref_note})",
              file=log, flush=True)
        for m in (*COMPILED, "RK4"):  # build the library outside the timed runs and budgets
            prob.run(m, 1e-3, max_step=1e-3 if m == "RK4" else None,
                     t_end=prob.t_start + 10 * prob.output_step)
        runs: list[tuple[str, str, float | None, float | None]] = []
        for m in (*COMPILED, *SCIPY):
            runs += [(m, "exact", tol, None) for tol in tols]
        runs += [("RK4", "exact", None, h) for h in (RK4_STEPS[1::2] if quick else RK4_STEPS)]
        runs += [(m, "fd", tol, None) for m in ("Radau", "BDF") for tol in tols]
        if not prob.name.startswith(("smooth", "two-drum", "winder line")):
            runs += [("LSODA", "pinocchio", tol, None) for tol in tols[:4]]
        given_up: set[tuple[str, str]] = set()
        for method, variant, tol, h in runs:
            label = {"exact": method, "pinocchio": f"{method} (Pinocchio RHS)",
                     "fd": f"{method} (FD Jacobian)"}[variant]
            if (label, prob.name) in given_up:
                continue
            row: dict[str, Any] = {"problem": prob.name, "method": label,
                                   "rtol": tol, "step": h}
            try:
                res, walls = timed(
                    prob, method, tol if tol is not None else 1e-6, repeats=repeats,
                    repeat_below=repeat_below,
                    backend="pinocchio" if variant == "pinocchio" else "compiled",
                    max_step=h, max_wall=max_wall, jacobian="fd" if variant == "fd" else "exact")
            except winder.SimulationError as exc:
                msg = str(exc)
                row["status"] = "wall limit" if "max_wall" in msg else "failed"
                row["message"] = msg.split(" at t =")[0][:80]
                given_up.add((label, prob.name))
            else:
                e = errors(res, prob.reference)
                row.update(status="ok", wall=float(np.median(walls)), walls=walls,
                           nfev=res.meta["rhs_evaluations"], events=res.meta["events"],
                           error=max(e.values()), **{f"err_{k}": v for k, v in e.items()})
            rows.append(row)
            print(f"  {label:24s} {tol or h:8.1e} {row['status']:10s} "
                  f"{row.get('wall', math.nan):8.3f} s  err {row.get('error', math.nan):.2e}",
                  file=log, flush=True)
    return rows


def best_per_level(rows: list[dict[str, Any]], problem: str) -> list[tuple[float, str, float]]:
    ok = [r for r in rows if r["problem"] == problem and r["status"] == "ok"]
    out = []
    for level in (1e-2, 1e-4, 1e-6, 1e-8):
        cand = [r for r in ok if r["error"] <= level]
        if cand:
            b = min(cand, key=lambda r: r["wall"])
            setting = f"rtol {b['rtol']:.0e}" if b["rtol"] else f"h {b['step']:.2e} s"
            out.append((level, f"{b['method']} ({setting})", b["wall"]))
    return out


def default_check(rows: list[dict[str, Any]], problem: str) -> str:
    """``auto`` at rtol 1e-6 against the fastest run reaching at least its accuracy."""
    ok = [r for r in rows if r["problem"] == problem and r["status"] == "ok"]
    auto = [r for r in ok if r["method"] == winder.DEFAULT_METHOD["compiled"]
            and r["rtol"] == 1e-6]
    if not auto:
        return "auto not measured"
    a = auto[0]
    best = min((r for r in ok if r["error"] <= a["error"]), key=lambda r: r["wall"])
    return (f"auto = {a['method']} at rtol 1e-6: {a['wall']:.3g} s, error {a['error']:.1e}; "
            f"fastest at that accuracy: {best['method']} {best['wall']:.3g} s "
            f"(ratio {a['wall'] / best['wall']:.2f})")


def at_1e6(rows: list[dict[str, Any]], problem: str) -> tuple[list[str], str]:
    """Rows of the rtol 1e-6 table (error, error/rtol, wall per method) and a verdict: the
    most accurate method, the one whose error is closest to the requested 1e-6 (in
    decades), and the fastest."""
    ok = [r for r in rows if r["problem"] == problem and r["status"] == "ok"
          and r["rtol"] == 1e-6]
    if not ok:
        return [], "no run at rtol 1e-6"
    ok.sort(key=lambda r: r["wall"])
    lines = [f"| {r['method']} | {r['error']:.1e} | {r['error'] / 1e-6:.2g} | {r['wall']:.3g} | "
             f"{r['nfev']:,} |" for r in ok]
    close = min(ok, key=lambda r: abs(math.log10(max(r["error"], 1e-300) / 1e-6)))
    best = min(ok, key=lambda r: r["error"])
    return lines, (f"most accurate: **{best['method']}** (error {best['error']:.1e}, "
                   f"{best['wall']:.3g} s); error closest to the requested 1e-6: "
                   f"{close['method']} ({close['error']:.1e}); fastest: {ok[0]['method']} "
                   f"({ok[0]['wall']:.3g} s, error {ok[0]['error']:.1e})")


def dopri5_curve(rows: list[dict[str, Any]], problem: str) -> str:
    """What DOPRI5's curve of ``problem`` does from loose to tight tolerances: whether the
    error, the RHS evaluations, the events and the (median) wall times are monotone, and
    how far the repeats of one point spread."""
    ok = sorted((r for r in rows if r["problem"] == problem and r["method"] == "DOPRI5"
                 and r["status"] == "ok"), key=lambda r: -r["rtol"])
    if len(ok) < 2:
        return "DOPRI5: fewer than two runs."

    def rises(key: str) -> list[str]:
        return [f"{a[key]:.3g} at rtol {a['rtol']:.0e} → {b[key]:.3g} at {b['rtol']:.0e}"
                for a, b in zip(ok, ok[1:], strict=False) if b[key] > a[key] * 1.05]

    def falls(key: str) -> list[str]:
        return [f"{a[key]:.3g} at rtol {a['rtol']:.0e} → {b[key]:.3g} at {b['rtol']:.0e}"
                for a, b in zip(ok, ok[1:], strict=False) if b[key] < a[key] / 1.05]

    err_up, nfev_down, wall_down = rises("error"), falls("nfev"), falls("wall")
    events = sorted({r["events"] for r in ok})
    spread = max(max(r.get("walls", [r["wall"]])) / min(r.get("walls", [r["wall"]]))
                 for r in ok)
    flat = [f"{a['rtol']:.0e}–{b['rtol']:.0e}" for a, b in zip(ok, ok[1:], strict=False)
            if b["nfev"] <= a["nfev"] * 1.05]
    return (f"DOPRI5 from rtol {ok[0]['rtol']:.0e} to {ok[-1]['rtol']:.0e}: error "
            + (f"rises at {'; '.join(err_up)}" if err_up else "never rises by more than 5 %")
            + "; RHS evaluations " + (f"fall at {'; '.join(nfev_down)}" if nfev_down else
                                      f"grow monotonically ({ok[0]['nfev']:,} → "
                                      f"{ok[-1]['nfev']:,})")
            + (f", flat (within 5 %) over rtol {', '.join(flat)}" if flat else "")
            + f"; located events per run: {', '.join(map(str, events))}"
            + "; median wall time " + (f"falls at {'; '.join(wall_down)}" if wall_down
                                       else "grows monotonically")
            + f"; the repeats of one point differ by up to ×{spread:.2f}.")


def write_markdown(rows: list[dict[str, Any]], problems: list[dict[str, Any]],
                   head: dict[str, Any], path: Path) -> None:
    lines = ["# Work–precision study", "",
             "Regenerate with `make bench` (`benchmarks/work_precision.py`). Errors: largest "
             "deviation over the output grid of each problem's channels, each scaled by the "
             "channel's largest magnitude; the table gives the largest of them. "
             "`atol = rtol/100`. Scipy's implicit methods use the exact generated Jacobian "
             "unless marked *FD Jacobian*. Runs are given up for tighter tolerances after "
             f"one reaches the wall limit ({head['max_wall']:g} s). Wall times (`meta"
             "[\"wall_time\"]`, the integration alone) on a shared, loaded machine "
             f"({head.get('machine', 'see git log')}; load average {head['load'][0]:.1f} at "
             f"the start, {head['load_after'][0]:.1f} at the end): the ratios between methods "
             "are more telling than the absolute times. Each wall time is the median of "
             f"{head.get('repeats', 1)} runs ({SHORT_REPEATS} for runs under "
             f"{SHORT_RUN * 1e3:g} ms, one for runs of {head.get('repeat_below', 0):g} s or "
             "more).", "", *ZIGZAG, "",
             "Evaluation costs and whole cycles: [rhs_speed.md](rhs_speed.md), "
             "[cycle_speed.md](cycle_speed.md), [codegen_speed.md](codegen_speed.md).", ""]
    for prob in problems:
        name, chans = prob["name"], prob["channels"]
        lines += [f"## {name}", "", prob["note"] + ".", "",
                  "Best method per accuracy level (fastest run with error at most the level):", ""]
        for level, label, wall in best_per_level(rows, name):
            lines.append(f"- error ≤ {level:.0e}: {label}, {wall:.3g} s")
        t1e6, verdict = at_1e6(rows, name)
        lines += ["", default_check(rows, name) + ".", "", f"At rtol 1e-6: {verdict}.", "",
                  dopri5_curve(rows, name), "",
                  "| method (rtol 1e-6) | error | error / rtol | wall [s] | RHS evals |",
                  "|---|---|---|---|---|", *t1e6, "",
                  "| method | rtol / step | status | wall [s] | RHS evals | events | error | "
                  + " | ".join(chans) + " |",
                  "|---|---|---|---|---|---|---|" + "---|" * len(chans)]
        for r in rows:
            if r["problem"] != name:
                continue
            setting = f"{r['rtol']:.0e}" if r["rtol"] else f"h = {r['step']:.3g} s"
            if r["status"] != "ok":
                lines.append(f"| {r['method']} | {setting} | {r['status']}: {r['message']} "
                             "| | | | " + "| " * len(chans) + "|")
                continue
            cells = [f"{r['err_' + c]:.1e}" if 'err_' + c in r else "–" for c in chans]
            lines.append(f"| {r['method']} | {setting} | ok | {r['wall']:.3g} | {r['nfev']:,} | "
                         f"{r['events']} | {r['error']:.1e} | " + " | ".join(cells) + " |")
        lines.append("")
    text = "\n".join(lines)
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


def plot(rows: list[dict[str, Any]], problems: list[dict[str, Any]], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = 2 if len(problems) > 2 else len(problems)
    nrows = math.ceil(len(problems) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(6.0 * cols, 4.6 * nrows), squeeze=False)
    axes = axes.ravel()
    methods = sorted({r["method"] for r in rows})
    colours = dict(zip(methods, plt.cm.tab20(np.linspace(0, 1, 20)), strict=False))
    for ax, prob in zip(axes, problems, strict=False):
        for m in methods:  # joined from loose to tight, not by wall time (ties zigzag)
            pts = [(-(r["rtol"] or r["step"]), r["wall"], max(r["error"], 1e-16)) for r in rows
                   if r["problem"] == prob["name"] and r["method"] == m
                   and r["status"] == "ok"]
            if pts:
                _, x, y = zip(*sorted(pts), strict=True)
                ax.loglog(x, y, "o-", color=colours[m], label=m, ms=4)
        ax.set_title(prob["name"], fontsize=10)
        ax.set_xlabel("wall time [s]")
        ax.grid(True, which="both", alpha=0.3)
    spare = axes[len(problems):]
    if len(spare):  # the timing-free view of DOPRI5: error against RHS evaluations
        ax = spare[0]
        for i, prob in enumerate(problems):
            pts = sorted((r["nfev"], max(r["error"], 1e-16)) for r in rows
                         if r["problem"] == prob["name"] and r["method"] == "DOPRI5"
                         and r["status"] == "ok")
            if pts:
                x, y = zip(*pts, strict=True)
                ax.loglog(x, y, "s-", color=plt.cm.Dark2(i), ms=3, lw=1,
                          label=prob["name"].split(",")[0])
        ax.set_title("DOPRI5: error against RHS evaluations (no timing noise)", fontsize=10)
        ax.set_xlabel("right-hand side evaluations")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
        for extra in spare[1:]:
            extra.set_visible(False)
    for ax in axes[::cols]:
        ax.set_ylabel("scaled max error [-]")
    handles = {}
    for ax in axes[:len(problems)]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="lower center", ncol=6, fontsize=8)
    fig.suptitle("winder work–precision (error against wall time, one line per method)")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer tolerances, shorter two-drum run")
    ap.add_argument("--max-wall", type=float, default=20.0,
                    help="give up a method's tighter tolerances after a run this long [s]")
    ap.add_argument("--repeats", type=int, default=3,
                    help="time each point as the median of this many runs (default 3)")
    ap.add_argument("--repeat-below", type=float, default=2.0,
                    help="repeat only runs shorter than this [s] (default 2)")
    ap.add_argument("--out", type=Path, default=DOCS, help="output folder (default docs/)")
    ap.add_argument("--replot", action="store_true",
                    help="rewrite the table and plot from the saved work_precision.json")
    ap.add_argument("--only", default=None,
                    help="run only the problems whose name starts with this text and merge "
                         "their rows into the saved work_precision.json")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    saved = args.out / "work_precision.json"
    if args.replot:
        data = json.loads(saved.read_text(encoding="utf-8"))
        rows, head, problems = data["rows"], data["head"], data["problems"]
    else:
        head: dict[str, Any] = {"load": os.getloadavg(), "max_wall": args.max_wall,
                                "repeats": args.repeats, "repeat_below": args.repeat_below}
        probs = build_problems(args.quick)
        keep: list[dict[str, Any]] = []
        kept: list[dict[str, Any]] = []
        if args.only is not None:
            probs = [p for p in probs if p.name.startswith(args.only)]
            old = json.loads(saved.read_text(encoding="utf-8"))
            keep = [r for r in old["rows"] if not r["problem"].startswith(args.only)]
            kept = [p for p in old["problems"] if not p["name"].startswith(args.only)]
        rows = keep + study(probs, max_wall=args.max_wall, quick=args.quick,
                            repeats=args.repeats, repeat_below=args.repeat_below)
        cpu = platform.processor() or platform.machine()
        head["machine"] = f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}"
        head["load_after"] = os.getloadavg()
        problems = kept + [{"name": p.name, "note": p.note, "channels": list(p.channels)}
                           for p in probs]
        text = json.dumps({"rows": rows, "head": head, "problems": problems}, indent=1)
        atomic_write(saved, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    write_markdown(rows, problems, head, args.out / "work_precision.md")
    plot(rows, problems, args.out / "work_precision.png")
    print(f"wrote {args.out / 'work_precision.md'} and {args.out / 'work_precision.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
