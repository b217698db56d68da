"""Step-wise simulation: inputs, fixed communication steps, accuracy against simulate()."""

from __future__ import annotations

import numpy as np
import pytest

import winder


def test_stepper_matches_adaptive_reference(paper_scene) -> None:
    """1 ms communication steps over the ramp and the first lift-offs (0-21 s): the
    restarted internal DOPRI5 (rtol 1e-8) stays within 1e-6 of a 1e-11 solution."""
    ref = winder.simulate(paper_scene, t_end=21.0, method="DOPRI5", rtol=1e-11, atol=1e-13,
                          output_step=0.1)
    sim = winder.Stepper(paper_scene)
    got = {k: [] for k in ("radius", "roll_speed", "z", "normal_force", "drum_torque")}
    for i in range(21_000):
        sim.step(1e-3)
        if (i + 1) % 100 == 0:
            for k in got:
                got[k].append(sim.output(k))
    assert sim.t == pytest.approx(21.0, abs=1e-9)
    for k, v in got.items():
        err = np.max(np.abs(np.array(v) - ref[k][1:])) / np.max(np.abs(ref[k]))
        assert err < 1e-6, (k, err)


def test_torque_drive_balance(paper_scene) -> None:
    """Free drum: J_d dΩ/dt = τ − R F_t (spec §5), checked by central differences of the
    drum speed output against the outputs at the midpoint."""
    scene = paper_scene.replace(drum={"drive": {"kind": "torque", "web_speed": 2.0,
                                                "torque": 0.0}})
    sim = winder.Stepper(scene, rtol=1e-11, atol=1e-13)
    sim.set_input("drum_torque", 300.0)
    dt = 1e-4
    speeds, balance = [], []
    for _ in range(3000):
        sim.step(dt)
        o = sim.outputs()
        speeds.append(o["drum_speed"])
        balance.append((o["drum_torque"] - 0.5 * o["friction_force"]) / scene.drum.inertia)
    speeds, balance = np.array(speeds), np.array(balance)
    fd = (speeds[2:] - speeds[:-2]) / (2 * dt)
    np.testing.assert_allclose(fd, balance[1:-1], rtol=0, atol=2e-4 * np.max(np.abs(balance)))
    assert speeds[-1] > speeds[0]  # 300 N·m accelerates the drum


def test_stepper_rejects_bad_use(paper_scene) -> None:
    sim = winder.Stepper(paper_scene)
    with pytest.raises(winder.ArgumentError, match="valid: drum_torque"):
        sim.set_input("drum_speed", 1.0)
    with pytest.raises(winder.ArgumentError, match="prescribes the drum speed"):
        sim.set_input("drum_torque", 1.0)
    with pytest.raises(winder.ArgumentError, match=r"dt = 0.0 is out of range"):
        sim.step(0.0)
    with pytest.raises(winder.ArgumentError, match="unknown output 'speed'"):
        sim.output("speed")
    torque = winder.Stepper(paper_scene.replace(drum={"drive": {"kind": "torque"}}))
    with pytest.raises(winder.ArgumentError, match=r"drum_torque = nan .* finite"):
        torque.set_input("drum_torque", float("nan"))
    with pytest.raises(winder.ArgumentTypeError, match="drum_torque must be a real number"):
        torque.set_input("drum_torque", "5")
