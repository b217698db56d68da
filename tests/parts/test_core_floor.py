"""The radius floor (spec §2): a roll turning backwards unwinds down to its core and no
further. While ``r = r_c`` and ``ω < 0``: ``ṙ = ṁ = J̇ = 0`` (constant-mass dynamics),
switched by events on every path; after it turns forwards, ``r = r_c + h (φ − φ_turn)/2π``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import random_states, to_machine, to_old

import winder
from winder.solve.system import MachineSystem

R_CORE, CALIPER = 0.075, 160e-6

#: (method, backend, options) of every integration path of simulate()
PATHS = [("DOPRI5", "compiled", {}), ("RK4", "compiled", {"max_step": 1e-4}),
         ("LSODA", "compiled", {}), ("RK45", "compiled", {}), ("Radau", "compiled", {}),
         ("LSODA", "pinocchio", {}), ("RK4", "pinocchio", {"max_step": 1e-4})]


def _tight(options: dict) -> dict:
    return options if "max_step" in options else {"rtol": 1e-10, "atol": 1e-12}


def _check_floor(res: winder.Result, core_mass: float) -> None:
    """r >= r_c on every sample; at the core turning backwards, ṁ = J̇ = 0 and m, J are
    the core's; once off the core, r − h φ/2π is constant and equals r_c − h φ_turn/2π
    (φ_turn: the angle where it turned forwards, the minimum of φ)."""
    r, phi, w = res["radius"], res["roll_angle"], res["roll_speed"]
    assert r.min() >= R_CORE  # exactly: the event lands on r_c
    at = r == R_CORE
    backwards = at & (w < 0)
    assert backwards.sum() > 10  # the case really meets the core
    assert np.all(res["mass"][at] == core_mass)
    assert np.all(res["mass_rate"][backwards] == 0.0)
    assert np.all(res["inertia_rate"][backwards] == 0.0)
    assert np.ptp(res["inertia"][at]) == 0.0
    off = ~at
    wound = r[off] - CALIPER * phi[off] / (2 * math.pi)
    # measured: ptp 2e-16 to 7e-16 m; offset 6e-14 m (paper) and 4.6e-13 m (ω₀ = −5), the
    # error of the sampled minimum of φ (1e-4 s sampling: ½|ω̇|(Δt/2)² h/2π)
    assert np.ptp(wound) < 1e-14
    assert wound[0] == pytest.approx(R_CORE - CALIPER * phi.min() / (2 * math.pi), abs=5e-12)


@pytest.mark.parametrize(("method", "backend", "options"), PATHS)
def test_paper_scene_meets_the_core(paper_scene, method, backend, options) -> None:
    """The shipped paper scene: the imbalance turns the empty core backwards for ~0.05 s
    (it went 33 nm below the core before the floor)."""
    res = winder.simulate(paper_scene, t_end=0.1, output_step=1e-4, method=method,
                          backend=backend, **_tight(options))
    _check_floor(res, paper_scene.roll.core_mass)


@pytest.mark.parametrize(("method", "backend", "options"), PATHS[:1] + PATHS[5:6])
def test_backwards_start_turns_forwards(paper_scene, method, backend, options) -> None:
    """initial_speed = −5 rad/s: at the core until the drum turns it forwards."""
    scene = paper_scene.replace(roll={"initial_speed": -5.0})
    res = winder.simulate(scene, t_end=0.3, output_step=1e-4, method=method, backend=backend,
                          **_tight(options))
    _check_floor(res, scene.roll.core_mass)
    assert res["roll_speed"][-1] > 0


@pytest.mark.parametrize(("method", "backend", "options"), PATHS)
def test_free_spin_backwards_keeps_omega(models_dir, method, backend, options) -> None:
    """Free spin backwards from the core: no paper to unwind, no force: ω, J ω, m and r
    constant (exactly: ṙ = 0 and no other term)."""
    scene = winder.load_scene(models_dir / "free_spin.toml").replace(
        roll={"initial_speed": -200.0})
    res = winder.simulate(scene, t_end=50.0, output_step=0.5, method=method, backend=backend,
                          **({"max_step": 0.05} if method == "RK4" else {}))
    assert np.all(res["radius"] == R_CORE)
    assert np.all(res["roll_speed"] == -200.0)
    assert np.all(res["mass"] == scene.roll.core_mass)
    assert np.all(res["inertia"] * res["roll_speed"] == res["inertia"][0] * -200.0)


@pytest.mark.parametrize(("method", "options", "tol"), [
    ("RK4", {"max_step": 1e-4}, 1e-14),  # measured: 7e-16 relative to the maximum
    ("LSODA", {"rtol": 1e-10, "atol": 1e-12}, 1e-8),  # measured: 1.1e-9 (mass_rate)
])
def test_backends_agree_at_the_core(paper_scene, method, options, tol) -> None:
    """Same method, both backends, through the backward phase and the turn: RK4 (same
    steps, same event location) to round-off; LSODA (its own step choices) closely."""
    scene = paper_scene.replace(roll={"initial_speed": -5.0})
    kw = {"t_end": 0.3, "output_step": 1e-3, "method": method, **options}
    a = winder.simulate(scene, backend="compiled", **kw)
    b = winder.simulate(scene, backend="pinocchio", **kw)
    for name in ("radius", "roll_speed", "roll_angle", "z", "mass", "mass_rate"):
        np.testing.assert_allclose(a[name], b[name], rtol=0,
                                   atol=tol * np.max(np.abs(b[name])), err_msg=name)


def test_stepper_agrees_with_simulate_at_the_core(paper_scene) -> None:
    """1 ms communication steps through the backward phase (r = r_c) and the turn."""
    scene = paper_scene.replace(roll={"initial_speed": -5.0})
    ref = winder.simulate(scene, t_end=0.3, method="DOPRI5", rtol=1e-11, atol=1e-13,
                          output_step=0.01)
    sim = winder.Stepper(scene)
    got = []
    for i in range(300):
        sim.step(1e-3)
        assert sim.y[4] >= R_CORE
        if (i + 1) % 10 == 0:
            got.append((sim.output("radius"), sim.output("roll_speed"), sim.output("mass")))
    got = np.array(got)
    for j, name in enumerate(("radius", "roll_speed", "mass")):
        # measured: 2e-10 (roll_speed), 1e-13 (radius, mass) relative to the maximum
        err = np.max(np.abs(got[:, j] - ref[name][1:])) / np.max(np.abs(ref[name]))
        assert err < 2e-9, (name, err)
    assert np.sum(ref["radius"] == R_CORE) > 10


@pytest.mark.parametrize("backend", ["compiled", "pinocchio"])
def test_at_core_rhs_is_constant_mass(paper_scene, backend) -> None:
    """At the core turning backwards, the right-hand side is that of constant mass: ṙ = 0
    and the accelerations equal those with variable_mass and web_momentum off (spec §3
    with ṁ = J̇ = 0); turning forwards at the core, ṙ = h ω/2π."""
    const = paper_scene.replace(effects={"variable_mass": False, "web_momentum": False})

    system, system_const = (MachineSystem(s, backend=backend) for s in (paper_scene, const))

    def f(t: float, y: np.ndarray, s: MachineSystem = system) -> np.ndarray:
        """The right-hand side in the old layout (z, φ, ż, ω, r, F_t)."""
        return to_old(s, s.rhs(t, to_machine(s, y)))

    rng = np.random.default_rng(5)
    for t, y_machine in random_states(system, rng, 20):
        y = to_old(system, y_machine)
        y[4] = R_CORE
        y[3] = -abs(y[3]) - 0.1
        dy = f(t, y)
        assert dy[4] == 0.0
        np.testing.assert_allclose(dy, f(t, y, system_const), rtol=1e-13, atol=1e-12)
        y[3] = -y[3]
        assert f(t, y)[4] == pytest.approx(CALIPER * y[3] / (2 * math.pi), rel=1e-15)


def test_initial_state_below_the_core_is_refused(paper_scene) -> None:
    system = MachineSystem(paper_scene)
    y0 = system.initial_state()
    y0[system.index("roll.radius")] = R_CORE - 1e-9
    with pytest.raises(winder.ArgumentError, match=r"initial_state.*roll.radius >= 0.075 m"):
        winder.simulate(paper_scene, initial_state=y0, t_end=1.0)
