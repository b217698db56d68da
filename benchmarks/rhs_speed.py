"""Measure µs per right-hand side evaluation of the paper scene (all effects on)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import winder
from winder import WinderSystem


def main(n: int = 20_000) -> float:
    scene = winder.load_scene(Path(__file__).resolve().parents[1] / "models" / "paper_winding.toml")
    system = WinderSystem(scene)
    y = system.initial_state()
    y[3] = 50.0
    for _ in range(1000):
        system.rhs(1.0, y)
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            system.rhs(1.0, y)
        best = min(best, (time.perf_counter() - t0) / n * 1e6)
    print(f"RHS: {best:.1f} µs per evaluation (best of 5 × {n})")
    return best


if __name__ == "__main__":
    main()
