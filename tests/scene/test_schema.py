"""Each scene key is declared once (:class:`winder._schema.Key`), and the parser, its
messages, key_unit/key_doc, the reference and the FMU's parameters read that declaration;
an effect's own settings (``[effects.NAME]``) are parsed, documented and honoured."""

from __future__ import annotations

import dataclasses
import inspect
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import winder
from winder._schema import NO_DEFAULT, Key, Table
from winder.cli import main
from winder.fmu.parameters import FMU_PARAMETERS, fmu_parameters, parameter_units
from winder.forces import FORCES
from winder.parts import PARTS, flex, nip, roll, web
from winder.scene import key_doc, key_unit
from winder.scene.keys import ALL_TABLES, find_key
from winder.scene.legacy import LEGACY_TABLES
from winder.scene.reference import reference
from winder.scene.schema import PAPER_KEYS, TABLES, effect_settings

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
#: The parts' own declarations, by module.
PART_TABLES = {**{sys.modules[cls.__module__]: (cls.KEYS, *(st.keys for st in
                                                            cls.SUB_TABLES.values()))
                  for cls in PARTS.values()},  # every registered body type's tables
               flex: (flex.FLEX_KEYS, flex.ROLL_FLEX_KEYS),
               nip: (nip.KEYS, nip.CONTACT_KEYS, nip.FRICTION_KEYS),
               web: (web.KEYS, web.SPAN_KEYS)}
#: A range written out: (0, 10], [0, 1e5], (0, ∞) ...; or a magnitude bound <= 1e8.
RANGE = re.compile(r"[\[(]-?[\d.]+(e-?\d+)?, ?(-?[\d.]+(e-?\d+)?|∞)[\])]|<= ?1e\d|<= ?\d{3,}")


def test_every_part_key_is_declared_once_and_shared_by_both_formats():
    """A key of the single-drum format that a part has is the part's very declaration
    (the same object), so a bound or unit cannot differ between the formats."""
    declared = {id(k): (mod.__name__, k.name) for mod, tables in PART_TABLES.items()
                for t in tables for k in t}
    for table in ("drum", "drum.drive", "contact", "friction"):
        for k in LEGACY_TABLES[table]:
            assert id(k) in declared, (table, k.name)
    for k in LEGACY_TABLES["roll"]:
        assert k.name == "initial_height" or id(k) in declared, k.name
    for k in PAPER_KEYS:  # [paper]: the roll's keys, required
        assert dataclasses.replace(roll.KEYS[k.name], required=True, default_text=None) == k
    for name, table in TABLES.items():
        if name.endswith("[]") or "[]." in name or name.startswith("web"):
            assert any(table is t for ts in PART_TABLES.values() for t in ts), name


def test_no_bound_is_written_outside_the_declarations():
    """The parts' and tables' docstrings point to the declarations instead of repeating
    a range; every numeric key has a unit (or says why not) and every key a meaning."""
    import winder.scene.legacy as legacy
    import winder.scene.tables as tables

    for mod in (*PART_TABLES, legacy, tables):
        for _, cls in inspect.getmembers(mod, dataclasses.is_dataclass):
            doc = cls.__doc__ or ""
            assert not RANGE.search(doc), (cls.__name__, RANGE.search(doc).group(0))
    for name, table in ALL_TABLES.items():
        for k in table:
            assert k.doc, (name, k.name)
            if k.kind == "num":
                assert k.unit or (name, k.name) == ("solver", "atol"), (name, k.name)


def test_scene_code_writes_no_bound():
    """Outside the declarations (scene/schema.py, scene/legacy.py, the parts' KEYS) the
    scene package writes no bound: no number in e-notation, no ``hi=`` or ``lo=`` with a number."""
    for path in sorted((ROOT / "src" / "winder" / "scene").glob("*.py")):
        if path.name in ("schema.py", "legacy.py", "reference.py"):
            continue
        code = [line.split("#")[0] for line in path.read_text(encoding="utf-8").splitlines()]
        for i, line in enumerate(code, 1):
            assert not re.search(r"\b\d+e\d+\b|\b(hi|lo)=\s*-?[\d.]", line) or "``" in line, \
                (path.name, i, line)


def test_single_drum_channels_are_documented_in_their_order():
    from winder.scene.legacy import CHANNELS, COLUMNS, EXTRA_CHANNELS
    from winder.scene.reference import reference

    assert ("t", *COLUMNS) == (*CHANNELS, *EXTRA_CHANNELS)
    text = reference()
    section = text[text.index("### Single-drum format", text.index("## Result channels")):]
    rows = re.findall(r"^\| `(\w+)` \|", section.split("### Scenes of parts")[0], re.M)
    assert tuple(rows) == (*CHANNELS, *EXTRA_CHANNELS)


def test_parser_bounds_are_the_declared_ones():
    """Just past a declared bound is refused with the declared range in the message, the
    bound itself accepted: for every bounded number of a roll (both formats)."""
    base = winder.load_scene(MODELS / "paper_winding.toml").replace(
        effects={"contact": False, "slip_relaxation": False})  # no rest-on-nip check
    for key in ("width", "core_mass", "core_inertia"):
        k = roll.KEYS[key]
        assert k.hi is not None and k.lo == 0.0 and k.lo_open
        ok = base.replace(roll={key: k.hi, "com_offset": 0.0})
        assert getattr(ok.roll, key) == k.hi
        hi = re.escape(f"{k.hi:g}")
        with pytest.raises(winder.SceneError, match=rf"\[roll\] {key}: must be > 0 and <= {hi}, "):
            base.replace(roll={key: k.hi * (1 + 1e-9)})


def test_key_validation():
    with pytest.raises(ValueError, match="kind"):
        Key(name="x", kind="colour", doc="a colour")
    with pytest.raises(ValueError, match="only a number"):
        Key(name="x", kind="bool", hi=1.0, doc="a flag")
    with pytest.raises(ValueError, match="lo"):
        Key(name="x", lo=2.0, hi=1.0, doc="a number")
    with pytest.raises(ValueError, match="required"):
        Key(name="x", required=True, default=1.0, doc="a number")
    with pytest.raises(ValueError, match="twice: a"):
        Table((Key(name="a", doc="one"), Key(name="a", doc="two")))
    with pytest.raises(ValueError, match="not in the table"):
        Table((Key(name="a", doc="one"),), kinds={"k": ("b",)})
    assert Key(name="x", lo=0.0, lo_open=True, hi=1e6, doc="d").range_text() == "(0, 1e6]"
    assert Key(name="x", hi=1e8, doc="d").range_text() == "\\|x\\| ≤ 1e8"


def test_fmu_parameter_units_and_descriptions_are_the_keys():
    """Every FMU parameter's unit is its scene key's (key_unit, both formats) and its
    description is the key's meaning with that unit."""
    for name, (table, key, text) in FMU_PARAMETERS.items():
        k = find_key(table, key)
        assert text == f"{k.doc} [{k.unit}]", name
    for model in ("paper_winding", "two_drum_winder", "winder_line"):
        scene = winder.load_scene(MODELS / f"{model}.toml")
        data = scene.to_dict()
        units = parameter_units(scene)
        params = fmu_parameters(scene)
        assert set(units) == set(params)
        for name, (place, text) in params.items():
            table, element, path = place
            dotted = ".".join(p for p in (table, element, *path) if p)
            assert units[name] == key_unit(dotted, data) != "", (model, name)
            assert text.endswith(f"[{units[name]}]"), (model, name, text)
    hc = winder.load_scene(MODELS / "paper_winding.toml").replace(
        contact={"law": "hunt_crossley"})
    assert parameter_units(hc)["contact_stiffness"] == "N/m^p"


# ---- an effect's own settings -----------------------------------------------------------

def _two_drum(effects: dict) -> winder.Scene:
    scene = winder.load_scene(MODELS / "two_drum_winder.toml")
    data = scene.to_dict()
    data["effects"].update(effects)
    return winder.scene_from_dict(data, source=scene.source)


def test_settings_are_declared_on_the_force_element_and_documented():
    assert [k.name for k in FORCES["rider_load"].settings] == ["scale"]
    assert all(cls.settings == () for n, cls in FORCES.items() if n != "rider_load")
    table = effect_settings("rider_load")
    assert table.names() == ("enabled", "scale")
    assert table["scale"].default == 1.0 and table["enabled"].default is True
    assert key_doc("effects.rider_load", "scale")[0] == "-"
    assert key_unit("effects.rider_load.scale") == "-"
    text = reference()
    assert "### `[effects.rider_load]`" in text
    assert re.search(r"\| `scale` \| number \| - \| \[0, 100\] \| 1 \| factor", text)
    assert effect_settings("gravity").names() == ("enabled",)
    assert effect_settings("gravity")["enabled"].default is not NO_DEFAULT


def test_setting_parsed_and_round_tripped():
    plain = _two_drum({})
    table = _two_drum({"rider_load": {"enabled": True}})
    assert table == plain and table.effects.setting("rider_load", "scale") == 1.0
    scaled = _two_drum({"rider_load": {"scale": 2.0}})
    assert scaled.effects.rider_load and scaled.effects.setting("rider_load", "scale") == 2.0
    assert scaled.to_dict()["effects"]["rider_load"] == {"enabled": True, "scale": 2.0}
    assert winder.scene_from_dict(scaled.to_dict(), source=scaled.source) == scaled
    assert plain.replace(effects={"rider_load": {"scale": 2.0}}) == scaled
    off = _two_drum({"rider_load": {"enabled": False, "scale": 3.0}})
    assert not off.effects.rider_load and "rider_load" not in off.effects.enabled()


def test_setting_is_honoured():
    """The rider's load channel at t = 0 is the schedule's load at the set's initial
    radius times the width (the closed form of machines.md §4; the channel is its
    magnitude), times the scale: exactly
    twice with scale 2, zero with scale 0; scale 1 (the default) gives today's run."""
    runs = {s: winder.simulate(_two_drum({"rider_load": {"scale": s}}), t_end=0.02,
                               output_step=0.01) for s in (0.0, 1.0, 2.0)}
    today = winder.simulate(_two_drum({}), t_end=0.02, output_step=0.01)
    scene = _two_drum({})
    r0 = scene.rolls[0].initial_radius
    (ra, qa), (rb, qb) = scene.riders[0].load
    q = qa + (qb - qa) * (r0 - ra) / (rb - ra) if r0 > ra else qa
    width = scene.rolls[0].width
    assert runs[1.0]["rider_load"][0] == pytest.approx(width * q, rel=1e-12)
    assert runs[2.0]["rider_load"][0] == 2.0 * runs[1.0]["rider_load"][0]
    assert runs[0.0]["rider_load"][0] == 0.0
    for name in today:
        np.testing.assert_array_equal(runs[1.0][name], today[name], err_msg=name)


@pytest.mark.parametrize("value, message", [
    ({"scale": -1.0}, r"\[effects.rider_load\] scale: must be >= 0 and <= 100, got -1.0"),
    ({"scale": "big"}, r"\[effects.rider_load\] scale: expected a number, got 'big'"),
    ({"gain": 1.0}, r"\[effects.rider_load\] gain: unknown key; valid keys: enabled, scale"),
    ({"enabled": "yes"}, r"\[effects.rider_load\] enabled: expected true or false"),
    (1, r"\[effects\] rider_load: expected true or false or a table \[effects.rider_load\] "
        r"of enabled and its settings \(scale\), got 1"),
])
def test_bad_setting_is_refused_naming_it(value, message):
    with pytest.raises(winder.SceneError, match=message):
        _two_drum({"rider_load": value})


def test_effects_built_in_python_validate_their_settings():
    from winder.scene import Effects

    e = Effects(settings={"rider_load": {"scale": 0.5}})
    assert e.setting("rider_load", "scale") == 0.5 and e == Effects(
        settings=(("rider_load", (("scale", 0.5),)),))
    assert Effects().setting("rider_load", "scale") == 1.0
    with pytest.raises(winder.ArgumentError, match="scale"):
        Effects(settings={"rider_load": {"scale": -2.0}})
    with pytest.raises(winder.ArgumentError, match="not a setting of gravity; valid: \\(none\\)"):
        Effects(settings={"gravity": {"g": 1.0}})
    with pytest.raises(winder.ArgumentError, match="not an effect"):
        Effects(settings={"wind": {"speed": 1.0}})


def test_bad_setting_exits_2_naming_it(tmp_path):
    text = (MODELS / "two_drum_winder.toml").read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("rider_load = true", "rider_load = { scale = 1e9 }"),
                   encoding="utf-8")
    assert main(["run", str(bad), "--out", str(tmp_path / "r.csv")]) == 2
    gravity = tmp_path / "gravity.toml"
    gravity.write_text(text.replace("gravity = true", "gravity = { g = 3.7 }"),
                       encoding="utf-8")
    with pytest.raises(winder.SceneError,
                       match=r"\[effects.gravity\] g: unknown key; valid keys: enabled$"):
        winder.load_scene(gravity)
