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
