"""Success rate of the operating point and of the static balance over random valid scenes.

Samples (fixed seed) the single-drum paper scene and the two-drum winder with random nip laws
(linear or Hunt–Crossley, stiffness 1e6 … 1e11 N/m log-uniform, exponent 1 … 2, damping),
effects on/off (slip relaxation, web momentum, variable mass) and radii of the wound roll
across its range, and counts for each of ``winder.operating_point`` (at that radius) and the
static balance of the initial state (that radius as ``initial_radius``):

- ``ok``: solved;
- ``refused``: refused because the nip is too soft to carry its load (the closed-form static
  penetration exceeds a radius: no valid scene in fact), naming the stiffness key;
- ``saturated``: no operating point because a nip's friction saturates (``|v_s| > 2 v_ref``
  at the last iterate: the nip cannot carry the roll's torque, e.g. web momentum without
  the variable-mass term near the core);
- ``failed``: any other refusal or error (a valid scene the solver could not handle).

Run: ``python benchmarks/balance_robustness.py [--samples N] [--seed S]``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections import Counter
from pathlib import Path

import numpy as np

import winder
from winder.analysis.modes import operating_point

MODELS = Path(__file__).resolve().parents[1] / "models"


def _contact(rng: np.random.Generator) -> dict:
    k = float(10 ** rng.uniform(6, 11))
    if rng.random() < 0.5:
        return {"law": "linear", "stiffness": k, "damping": float(rng.uniform(0, 5e4))}
    return {"law": "hunt_crossley", "stiffness": k, "exponent": float(rng.uniform(1, 2)),
            "hc_damping": float(rng.uniform(0, 1))}


def _effects(rng: np.random.Generator) -> dict:
    return {k: bool(rng.random() < 0.5) for k in ("slip_relaxation", "web_momentum",
                                                  "variable_mass")}


def _single(rng: np.random.Generator, base: winder.Scene) -> tuple[winder.Scene, float]:
    r = float(rng.uniform(0.075, 0.8))
    return base.replace(contact=_contact(rng), effects=_effects(rng)), r


def _two_drum(rng: np.random.Generator, base: winder.Scene) -> tuple[winder.Scene, float]:
    r = float(rng.uniform(0.05, 0.6))
    which = rng.integers(3)  # all nips alike, only the rider nip, each its own law
    c = _contact(rng)
    nips = {}
    for name in ("front_nip", "rear_nip", "rider_nip"):
        if which == 2:
            c = _contact(rng)
        if which != 1 or name == "rider_nip":
            nips[name] = {"contact": c}
    return base.replace(nip=nips, effects=_effects(rng)), r


def _with_radius(scene: winder.Scene, r: float) -> winder.Scene:
    if scene.legacy:
        return scene.replace(roll={"initial_radius": r})
    return scene.replace(roll={"set": {"initial_radius": r}})


def _classify(exc: BaseException) -> str:
    text = str(exc)
    if "too soft" in text and "stiffness" in text:
        return "refused"
    return "saturated" if "friction saturated" in text else "failed"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=100, help="scenes per machine (default 100)")
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("-v", "--verbose", action="store_true", help="print every failure")
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    bases = {"single": winder.load_scene(MODELS / "paper_winding.toml"),
             "two_drum": winder.load_scene(MODELS / "two_drum_winder.toml")}
    counts: dict[tuple[str, str], Counter] = {}
    t0 = time.perf_counter()
    for kind, make in (("single", _single), ("two_drum", _two_drum)):
        for i in range(args.samples):
            try:
                scene, r = make(rng, bases[kind])
                static_scene = _with_radius(scene, r)
            except winder.SceneError as exc:  # not a valid scene: not sampled
                counts.setdefault((kind, "invalid"), Counter())["skipped"] += 1
                if args.verbose:
                    print(f"{kind} #{i}: invalid: {str(exc)[:200]}")
                continue
            for what in ("operating_point", "static_balance"):
                c = counts.setdefault((kind, what), Counter())
                try:
                    if what == "operating_point":
                        operating_point(scene, r)
                    else:
                        winder.MachineSystem(static_scene).initial_state()
                    c["ok"] += 1
                except Exception as exc:  # noqa: BLE001 - every way of failing is counted
                    c[_classify(exc)] += 1
                    if args.verbose:
                        nips = {n.name: n.contact for n in scene.nips}
                        print(f"{kind} #{i} {what} r={r!r}: {type(exc).__name__}: "
                              f"{str(exc)[:300]}\n    {scene.effects}\n    {nips}")
    for (kind, what), c in sorted(counts.items()):
        n = sum(c.values())
        if what == "invalid":
            print(f"{kind:9s} invalid scenes skipped: {n}")
            continue
        valid = c["ok"] + c["failed"] + c["saturated"]
        rate = c["ok"] / valid if valid else math.nan
        print(f"{kind:9s} {what:16s} ok {c['ok']:3d}  too soft {c['refused']:3d}  "
              f"saturated {c['saturated']:3d}  failed {c['failed']:3d}  "
              f"success {100 * rate:5.1f} % of {valid}")
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
