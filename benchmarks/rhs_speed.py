"""Measure µs per right-hand side evaluation of the paper scene (all effects on), for the
compiled planar backend and the Pinocchio backend."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

import winder
from winder import WinderSystem
from winder._planar import PlanarSystem


def _time(f, y: np.ndarray, n: int) -> float:
    for _ in range(1000):
        f(1.0, y)
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            f(1.0, y)
        best = min(best, (time.perf_counter() - t0) / n * 1e6)
    return best


def main() -> dict[str, float]:
    scene = winder.load_scene(Path(__file__).resolve().parents[1] / "models"
                              / "paper_winding.toml")
    system = WinderSystem(scene)
    planar = PlanarSystem(scene, system)
    y = system.initial_state()
    y[3] = 50.0
    out = {"compiled": _time(planar.rhs, y, 200_000), "pinocchio": _time(system.rhs, y, 20_000)}
    for name, us in out.items():
        print(f"RHS ({name} backend): {us:.2f} µs per evaluation (best of 5)")
    return out


if __name__ == "__main__":
    main()
