"""The scene reference (docs/scene-reference.md) is generated from the scene schema and up
to date; its defaults are what loading gives; every result channel is documented; the
README and docs send users to no file outside the package."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import winder
from winder._schema import format_number as _num
from winder.parts import PARTS
from winder.scene.keys import ALL_TABLES
from winder.scene.legacy import COLUMNS
from winder.scene.reference import (
    CHANNEL_DECLARATIONS,
    channel_declarations,
    channel_pattern,
    main,
    reference,
)
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "scene-reference.md"


def test_reference_is_up_to_date():
    """Stale file (a key, bound, unit or default changed without regenerating) fails."""
    assert DOC.read_text(encoding="utf-8") == reference(), \
        "docs/scene-reference.md is stale: run make scene-reference"
    assert main(["--check", "--out", str(DOC)]) == 0


def test_check_flags_a_stale_file(tmp_path):
    stale = tmp_path / "ref.md"
    stale.write_text(reference().replace("| `caliper` |", "| `thickness` |"), encoding="utf-8")
    assert main(["--check", "--out", str(stale)]) == 1
    assert main(["--out", str(stale)]) == 0
    assert main(["--check", "--out", str(stale)]) == 0


#: The heading of the web's table: one [web], or one [[web]] per wound roll.
WEB = "[web] or [[web]] (one per wound roll)"


def _rows(text: str) -> dict[str, dict[str, list[str]]]:
    """Section heading -> key -> cells of its row."""
    out: dict[str, dict[str, list[str]]] = {}
    head = ""
    for line in text.splitlines():
        if line.startswith("### "):
            head = line[4:].strip("`")
            out[head] = {}
        m = re.match(r"\| `([^`]+)` \| (.*) \|$", line)
        if m and head:
            out[head][m.group(1)] = [c.strip() for c in re.split(r"(?<!\\)\|", m.group(2))]
    return out


def test_every_schema_key_is_listed_once_with_unit_and_meaning():
    rows = _rows(reference())
    heads = {"scene": "[scene]", "effects": "[effects]", "solver": "[solver]",
             "paper": "[paper]", "drum": "[drum]", "drum.drive": "[drum.drive]",
             "roll": "[roll]", "contact": "[contact]", "friction": "[friction]"}
    tables = [(heads[t], t, ALL_TABLES[t]) for t in heads]
    tables += [(h, t, ALL_TABLES[t]) for t, h in (
        ("drum[]", "[[drum]]"), ("drum[].drive", "[[drum]] drive"), ("roll[]", "[[roll]]"),
        ("roll[].drive", "[[roll]] drive (unwinding rolls)"), ("rider[]", "[[rider]]"),
        ("nip[]", "[[nip]]"), ("nip[].contact", "[[nip]] contact"),
        ("nip[].friction", "[[nip]] friction"), ("web", WEB),
        ("web.span", "[web.span]"))]
    for head, _table, spec in tables:
        assert list(rows[head]) == list(spec.names()), head
        for key, cells in rows[head].items():
            kind, unit, rng, default, meaning = cells
            assert unit and meaning and default, (head, key)
            if spec[key].required:
                assert default.startswith("required"), (head, key, default)
            if spec[key].kind == "num":
                hi = spec[key].hi
                if hi is not None:  # the upper bound the parser enforces is the one shown
                    assert _num(hi) in rng, (head, key, rng)


def test_documented_ranges_are_the_parsers():
    """A value just past a documented bound is refused, the bound itself accepted."""
    base = winder.load_scene(ROOT / "models" / "paper_winding.toml")
    rows = _rows(reference())
    rng = rows["[paper]"]["caliper"][2]
    assert rng == "(0, 0.1]"
    base.replace(paper={"caliper": 0.1})
    with pytest.raises(winder.SceneError, match="caliper"):
        base.replace(paper={"caliper": 0.1000001})
    with pytest.raises(winder.SceneError, match="caliper"):
        base.replace(paper={"caliper": 0.0})


def test_documented_defaults_are_what_loading_gives():
    """The defaults shown for the keys a minimal scene of parts leaves out are the values
    the loaded scene has."""
    scene = winder.scene_from_dict({
        "scene": {"duration": 1.0},
        "paper": {"density": 800.0, "caliper": 1e-4},
        "drum": [{"name": "d", "radius": 0.5, "inertia": 10.0, "mass": 100.0,
                  "centre": [0.0, 0.0], "drive": {"kind": "speed_profile",
                                                  "web_speed": 1.0}}],
        "roll": [{"name": "r", "centre": [0.0, 0.6], "core_radius": 0.1,
                  "core_mass": 10.0, "core_inertia": 0.1, "width": 1.0}],
        "nip": [{"name": "n", "a": "d", "b": "r", "contact": {"stiffness": 1e8}}],
        "web": {"entry_nip": "n"},
    })
    rows = _rows(reference())
    got = {
        "[scene]": {k: getattr(scene.scene, k) for k in ("output_step", "gravity")},
        "[solver]": {k: getattr(scene.solver, k) for k in ("rtol", "atol", "max_wall",
                                                           "method", "backend")},
        "[[drum]]": {"sense": scene.drums[0].sense},
        "[[drum]] drive": {"ratio": scene.drums[0].drive.ratio,
                           "web_acceleration": scene.drums[0].drive.web_acceleration},
        "[[roll]]": {"sense": scene.rolls[0].sense, "kind": scene.rolls[0].kind,
                     "com_offset": scene.rolls[0].com_offset,
                     "initial_speed": scene.rolls[0].initial_speed},
        "[[nip]] friction": {k: getattr(scene.nips[0].friction, k)
                             for k in ("mu", "slip_velocity", "relaxation_length",
                                       "min_speed")},
        "[[nip]] contact": {k: getattr(scene.nips[0].contact, k)
                            for k in ("law", "damping", "exponent", "hc_damping")},
        WEB: {"tension": scene.web.tension},
    }
    for head, values in got.items():
        for key, value in values.items():
            shown = rows[head][key][3]
            want = f'"{value}"' if isinstance(value, str) else _num(value)
            assert shown == want, (head, key, shown, value)
    assert scene.rolls[0].initial_radius == scene.rolls[0].core_radius
    assert rows["[[roll]]"]["initial_radius"][3] == "core_radius"
    # no max_rhs: the path's own budget (winder.solve.budgets.default_max_rhs), each shown
    from winder.solve.budgets import default_max_rhs

    assert scene.solver.max_rhs is None
    shown = rows["[solver]"]["max_rhs"][3]
    for stepwise, backend in ((False, "compiled"), (True, "compiled"), (True, "pinocchio")):
        assert f"{default_max_rhs(stepwise=stepwise, backend=backend, n_states=6):,}" in shown
    assert scene.rolls[0].free == ("z",)
    assert rows["[[roll]]"]["free"][3].startswith('["z"] (wound)')
    assert scene.web.name == scene.web.entry_nip
    assert rows[WEB]["name"][3] == "its entry_nip"


@pytest.mark.parametrize("model", ["two_drum_winder", "winder_line"])
def test_every_channel_of_a_scene_of_parts_is_documented(model):
    scene = winder.load_scene(ROOT / "models" / f"{model}.toml")
    res = winder.simulate(scene, t_end=0.02, output_step=0.01)
    kinds = {p.name: k for k, parts in (("drum", scene.drums), ("roll", scene.rolls),
                                        ("rider", scene.riders), ("nip", scene.nips))
             for p in parts}
    names = list(res)
    missing = [n for n in names if channel_pattern(n, kinds) is None]
    assert not missing
    used = {channel_pattern(n, kinds) for n in names}
    assert {"BODY_torque", "NIP_penetration", "ROLL_radius", "web_speed"} <= used
    if model == "winder_line":
        assert {"span_tension", "tension_error"} <= used


def test_every_channel_of_a_single_drum_scene_is_documented():
    res = winder.simulate(ROOT / "models" / "paper_winding.toml", t_end=0.02)
    names = list(res)
    assert names == ["t", *COLUMNS]
    assert {c.name for c in CHANNEL_DECLARATIONS} >= {"t", "NIP_normal_force", "BODY_speed"}


@pytest.mark.parametrize("model", sorted(p.stem for p in (ROOT / "models").glob("*.toml")))
def test_every_channel_of_a_shipped_scene_is_declared_once_with_its_unit(model):
    """Each result channel of each shipped scene (models/*.toml) is one channel of its
    machine (a single-drum column through the scene's naming) that matches exactly one
    declaration, and its unit (:attr:`MachineSystem.channel_units`) is the declared one."""
    scene = winder.load_scene(ROOT / "models" / f"{model}.toml")
    system = MachineSystem(scene, backend="pinocchio")
    units = system.channel_units
    parts = {p.name: k for k, group in (*((c.table, scene.bodies[a]) for a, c in PARTS.items()),
                                        ("nip", scene.nips))
             for p in group}
    # a flexible body's segments NAME_s{i} are bodies of its kind, its nips' slices nips
    parts |= {b.name: b.table for b in system.machine.bodies if b.segment_of}
    parts |= {n.name: "nip" for n in system.machine.nips if n.whole is not None}
    machine = {"t": "t", **{out: ch for out, (ch, _) in system.outputs.items()}}
    assert list(machine) == list(units)
    for out, channel in machine.items():
        found = channel_declarations(channel, parts, [w.name for w in scene.webs])
        assert len(found) == 1, (out, channel, [d.name for d in found])
        assert units[out] == found[0].unit, (out, units[out], found[0])
        if channel in system.machine.channel_units:
            assert system.machine.channel_units[channel] == found[0].unit
    if scene.naming.by_parts:  # the machine's channels, unrenamed
        assert [c for c in machine if c != "t"] == system.machine.channel_names


def test_readme_and_docs_point_only_to_files_of_the_package():
    """Users get the repository, not the specification folder beside it: no reference to
    it, and every local Markdown link resolves."""
    texts = {p: p.read_text(encoding="utf-8") for p in
             [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]}
    for path, text in texts.items():
        for bad in ("../shared", "shared/spec", "winder-model.md", "machines.md", "spec §"):
            assert bad not in text, (path.name, bad)
        for link in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
            assert (path.parent / link).exists(), (path.name, link)
    assert "docs/scene-reference.md" in texts[ROOT / "README.md"]
    assert "docs/model.md" in texts[ROOT / "README.md"]
