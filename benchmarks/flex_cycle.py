"""The whole two-drum cycle with 8-segment drums, rider and set against the rigid machine
(issue #25; writes docs/flex_cycle.md and .json).

Both machines (``models/two_drum_winder.toml`` and ``models/two_drum_winder_flexible.toml``)
run their whole cycle, 414.5 s, with the compiled DOPRI5 at rtol 1e-6, sampled every
0.25 s. Reported: wall time of the integration, right-hand-side evaluations, located
contact events, and what the flexible machine shows that the rigid one cannot: the line
load's spread along each nip (``(max − min)/mean``, its largest over the run and at the
end), the drums' twist, the drums' and the set's largest mid-span deflection, and the
difference of the set's final radius and the nips' mean total force from the rigid run.

``--methods``: instead, the integrators side by side (DOPRI5, RODAS4, RODAS3, ROS34PW2)
on the first ``--window`` seconds, their work–precision diagram and what
``method="auto"`` picks per shipped scene (``benchmarks/flex_methods.py``, writes
docs/flex_methods.*).

Run:  python benchmarks/flex_cycle.py [--t-end 414.5] [--methods [--window 20]]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import winder
from winder.io.files import atomic_write_all

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
NIPS = ("front_nip", "rear_nip", "rider_nip")


def _run(name: str, t_end: float) -> tuple[winder.Result, float]:
    scene = winder.load_scene(ROOT / "models" / f"{name}.toml")
    winder.simulate(scene, t_end=1e-3, rtol=1e-6)  # compile and balance outside the timing
    t0 = time.perf_counter()
    res = winder.simulate(scene, t_end=t_end, rtol=1e-6, output_step=0.25, progress=True)
    return res, time.perf_counter() - t0


def _midspan(res: winder.Result, body: str, axis: str) -> float:
    """Largest |mid-span − mean of the two ends| of ``body``'s segment ``axis`` [m]."""
    segs = sorted(int(k.split("_s")[1].split("_")[0]) for k in res
                  if k.startswith(f"{body}_s") and k.endswith(f"_{axis}"))
    if not segs:
        return 0.0
    mid = np.mean([res[f"{body}_s{i}_{axis}"] for i in segs[len(segs) // 2 - 1:
                                                            len(segs) // 2 + 1]], axis=0)
    ends = 0.5 * (res[f"{body}_s{segs[0]}_{axis}"] + res[f"{body}_s{segs[-1]}_{axis}"])
    return float(np.max(np.abs(mid - ends)))


def measure(t_end: float) -> dict:
    rigid, w_rigid = _run("two_drum_winder", t_end)
    flex, w_flex = _run("two_drum_winder_flexible", t_end)
    out = {"t_end": t_end, "rtol": 1e-6, "runs": {}}
    for name, res, wall in (("rigid", rigid, w_rigid), ("flexible", flex, w_flex)):
        out["runs"][name] = {"wall": wall, "rhs": int(res.meta["rhs_evaluations"]),
                             "events": int(res.meta["events"]),
                             "final_radius": float(res["set_radius"][-1])}
    spread = {}
    for nip in NIPS:
        lo, hi, mean = (flex[f"{nip}_line_load_{k}"] for k in ("min", "max", "mean"))
        loaded = mean > 0.05 * np.max(mean)
        s = np.where(loaded, (hi - lo) / np.where(loaded, mean, 1.0), 0.0)
        k = int(np.argmax(s))
        spread[nip] = {"max": float(s[k]), "at_t": float(flex.t[k]),
                       "at_radius": float(flex["set_radius"][k]), "end": float(s[-1])}
    out["line_load_spread"] = spread
    out["twist"] = {d: float(np.max(np.abs(flex[f"{d}_twist"]))) for d in ("front", "rear")}
    out["midspan"] = {f"{b}.{a}": _midspan(flex, b, a) for b in ("front", "rear", "set")
                      for a in ("x", "z")}
    out["vs_rigid"] = {
        "final_radius": float(flex["set_radius"][-1] - rigid["set_radius"][-1]),
        **{f"{nip}_mean_force": float(np.mean(flex[f"{nip}_normal_force"])
                                      / np.mean(rigid[f"{nip}_normal_force"]) - 1.0)
           for nip in NIPS}}
    return out


def write(data: dict) -> None:
    r, f = data["runs"]["rigid"], data["runs"]["flexible"]
    lines = [
        "# The whole two-drum cycle, flexible against rigid", "",
        f"`python benchmarks/flex_cycle.py`: both machines over {data['t_end']:g} s with the "
        f"compiled DOPRI5 at rtol {data['rtol']:g}, sampled every 0.25 s (compile and static "
        "balance outside the timing), on the shared 2-core machine.", "",
        "| machine | wall [s] | rhs evaluations | contact events | final set radius [m] |",
        "|---|---|---|---|---|",
        f"| rigid | {r['wall']:.1f} | {r['rhs']:,} | {r['events']} | {r['final_radius']:.6f} |",
        f"| flexible (8 segments each: drums, rider, set) | {f['wall']:.1f} | {f['rhs']:,} | "
        f"{f['events']} | {f['final_radius']:.6f} |", "",
        "What the flexible machine shows that the rigid one cannot:", "",
        "| nip | largest line-load spread (max − min)/mean | at t [s] | set radius [m] | "
        "at the end |", "|---|---|---|---|---|"]
    for nip, s in data["line_load_spread"].items():
        lines.append(f"| {nip} | {100 * s['max']:.2f} % | {s['at_t']:.2f} | "
                     f"{s['at_radius']:.3f} | {100 * s['end']:.2f} % |")
    lines += ["", "| quantity | largest over the cycle |", "|---|---|"]
    for d, v in data["twist"].items():
        lines.append(f"| {d} drum twist | {v:.3e} rad |")
    for k, v in data["midspan"].items():
        lines.append(f"| {k} mid-span deflection (from its ends' mean) | {v * 1e3:.4f} mm |")
    vr = data["vs_rigid"]
    lines += ["", f"Flexible minus rigid: final set radius {vr['final_radius']:.3e} m; mean "
              "normal force " + ", ".join(f"{n} {100 * vr[f'{n}_mean_force']:+.3f} %"
                                           for n in NIPS) + "."]
    md = "\n".join(lines) + "\n"
    js = json.dumps(data, indent=1)
    atomic_write_all([(DOCS / "flex_cycle.md", lambda p: Path(p).write_text(md)),
                      (DOCS / "flex_cycle.json", lambda p: Path(p).write_text(js))])
    print(md)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=414.5, help="simulated time [s]")
    ap.add_argument("--methods", action="store_true",
                    help="the integrators side by side, work–precision, auto's picks")
    ap.add_argument("--window", type=float, default=20.0,
                    help="--methods: the window of the cycle run side by side [s]")
    args = ap.parse_args(argv)
    if args.methods:
        import flex_methods  # beside this file

        flex_methods.main(args.window)
        return 0
    write(measure(args.t_end))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
