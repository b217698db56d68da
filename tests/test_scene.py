"""Scene validation (spec §7): every bad input is rejected naming key and file."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
import tomli_w

import winder


def _write(tmp_path: Path, models_dir: Path, edit) -> Path:
    data = tomllib.loads((models_dir / "paper_winding.toml").read_text())
    edit(data)
    p = tmp_path / "bad.toml"
    p.write_text(tomli_w.dumps(data))
    return p


@pytest.mark.parametrize("edit, pattern", [
    (lambda d: d["roll"].update(colour="red"), r"\[roll\] colour: unknown key; valid keys:"),
    (lambda d: d["drum"].pop("radius"), r"\[drum\] radius: missing required key"),
    (lambda d: d["paper"].update(caliper="thin"), r"\[paper\] caliper: expected a number"),
    (lambda d: d["paper"].update(caliper=0.0), r"\[paper\] caliper: must be > 0"),
    (lambda d: d["roll"].update(core_radius=-0.1), r"\[roll\] core_radius: must be > 0"),
    (lambda d: d["roll"].update(initial_radius=0.05), r"\[roll\] initial_radius: .*below"),
    (lambda d: d["drum"].update(inertia=float("nan")), r"\[drum\] inertia: must be finite"),
    (lambda d: d["effects"].update(gravity=1), r"\[effects\] gravity: expected true or false"),
    (lambda d: d["contact"].update(law="hertz"), r"\[contact\] law: 'hertz' is not one of"),
    (lambda d: d["drum"]["drive"].update(kind="belt"), r"kind: 'belt' is not one of"),
    (lambda d: d.update(extra={"a": 1}), r"\[extra\]: unknown table"),
    (lambda d: d.pop("paper"), r"\[paper\]: missing required table"),
    (lambda d: d["solver"].update(method="Euler"), r"method: 'Euler' is not one of"),
])
def test_bad_scene_names_key_and_file(tmp_path, models_dir, edit, pattern) -> None:
    path = _write(tmp_path, models_dir, edit)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        winder.load_scene(path)
    assert str(path) in str(info.value)


def test_not_toml_and_missing_file(tmp_path) -> None:
    p = tmp_path / "x.toml"
    p.write_text("[scene\nduration = 1")
    with pytest.raises(winder.SceneError, match="not valid TOML"):
        winder.load_scene(p)
    with pytest.raises(winder.SceneError, match="cannot read"):
        winder.load_scene(tmp_path / "missing.toml")


def test_all_shipped_scenes_load(models_dir) -> None:
    names = {p.stem for p in models_dir.glob("*.toml")}
    assert {"paper_winding", "paper_winding_no_web", "free_spin",
            "paper_winding_smooth"} <= names
    for p in models_dir.glob("*.toml"):
        assert winder.load_scene(p).name == p.stem


def test_paper_scene_values(paper_scene) -> None:
    s = paper_scene
    assert (s.drum.radius, s.drum.inertia, s.drum.mass) == (0.5, 400.0, 2000.0)
    assert (s.drum.drive.web_acceleration, s.drum.drive.web_speed) == (0.5, 20.0)
    assert (s.roll.core_radius, s.roll.core_mass, s.roll.core_inertia, s.roll.width,
            s.roll.com_offset) == (0.075, 30.0, 0.12, 2.0, 0.001)
    assert (s.paper.density, s.paper.caliper) == (800.0, 160e-6)
    assert (s.contact.law, s.contact.stiffness, s.contact.damping) == ("linear", 2e7, 2e4)
    assert (s.friction.mu, s.friction.slip_velocity, s.friction.relaxation_length,
            s.friction.min_speed) == (0.3, 0.05, 0.01, 0.1)
    assert s.scene.duration == 700.0 and s.effects.enabled() == winder.EFFECTS.keys() \
        or set(s.effects.enabled()) == set(winder.EFFECTS)


def test_replace_validates(paper_scene) -> None:
    s = paper_scene.replace(roll={"com_offset": 0.0}, drum={"drive": {"web_speed": 5.0}})
    assert s.roll.com_offset == 0.0 and s.drum.drive.web_speed == 5.0
    with pytest.raises(winder.SceneError, match="core_radius"):
        paper_scene.replace(roll={"core_radius": -1.0})
