from __future__ import annotations

from pathlib import Path

import pytest

import winder

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


@pytest.fixture(scope="session")
def paper_scene() -> winder.Scene:
    return winder.load_scene(MODELS / "paper_winding.toml")


@pytest.fixture(scope="session")
def models_dir() -> Path:
    return MODELS


def random_states(system, rng, n: int):
    """``n`` random ``(t, y)`` around the initial state of a ``WinderSystem``: in and out
    of contact, any angle, speeds up to 300 rad/s, radii over the whole cycle."""
    import math

    y0 = system.initial_state()
    for _ in range(n):
        y = y0.copy()
        y[0] += rng.uniform(-2e-4, 5e-5)
        y[1] = rng.uniform(-math.pi, math.pi)
        y[2] = rng.normal(0, 0.05)
        y[3] = rng.uniform(-10, 300)
        y[4] = rng.uniform(0.075, 0.85)
        y[5:] = rng.normal(0, 200, len(y) - 5)
        yield rng.uniform(0, 60), y
