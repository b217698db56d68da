"""Switching ``flex`` on keeps the body's channels (issue 32, item 4): a flexible body keeps
every body-level channel of its rigid self, with the same name, unit and meaning, beside
its segments' ``NAME_s{i}_...`` (:mod:`winder.model.whole_body`).

- Names and units: every scene with ``flex`` (the shipped ones and one of each flexible
  part here) against its rigid twin (every ``flex`` removed): the rigid machine's
  body-level channels are a subset of the flexible machine's, in the same units, and the
  inputs (a torque-driven drum's ``DRUM_torque``) are the same.
- Formed from the segments (identity, numeric path, a perturbed state of the shipped
  flexible winder): a driven drum's speed, angle, acceleration and torque are its drive
  end's (segment 0); an undriven body's speed, angle and acceleration the segments' mean,
  its torque their sum; a free body's ``x``, ``z`` the mean of its segments' states; a
  roll's radius the shared state, its mass the sum; a rider's load the sum.
- Meaning (the rigid run): a flexible drum under a rigid roll keeps the rigid drum's
  speed, angle and acceleration exactly (a speed profile: its drive end is prescribed)
  and its drive torque after the start (t ≥ 0.1 s; the step of the acceleration at t = 0
  rings the torsion); a torque-driven one its torque exactly and its speed to the
  integrator's tolerance; a stiff flexible roll every channel of the rigid roll.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import winder
from winder.model.machine import Machine
from winder.scene.load import load_scene
from winder.solve.stepper import inputs_of
from winder.solve.system import MachineSystem

sys.path.insert(0, str(Path(__file__).resolve().parent))
import test_flex_nip as fnip  # noqa: E402
import test_flex_rest as frest  # noqa: E402
import test_flex_rider as frider  # noqa: E402
import test_flex_roll as froll  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = sorted(p for p in (ROOT / "models").glob("*.toml") if "flex" in p.read_text())


def rigid_twin(scene: winder.Scene) -> winder.Scene:
    """``scene`` with every part's ``flex`` removed."""
    data = scene.to_dict()
    for table in data.values():
        for part in table if isinstance(table, list) else ():
            if isinstance(part, dict):
                part.pop("flex", None)
    return winder.scene_from_dict(data, source=f"{scene.source} (rigid)")


def body_channels(machine: Machine) -> dict[str, str]:
    """The body-level channels of ``machine`` (those a body registers for itself, its
    own or an effect's), with their units."""
    bodies = {b.name for b in machine.bodies} | {w.name for w in machine.wholes}
    return {n: machine.channel_units[n] for n, (_, owner) in machine.channel_owners.items()
            if owner in bodies}


def _scenes() -> list[Any]:
    def text(t: str) -> winder.Scene:
        return winder.scene_from_dict(tomllib.loads(t), source="case.toml")

    torque = '{ kind = "torque", torque = 2000.0, web_speed = 5.0 }'
    return [*(pytest.param(p, id=p.stem) for p in SHIPPED),
            pytest.param(frest.lone_drum(4, drive=torque), id="torque_drum"),
            pytest.param(text(fnip.scene_text(3)), id="drum_under_roll"),
            pytest.param(froll.scene(3, free='["x", "z"]'), id="free_roll"),
            pytest.param(froll.chucked(3), id="roll_on_chucks"),
            pytest.param(text(frider.scene_text(4)), id="rider")]


def test_every_shipped_flexible_scene_is_covered() -> None:
    assert [p.stem for p in SHIPPED] == ["two_drum_winder_flexible"]


@pytest.mark.parametrize("scene", _scenes())
def test_a_flexible_body_keeps_its_rigid_channels(scene: Any) -> None:
    flex = load_scene(scene) if isinstance(scene, Path) else scene
    rigid = rigid_twin(flex)
    mf, mr = Machine(flex), Machine(rigid)
    assert mf.wholes, "no flexible body"
    want, got = body_channels(mr), body_channels(mf)
    missing = sorted(set(want) - set(got))
    assert not missing, missing
    assert {n: got[n] for n in want} == want
    for w in mf.wholes:  # and they are the whole body's, not a segment's
        assert all(mf.channel_owners[n][1] == w.name
                   for n in want if mr.channel_owners[n][1] == w.name)
    # the inputs of a co-simulation (FMU, Stepper) too
    assert inputs_of(MachineSystem(flex, backend="pinocchio")) == \
        inputs_of(MachineSystem(rigid, backend="pinocchio"))


def test_whole_channels_are_formed_from_their_segments() -> None:
    """Numeric path, the shipped flexible winder at its balance with every state perturbed:
    each whole-body channel against its definition, from the states where it can be (the
    segments' channels otherwise). Measured: equal to 1e-16 relative (summation order)."""
    sys_ = MachineSystem(load_scene(SHIPPED[0]), backend="pinocchio")
    m = sys_.machine
    y = sys_.initial_state()
    rng = np.random.default_rng(32)
    y = y + 1e-4 * rng.standard_normal(y.size) * np.maximum(np.abs(y), 1e-2)
    ev = sys_.evaluate_numeric(0.3, y)
    ch = {k: float(v) for k, v in ev.channels.items()}

    def seg(body: str, what: str) -> np.ndarray:
        return np.array([ch[f"{body}_s{i}_{what}"] for i in range(8)])

    def st(body: str, coord: str) -> np.ndarray:
        return np.array([y[m.index(f"{body}_s{i}.{coord}")] for i in range(8)])

    def close(got: float, values: np.ndarray, how: Any = np.mean, sense: int = 1) -> bool:
        """``got`` is ``sense · how(values)`` to round-off, relative to the values."""
        return abs(got - sense * float(how(values))) <= 1e-14 * float(np.max(np.abs(values)))

    for drum in ("front", "rear"):  # driven (speed profile): the drive end
        for what in ("speed", "angle", "accel", "torque"):
            assert ch[f"{drum}_{what}"] == ch[f"{drum}_s0_{what}"], (drum, what)
        assert f"{drum}_x" not in ch and f"{drum}_z" not in ch  # the rigid drum is fixed
    for body, sense in (("set", -1), ("rider", 1)):  # undriven: mean, sum
        assert close(ch[f"{body}_speed"], st(body, "theta_dot"), sense=sense)
        assert close(ch[f"{body}_angle"], st(body, "theta"), sense=sense)
        assert close(ch[f"{body}_accel"], seg(body, "accel"))
        assert close(ch[f"{body}_torque"], seg(body, "torque"), np.sum)
        for c in ("z",) if body == "rider" else ("x", "z"):
            assert close(ch[f"{body}_{c}"], st(body, c))
            assert close(ch[f"{body}_{c}_dot"], st(body, f"{c}_dot"))
            assert close(ch[f"{body}_{c}_accel"], seg(body, f"{c}_accel"))
    assert "rider_x" not in ch  # the rigid rider is free in z only
    assert ch["set_radius"] == y[m.index("set.radius")]
    for what in ("mass", "inertia", "mass_rate", "inertia_rate"):
        assert close(ch[f"set_{what}"], seg("set", what), np.sum)
    assert close(ch["rider_load"], seg("rider", "load"), np.sum)
    assert ch["rider_load"] > 0.0


# ---- the meaning: against the rigid run ---------------------------------------------------
SPEED_PROFILE = '{ kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }'
TORQUE = '{ kind = "torque", torque = 2000.0, web_speed = 5.0 }'


def drum_under_roll(drive: str, *, rigid: bool = False, scale: float = 1.0) -> winder.Scene:
    """The flexible drum of ``test_flex_nip.py`` (N = 3, damped ζ = 0.2) under its rigid
    roll, with ``drive``; ``scale`` × its stiffnesses; ``rigid``: its rigid twin."""
    data = tomllib.loads(fnip.scene_text(3).replace("damping_ratio = 0.02",
                                                    "damping_ratio = 0.2")
                         .replace(SPEED_PROFILE, drive))
    flex = data["drum"][0]["flex"]
    for key in ("EI", "kGA", "GJ", "bearing_stiffness"):
        flex[key] *= scale
    if rigid:
        del data["drum"][0]["flex"]
    return winder.scene_from_dict(data, source="drum.toml")


def _err(rigid: Any, flex: Any, name: str, after: float = 0.0) -> float:
    """Largest difference of channel ``name`` at ``t ≥ after``, relative to the rigid
    run's largest value."""
    w = rigid.t >= after
    return float(np.max(np.abs(flex[name][w] - rigid[name][w])) /
                 np.max(np.abs(rigid[name])))


def test_speed_profile_drum_keeps_its_speed_and_drive_torque() -> None:
    """Speed, angle, acceleration: the rigid drum's exactly (the prescribed profile at the
    drive end; the segments' mean would differ by 1.4e-5, 3.2e-5 and 4.1e-4). Drive
    torque after the start: measured 6.9e-4 of its largest (the segments' mean: 0.68; at
    t < 0.1 s the step of the acceleration rings the torsion: 0.55)."""
    rigid = winder.simulate(drum_under_roll(SPEED_PROFILE, rigid=True), t_end=0.3)
    flex = winder.simulate(drum_under_roll(SPEED_PROFILE), t_end=0.3)
    for name in ("drum_speed", "drum_angle", "drum_accel"):
        assert _err(rigid, flex, name) <= 1e-15, name
    assert _err(rigid, flex, "drum_torque", after=0.1) < 7e-3


def test_torque_drum_keeps_its_torque_and_speed() -> None:
    """The drive torque is the input (exactly); the drive end's speed after the start the
    rigid drum's to the integrator's tolerance (rtol 1e-6; measured 2.1e-6 at 1× and 10×
    the stiffness); its angle leads the rigid one by the twist, ∝ 1/stiffness, once the
    start has rung out (t ≥ 0.05 s; measured 5.77e-7 and 6.13e-8: 9.4 ×; over the start
    the soft drum's first swing, ζ = 0.2 on its first torsion mode since issue #33, gives
    7.6e-7: 12.4 ×)."""
    rigid = winder.simulate(drum_under_roll(TORQUE, rigid=True), t_end=0.3)
    flex = winder.simulate(drum_under_roll(TORQUE), t_end=0.3)
    stiff = winder.simulate(drum_under_roll(TORQUE, scale=10.0), t_end=0.3)
    assert np.all(flex["drum_torque"] == 2000.0) and np.all(rigid["drum_torque"] == 2000.0)
    assert _err(rigid, flex, "drum_speed", after=0.1) < 2e-5
    assert _err(rigid, stiff, "drum_speed", after=0.1) < 2e-5
    ratio = _err(rigid, flex, "drum_angle", after=0.05) / \
        _err(rigid, stiff, "drum_angle", after=0.05)
    assert 7.0 < ratio < 12.0, ratio


#: each channel of the rigid roll: 10 × the measured difference of the stiff flexible roll
ROLL_TOLERANCE = {"roll_speed": 9e-9, "roll_angle": 2e-9, "roll_torque": 4e-8,
                  "roll_accel": 4e-8, "roll_z": 1e-14, "roll_z_dot": 3e-7,
                  "roll_z_accel": 4e-6, "roll_radius": 1e-14, "roll_mass": 2e-14,
                  "roll_inertia": 3e-14, "roll_mass_rate": 9e-9, "roll_inertia_rate": 9e-9}


def test_stiff_flexible_roll_keeps_every_channel_of_the_rigid_roll() -> None:
    """The stiff roll of ``test_flex_roll.py`` (core_EI, paper_E, GJ × 1e6, ζ 0.05), 0.2 s
    of winding from standstill at rtol 1e-9: every channel of the rigid roll (speed and
    angle the segments' mean, torque their sum, ``z`` their mean, radius the shared state,
    mass the sum, ...) against the rigid run (measured: speed 8.8e-10, torque 3.2e-9,
    z 6.9e-16, ż 2.7e-8, z̈ 3.3e-7, mass 1.2e-15, ṁ 8.8e-10; the segments' sum as the
    speed would be 3 ×, one segment's speed rings at 6.6e-7)."""
    text = froll.scene_text(3)
    rigid_scene = winder.scene_from_dict(tomllib.loads(
        text.split("flex = ")[0] + "[[nip]]" + text.split("[[nip]]")[1]), source="r.toml")
    stiff = froll.scene_text(3, core_ei=froll.CORE_EI * 1e6, paper_e=froll.PAPER_E * 1e6,
                             gj=froll.GJ * 1e6, damping=0.05)
    rigid = winder.simulate(rigid_scene, t_end=0.2, rtol=1e-9)
    flex = winder.simulate(winder.scene_from_dict(tomllib.loads(stiff), source="f.toml"),
                           t_end=0.2, rtol=1e-9)
    assert set(ROLL_TOLERANCE) == set(body_channels(Machine(rigid_scene))) - \
        {c for c in body_channels(Machine(rigid_scene)) if not c.startswith("roll_")}
    for name, tol in ROLL_TOLERANCE.items():
        assert _err(rigid, flex, name) < tol, (name, _err(rigid, flex, name))
