"""MuJoCo side by side with winder: what the mass overwrite gets wrong, and what it costs.

Scenes: free spin without and with web momentum (closed forms), the smooth paper scene
over 200 s with and without web momentum, and the bouncing paper scene up to just after
its first lift-off. Ways: (a) MuJoCo with the roll's mass and inertia overwritten every
step, (b) the same plus ``−(∂M/∂r·ṙ) q̇`` and the web flux applied by hand, each with
MuJoCo's Euler, RK4 and implicitfast integrators at several time steps, and (c) winder at
rtol 1e-3 … 1e-9. Errors: largest deviation over the output grid, scaled by the
channel's largest magnitude, against winder at rtol 1e-10 (against the closed forms for
free spin). The h → 0 limit of way (a) is winder's own ``variable_mass = false`` mode
(spec §3), so the overwrite's error plateau is measured exactly, free of step errors.

Run:  make peers      (or  python benchmarks/peers/study.py [--quick] [--replot])
Writes docs/peers.md and docs/peers.png (and out/peers.json, for --replot).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

import winder

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE.parent))
from work_precision import free_spin_closed_form  # noqa: E402

from peers.mujoco_winder import CLOCK, INTEGRATORS, MujocoWinder, mass_properties  # noqa: E402

MODELS, DOCS = ROOT / "models", ROOT / "docs"
WINDER_RTOLS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
REF_RTOL = 1e-10
MJ_WAYS = ("overwrite", "corrected")
LABEL = {"overwrite": "(a) overwrite", "corrected": "(b) overwrite + −(∂M/∂r·ṙ)q̇",
         "winder": "(c) winder"}
PAPER_CHANNELS = ("roll_speed", "radius", "z", "normal_force", "drum_torque")

Channels = dict[str, np.ndarray]


@dataclass
class Case:
    """One scene over one time window, with its reference and the overwrite's limits."""

    key: str
    title: str
    scene: winder.Scene | None         # None when re-read from the cache (--replot)
    t_end: float                      # [s]
    output_step: float                # [s]
    dts: tuple[float, ...]            # [s] MuJoCo time steps
    channels: tuple[str, ...]
    note: str
    closed_form: Callable[[np.ndarray], Channels] | None = None
    lift_off: bool = False            # report the first lift-off time
    ref: Channels = field(default_factory=dict)
    ref_note: str = ""
    ref_lift_off: float = math.nan
    limits: dict[str, dict[str, Any]] = field(default_factory=dict)


def channels_of(res: Any, names: tuple[str, ...]) -> Channels:
    """The named channels of a winder ``Result`` or a ``MujocoRun``; ``angular_momentum``
    is ``inertia · roll_speed`` [kg·m²/s]."""
    out = {}
    for n in names:
        out[n] = (np.asarray(res["inertia"]) * np.asarray(res["roll_speed"])
                  if n == "angular_momentum" else np.asarray(res[n]))
    return out


def errors(run: Channels, ref: Channels) -> dict[str, float]:
    """Largest deviation over the grid, scaled by the reference channel's largest
    magnitude [-], per channel."""
    return {ch: float(np.max(np.abs(run[ch] - ref[ch])) / np.max(np.abs(ref[ch])))
            for ch in ref}


def lift_off_time(res: winder.Result, scene: winder.Scene) -> float:
    """First time the nip opens [s]: the first zero of the (clamped) normal force on the
    grid, refined by linear interpolation of the unclamped linear law ``k δ + c δ̇``."""
    fn = np.asarray(res["normal_force"])
    idx = np.flatnonzero(fn <= 0.0)
    if idx.size == 0 or idx[0] == 0:
        return math.nan
    i = int(idx[0])
    co, h2pi = scene.contact, scene.paper.caliper / (2 * math.pi)

    def unclamped(j: int) -> float:
        delta = scene.drum.radius + res["radius"][j] - res["z"][j]
        return co.stiffness * delta + co.damping * (h2pi * res["roll_speed"][j]
                                                    - res["z_dot"][j])
    f0, f1 = unclamped(i - 1), unclamped(i)
    t0, t1 = res.t[i - 1], res.t[i]
    return float(t0 + (t1 - t0) * f0 / (f0 - f1)) if f0 > 0 > f1 else float(t1)


def simulate(scene: winder.Scene, case: Case, rtol: float,
             output_step: float | None = None) -> tuple[winder.Result, float]:
    """winder's DOPRI5 over the case's window; returns the result and its CPU time [s]
    (``CLOCK``; the whole call, output channels included)."""
    t0 = CLOCK()
    res = winder.simulate(scene, t_end=case.t_end, rtol=rtol, atol=rtol * 1e-2,
                          output_step=output_step or case.output_step, method="DOPRI5")
    return res, CLOCK() - t0


def spin_flux_closed_form(scene: winder.Scene) -> Callable[[np.ndarray], Channels]:
    """Free spin with the web flux at ``u = ω r`` (spec §3): ``ω = ω₀`` and
    ``r = r₀ + h ω₀ t / 2π``."""
    w0, r0, h = scene.roll.initial_speed, scene.roll.initial_radius, scene.paper.caliper

    def cf(t: np.ndarray) -> Channels:
        return {"roll_speed": np.full_like(t, w0), "radius": r0 + h * w0 * t / (2 * math.pi)}
    return cf


def spin_closed_form(scene: winder.Scene) -> Callable[[np.ndarray], Channels]:
    """Free spin, paper from rest: ``J ω = J₀ ω₀`` (the work–precision study's inversion)."""
    L0 = mass_properties(scene, scene.roll.initial_radius)[1] * scene.roll.initial_speed

    def cf(t: np.ndarray) -> Channels:
        out = free_spin_closed_form(scene, t)
        out["angular_momentum"] = np.full_like(t, L0)
        return out
    return cf


def build_cases(quick: bool) -> list[Case]:
    spin = winder.load_scene(MODELS / "free_spin.toml")
    spin_web = spin.replace(effects={"web_momentum": True})
    smooth = winder.load_scene(MODELS / "paper_winding_smooth.toml")
    smooth_nw = smooth.replace(effects={"web_momentum": False})
    paper = winder.load_scene(MODELS / "paper_winding.toml")
    t_smooth = 20.0 if quick else 200.0
    dts_smooth = (1e-3, 5e-4) if quick else (1e-3, 5e-4, 2.5e-4)
    dts_spin = (0.1, 0.02) if quick else (0.1, 0.02, 5e-3)
    return [
        Case("spin", "free spin, no web momentum, 0–300 s", spin, 300.0, 1.0, dts_spin,
             ("roll_speed", "radius", "angular_momentum"),
             "`models/free_spin.toml`: paper joins from rest, `J ω` stays constant",
             closed_form=spin_closed_form(spin)),
        Case("spin_web", "free spin with web momentum, 0–300 s", spin_web, 300.0, 1.0,
             dts_spin, ("roll_speed", "radius"),
             "the same with the web flux at the roll's surface speed (`u = ω r`): ω stays "
             "constant", closed_form=spin_flux_closed_form(spin_web)),
        Case("smooth", f"smooth paper scene, 0–{t_smooth:g} s", smooth, t_smooth, 0.05,
             dts_smooth, PAPER_CHANNELS,
             "`models/paper_winding_smooth.toml` (web momentum on, as in the file)"),
        Case("smooth_nw", f"smooth paper scene without web momentum, 0–{t_smooth:g} s",
             smooth_nw, t_smooth, 0.05, dts_smooth, PAPER_CHANNELS,
             "the same with `web_momentum = false`: the paper joins the roll from rest (the "
             "paper's Fig. 5 case)"),
        Case("bounce", "paper scene to its first lift-off, 0–20.6 s", paper, 20.6, 1e-3,
             (1e-3, 2.5e-4) if quick else (1e-3, 2.5e-4, 6.25e-5), PAPER_CHANNELS,
             "`models/paper_winding.toml`: the nip first opens at about 20.52 s for about a "
             "millisecond", lift_off=True),
    ]


def overwrite_limits(case: Case) -> None:
    """The h → 0 limits of the MuJoCo ways without the mass terms, computed by winder's
    ``variable_mass = false`` mode (spec §3): the bare overwrite (no web flux) and, where
    the scene has web momentum, the overwrite with the flux on top (the double count)."""
    variants = {"overwrite": {"variable_mass": False, "web_momentum": False}}
    if case.scene.effects.web_momentum:
        variants["overwrite+flux"] = {"variable_mass": False}
    for name, fx in variants.items():
        try:
            res, _ = simulate(case.scene.replace(effects=fx), case, REF_RTOL)
        except winder.SimulationError as exc:  # the double count can blow up
            t_fail = str(exc).split(" at t = ")[-1].split(" ")[0]
            case.limits[name] = {"errors": dict.fromkeys(case.channels, math.inf),
                                 "note": f"diverges: the radius grows without bound at "
                                         f"t = {float(t_fail):.2f} s"}
            continue
        lim: dict[str, Any] = {"errors": errors(channels_of(res, case.channels), case.ref)}
        if case.lift_off:
            fine, _ = simulate(case.scene.replace(effects=fx), case, REF_RTOL, 1e-4)
            lim["lift_off"] = lift_off_time(fine, case.scene)
        case.limits[name] = lim


def reference(case: Case, log: Any) -> None:
    t0 = time.perf_counter()
    res, _ = simulate(case.scene, case, REF_RTOL)
    if case.closed_form is not None:
        case.ref = {k: v for k, v in case.closed_form(res.t).items() if k in case.channels}
        spread = max(errors(channels_of(res, case.channels), case.ref).values())
        case.ref_note = f"closed form (winder at rtol 1e-10 is within {spread:.1e} of it)"
    else:
        case.ref = channels_of(res, case.channels)
        chk, _ = simulate(case.scene, case, 1e-11)
        spread = max(errors(channels_of(chk, case.channels), case.ref).values())
        case.ref_note = f"winder at rtol 1e-10 (rtol 1e-11 differs by {spread:.1e})"
    if case.lift_off:
        fine, _ = simulate(case.scene, case, REF_RTOL, 1e-4)
        case.ref_lift_off = lift_off_time(fine, case.scene)
    overwrite_limits(case)
    print(f"{case.title}: reference and limits in {time.perf_counter() - t0:.1f} s "
          f"({case.ref_note})", file=log, flush=True)


def run_case(case: Case, log: Any) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for way in MJ_WAYS:
        mw = MujocoWinder(case.scene, way)
        for integ in INTEGRATORS:
            for dt in case.dts:
                run = mw.run(case.t_end, dt, case.output_step, integ)
                row: dict[str, Any] = {"case": case.key, "way": way, "integrator": integ,
                                       "setting": dt, "cpu": run.cpu,
                                       "us_per_step": run.us_per_step, "steps": run.steps,
                                       "blowups": run.bad_qacc}
                if run.bad_qacc:
                    row["error"] = math.nan
                else:
                    e = errors(channels_of(run, case.channels), case.ref)
                    row.update(error=max(e.values()), errors=e)
                if case.lift_off:
                    row["lift_off"] = run.first_lift_off
                rows.append(row)
                print(f"  {way:9s} {integ:12s} dt {dt:8.2e}  {run.cpu:7.2f} s "
                      f"{run.us_per_step:6.2f} µs/step  error {row['error']:.2e}",
                      file=log, flush=True)
    for rtol in WINDER_RTOLS:
        try:
            res, cpu = simulate(case.scene, case, rtol)
        except winder.SimulationError as exc:
            print(f"  winder    DOPRI5       rtol {rtol:7.0e}  failed: {exc}", file=log)
            continue
        if cpu < 1.0:  # short runs: best of three against timer noise
            cpu = min([cpu] + [simulate(case.scene, case, rtol)[1] for _ in range(2)])
        e = errors(channels_of(res, case.channels), case.ref)
        rows.append({"case": case.key, "way": "winder", "integrator": "DOPRI5",
                     "setting": rtol, "cpu": cpu, "error": max(e.values()), "errors": e,
                     "nfev": res.meta["rhs_evaluations"]})
        print(f"  winder    DOPRI5       rtol {rtol:7.0e}  {cpu:7.3f} s  "
              f"error {max(e.values()):.2e}", file=log, flush=True)
    return rows


def winder_cpu_at(rows: list[dict[str, Any]], error: float) -> tuple[float, bool]:
    """winder's CPU time [s] to reach ``error``: log–log interpolation along the envelope
    of its work–precision line (the cheapest run at least that accurate). Returns
    ``(cpu, exact)``; ``exact`` is False when ``error`` is coarser than winder's loosest
    run, whose time is then returned (an upper bound)."""
    pts = sorted((r["error"], r["cpu"]) for r in rows if r["way"] == "winder")
    if error >= pts[-1][0]:
        return pts[-1][1], False
    errs = np.log([p[0] for p in pts])
    cost = np.minimum.accumulate(np.log([p[1] for p in pts]))
    return float(np.exp(np.interp(np.log(error), errs, cost))), True


def speed_ratios(cases: list[Case], rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """For each case: the most accurate run of way (b) and the CPU time winder needs for
    the same error; and the range of that ratio over all runs of way (b)."""
    out = []
    for c in cases:
        wr = [r for r in rows if r["case"] == c.key]
        mj = [r for r in wr if r["way"] == "corrected" and math.isfinite(r["error"])]
        if not mj:
            continue
        best = min(mj, key=lambda r: (r["error"], r["cpu"]))
        w, exact = winder_cpu_at(wr, max(best["error"], 1e-15))
        every = [r["cpu"] / winder_cpu_at(wr, max(r["error"], 1e-15))[0] for r in mj]
        out.append({"case": c.key, "title": c.title, "mj": best, "winder_cpu": w,
                    "exact": exact, "ratio": best["cpu"] / w,
                    "range": (min(every), max(every))})
    return out


def step_costs(rows: list[dict[str, Any]], cases: list[Case]) -> dict[str, Any]:
    contact = {c.key for c in cases if c.scene.effects.contact}
    out: dict[str, Any] = {}
    for integ in INTEGRATORS:
        us = [r["us_per_step"] for r in rows if r.get("integrator") == integ
              and r["case"] in contact]
        out[integ] = float(np.median(us)) if us else math.nan
    mw = MujocoWinder(cases[-1].scene, "corrected")
    out["bare"] = {integ: min(mw.bare_step_cost(integrator=integ) for _ in range(3))
                   for integ in INTEGRATORS}
    return out


# ---- output ----------------------------------------------------------------------------

def _fmt(x: float) -> str:
    return "∞" if x == math.inf else "–" if not math.isfinite(x) else f"{x:.1e}"


def headline(cases: list[Case], ratios: list[dict], costs: dict[str, Any]) -> list[str]:
    """The numbers the README quotes, as bullet lines."""
    out = []
    for c in cases:
        e = c.limits["overwrite"]["errors"]
        parts = ", ".join(f"{ch} {_fmt(e[ch])}" for ch in c.channels)
        fl = c.limits.get("overwrite+flux", {})
        extra = ""
        if "note" in fl:
            extra = f"; with the web flux added on top it {fl['note']}"
        elif fl:
            extra = ("; with the web flux added on top (double count): "
                     + ", ".join(f"{ch} {_fmt(fl['errors'][ch])}" for ch in c.channels))
        out.append(f"- {c.title}: the overwrite's plateau is {parts}{extra}.")
    rs = [q for q in ratios if q["mj"]["error"] > 1e-10]
    if rs:
        out.append("- At equal accuracy, MuJoCo with the missing term by hand took "
                   + ", ".join(f"{'≥ ' if not q['exact'] else ''}{q['ratio']:.0f}× "
                               f"({q['title'].split(',')[0]}, error {_fmt(q['mj']['error'])})"
                               for q in rs)
                   + " winder's CPU time.")
    out.append("- A MuJoCo step with the Python side: "
               + ", ".join(f"{k} {costs[k]:.1f} µs" for k in INTEGRATORS)
               + "; `mj_step` alone " + ", ".join(f"{k} {v:.1f} µs"
                                                   for k, v in costs["bare"].items()) + ".")
    return out


def write_markdown(cases: list[Case], rows: list[dict[str, Any]], ratios: list[dict],
                   costs: dict[str, Any], machine: str, total: tuple[float, float],
                   path: Path) -> None:
    """docs/peers.md; ``total`` is the study's (wall, CPU) time [s]."""
    L = ["# Side by side with MuJoCo: the mass overwrite, and what the missing term costs", "",
         "Regenerate with `make peers` (`benchmarks/peers/`, MuJoCo from pip: the `peers` "
         "extra). The MuJoCo model (`benchmarks/peers/mujoco_winder.py`) is written from the "
         "scene as MJCF: drum hinge about +y, roll on a slide along z with a hinge about −y "
         "([model.md](model.md) §1). The nip and the relaxed slip force are the laws of "
         "[model.md](model.md) §4 computed in Python "
         "and applied through `qfrc_applied` (MuJoCo's own contact is off), so the ways differ "
         "only in the mass terms. `tests/test_peers.py` holds the MuJoCo model to winder with "
         "the mass held constant, and checks the free-spin closed forms.", "",
         "- **(a) overwrite**: the roll's `body_mass` and `body_inertia` overwritten every "
         "step from the radius; nothing else. This is the zero-relative-velocity convention: "
         "the paper silently arrives with the roll's own velocity, so the web flux is *not* "
         "added (on top of the overwrite it would count the arriving paper twice).",
         "- **(b) overwrite + −(∂M/∂r·ṙ) q̇**: the same plus the missing term of "
         "[model.md](model.md) §3 and the web flux `ṁ u`, by hand through `qfrc_applied`: "
         "the winder's equations.",
         "- **(c) winder**: `winder.simulate(method=\"DOPRI5\")` at rtol 1e-3 … 1e-9 "
         "(atol = rtol/100), the whole call.", "",
         "Times are this process's CPU time (`time.process_time`): the same as the wall time "
         "on an idle core for this single-threaded work, and not inflated when other "
         "processes share the machine.", "",
         "Errors: the largest deviation over the output grid, scaled by the channel's "
         "largest magnitude, against winder at rtol 1e-10 (against the closed form for free "
         "spin); the *error* column is the worst channel. The overwrite's h → 0 limit is "
         "winder's `variable_mass = false` mode ([model.md](model.md) §3), so its plateau "
         "below is exact. "
         f"Machine: {machine}; the whole study took {total[0] / 60:.1f} min "
         f"({total[1] / 60:.1f} min of CPU time).", "",
         "## Headline", "", *headline(cases, ratios, costs), "",
         "## The overwrite's error plateau (h → 0)", "",
         "| scene | channel | (a) overwrite | (a) + web flux (double count) | "
         "(a) finest MuJoCo run |", "|---|---|---|---|---|"]
    for c in cases:
        fin = [r for r in rows if r["case"] == c.key and r["way"] == "overwrite"
               and math.isfinite(r["error"])]
        finest = min(fin, key=lambda r: r["error"]) if fin else None
        for ch in c.channels:
            ow = c.limits["overwrite"]["errors"][ch]
            fl = c.limits.get("overwrite+flux", {}).get("errors", {}).get(ch, math.nan)
            fr = finest["errors"][ch] if finest else math.nan
            L.append(f"| {c.title} | {ch} | {_fmt(ow)} | {_fmt(fl)} | {_fmt(fr)} |")
    for c in cases:
        for name, lim in c.limits.items():
            if "note" in lim:
                L += ["", f"{c.title}, {name}: {lim['note']} (ω grows with J)."]
    L += ["", "With web momentum the web arrives at the drum's surface speed, and the roll's "
          "surface moves at nearly that speed: the overwrite's hidden assumption (paper "
          "arrives with the roll's velocity) is then almost right, and its plateau is far "
          "below the step-size error of any MuJoCo run here. Where the paper joins from rest "
          "(free spin, or a scene without web momentum), the overwrite is wrong by a fixed "
          "amount that no step size removes. Adding the web flux on top of the overwrite "
          "gives the large plateau on the scene with web momentum: the double count.", ""]
    lo = [c for c in cases if c.lift_off]
    for c in lo:
        L += [f"First lift-off ({c.title}): winder {c.ref_lift_off:.5f} s; overwrite limit "
              f"{c.limits['overwrite']['lift_off']:.5f} s"
              + (f"; overwrite + flux limit {c.limits['overwrite+flux']['lift_off']:.5f} s"
                 if "overwrite+flux" in c.limits else "") + ".", ""]
    rs = [q for q in ratios if q["mj"]["error"] > 1e-10]
    L += ["## Speed at equal accuracy", "",
          "Most accurate run of way (b) per scene, against winder's CPU time for the same "
          "error (interpolated along its work–precision line; ≥ where the MuJoCo error is "
          "coarser than winder's loosest run, at rtol 1e-2, whose time is then used).", "",
          "| scene | (b) run | error | MuJoCo [s] | winder [s] | ratio | "
          "ratio over all (b) runs |", "|---|---|---|---|---|---|---|"]
    for q in ratios:
        b = q["mj"]
        ratio = (f"{'' if q['exact'] else '≥ '}{q['ratio']:.0f}× | "
                 f"{q['range'][0]:.0f}–{q['range'][1]:.0f}×")
        if b["error"] < 1e-10:
            ratio = f"both exact to round-off | CPU ratio {q['range'][0]:.0f}–{q['range'][1]:.0f}×"
        L.append(f"| {q['title']} | {b['integrator']}, dt {b['setting']:.3g} s | "
                 f"{_fmt(b['error'])} | {b['cpu']:.3g} | {q['winder_cpu']:.3g} | {ratio} |")
    L += ["", "Cost of a MuJoCo step with the Python side (median over the runs with "
          "contact): " + ", ".join(f"{k} {costs[k]:.1f} µs" for k in INTEGRATORS)
          + "; `mj_step` alone: " + ", ".join(f"{k} {v:.1f} µs"
                                               for k, v in costs["bare"].items()) + ".", "",
          "With the forces and masses set from Python between steps, every MuJoCo integrator "
          "is first order here: `qfrc_applied` and the overwritten mass are held over a step, "
          "so RK4's four stages all see the start-of-step values; implicitfast treats only "
          "joint damping and actuator forces implicitly, and this model has none, so it "
          "gives Euler's numbers.", "",
          "## Where each is the better choice", "",
          "- **MuJoCo**: contact-rich 3D scenes, robots and many-body mechanisms with "
          "collisions and constraints, fixed-step real-time loops; and growing bodies whose "
          "new mass arrives at the body's own velocity (here: the web with its momentum, the "
          "free spin with the flux). There the bare overwrite is the right model and its "
          "error is the integrator's step error.",
          "- **winder**: mass that joins from rest or at another velocity (free spin, paper "
          "without web momentum), where the overwrite has an error that no step size "
          "removes; and machines that need converged results: with the mass terms and the "
          "nip inside one adaptive high-order integrator with located contact events, "
          "winder reached MuJoCo's best accuracy (with the missing term by hand) in "
          + (f"{min(q['ratio'] for q in rs):.0f}–{max(q['ratio'] for q in rs):.0f}× "
             if rs else "")
          + "less CPU time, and goes on to 1e-9.", ""]
    for c in cases:
        L += [f"## {c.title}", "", f"{c.note}. Reference: {c.ref_note}.", ""]
        if c.lift_off:
            L += [f"First lift-off: winder {c.ref_lift_off:.5f} s. The MuJoCo column gives "
                  "the start of the first step with zero normal force (– if none).", ""]
        head = "| way | integrator | dt / rtol | CPU [s] | µs/step | error | " + \
            " | ".join(c.channels) + (" | lift-off [s]" if c.lift_off else "") + " |"
        L += [head, "|" + "---|" * (6 + len(c.channels) + int(c.lift_off))]
        for r in rows:
            if r["case"] != c.key:
                continue
            us = f"{r['us_per_step']:.1f}" if "us_per_step" in r else "–"
            setting = (f"{r['setting']:.0e}" if r["way"] == "winder"
                       else f"{r['setting']:.3g} s")
            if not math.isfinite(r["error"]):
                cells = ["blew up"] + [""] * len(c.channels)
            else:
                cells = [_fmt(r["error"])] + [_fmt(r["errors"][ch]) for ch in c.channels]
            lift = ([f"{r['lift_off']:.5f}" if math.isfinite(r.get("lift_off", math.nan))
                     else "–"] if c.lift_off else [])
            L.append(f"| {LABEL[r['way']]} | {r['integrator']} | {setting} | "
                     f"{r['cpu']:.3g} | {us} | " + " | ".join(cells + lift) + " |")
        L.append("")
    path.write_text("\n".join(L), encoding="utf-8")


def plot(cases: list[Case], rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(16, 9.5))
    axes = axes.ravel()
    colour = {"overwrite": "tab:red", "corrected": "tab:blue", "winder": "black"}
    style = {"Euler": "o-", "RK4": "s--", "implicitfast": "^:", "DOPRI5": "D-"}
    floor = 1e-16
    for ax, c in zip(axes, cases, strict=False):
        for way in (*MJ_WAYS, "winder"):
            for integ in (*INTEGRATORS, "DOPRI5"):
                # along the line of settings (coarse to fine), not sorted by time
                pts = sorted((-r["setting"], r["cpu"], max(r["error"], floor)) for r in rows
                              if r["case"] == c.key and r["way"] == way
                              and r["integrator"] == integ and math.isfinite(r["error"]))
                if pts:
                    _, x, y = zip(*pts, strict=True)
                    lab = LABEL[way] if way == "winder" else f"{LABEL[way]}, {integ}"
                    ax.loglog(x, y, style[integ], color=colour[way], label=lab, ms=5,
                              alpha=0.85)
        lim = max(c.limits["overwrite"]["errors"].values())
        if lim > floor:
            ax.axhline(lim, color="tab:red", lw=1, alpha=0.6)
            ax.annotate("(a) overwrite, h → 0", (0.02, lim), xycoords=("axes fraction", "data"),
                        color="tab:red", fontsize=8, va="bottom")
        exact = all(r["error"] < 1e-10 for r in rows
                    if r["case"] == c.key and math.isfinite(r["error"]))
        ax.set_title(c.title + ("\n(every way exact to round-off)" if exact else ""),
                     fontsize=10)
        ax.set_xlabel("CPU time of the run [s]")
        ax.set_ylabel("worst channel, scaled max error [-]")
        ax.grid(True, which="both", alpha=0.3)
    handles: dict[str, Any] = {}
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    axes[-1].axis("off")
    axes[-1].legend(handles.values(), handles.keys(), loc="center", fontsize=9)
    fig.suptitle("MuJoCo with the mass overwritten (a), with the missing term by hand (b), "
                 "and winder (c): error against CPU time")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


CACHE_KEYS = ("key", "title", "t_end", "output_step", "dts", "channels", "note", "lift_off",
              "ref_note", "ref_lift_off", "limits")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true",
                    help="short windows and fewer steps (a check, not the committed table)")
    ap.add_argument("--out", type=Path, default=DOCS, help="output folder (default docs/)")
    ap.add_argument("--replot", action="store_true",
                    help="rewrite the table and plot from the last run's out/peers.json")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    cache = ROOT / "out" / "peers.json"
    if args.replot:
        data = json.loads(cache.read_text(encoding="utf-8"))
        cases = [Case(scene=None, **c) for c in data["cases"]]  # type: ignore[arg-type]
        rows, costs, machine, total = (data[k] for k in ("rows", "costs", "machine", "total"))
    else:
        t0, c0 = time.perf_counter(), CLOCK()
        log = sys.stderr
        cases = build_cases(args.quick)
        winder.simulate(cases[-1].scene, t_end=0.1)  # compile and warm up
        rows = []
        for c in cases:
            reference(c, log)
            rows += run_case(c, log)
        costs = step_costs(rows, cases)
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
        machine = (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores "
                   f"(load average {load:.1f} at the end), Python "
                   f"{platform.python_version()}, MuJoCo {mujoco.__version__}")
        total = (time.perf_counter() - t0, CLOCK() - c0)
        cache.parent.mkdir(exist_ok=True)
        cache.write_text(json.dumps({
            "cases": [{k: getattr(c, k) for k in CACHE_KEYS} for c in cases], "rows": rows,
            "costs": costs, "machine": machine, "total": total}, indent=1), encoding="utf-8")
    ratios = speed_ratios(cases, rows)
    write_markdown(cases, rows, ratios, costs, machine, total, args.out / "peers.md")
    plot(cases, rows, args.out / "peers.png")
    print(f"wrote {args.out / 'peers.md'} and {args.out / 'peers.png'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
