"""Scene validation (spec §7): every bad input is rejected naming key and file."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
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
    assert s.scene.duration == 700.0
    assert s.effects.enabled() == winder.scene.EFFECT_NAMES  # all on, in spec order
    assert set(winder.FORCES) == set(winder.scene.EFFECT_NAMES)


def test_replace_validates(paper_scene) -> None:
    s = paper_scene.replace(roll={"com_offset": 0.0}, drum={"drive": {"web_speed": 5.0}})
    assert s.roll.com_offset == 0.0 and s.drum.drive.web_speed == 5.0
    with pytest.raises(winder.SceneError, match="core_radius"):
        paper_scene.replace(roll={"core_radius": -1.0})


def test_replace_argument_errors(paper_scene) -> None:
    with pytest.raises(winder.ArgumentTypeError, match=r"Scene.replace: roll must be a mapping "
                                                       r"of \[roll\] keys to values.*got 5"):
        paper_scene.replace(roll=5)
    with pytest.raises(winder.ArgumentTypeError, match=r"drum\['drive'\] must be a mapping"):
        paper_scene.replace(drum={"drive": 20.0})
    with pytest.raises(winder.ArgumentError, match=r"Scene.replace: rol is not a table of the "
                                                   r"scene; valid tables: scene, effects, "
                                                   r"drum, roll, paper, contact, friction, "
                                                   r"solver"):
        paper_scene.replace(rol={"width": 1.0})


# ---- files that are not scenes --------------------------------------------------------

@pytest.mark.parametrize("content, pattern", [
    ("name = 'Bäckerei'\n".encode("latin-1"), r"not UTF-8 text: byte 0xe4 at line 1"),
    ("[scene]\nname = 'x'\n".encode("utf-16"), r"UTF-16 text; a scene file must be UTF-8"),
    (bytes(range(256)) * 4, r"a binary file \(NUL byte at offset 0\)"),
    (b"PK\x03\x04" + bytes(100), r"a zip archive \(a .npz result\?\), not a TOML scene"),
    (b"x = " + b"[" * 100_000 + b"]" * 100_000, r"nested too deeply"),
    (b"[scene\nduration = 1", r"not valid TOML"),
    (b"x" * (2 << 20), r"larger than 1048576 bytes"),
])
def test_file_that_is_not_a_scene(tmp_path, content, pattern) -> None:
    p = tmp_path / "bad.toml"
    p.write_bytes(content)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        winder.load_scene(p)
    assert str(info.value).startswith(f"{p}: ")
    assert len(str(info.value)) < 400


def test_utf8_bom_is_read(tmp_path, models_dir) -> None:
    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + (models_dir / "paper_winding.toml").read_bytes())
    assert winder.load_scene(p).drum.radius == 0.5


def test_npz_result_given_as_scene(tmp_path) -> None:
    p = tmp_path / "result.npz"
    np.savez(p, t=np.arange(3.0))
    with pytest.raises(winder.SceneError, match=rf"{p}: a zip archive"):
        winder.load_scene(p)


def test_not_toml_and_missing_file_or_directory(tmp_path) -> None:
    with pytest.raises(winder.SceneError, match=rf"{tmp_path}: is a directory, not a scene"):
        winder.load_scene(tmp_path)
    with pytest.raises(winder.SceneError, match="missing.toml: cannot read scene file: No "
                                                "such file"):
        winder.load_scene(tmp_path / "missing.toml")
    with pytest.raises(winder.SceneError, match="cannot contain a NUL byte"):
        winder.load_scene("a\x00b.toml")
    with pytest.raises(winder.ArgumentTypeError, match="path must be a str or os.PathLike"):
        winder.load_scene(3)


# ---- values out of range and impossible combinations ---------------------------------

@pytest.mark.parametrize("table, key, value, pattern", [
    ("drum", "mass", 1e308, r"\[drum\] mass: must be > 0 and <= 1e\+06, got 1e\+308"),
    ("roll", "width", 1e300, r"\[roll\] width: must be > 0 and <= 100, got 1e\+300"),
    ("paper", "density", 1e9, r"\[paper\] density: must be >= 0 and <= 100000"),
    ("roll", "core_inertia", 1e30, r"\[roll\] core_inertia: must be > 0 and <= 1e\+07"),
    ("drum.drive", "torque", -1e20, r"\[drum.drive\] torque: must be \|value\| <= 1e\+08"),
    ("roll", "initial_speed", 10**400, r"initial_speed: must be finite, got 1000000000"),
    ("scene", "name", "x" * 100_000, r"\[scene\] name: 'xxx.*\(100000 characters\) is not a "
                                     r"plain name; valid: 1 to 200 printable characters"),
    ("scene", "name", "a\nb", r"name: 'a\\nb' is not a plain name"),
    ("contact", "law", "y" * 100_000, r"law: 'yyy.*\(100000 characters\) is not one of"),
    ("solver", "max_rhs", 1000.5, r"\[solver\] max_rhs: 1000.5 is not a whole number"),
    ("solver", "rtol", 2.0, r"\[solver\] rtol: must be > 0 and <= 0.1, got 2.0"),
    ("solver", "atol", 1e300, r"\[solver\] atol: must be > 0 and <= 0.001, got 1e\+300"),
])
def test_out_of_range_names_key_and_bound(tmp_path, models_dir, table, key, value,
                                          pattern) -> None:
    def edit(d):
        (d["drum"]["drive"] if table == "drum.drive" else d[table])[key] = value

    path = _write(tmp_path, models_dir, edit)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        winder.load_scene(path)
    assert str(info.value).startswith(f"{path}: [{table}] {key}: ")
    assert len(str(info.value)) < 400


@pytest.mark.parametrize("height", [0.5, 0.3, 0.0, -2.0])
def test_initial_height_inside_or_below_the_drum(tmp_path, models_dir, height) -> None:
    path = _write(tmp_path, models_dir, lambda d: d["roll"].update(initial_height=height))
    with pytest.raises(winder.SceneError, match=rf"\[roll\] initial_height: {height!r} m puts "
                                                r"the roll axis inside the drum or below it; "
                                                r"valid: > 0.5 m \(the drum radius"):
        winder.load_scene(path)
    ok = _write(tmp_path, models_dir, lambda d: d["roll"].update(initial_height=0.5 + 1e-9))
    assert winder.load_scene(ok).roll.initial_height == 0.5 + 1e-9


def test_com_offset_outside_the_core(tmp_path, models_dir) -> None:
    """√(J_core/m_core) = √(0.12/30) = 0.0632 m bounds the imbalance of the paper scene."""
    path = _write(tmp_path, models_dir, lambda d: d["roll"].update(com_offset=0.07))
    with pytest.raises(winder.SceneError, match=r"\[roll\] com_offset: 0.07 m puts the centre "
                                                r"of mass outside the core.*valid: com_offset "
                                                r"< .* = 0.0632456 m"):
        winder.load_scene(path)
    ok = _write(tmp_path, models_dir, lambda d: d["roll"].update(com_offset=0.063))
    assert winder.load_scene(ok).roll.com_offset == 0.063


def test_nip_too_soft_for_the_roll(tmp_path, models_dir) -> None:
    """At rest the 30 kg core compresses a 1000 N/m nip by m g/k = 0.29 m, more than its
    radius 0.075 m: the roll would start with its axis inside the drum."""
    path = _write(tmp_path, models_dir, lambda d: d["contact"].update(stiffness=1000.0,
                                                                      damping=0.0))
    with pytest.raises(winder.SceneError, match=r"\[contact\] stiffness: 1000.0 \(linear\) is "
                                                r"too soft for the roll's weight 294.3 N: at "
                                                r"rest the nip would be compressed by 0.294 m"):
        winder.load_scene(path)
    heavy = _write(tmp_path, models_dir, lambda d: d["roll"].update(core_mass=1e6))
    with pytest.raises(winder.SceneError, match=r"core_mass"):
        winder.load_scene(heavy)
    # 4000 N/m carries it with 0.0736 m < 0.075 m
    ok = _write(tmp_path, models_dir, lambda d: d["contact"].update(stiffness=4000.0,
                                                                    damping=0.0))
    system = winder.MachineSystem(winder.load_scene(ok))
    y0 = system.initial_state()
    assert y0[system.index("roll.z")] - 0.5 == pytest.approx(0.075 - 30 * 9.81 / 4000.0, rel=1e-12)


def test_output_grid_too_large(tmp_path, models_dir) -> None:
    path = _write(tmp_path, models_dir, lambda d: d["scene"].update(duration=1e6,
                                                                    output_step=1e-3))
    with pytest.raises(winder.SceneError, match=r"\[scene\] output_step: 0.001 s over duration "
                                                r"1000000.0 s gives 1e\+09 samples; valid: at "
                                                r"most 1e\+07 samples \(output_step >= 0.1 s\)"):
        winder.load_scene(path)


def test_max_wall_key(tmp_path, models_dir, paper_scene) -> None:
    assert paper_scene.solver.max_wall == 600.0
    path = _write(tmp_path, models_dir, lambda d: d["solver"].update(max_wall=0.0))
    with pytest.raises(winder.SceneError, match=r"\[solver\] max_wall: must be > 0"):
        winder.load_scene(path)


@pytest.mark.parametrize("edit, pattern", [
    (lambda d: d["roll"].update({"k" * 100_000: 1}),
     r"\[roll\] 'kkk.*\(100000 characters\): unknown key; valid keys: core_radius"),
    (lambda d: d.update({"t\nx": {}}), r"\['t\\nx'\]: unknown table; valid tables: scene"),
    (lambda d: d.update(roll=[1] * 100_000), r"\[roll\] must be a table of keys, got \[1, 1"),
])
def test_junk_names_stay_on_one_short_line(paper_scene, edit, pattern) -> None:
    data = paper_scene.to_dict()
    edit(data)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        winder.scene_from_dict(data, source="junk.toml")
    assert "\n" not in str(info.value) and len(str(info.value)) < 300
