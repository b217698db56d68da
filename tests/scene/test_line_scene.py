"""The winder line's scene (machines spec §1, §5, §6, §8, §10): an unwinding parent roll
feeding the two-drum winder through one web span; its values, its geometry, the small
line whose parent runs out within the demo, the key paths of the span and the unwind
drive, and every bad span or unwinding roll rejected naming the key, the value and the
valid names."""

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
    RollPart,
    SpanPart,
    SpeedProfileDrive,
    TensionControl,
    UnwindTorqueDrive,
    WebPart,
)
from winder.scene import EFFECT_NAMES

MODELS = Path(__file__).resolve().parents[2] / "models"
LINE = MODELS / "winder_line.toml"
SMALL = MODELS / "winder_line_small.toml"
TWO_DRUM = MODELS / "two_drum_winder.toml"


def _line() -> dict[str, Any]:
    return tomllib.loads(LINE.read_text(encoding="utf-8"))


def _load(tmp_path: Path, data: dict[str, Any]) -> winder.Scene:
    p = tmp_path / "scene.toml"
    p.write_text(tomli_w.dumps(data), encoding="utf-8")
    return winder.load_scene(p)


def _paper_length(r_from: float, r_to: float, caliper: float) -> float:
    """Paper [m] between two radii of a roll: ``dL = 2π r dr / h``."""
    return math.pi * abs(r_from**2 - r_to**2) / caliper


def _runout_time(length: float, drive: SpeedProfileDrive) -> float:
    """When the web speed profile ``min(a t, v)`` has carried ``length`` [m] [s]."""
    a, v = drive.web_acceleration, drive.web_speed
    ramp = v / a
    if length <= v * ramp / 2:
        return math.sqrt(2 * length / a)
    return ramp + (length - v * ramp / 2) / v


# ---- the line (spec §10) ---------------------------------------------------------------

PARENT = RollPart(name="parent", kind="unwinding", centre=(3.2, 0.8), free=(), sense=1,
                  core_radius=0.4, core_mass=3000.0, core_inertia=300.0, width=5.0,
                  initial_radius=1.25, initial_speed=0.0, com_offset=0.0, density=650.0,
                  caliper=70e-6, drive=TensionControl(tension=1000.0, bandwidth=10.0))


def test_winder_line_values() -> None:
    s = winder.load_scene(LINE)
    two = winder.load_scene(TWO_DRUM)
    assert not s.legacy and s.name == "winder_line"
    # the winder is the two-drum winder's, part for part
    assert s.drums == two.drums and s.riders == two.riders and s.nips == two.nips
    assert s.paper == two.paper and s.effects == two.effects and s.solver == two.solver
    assert s.effects.enabled() == EFFECT_NAMES
    set_roll, parent = s.rolls
    assert set_roll == two.rolls[0]
    assert parent == PARENT
    assert s.web == WebPart("rear_nip", 0.0, SpanPart("parent", 3.0, 1.4e6, 0.0, 1000.0))
    # the parent's paper (spec §10: ≈ 14 t): π (1.25² − 0.4²) · 5 · 650 = 14 320 kg
    paper_mass = math.pi * (1.25**2 - 0.4**2) * parent.width * parent.density
    assert paper_mass == pytest.approx(14_320, abs=1)
    # the same winding as the two-drum winder, and the parent has far more paper
    assert s.scene == dataclasses.replace(two.scene, name="winder_line")
    wound = _paper_length(0.6, 0.05, set_roll.caliper)
    assert _paper_length(1.25, 0.4, parent.caliper) > 3.5 * wound
    # the initial web speed: drums from rest, the parent at rest too
    assert all(d.drive.web_acceleration > 0 for d in s.drums) and parent.initial_speed == 0


@pytest.mark.parametrize("path", [LINE, SMALL], ids=["line", "small"])
def test_line_geometry(path) -> None:
    """Nothing overlaps at the parent's full size and the set's final one, and with its
    sense the parent's underside pays the web off towards the rear drum's underside
    (spec §1: ``θ̇ = s · speed``; the velocity of the point ``(0, −r)`` from the centre of
    a body turning at ``θ̇`` about ``+y`` is ``θ̇ ŷ × (−r ẑ) = −θ̇ r x̂``)."""
    s = winder.load_scene(path)
    set_roll, parent = s.rolls
    rear = next(d for d in s.drums if d.name == "rear")
    bodies = [(d.centre, d.radius) for d in s.drums]
    # the set fully wound (r = 0.6 m) in the valley, the rider on top of it
    z_set = math.sqrt((rear.radius + 0.6) ** 2 - rear.centre[0] ** 2)
    bodies.append(((set_roll.centre[0], z_set), 0.6))
    rider = s.riders[0]
    bodies.append(((rider.x, z_set + 0.6 + rider.radius), rider.radius))
    for (x, z), r in bodies:
        gap = math.hypot(parent.centre[0] - x, parent.centre[1] - z) - r - 1.25
        assert gap > 0.5, (x, z, r, gap)
    theta_dot = parent.sense * 1.0  # speed = +1 rad/s
    underside_velocity_x = -theta_dot * parent.initial_radius
    towards_rear = rear.centre[0] - parent.centre[0]
    assert underside_velocity_x * towards_rear > 0
    # the rear drum (sense +1) moves its underside the same way: the web runs level
    assert -rear.sense * rear.radius * towards_rear > 0
    assert abs((parent.centre[1] - parent.initial_radius) - (rear.centre[1] - rear.radius)) \
        < 0.1 or path == SMALL


def test_small_line_runs_out_within_the_demo() -> None:
    """The small parent's paper lasts ``π (r0² − r_c²) / h`` metres of web; under the
    drums' speed profile it is used up at ≈ 56.2 s (< 60 s), and the duration goes a
    little beyond (the run ends when the parent reaches its core)."""
    s = winder.load_scene(SMALL)
    line = winder.load_scene(LINE)
    set_roll, parent = s.rolls
    assert parent == dataclasses.replace(PARENT, initial_radius=0.45)
    length = _paper_length(parent.initial_radius, parent.core_radius, parent.caliper)
    assert length == pytest.approx(1907.4, abs=0.1)
    t_out = _runout_time(length, s.drums[1].drive)
    assert t_out == pytest.approx(56.17, abs=0.01) and t_out < 60.0
    assert 0 < s.scene.duration - t_out < 3.0
    # at the span's steady strain the parent runs slower by T/EA (0.07 %): still in time
    assert t_out * (1 + 1000.0 / 1.4e6) < s.scene.duration
    # the rest is the line, with a shorter ramp
    fast = SpeedProfileDrive(web_acceleration=2.0, web_speed=41.7)
    assert [d.drive for d in s.drums] == [fast, fast]
    assert [dataclasses.replace(d, drive=line.drums[0].drive) for d in s.drums] == \
        list(line.drums)
    assert (set_roll, s.riders, s.nips, s.web, s.effects, s.paper) == \
        (line.rolls[0], line.riders, line.nips, line.web, line.effects, line.paper)


def test_line_round_trip_replace_and_sweep_keys(tmp_path) -> None:
    s = winder.load_scene(LINE)
    d = s.to_dict()
    assert d["web"] == {"entry_nip": "rear_nip",
                        "span": {"from": "parent", "length": 3.0, "EA": 1.4e6, "T_in": 0.0,
                                 "initial_tension": 1000.0}}
    assert d["roll"][1]["drive"] == {"kind": "tension_control", "tension": 1000.0,
                                     "bandwidth": 10.0}
    assert "drive" not in d["roll"][0]
    assert winder.scene_from_dict(d, source=s.source) == s
    assert dataclasses.replace(_load(tmp_path, d), source=s.source) == s
    r = s.replace(web={"span": {"EA": 1e7, "initial_tension": 0.0}},
                  roll={"parent": {"drive": {"bandwidth": 20.0}}})
    assert r.web.span == SpanPart("parent", 3.0, 1e7, 0.0, 0.0)
    assert r.rolls[1].drive == TensionControl(tension=1000.0, bandwidth=20.0)
    grid = build_grid(s, {"web.span.EA": [1e6, 2e6], "roll.parent.drive.tension": [500.0]})
    assert [g.web.span.EA for g in grid.scenes] == [1e6, 2e6]
    assert {g.rolls[1].drive.tension for g in grid.scenes} == {500.0}
    with pytest.raises(winder.SceneError, match=r"\[web\] tension: 5.0: with \[web.span\] "
                                                r"the tension is the span's state"):
        s.replace(web={"tension": 5.0})


def test_unwind_drives_and_defaults(tmp_path) -> None:
    """The torque drive, a free unwinding roll (no drive), and the defaults: free [],
    sense −1, bandwidth 10 rad/s, T_in 0, initial_tension None (the engine uses T_in)."""
    data = _line()
    parent = data["roll"][1]
    parent["drive"] = {"kind": "torque", "torque": -150.0}
    assert _load(tmp_path, data).rolls[1].drive == UnwindTorqueDrive(torque=-150.0)
    parent["drive"] = {"kind": "tension_control", "tension": 800.0}
    assert _load(tmp_path, data).rolls[1].drive == TensionControl(tension=800.0,
                                                                  bandwidth=10.0)
    for key in ("drive", "free", "sense"):
        del parent[key]
    for key in ("T_in", "initial_tension"):
        del data["web"]["span"][key]
    s = _load(tmp_path, data)
    assert s.rolls[1].drive is None and s.rolls[1].free == () and s.rolls[1].sense == -1
    assert s.web.span == SpanPart("parent", 3.0, 1.4e6, 0.0, None)
    assert winder.scene_from_dict(s.to_dict(), source=s.source) == s


# ---- bad lines -------------------------------------------------------------------------

def _parent(d: dict) -> dict:
    return d["roll"][1]


def _second_parent(d: dict) -> None:
    extra = copy.deepcopy(_parent(d))
    extra.update(name="parent2", centre=[8.0, 0.8])
    d["roll"].append(extra)


BAD = [
    # the unwinding roll
    ("unwinding free z", lambda d: _parent(d).update(free=["z"]),
     r"\[roll 'parent'\] free: \['z'\]: an unwinding roll's centre is fixed \(docs/model.md §1\); "
     r"valid: \[\]"),
    ("unwinding free xz", lambda d: _parent(d).update(free=["x", "z"]),
     r"\[roll 'parent'\] free: \['x', 'z'\]: an unwinding roll's centre is fixed"),
    ("drive on wound roll", lambda d: d["roll"][0].update(drive={"kind": "torque"}),
     r"\[roll 'set'\] drive: \{'kind': 'torque'\}: a drive on a wound roll; only unwinding "
     r"rolls \(kind = 'unwinding'\) have a drive.*valid: remove drive"),
    ("drive kind", lambda d: _parent(d)["drive"].update(kind="speed_profile"),
     r"\[roll 'parent'.drive\] kind: 'speed_profile' is not one of: 'torque', "
     r"'tension_control'"),
    ("drive no kind", lambda d: _parent(d)["drive"].pop("kind"),
     r"\[roll 'parent'.drive\] kind: missing required key"),
    ("drive not a table", lambda d: _parent(d).update(drive=5.0),
     r"\[roll 'parent'.drive\] must be a table of keys, got 5.0"),
    ("torque drive key", lambda d: _parent(d).update(drive={"kind": "torque",
                                                            "tension": 1.0}),
     r"\[roll 'parent'.drive\] tension: not a key of kind 'torque'; valid keys: kind, "
     r"torque"),
    ("control drive key", lambda d: _parent(d)["drive"].update(torque=1.0),
     r"\[roll 'parent'.drive\] torque: not a key of kind 'tension_control'; valid keys: "
     r"kind, tension, bandwidth"),
    ("unknown drive key", lambda d: _parent(d)["drive"].update(gain=1.0),
     r"\[roll 'parent'.drive\] gain: unknown key; valid keys: kind, torque, tension, "
     r"bandwidth"),
    ("no set-point", lambda d: _parent(d)["drive"].pop("tension"),
     r"\[roll 'parent'.drive\] tension: missing required key \(kind = 'tension_control'"),
    ("set-point 0", lambda d: _parent(d)["drive"].update(tension=0.0),
     r"\[roll 'parent'.drive\] tension: must be > 0 and <= 1e\+07, got 0.0"),
    ("bandwidth 0", lambda d: _parent(d)["drive"].update(bandwidth=0.0),
     r"\[roll 'parent'.drive\] bandwidth: must be > 0 and <= 10000, got 0.0"),
    ("bandwidth high", lambda d: _parent(d)["drive"].update(bandwidth=2e4),
     r"\[roll 'parent'.drive\] bandwidth: must be > 0 and <= 10000, got 20000.0"),
    ("torque huge", lambda d: _parent(d).update(drive={"kind": "torque", "torque": -2e8}),
     r"\[roll 'parent'.drive\] torque: .*1e\+08, got -200000000.0"),
    ("second unwinding roll", _second_parent,
     r"\[roll 'parent2'\] kind: 'unwinding': an unwinding roll feeds a web span, and no "
     r"\[web.span\] has from = 'parent2'; add one to the web it feeds"),
    ("unwinding without span", lambda d: d["web"].pop("span") and d["web"].update(
        tension=1000.0),
     r"\[roll 'parent'\] kind: 'unwinding': an unwinding roll feeds a web span, and the "
     r"scene has no \[web.span\]; add \[web.span\] with from = 'parent'"),
    # the span
    ("span from unknown", lambda d: d["web"]["span"].update({"from": "mother"}),
     r"\[web.span\] from: 'mother' is not a roll of the scene; .*valid names: parent"),
    ("span from wound", lambda d: d["web"]["span"].update({"from": "set"}),
     r"\[web.span\] from: 'set' is roll 'set' of kind 'wound', not an unwinding roll; "
     r".*valid names: parent"),
    ("span from drum", lambda d: d["web"]["span"].update({"from": "rear"}),
     r"\[web.span\] from: 'rear' is drum 'rear', not an unwinding roll; .*valid names: "
     r"parent"),
    ("span from nothing", lambda d: [_parent(d).pop("drive"),
                                     _parent(d).update(kind="wound", free=["z"])],
     r"\[web.span\] from: 'parent' is roll 'parent' of kind 'wound', not an unwinding "
     r"roll; .*valid names: \(none: no roll has kind = unwinding\)"),
    ("span from missing", lambda d: d["web"]["span"].pop("from"),
     r"\[web.span\] from: missing required key"),
    ("span with tension", lambda d: d["web"].update(tension=1000.0),
     r"\[web\] tension: 1000.0: with \[web.span\] the tension is the span's state, "
     r"docs/model.md §6; valid: remove tension"),
    ("span without entry", lambda d: d["web"].pop("entry_nip"),
     r"\[web\] entry_nip: missing required key"),
    ("span length 0", lambda d: d["web"]["span"].update(length=0.0),
     r"\[web.span\] length: must be > 0 and <= 1000, got 0.0"),
    ("span no EA", lambda d: d["web"]["span"].pop("EA"),
     r"\[web.span\] EA: missing required key"),
    ("span EA negative", lambda d: d["web"]["span"].update(EA=-1.0),
     r"\[web.span\] EA: must be > 0 and <= 1e\+12, got -1.0"),
    ("span T_in negative", lambda d: d["web"]["span"].update(T_in=-1.0),
     r"\[web.span\] T_in: must be >= 0 and <= 1e\+07, got -1.0"),
    ("span initial negative", lambda d: d["web"]["span"].update(initial_tension=-5.0),
     r"\[web.span\] initial_tension: must be >= 0 and <= 1e\+07, got -5.0"),
    ("span initial nan", lambda d: d["web"]["span"].update(initial_tension=math.nan),
     r"\[web.span\] initial_tension: must be finite, got nan"),
    ("span unknown key", lambda d: d["web"]["span"].update(width=5.0),
     r"\[web.span\] width: unknown key; valid keys: from, to, length, EA, T_in, "
     r"initial_tension"),
    ("span to on the only span", lambda d: d["web"]["span"].update(to="set"),
     r"\[web.span\] to: 'set': the last span ends at the entry nip's drum"),
    ("span not a table", lambda d: d["web"].update(span=3.0),
     r"\[web.span\] must be a table of keys, got 3.0"),
    ("span from a number", lambda d: d["web"]["span"].update({"from": 1}),
     r"\[web.span\] from: expected a string, got 1 \(int\)"),
]


@pytest.mark.parametrize("case, edit, pattern", BAD, ids=[b[0] for b in BAD])
def test_bad_line_names_key_value_and_valid(tmp_path, case, edit, pattern) -> None:
    data = _line()
    edit(data)
    with pytest.raises(winder.SceneError, match=pattern) as info:
        _load(tmp_path, data)
    assert str(info.value).startswith(f"{tmp_path / 'scene.toml'}: ")
    assert len(str(info.value)) < 600


def test_single_drum_format_has_no_unwinding_or_span(tmp_path, models_dir) -> None:
    """Unwinding rolls and spans are parts: the single-drum format rejects both."""
    data = tomllib.loads((models_dir / "paper_winding.toml").read_text(encoding="utf-8"))
    data["roll"]["kind"] = "unwinding"
    with pytest.raises(winder.SceneError, match=r"\[roll\] kind: unknown key; valid keys: "
                                                r"core_radius"):
        _load(tmp_path, data)
    del data["roll"]["kind"]
    data["web"] = {"entry_nip": "nip", "span": {"from": "roll", "length": 3.0, "EA": 1e6}}
    with pytest.raises(winder.SceneError, match=r"\[web\]: a table of scenes of parts in a "
                                                r"scene of the single-drum format"):
        _load(tmp_path, data)
