"""The speed target of ``winder fit`` (issue 35): 2 nip parameters (contact stiffness and
damping) of the single-drum winder ``models/paper_winding.toml`` fitted to 3,500 samples
of 2 channels (the roll's vertical position ``z`` and the nip's ``normal_force``) over the
first 7 s of its run-up, within 30 s.

The record is synthetic: the scene's run-up (``winder.simulate``, DOP853 at rtol 1e-10)
sampled every 2 ms with Gaussian noise (σ_z = 1 µm, σ_F = 2 N; fixed seed); the fit
starts from stiffness × 1.3 and damping × 0.75 with the noise estimated. Prints the wall
time, the evaluations, where the time goes (the first simulation with sensitivities, one
without), the estimates against the truth with their intervals; then the cost of one
simulation of the two-drum winder's first 0.5 s with and without the sensitivities of two
keys (a machine from parts). Writes all of it to ``docs/fit_speed.json`` (``--json``),
from which ``benchmarks/doc_numbers.py`` fills the calibration page's numbers.

Run: ``python benchmarks/fit_speed.py [--rtol R] [--json docs/fit_speed.json]``.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import winder
from winder.analysis.fit_model import ForwardModel, scene_with

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "paper_winding.toml"
TWO_DRUM = ROOT / "models" / "two_drum_winder.toml"
TWO_DRUM_KEYS = ["nip.front_nip.contact.stiffness", "nip.rider_nip.contact.damping"]
TWO_DRUM_CHANNELS = ["set_z", "front_nip_normal_force", "rider_nip_normal_force"]
TRUE = {"contact.stiffness": 2e7, "contact.damping": 2e4}
SIGMA = {"z": 1e-6, "normal_force": 2.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, default=1e-8)
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "fit_speed.json",
                    help="where the numbers go (default docs/fit_speed.json)")
    args = ap.parse_args()
    scene = winder.load_scene(MODEL)
    run = winder.simulate(scene, t_end=7.0, rtol=1e-10, atol=1e-12, output_step=0.002,
                          method="DOP853")
    rng = np.random.default_rng(35)
    keep = run.t > 0
    data = {"t": run.t[keep]}
    for name, s in SIGMA.items():
        data[f"{name} [{run.units[name]}]"] = run[name][keep] + rng.normal(0, s, keep.sum())
    guess = scene_with(scene, {"contact.stiffness": 2.6e7, "contact.damping": 1.5e4})
    n = int(keep.sum())
    print(f"record: {n} samples of {len(SIGMA)} channels over {data['t'][-1]:.3g} s")
    start = time.perf_counter()
    model = ForwardModel(guess, list(TRUE), list(SIGMA), data["t"], rtol=args.rtol)
    build = time.perf_counter() - start
    start = time.perf_counter()
    model.evaluate(model.theta0)
    with_s = time.perf_counter() - start
    start = time.perf_counter()
    model.evaluate(model.theta0, sensitivities=False, check=False)
    without = time.perf_counter() - start
    print(f"build {build:.2f} s; one simulation with sensitivities {with_s:.2f} s, "
          f"without {without:.2f} s (rtol {args.rtol:g})")
    start, cpu = time.perf_counter(), time.process_time()
    res = winder.fit(guess, data, list(TRUE), rtol=args.rtol)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    print(res.table())
    for k, v in TRUE.items():
        j = res.keys.index(k)
        lo, hi = res.ci95[j]
        print(f"  {k}: truth {v:.6g}, estimate {res[k]:.6g} ({res[k] / v - 1:+.2e}), "
              f"95 % [{lo:.6g}, {hi:.6g}] {'holds' if lo <= v <= hi else 'MISSES'} it")
    print("sigma estimated: " + ", ".join(f"{c} {s:.3g}" for c, s in res.sigma.items()))
    print(f"fit: {wall:.1f} s wall, {cpu:.1f} s CPU ({res.evaluations} evaluations with "
          f"sensitivities, {res.iterations} iterations), target 30 s: "
          f"{'met' if wall < 30 else 'MISSED'}")
    two = two_drum_cost(args.rtol)
    print(f"two-drum winder, {two['t_end']:g} s: one simulation with sensitivities "
          f"{two['with_sensitivities']:.2f} s, without {two['without']:.2f} s")
    out = {"samples": n, "channels": len(SIGMA), "window": float(data["t"][-1]),
           "rtol": args.rtol, "build": build, "with_sensitivities": with_s,
           "without": without, "wall": wall, "cpu": cpu, "evaluations": res.evaluations,
           "iterations": res.iterations, "load": os.getloadavg()[0], "two_drum": two}
    args.json.write_text(json.dumps(out, indent=1) + "\n", "utf-8")
    print(f"{args.json}: written")


def two_drum_cost(rtol: float, t_end: float = 0.5) -> dict:
    """One simulation of the two-drum winder's first ``t_end`` [s] (samples every 2 ms)
    with the sensitivities of two nip keys, and one without [s wall]."""
    scene = winder.load_scene(TWO_DRUM)
    t = np.arange(1, int(round(t_end / 0.002)) + 1) * 0.002
    model = ForwardModel(scene, TWO_DRUM_KEYS, TWO_DRUM_CHANNELS, t, rtol=rtol)
    model.evaluate(model.theta0)  # the first call builds the integrator
    start = time.perf_counter()
    model.evaluate(model.theta0)
    with_s = time.perf_counter() - start
    start = time.perf_counter()
    model.evaluate(model.theta0, sensitivities=False, check=False)
    without = time.perf_counter() - start
    return {"t_end": t_end, "states": len(model.system.machine.state_names),
            "with_sensitivities": with_s, "without": without}


if __name__ == "__main__":
    main()
