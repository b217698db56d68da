"""Scenes of parts (machines spec §8): the two-drum winder, the single-drum format read as
parts, and every bad name or reference rejected naming the key, the value and the valid
names."""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any

import pytest
import tomli_w

import winder
from winder.analysis.sweep_grid import build_grid
from winder.parts import (
    PARTS,
    ContactLaw,
    DrumPart,
    FrictionLaw,
    NipPart,
    RiderPart,
    RollPart,
    SpeedProfileDrive,
    TorqueDrive,
    WebPart,
)
from winder.scene import EFFECT_NAMES, Effects, LegacyContact, LegacyFriction

MODELS = Path(__file__).resolve().parents[2] / "models"
TWO_DRUM = MODELS / "two_drum_winder.toml"
LEGACY = ("paper_winding", "paper_winding_no_web", "paper_winding_smooth", "free_spin")


def _two_drum() -> dict[str, Any]:
    return tomllib.loads(TWO_DRUM.read_text(encoding="utf-8"))


def _load(tmp_path: Path, data: dict[str, Any]) -> winder.Scene:
    p = tmp_path / "scene.toml"
    p.write_text(tomli_w.dumps(data), encoding="utf-8")
    return winder.load_scene(p)


# ---- the two-drum winder (spec §10) ----------------------------------------------------

def test_two_drum_winder_values() -> None:
    s = winder.load_scene(TWO_DRUM)
    assert not s.legacy and s.name == "two_drum_winder"
    assert (s.drum, s.roll, s.contact, s.friction) == (None, None, None, None)
    profile = SpeedProfileDrive(web_acceleration=0.7, web_speed=41.7, ratio=1.0)
    assert s.drums == (
        DrumPart("front", 0.5, 600.0, 3000.0, (-0.525, 0.0), 1, profile),
        DrumPart("rear", 0.5, 600.0, 3000.0, (0.525, 0.0), 1, profile))
    (roll,) = s.rolls
    z0 = math.sqrt(0.55**2 - 0.525**2)  # touching both drums: |c - c_drum| = R + r_c
    assert roll == RollPart(name="set", kind="wound", centre=(0.0, round(z0, 6)),
                            free=("x", "z"), sense=-1, core_radius=0.05, core_mass=40.0,
                            core_inertia=0.1, width=5.0, initial_radius=0.05,
                            initial_speed=0.0, com_offset=0.0005, density=650.0,
                            caliper=70e-6)
    assert s.riders == (RiderPart("rider", "set", 0.15, 1500.0, 25.0, 0.0,
                                  ((0.05, 3000.0), (0.3, 300.0))),)
    law = ContactLaw("linear", 2.5e7, 1.5e4)
    friction = FrictionLaw(0.35, 0.05, 0.01, 0.1)
    assert s.nips == (NipPart("front_nip", "front", "set", law, friction),
                      NipPart("rear_nip", "rear", "set", law, friction),
                      NipPart("rider_nip", "set", "rider", law, friction))
    assert s.web == WebPart("rear_nip", 1000.0)
    assert s.web.tension / roll.width == 200.0  # [N/m]
    assert s.effects.enabled() == EFFECT_NAMES
    assert s.scene.output_step == 0.01


def test_two_drum_winder_duration_winds_to_0_6_m() -> None:
    """Without slip the set's surface moves with the web: the paper length wound by
    ``T`` is the integral of the speed profile, and ``r² = r_c² + h L / π`` (r grows by
    ``h/2π`` per radian). The scene's duration (rounded to 0.1 s) reaches 0.6 m."""
    s = winder.load_scene(TWO_DRUM)
    d = s.drums[1].drive
    t_ramp = d.web_speed / d.web_acceleration
    length = d.web_speed * (s.scene.duration - t_ramp / 2)  # ramp, then full speed
    (roll,) = s.rolls
    r_end = math.sqrt(roll.core_radius**2 + roll.caliper * length / math.pi)
    assert r_end == pytest.approx(0.6, abs=2e-4)  # 0.1 s of winding is 0.12 mm here


def test_inline_tables_and_sub_tables_are_the_same(tmp_path) -> None:
    text = TWO_DRUM.read_text(encoding="utf-8").replace(
        'name = "rear"\nradius = 0.5\ninertia = 600.0\nmass = 3000.0\ncentre = [0.525, 0.0]\n'
        'sense = 1\ndrive = { kind = "speed_profile", web_acceleration = 0.7, '
        'web_speed = 41.7 }\n',
        'name = "rear"\nradius = 0.5\ninertia = 600.0\nmass = 3000.0\ncentre = [0.525, 0.0]\n'
        'sense = 1\n\n[drum.drive]\nkind = "speed_profile"\nweb_acceleration = 0.7\n'
        'web_speed = 41.7\n')
    assert "[drum.drive]" in text
    p = tmp_path / "two_drum_winder.toml"
    p.write_text(text, encoding="utf-8")
    assert dataclasses.replace(winder.load_scene(p), source=str(TWO_DRUM)) == \
        winder.load_scene(TWO_DRUM)


def test_parts_round_trip_replace_and_sweep_keys(tmp_path) -> None:
    s = winder.load_scene(TWO_DRUM)
    assert winder.scene_from_dict(s.to_dict(), source=s.source) == s
    written = _load(tmp_path, s.to_dict())  # TOML text again
    assert dataclasses.replace(written, source=s.source) == s
    r = s.replace(nip={"front_nip": {"contact": {"stiffness": 1e8}}},
                  drum={"rear": {"drive": {"web_speed": 30.0}}}, web={"tension": 0.0})
    assert r.nips[0].contact.stiffness == 1e8 and r.nips[1:] == s.nips[1:]
    assert r.drums[1].drive.web_speed == 30.0 and r.drums[0] == s.drums[0]
    assert r.web == WebPart("rear_nip", 0.0)
    # a roll's paper left to [paper] follows it
    assert s.replace(paper={"density": 700.0}).rolls[0].density == 700.0
    grid = build_grid(s, {"nip.rear_nip.contact.stiffness": [1e7, 5e7],
                          "rider.rider.mass": [1000.0]})
    assert [g.nips[1].contact.stiffness for g in grid.scenes] == [1e7, 5e7]
    assert grid.scenes[0].riders[0].mass == 1000.0
    with pytest.raises(winder.ArgumentError, match=r"nip has no element named 'back'; valid "
                                                   r"names: front_nip, rear_nip, rider_nip"):
        s.replace(nip={"back": {"a": "front"}})
    with pytest.raises(winder.ArgumentTypeError, match=r"nip\['front_nip'\] must be a mapping "
                                                       r"of \[nip.front_nip\] keys"):
        s.replace(nip={"front_nip": 3})
    with pytest.raises(winder.ArgumentError, match=r"no element named 'back' in nip; valid "
                                                   r"names: front_nip, rear_nip, rider_nip"):
        build_grid(s, {"nip.back.contact.stiffness": [1e7]})


# ---- the single-drum format, read as parts ---------------------------------------------

@pytest.mark.parametrize("name", LEGACY)
def test_single_drum_scene_as_parts(name) -> None:
    path = MODELS / f"{name}.toml"
    raw = tomllib.loads(path.read_text(encoding="utf-8"))
    s = winder.load_scene(path)
    assert s.legacy
    # the old fields hold the file's values (every key the file gives)
    for table in ("drum", "roll", "paper", "contact", "friction"):
        for key, value in raw.get(table, {}).items():
            if key != "drive":
                assert getattr(getattr(s, table), key) == value, (table, key)
    for key, value in raw["drum"]["drive"].items():
        assert getattr(s.drum.drive, key) == value, key
    assert s.contact == LegacyContact(**raw.get("contact", {}))
    assert s.friction == LegacyFriction(**raw.get("friction", {}))
    # the parts (machines spec §8, last paragraph)
    d, ro, pa = s.drum, s.roll, s.paper
    drive = (TorqueDrive(torque=d.drive.torque, web_speed=d.drive.web_speed)
             if d.drive.kind == "torque" else
             SpeedProfileDrive(web_acceleration=d.drive.web_acceleration,
                               web_speed=d.drive.web_speed))
    assert s.drums == (DrumPart("drum", d.radius, d.inertia, d.mass, (0.0, 0.0), 1, drive),)
    assert s.rolls == (RollPart(
        name="roll", kind="wound", centre=(0.0, d.radius + ro.initial_radius), free=("z",),
        sense=-1, core_radius=ro.core_radius, core_mass=ro.core_mass,
        core_inertia=ro.core_inertia, width=ro.width, initial_radius=ro.initial_radius,
        initial_speed=ro.initial_speed, com_offset=ro.com_offset, density=pa.density,
        caliper=pa.caliper, held_z=ro.initial_height),)
    assert s.riders == ()
    assert s.nips == (NipPart("nip", "drum", "roll",
                              ContactLaw(**dataclasses.asdict(s.contact)),
                              FrictionLaw(**dataclasses.asdict(s.friction))),)
    assert s.web == WebPart("nip", 0.0)
    # the old tables only, and the same scene back
    assert list(s.to_dict()) == ["scene", "effects", "drum", "roll", "paper", "contact",
                                 "friction", "solver"]
    assert winder.scene_from_dict(s.to_dict(), source=s.source) == s


def test_single_drum_parts_follow_replace(paper_scene) -> None:
    s = paper_scene.replace(drum={"drive": {"kind": "torque", "torque": 50.0,
                                            "web_speed": 3.0}},
                            roll={"initial_height": 0.7}, contact={"stiffness": 3e7})
    assert s.drums[0].drive == TorqueDrive(torque=50.0, web_speed=3.0)
    assert s.rolls[0].held_z == 0.7
    assert s.nips[0].contact.stiffness == 3e7
    r = dataclasses.replace(s, friction=LegacyFriction(mu=0.5))
    assert r.nips[0].friction == FrictionLaw(mu=0.5) and r.legacy


def test_new_effects_switch(tmp_path) -> None:
    data = _two_drum()
    data["effects"].update(rider_load=False, web_tension=False)
    fx = _load(tmp_path, data).effects
    assert not fx.rider_load and not fx.web_tension and fx.gravity
    assert "rider_load" not in fx.enabled() and "web_tension" not in fx.enabled()
    del data["effects"]
    assert _load(tmp_path, data).effects == Effects()  # a missing one is on


# ---- bad scenes of parts ----------------------------------------------------------------

def _nip(data: dict, name: str) -> dict:
    return next(n for n in data["nip"] if n["name"] == name)


BAD = [
    # unique names
    ("duplicate name", lambda d: d["nip"][0].update(name="set"),
     r"\[nip #1\] name: 'set' is already the name of roll 'set'; every part needs its "
     r"own name \(taken: front, rear, set, rider\)"),
    ("duplicate drum", lambda d: d["drum"][1].update(name="front"),
     r"\[drum #2\] name: 'front' is already the name of drum 'front'"),
    ("bad name", lambda d: d["drum"][0].update(name="front drum"),
     r"\[drum #1\] name: 'front drum' is not a part name; valid: 1 to 40 letters"),
    ("missing name", lambda d: d["roll"][0].pop("name"), r"\[roll #1\] name: missing "
                                                         r"required key"),
    # references
    ("nip a unknown", lambda d: d["nip"][0].update(a="middle"),
     r"\[nip 'front_nip'\] a: 'middle' is not a body of the scene; a nip joins two bodies; "
     r"valid names: front, rear, set, rider"),
    ("nip b is a nip", lambda d: d["nip"][0].update(b="rear_nip"),
     r"\[nip 'front_nip'\] b: 'rear_nip' is nip 'rear_nip', not a body; .*valid names: "
     r"front, rear, set, rider"),
    ("nip a == b", lambda d: d["nip"][0].update(b="front"),
     r"\[nip 'front_nip'\] b: 'front' is also a: a nip joins two different bodies; valid "
     r"names: rear, set, rider"),
    ("nip between drums", lambda d: d["nip"][0].update(b="rear"),
     r"\[nip 'front_nip'\] b: 'rear': a nip between two bodies with fixed centres \(drum "
     r"'front' and drum 'rear'\) cannot be assembled.*valid names: .*: set, rider"),
    ("two nips, one pair", lambda d: d["nip"][1].update(a="front"),
     r"\[nip 'rear_nip'\] b: 'set': nip 'front_nip' already joins 'front' and 'set'"),
    ("rides a drum", lambda d: d["rider"][0].update(rides="front"),
     r"\[rider 'rider'\] rides: 'front' is drum 'front', not a roll; a rider rides a paper "
     r"roll; valid names: set"),
    ("rides nothing", lambda d: d["rider"][0].update(rides="core"),
     r"\[rider 'rider'\] rides: 'core' is not a roll of the scene; valid names: set"),
    ("rider without nip", lambda d: d["nip"].pop(2),
     r"\[rider 'rider'\] rides: 'set': no \[\[nip\]\] with a = 'set' and b = 'rider'.*nips: "
     r"front_nip \(front, set\), rear_nip \(rear, set\)"),
    ("rider nip reversed", lambda d: d["nip"][2].update(a="rider", b="set"),
     r"\[rider 'rider'\] rides: 'set': no \[\[nip\]\] with a = 'set' and b = 'rider'.*"
     r"rider_nip \(rider, set\)"),
    ("entry nip unknown", lambda d: d["web"].update(entry_nip="back_nip"),
     r"\[web\] entry_nip: 'back_nip' is not a nip of the scene; valid names: front_nip, "
     r"rear_nip"),
    ("entry nip rider", lambda d: d["web"].update(entry_nip="rider_nip"),
     r"\[web\] entry_nip: 'rider_nip' is nip 'rider_nip' joining roll 'set' \(a\) and rider "
     r"'rider' \(b\); the web enters a wound roll \(b\) from the drum it wraps \(a\); valid "
     r"names: front_nip, rear_nip"),
    ("entry nip is a body", lambda d: d["web"].update(entry_nip="rear"),
     r"\[web\] entry_nip: 'rear' is drum 'rear', not a nip; valid names: front_nip, rear_nip"),
    ("no web", lambda d: d.pop("web"),
     r"\[web\]: missing required table: the scene has the wound roll 'set'; add \[web\] with "
     r"entry_nip = .*valid names: front_nip, rear_nip"),
    ("two webs into one roll", lambda d: d.update(web=[d["web"], d["web"]]),
     r"\[web #2\] entry_nip: 'rear_nip' enters wound roll 'set', which \[web #1\] already "
     r"feeds: two webs into one roll; every wound roll is fed by exactly one web; valid "
     r"names: nips into the other wound rolls: \(none\)"),
    ("no body", lambda d: [d.pop(c.table, None) for c in PARTS.values()] and d.pop("web") and
     d.update(nip=[]), r"a scene of parts needs at least one body"),
    # keys and values
    ("unknown drum key", lambda d: d["drum"][0].update(colour="red"),
     r"\[drum 'front'\] colour: unknown key; valid keys: name, radius, inertia, mass, "
     r"centre, sense, drive"),
    ("unknown drive key", lambda d: d["drum"][0]["drive"].update(ratio=2.0, torque=5.0),
     r"\[drum 'front'.drive\] torque: not a key of kind 'speed_profile'; valid keys: kind, "
     r"web_acceleration, web_speed, ratio"),
    ("bad drive kind", lambda d: d["drum"][0]["drive"].update(kind="belt"),
     r"\[drum 'front'.drive\] kind: 'belt' is not one of: 'speed_profile', 'torque'"),
    ("missing drive", lambda d: d["drum"][0].pop("drive"),
     r"\[drum 'front'\] drive: missing required key"),
    ("unknown nip contact key", lambda d: d["nip"][1]["contact"].update(stiff=1.0),
     r"\[nip 'rear_nip'.contact\] stiff: unknown key; valid keys: law, stiffness"),
    ("nip friction range", lambda d: d["nip"][1]["friction"].update(mu=11.0),
     r"\[nip 'rear_nip'.friction\] mu: must be >= 0 and <= 10, got 11.0"),
    ("nip without contact", lambda d: d["nip"][1].pop("contact"),
     r"\[nip 'rear_nip'\] contact: missing required table \(effects.contact is on\)"),
    ("centre of 3", lambda d: d["drum"][0].update(centre=[0.0, 0.0, 1.0]),
     r"\[drum 'front'\] centre: expected a list of two numbers \[x, z\], got \[0.0, 0.0, 1.0\]"),
    ("centre nan", lambda d: d["roll"][0].update(centre=[0.0, float("nan")]),
     r"\[roll 'set'\] centre: z must be finite, got nan"),
    ("sense 2", lambda d: d["drum"][0].update(sense=2),
     r"\[drum 'front'\] sense: 2 is not a sense; valid: 1 or -1"),
    ("free y", lambda d: d["roll"][0].update(free=["y"]),
     r"\[roll 'set'\] free: \['y'\] is not a set of axes; valid: \[\], \[\"z\"\]"),
    ("free twice", lambda d: d["roll"][0].update(free=["z", "z"]),
     r"\[roll 'set'\] free: \['z', 'z'\] is not a set of axes"),
    ("load decreasing", lambda d: d["rider"][0].update(load=[[0.3, 1.0], [0.1, 2.0]]),
     r"\[rider 'rider'\] load\[1\]: radius 0.1 m does not follow 0.3 m; valid: strictly "
     r"increasing radii"),
    ("load negative", lambda d: d["rider"][0].update(load=[[0.1, -1.0]]),
     r"\[rider 'rider'\] load\[0\]: line_load must be >= 0 and <= 1e\+07, got -1.0"),
    ("load not pairs", lambda d: d["rider"][0].update(load=3000.0),
     r"\[rider 'rider'\] load: expected a list of \[radius, line_load\] pairs"),
    ("roll below core", lambda d: d["roll"][0].update(initial_radius=0.04),
     r"\[roll 'set'\] initial_radius: 0.04 m is below core_radius 0.05 m"),
    ("roll imbalance", lambda d: d["roll"][0].update(com_offset=0.06),
     r"\[roll 'set'\] com_offset: 0.06 m puts the centre of mass outside the core"),
    ("roll no paper", lambda d: d.pop("paper"),
     r"\[roll 'set'\] density: missing required key \(the scene has no \[paper\] density"),
    ("roll initial_height", lambda d: d["roll"][0].update(initial_height=1.0),
     r"\[roll 'set'\] initial_height: unknown key; valid keys: name, kind, centre, free"),
    ("web tension negative", lambda d: d["web"].update(tension=-1.0),
     r"\[web\] tension: must be >= 0"),
    ("nip as a table", lambda d: d.update(nip=d["nip"][0]),
     r"\[nip\] must be an array of tables \(\[\[nip\]\]"),
    ("mixed formats", lambda d: d.update(contact={"stiffness": 1e7}),
     r"\[contact\]: a table of the single-drum format in a scene of parts; each \[\[nip\]\] "
     r"has its own contact and friction; valid tables: scene, effects, paper, "
     + ", ".join(c.table for c in PARTS.values()) + ", nip, web, solver"),
    ("single drum table", lambda d: d.update(drum=d["drum"][0]),
     r"\[rider\]: a table of scenes of parts in a scene of the single-drum format"),
    ("unknown table", lambda d: d.update(span={}), r"\[span\]: unknown table; valid tables: "),
    # the line's parts in a winder without an unwind (more in test_line_scene.py)
    ("unwinding set", lambda d: d["roll"][0].update(kind="unwinding"),
     r"\[roll 'set'\] free: \['x', 'z'\]: an unwinding roll's centre is fixed"),
    ("roll drive", lambda d: d["roll"][0].update(drive={"kind": "torque", "torque": 1.0}),
     r"\[roll 'set'\] drive: .*: a drive on a wound roll; only unwinding rolls"),
    ("web span and tension", lambda d: d["web"].update(span={"from": "set", "length": 3.0}),
     r"\[web\] tension: 1000.0: with \[web.span\] the tension is the span's state"),
    ("web span from the set", lambda d: d["web"].pop("tension") and d["web"].update(
        span={"from": "set", "length": 3.0, "EA": 1e6}),
     r"\[web.span\] from: 'set' is roll 'set' of kind 'wound', not an unwinding roll; "
     r".*valid names: \(none: no roll has kind = unwinding\)"),
]


@pytest.mark.parametrize("case, edit, pattern", BAD, ids=[b[0] for b in BAD])
def test_bad_parts_scene_names_key_value_and_valid(tmp_path, case, edit, pattern) -> None:
    data = _two_drum()
    edit(data)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        _load(tmp_path, data)
    assert str(info.value).startswith(f"{tmp_path / 'scene.toml'}: ")
    assert len(str(info.value)) < 600


def test_torque_drive_and_fixed_roll(tmp_path) -> None:
    """The torque drive's keys; a roll free in z only; a roll fixed in place cannot form
    a nip with a drum (neither body could carry the normal force)."""
    data = _two_drum()
    data["drum"][0]["drive"] = {"kind": "torque", "torque": -20.0, "web_speed": 2.0}
    data["roll"][0]["free"] = ["z"]
    s = _load(tmp_path, data)
    assert s.drums[0].drive == TorqueDrive(torque=-20.0, web_speed=2.0)
    assert s.rolls[0].free == ("z",)
    data["drum"][0]["drive"]["ratio"] = 2.0
    with pytest.raises(winder.SceneError, match=r"\[drum 'front'.drive\] ratio: not a key of "
                                                r"kind 'torque'; valid keys: kind, torque, "
                                                r"web_speed"):
        _load(tmp_path, data)
    fixed = copy.deepcopy(_two_drum())
    fixed["roll"][0]["free"] = []
    with pytest.raises(winder.SceneError, match=r"\[nip 'front_nip'\] b: 'set': a nip "
                                                r"between two bodies with fixed centres "
                                                r"\(drum 'front' and roll 'set'\)"):
        _load(tmp_path, fixed)


def test_replace_sets_a_list_valued_key(models_dir) -> None:
    """A rider's load schedule is a list of values, not an array of tables: replace sets
    it whole (it used to fail with an AttributeError)."""
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    flat = scene.replace(rider={"rider": {"load": [[0.05, 3000.0], [0.6, 3000.0]]}})
    assert flat.riders[0].load == ((0.05, 3000.0), (0.6, 3000.0))
    assert scene.riders[0].load == ((0.05, 3000.0), (0.3, 300.0))
    with pytest.raises(winder.SceneError, match=r"\[rider 'rider'\] load"):
        scene.replace(rider={"rider": {"load": 5}})


@pytest.mark.parametrize("path", sorted((Path(__file__).resolve().parents[2] / "models")
                                        .glob("*.toml")), ids=lambda p: p.stem)
def test_every_shipped_scene_round_trips(path: Path) -> None:
    """Every scene in models/ written as a dict and read again is the same scene (a
    result stores its scene this way: ``winder view`` reads it back). A flexible roll on
    its drums writes no chuck_stiffness, which it would refuse on reading."""
    s = winder.load_scene(path)
    assert winder.scene_from_dict(s.to_dict(), source=s.source) == s
