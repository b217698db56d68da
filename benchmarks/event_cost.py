"""What the located contact events cost on the whole two-drum cycle, rigid and flexible
(issue #33; writes docs/event_cost.md and .json).

Both machines run their whole cycle (414.5 s, the compiled DOPRI5 at rtol 1e-6, sampled
every 0.25 s, in chunks of ``CHUNK`` evaluations as ``simulate`` runs them) with the
kernel's 8 counters (``docs/c-integrators.md``): right-hand-side evaluations, accepted
and rejected steps, located events, switching-function evaluations (all, and in the
events' root finding) and root findings. The cost of an evaluation of the generated
``rhs`` and ``sw`` (thread CPU time in the library's C loop, the median over states of the
run, each the best of 5 loops) turns the counts into time. The counts are exact and
load-free; the unit costs carry the shared machine's load (their ratio less so).

Before this change (20d06c2) every step evaluated its start's switches again and every
located event probed its step's dense output at 64 points: there the switches were
evaluated ``calls + 2·accepted + 65·events + samples`` times outside the root finding
(now ``2·calls + accepted + 2·events + samples``; ``tests/solve/test_event_cost.py``);
the other counts are unchanged (the same steps, bit for bit).

Run:  python benchmarks/event_cost.py [--t-end 414.5]
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import winder
from winder.io.files import atomic_write_all
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SCENES = {"rigid": "two_drum_winder", "flexible": "two_drum_winder_flexible"}
COUNTERS = ("nfev", "accepted", "rejected", "events", "stiff", "sw", "sw_locate", "locates")


def _unit_costs(system: MachineSystem, t: np.ndarray, Y: np.ndarray) -> dict[str, float]:
    """µs per evaluation of the generated rhs and sw: the median over 20 states of the
    run of the best of 5 loops, thread CPU time."""
    lib, out = system.kernels, np.empty(max(system.n_states, system.kernels.n_switches))
    costs: dict[str, list[float]] = {"rhs": [], "sw": []}
    for i in np.linspace(0, len(t) - 1, 20).astype(int):
        y = np.ascontiguousarray(Y[:, i])
        m = system.modes.copy()
        lib.modes(system.fns, system.table, float(t[i]), y, system.params, m,
                  contact_auto=False)
        for name, which, count in (("rhs", integ.F_RHS, 2000), ("sw", integ.F_SW, 2000)):
            best = math.inf
            for _ in range(5):
                c0 = time.thread_time()
                lib.repeat(system.fns, which, count, float(t[i]), y, system.params, m, out)
                best = min(best, time.thread_time() - c0)
            costs[name].append(best / count * 1e6)
    return {k: float(np.median(v)) for k, v in costs.items()}


def run(name: str, t_end: float) -> dict:
    scene = winder.load_scene(ROOT / "models" / f"{name}.toml")
    winder.simulate(scene, t_end=1e-3, rtol=1e-6)  # build and balance outside the timing
    system = MachineSystem(scene)
    y, m = system.initial_state(), system.modes.copy()
    t_out = np.arange(0.0, t_end + 1e-9, 0.25)
    Y = np.empty((len(y), len(t_out)))
    stats = np.zeros(len(COUNTERS), dtype=np.int64)
    t, h, k, calls = 0.0, 0.0, 0, 0
    breaks = sorted({b for b in system.breakpoints if 0.0 < b < t_end} | {t_end})
    c0 = time.thread_time()
    for tb in breaks:
        while t < tb:
            status, t, h, k = system.kernels.dopri5(
                system.fns, system.table, t, tb, y, system.params, m, 1e-6,
                scene.solver.atol, h, math.inf, t_out, Y, k, integ.CHUNK, stats)
            calls += 1
            if status not in (integ.DONE, integ.PAUSED):
                raise SystemExit(f"{name}: status {status} at t = {t}")
    cpu = time.thread_time() - c0
    c = dict(zip(COUNTERS, map(int, stats), strict=True))
    samples = int(k)
    before = calls + 2 * c["accepted"] + 65 * c["events"] + samples
    unit = _unit_costs(system, t_out, Y)
    radius = float(Y[system.index("set.radius"), -1])
    return {"scene": name, "cpu": cpu, "calls": calls, "samples": samples, **c,
            "sw_outside_locate": c["sw"] - c["sw_locate"], "sw_before": before + c["sw_locate"],
            "rhs_us": unit["rhs"], "sw_us": unit["sw"], "final_radius": radius,
            "n_switches": int(system.kernels.n_switches), "slots": int(system.table.shape[0])}


def _share(r: dict, sw: int) -> float:
    """The switches' time as a fraction of the rhs evaluations' (from the unit costs)."""
    return sw * r["sw_us"] / (r["nfev"] * r["rhs_us"])


def write(data: dict) -> None:
    lines = [
        "# What the contact events cost: the whole two-drum cycle", "",
        f"`python benchmarks/event_cost.py`: both machines over {data['t_end']:g} s, the "
        "compiled DOPRI5 at rtol 1e-6, sampled every 0.25 s, with the kernel's counters "
        "(exact, load-free); µs per evaluation: thread CPU time in the library's C loop, "
        "median over 20 states of the run (the shared 2-core machine's load is in them).", "",
        "| | rigid | flexible (8 segments each) |", "|---|---|---|"]
    r, f = data["runs"]["rigid"], data["runs"]["flexible"]

    def row(label: str, fmt: str, key: str | None = None, fn=None) -> None:  # noqa: ANN001
        a = fn(r) if fn else r[key]
        b = fn(f) if fn else f[key]
        lines.append(f"| {label} | {fmt.format(a)} | {fmt.format(b)} |")

    row("mode slots (contact slices and cores) / switching functions", "{}",
        fn=lambda x: f"{x['slots']} / {x['n_switches']}")
    row("rhs evaluations", "{:,}", "nfev")
    row("accepted / rejected steps", "{}", fn=lambda x: f"{x['accepted']:,} / "
        f"{x['rejected']:,}")
    row("located events (each: a step cut there, one rhs evaluation)", "{:,}", "events")
    row("root findings (candidate switches in accepted steps)", "{:,}", "locates")
    row("sw evaluations in the root finding (per finding)", "{}",
        fn=lambda x: f"{x['sw_locate']:,} ({x['sw_locate'] / max(x['locates'], 1):.1f})")
    row("sw evaluations, all: before (20d06c2) → now", "{}",
        fn=lambda x: f"{x['sw_before']:,} → {x['sw']:,}")
    row("µs per rhs / per sw evaluation", "{}",
        fn=lambda x: f"{x['rhs_us']:.3f} / {x['sw_us']:.3f}")
    row("the switches' time ÷ the rhs evaluations': before → now", "{}",
        fn=lambda x: f"{100 * _share(x, x['sw_before']):.1f} % → {100 * _share(x, x['sw']):.1f} %")
    row("the events' restarts (one rhs each) ÷ the rhs evaluations", "{}",
        fn=lambda x: f"{100 * x['events'] / x['nfev']:.2f} %")
    row("the cut steps' part after their event (at most 6 evaluations an event) ÷ the rhs "
        "evaluations", "{}", fn=lambda x: f"≤ {100 * 6 * x['events'] / x['nfev']:.2f} %")
    row("the root finding ÷ the rhs evaluations' time", "{}",
        fn=lambda x: f"{100 * _share(x, x['sw_locate']):.2f} %")
    row("integration, thread CPU [s]", "{:.1f}", "cpu")
    row("final set radius [m]", "{:.6f}", "final_radius")
    lines += ["", data["note"]]
    md = "\n".join(lines) + "\n"
    js = json.dumps(data, indent=1)
    atomic_write_all([(DOCS / "event_cost.md", lambda p: Path(p).write_text(md)),
                      (DOCS / "event_cost.json", lambda p: Path(p).write_text(js))])
    print(md)


NOTE = (
    "Each located event costs the part of its step after it (at most a whole step, 6 "
    "evaluations), one rhs evaluation (the new mode's first stage) and its root finding: "
    "together under 1 % of either cycle's evaluations. Sharing the event handling of a "
    "nip's slices (one switching function per nip, or no restart where the force is "
    "continuous, as at lift-off) could save only part of that; the flexible cycle's cost "
    "is its evaluations, its steps limited by the bodies' fast modes (the rejected steps' "
    "share: a stiff method's case, not the events'). Before, each located event also "
    "evaluated the switches at 64 points of its step for nothing, and each step evaluated "
    "its start's switches again: both gone, with the same steps bit for bit.")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=414.5, help="simulated time [s]")
    ap.add_argument("--rewrite", action="store_true",
                    help="rewrite docs/event_cost.md from docs/event_cost.json (no runs)")
    args = ap.parse_args(argv)
    if args.rewrite:
        data = json.loads((DOCS / "event_cost.json").read_text())
        write({**data, "note": NOTE})
        return 0
    runs = {label: run(name, args.t_end) for label, name in SCENES.items()}
    write({"t_end": args.t_end, "runs": runs, "note": NOTE})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
