"""``scene_toml``: every shipped scene written as TOML reads back as the same scene."""

from __future__ import annotations

import tomllib

import pytest

import winder
from winder.scene.write import scene_toml


@pytest.mark.parametrize("name", ["paper_winding", "two_drum_winder", "winder_line",
                                  "two_drum_winder_flexible"])
def test_round_trip(models_dir, name):
    scene = winder.load_scene(models_dir / f"{name}.toml")
    back = winder.scene_from_dict(tomllib.loads(scene_toml(scene)))
    assert back.to_dict() == scene.to_dict()
