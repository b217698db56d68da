"""The speed target of ``winder fit`` (issue 35): 2 nip parameters (contact stiffness and
damping) of the single-drum winder ``models/paper_winding.toml`` fitted to 3,500 samples
of 2 channels (the roll's vertical position ``z`` and the nip's ``normal_force``) over the
first 7 s of its run-up, within 30 s.

The record is synthetic: the scene's run-up (``winder.simulate``, DOP853 at rtol 1e-10)
sampled every 2 ms with Gaussian noise (σ_z = 1 µm, σ_F = 2 N; fixed seed); the fit
starts from stiffness × 1.3 and damping × 0.75 with the noise estimated. Prints the wall
time, the evaluations, where the time goes (the first simulation with sensitivities, one
without), the estimates against the truth with their intervals.

Run: ``python benchmarks/fit_speed.py [--rtol R]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import winder
from winder.analysis.fit_model import ForwardModel, scene_with

MODEL = Path(__file__).resolve().parents[1] / "models" / "paper_winding.toml"
TRUE = {"contact.stiffness": 2e7, "contact.damping": 2e4}
SIGMA = {"z": 1e-6, "normal_force": 2.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rtol", type=float, default=1e-8)
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
    start = time.perf_counter()
    res = winder.fit(guess, data, list(TRUE), rtol=args.rtol)
    wall = time.perf_counter() - start
    print(res.table())
    for k, v in TRUE.items():
        j = res.keys.index(k)
        lo, hi = res.ci95[j]
        print(f"  {k}: truth {v:.6g}, estimate {res[k]:.6g} ({res[k] / v - 1:+.2e}), "
              f"95 % [{lo:.6g}, {hi:.6g}] {'holds' if lo <= v <= hi else 'MISSES'} it")
    print("sigma estimated: " + ", ".join(f"{c} {s:.3g}" for c, s in res.sigma.items()))
    print(f"fit: {wall:.1f} s wall ({res.evaluations} evaluations with sensitivities, "
          f"{res.iterations} iterations), target 30 s: {'met' if wall < 30 else 'MISSED'}")


if __name__ == "__main__":
    main()
