"""Hard cases: each completes with finite results and a balance that holds, or stops with
a clear winder exception naming time and state — never NaN, never a hang."""

from __future__ import annotations

import math

import numpy as np
import pytest

import winder


def _finite(res: winder.Result) -> None:
    for name in res:
        assert np.all(np.isfinite(res[name])), name


def _smooth(paper_scene, **changes) -> winder.Scene:
    roll = {"com_offset": 0.0, **changes.pop("roll", {})}
    return paper_scene.replace(roll=roll, **changes)


def test_very_stiff_nip(paper_scene) -> None:
    """k = 1e10 N/m: the roll rests on the drum with F_n = m g on average."""
    scene = _smooth(paper_scene, contact={"stiffness": 1e10, "damping": 1e5})
    res = winder.simulate(scene, t_end=5.0, output_step=0.01)
    _finite(res)
    late = res.t > 1.0
    np.testing.assert_allclose(res["normal_force"][late], res["mass"][late] * 9.81, rtol=1e-3)


def test_tiny_slip_velocity(paper_scene) -> None:
    """v_ref = 1e-5 m/s (stiff friction): the roll follows the drum, Ω R = ω r."""
    scene = _smooth(paper_scene, friction={"slip_velocity": 1e-5})
    res = winder.simulate(scene, t_end=5.0, output_step=0.01)
    _finite(res)
    late = res.t > 2.0
    v = res["drum_speed"][late] * 0.5
    assert np.max(np.abs(res["slip_velocity"][late])) < 1e-3 * np.max(v)


def test_violent_bouncing(paper_scene) -> None:
    """com_offset 5 mm: the roll flies; momentum balance in z over the run:
    m ż(T) − m ż(0) ≈ ∫ (F_n − m g) dt (growth adds little here), and it lands again."""
    scene = paper_scene.replace(roll={"com_offset": 0.005}, paper={"density": 0.0,
                                                                   "caliper": 1e-9})
    res = winder.simulate(scene, t_end=8.0, output_step=1e-4)
    _finite(res)
    assert np.mean(res["normal_force"] == 0.0) > 0.05  # really in the air
    m, e = 30.0, 0.005
    # vertical momentum of the CoM: p = m (ż + e cos φ ω)
    p = m * (res["z_dot"] + e * np.cos(res["roll_angle"]) * res["roll_speed"])
    impulse = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(res.t) * (
        (res["normal_force"] - m * 9.81)[1:] + (res["normal_force"] - m * 9.81)[:-1]))])
    # measured: 6.8e-4 of a second of weight, the same at rtol 1e-10 (the trapezoidal
    # impulse over the force jumps at touch-down, falling with the sampling step)
    assert np.max(np.abs(p - p[0] - impulse)) < 7e-3 * m * 9.81


def test_long_run_keeps_angular_momentum(models_dir) -> None:
    """10 000 s of free spin: J ω stays constant."""
    scene = winder.load_scene(models_dir / "free_spin.toml")
    res = winder.simulate(scene, t_end=10_000.0, output_step=10.0, rtol=1e-10, atol=1e-12)
    _finite(res)
    jw = res["inertia"] * res["roll_speed"]
    assert np.max(np.abs(jw - jw[0])) / jw[0] < 1e-7
    assert res["radius"][-1] > 0.3


def test_zero_caliper_is_rejected_with_the_key(tmp_path, models_dir) -> None:
    text = (models_dir / "paper_winding.toml").read_text().replace(
        "caliper = 160e-6", "caliper = 0.0")
    p = tmp_path / "flat.toml"
    p.write_text(text)
    with pytest.raises(winder.SceneError, match=r"\[paper\] caliper: must be > 0"):
        winder.load_scene(p)


@pytest.mark.parametrize(("method", "backend"), [("DOPRI5", "compiled"),
                                                 ("LSODA", "pinocchio")])
def test_variable_mass_terms_against_closed_forms(models_dir, method, backend) -> None:
    """Free spin with a caliper that matters (J grows 4.4x in 20 s): with −Ẏv, J ω stays
    J₀ ω₀ (dropping, doubling or flipping the term breaks it by a factor of ~4); with
    variable_mass off, the constant-mass closed form ω = ω₀ although m(r), J(r) grow; with
    the web's momentum ṁ u at u = ω r, −Ẏv is cancelled and ω = ω₀ again (spec §3)."""
    scene = winder.load_scene(models_dir / "free_spin.toml")
    kw = {"t_end": 20.0, "output_step": 0.5, "method": method, "backend": backend,
          "rtol": 1e-10, "atol": 1e-12}
    on = winder.simulate(scene, **kw)
    L = on["inertia"] * on["roll_speed"]
    assert on["inertia"][-1] > 4 * on["inertia"][0]
    assert np.max(np.abs(L / L[0] - 1)) < 1e-9  # measured: 9.4e-11 and 9.9e-11
    for effects in ({"variable_mass": False}, {"web_momentum": True}):
        res = winder.simulate(scene.replace(effects=effects), **kw)
        assert res["inertia"][-1] > 20 * res["inertia"][0]
        # measured: 0 to 1.1e-16 (nothing changes ω)
        np.testing.assert_allclose(res["roll_speed"], 200.0, rtol=1e-14, err_msg=str(effects))


@pytest.mark.parametrize("width", [50.0, 0.01])
def test_huge_and_tiny_widths(paper_scene, width: float) -> None:
    scene = _smooth(paper_scene, roll={"width": width})
    res = winder.simulate(scene, t_end=3.0, output_step=0.01)
    _finite(res)
    late = res.t > 1.0
    # measured: 3.2e-5 (width 50 m) and 3.5e-5 (1 cm)
    np.testing.assert_allclose(res["normal_force"][late], res["mass"][late] * 9.81,
                               rtol=3.5e-4)


def test_roll_dropped_onto_the_drum(paper_scene) -> None:
    """Released 5 cm above contact: it lands (impacts) and settles on F_n = m g."""
    scene = _smooth(paper_scene, roll={"initial_height": 0.5 + 0.075 + 0.05})
    res = winder.simulate(scene, t_end=3.0, output_step=1e-3)
    _finite(res)
    t_land = res.t[np.argmax(res["normal_force"] > 0)]
    assert t_land == pytest.approx(math.sqrt(2 * 0.05 / 9.81), abs=2e-3)  # free fall
    assert res["normal_force"].max() > 10 * 30 * 9.81  # an impact
    assert res["normal_force"][-1] == pytest.approx(res["mass"][-1] * 9.81, rel=1e-2)


def test_budget_is_reported_with_time_step_and_state(paper_scene) -> None:
    """The evaluation budget stops the run with BudgetExceeded naming the budget, how to
    raise it, the time, the last step and the state."""
    with pytest.raises(winder.BudgetExceeded,
                       match=r"max_rhs = 500 evaluations reached at t = .* s of t_end = 5 s "
                             r".*last step .* s; state: roll.z=.*raise max_rhs") as e:
        winder.simulate(paper_scene, t_end=5.0, max_rhs=500)
    assert e.value.time is not None and "roll.radius" in e.value.state and e.value.step > 0


def test_scipy_integrator_failure_is_a_clear_error(paper_scene) -> None:
    """DOP853 at rtol 1e-12 cannot step over the touch-down jump of the damped nip force
    in the bouncing phase: a SimulationError naming the method, time and state (this
    used to crash with an AttributeError when no sample had been written)."""
    start = winder.simulate(paper_scene, t_end=25.0, method="DOPRI5", rtol=1e-10,
                            atol=1e-12, output_step=25.0)
    # the state vector by name (roll.theta = -roll_angle: the roll's sense is -1)
    y25 = [start["z"][-1], -start["roll_angle"][-1], start["z_dot"][-1],
           -start["roll_speed"][-1], start["radius"][-1], start["friction_force"][-1]]
    with pytest.raises(winder.SimulationError, match="integrator DOP853 failed") as info:
        winder.simulate(paper_scene, t_start=25.0, initial_state=y25, t_end=25.5,
                        method="DOP853", rtol=1e-12, atol=1e-14, output_step=0.5)
    assert 25.0 <= info.value.time < 25.5
    assert set(info.value.state) == {"roll.z", "roll.theta", "roll.z_dot", "roll.theta_dot",
                                     "roll.radius", "nip.friction"}


def test_initial_radius_equal_to_core(paper_scene) -> None:
    """r₀ = r_c exactly: static equilibrium F_n = m g at t = 0; the imbalance turns the
    empty core backwards (r stays r_c, spec §2), then the wound length identity
    r = r_c + h (φ − φ_turn)/2π (one caliper per turn from the turning point) holds."""
    scene = paper_scene.replace(roll={"initial_radius": paper_scene.roll.core_radius})
    res = winder.simulate(scene, t_end=5.0, output_step=0.001)
    _finite(res)
    # to the round-off floor of F_n = k (R + r − z): k·z·ε ≈ 2e7·0.575·2.2e-16 ≈ 3e-9 N
    assert res["normal_force"][0] == pytest.approx(res["mass"][0] * 9.81, abs=1e-8)
    phi = res["roll_angle"]
    turn = np.argmin(phi)
    assert phi[turn] < 0 and np.all(res["radius"][:turn + 1] == 0.075)
    wound = res["radius"][turn + 1:] - scene.paper.caliper * phi[turn + 1:] / (2 * math.pi)
    assert np.ptp(wound) < 5e-15  # r − h φ/2π is constant after the turn; measured 4e-16
    r_expected = 0.075 + scene.paper.caliper * (phi[turn:] - phi[turn]) / (2 * math.pi)
    # measured: 1.6e-10 relative (the sampled minimum of φ misses the turn by ≤ 0.5 ms:
    # ½|ω̇|Δt² h/2π ≈ 1e-11 m)
    np.testing.assert_allclose(res["radius"][turn:], r_expected, rtol=1.5e-9)


@pytest.mark.parametrize("method", ["DOPRI5", "LSODA"])
def test_evaluation_guard_stops_with_time_and_state(paper_scene, method) -> None:
    """A run that would need more evaluations than max_rhs stops with BudgetExceeded
    naming the budget, time and state instead of running on."""
    with pytest.raises(winder.BudgetExceeded, match="max_rhs") as info:
        winder.simulate(paper_scene, t_end=30.0, method=method, max_rhs=5_000)
    assert 0.0 <= info.value.time < 30.0 and "roll.radius" in info.value.state
