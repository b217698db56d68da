"""A free drum driven by ``[drum.drive] torque`` (spec §5 with the drum a free DOF):
``J_d dΩ/dt = τ − R F_t`` with τ the scene's torque, on every path."""

from __future__ import annotations

import numpy as np
import pytest

import winder

TORQUE = 300.0  # [N·m]
DT = 1e-4  # [s] sampling of the central differences


def _scene(paper_scene: winder.Scene, torque: float = TORQUE) -> winder.Scene:
    return paper_scene.replace(drum={"drive": {"kind": "torque", "web_speed": 2.0,
                                               "torque": torque}})


def _balance_error(scene: winder.Scene, t: np.ndarray, drum_speed: np.ndarray,
                   friction: np.ndarray) -> float:
    """Largest |central difference of Ω − (τ − R F_t)/J_d| with τ = TORQUE, relative to
    the largest |(τ − R F_t)/J_d|."""
    fd = (drum_speed[2:] - drum_speed[:-2]) / (t[2:] - t[:-2])
    balance = (TORQUE - scene.drum.radius * friction[1:-1]) / scene.drum.inertia
    return float(np.max(np.abs(fd - balance)) / np.max(np.abs(balance)))


@pytest.mark.parametrize(("method", "backend"), [("DOPRI5", "compiled"), ("RK4", "compiled"),
                                                 ("LSODA", "compiled"),
                                                 ("LSODA", "pinocchio"),
                                                 ("RK4", "pinocchio")])
def test_scene_torque_drives_the_drum(paper_scene, method, backend) -> None:
    scene = _scene(paper_scene)
    options = {"max_step": 1e-5} if method == "RK4" else {"rtol": 1e-10, "atol": 1e-12}
    # RK4 on the numeric backend: 80 000 evaluations, beyond that path's default budget
    res = winder.simulate(scene, t_end=0.2, output_step=DT, method=method, backend=backend,
                          max_rhs=200_000, **options)
    # measured: 1.06e-5 on every path (the O(Δt²) error of the central difference)
    assert _balance_error(scene, res.t, res["drum_speed"], res["friction_force"]) < 1e-4
    np.testing.assert_allclose(res["drum_torque"], TORQUE, rtol=1e-12)


def test_stepper_starts_from_the_scene_torque(paper_scene) -> None:
    """The Stepper's input is the scene's torque until set_input changes it."""
    scene = _scene(paper_scene)
    sim = winder.Stepper(scene, rtol=1e-11, atol=1e-13)
    assert sim.output("drum_torque") == TORQUE
    t, speed, friction = [0.0], [sim.output("drum_speed")], [sim.output("friction_force")]
    for _ in range(2000):
        sim.step(DT)
        t.append(sim.t)
        speed.append(sim.output("drum_speed"))
        friction.append(sim.output("friction_force"))
    # measured: 1.06e-5 (as simulate)
    assert _balance_error(scene, np.array(t), np.array(speed), np.array(friction)) < 1e-4
    sim.set_input("drum_torque", -TORQUE)
    assert sim.output("drum_torque") == -TORQUE


def test_other_torque_fails_the_balance(paper_scene) -> None:
    """The oracle bites: a run with another scene torque does not satisfy the balance
    with τ = TORQUE (as a path that ignored the key would not)."""
    scene = _scene(paper_scene, torque=0.0)
    res = winder.simulate(scene, t_end=0.2, output_step=DT, rtol=1e-10, atol=1e-12)
    assert _balance_error(_scene(paper_scene), res.t, res["drum_speed"],
                          res["friction_force"]) > 0.5
