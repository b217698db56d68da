"""Oracle tests of the winder model (spec §§1-6) against closed forms and identities."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import random_states

import winder
from winder._system import WinderSystem


def _planar_accel(scene: winder.Scene, sys_: WinderSystem, t: float, y: np.ndarray):
    """Spec §3 by hand: M(q,r) q̈ = Q − (∂M/∂r ṙ) q̇ − C − G, q = (z, φ)."""
    z, phi, zd, w, r = y[:5]
    fx = scene.effects
    e = scene.roll.com_offset if fx.imbalance else 0.0
    g = scene.scene.gravity if fx.gravity else 0.0
    law = sys_.law
    m, J = law.mass(r), law.polar_inertia(r)
    rdot = scene.paper.caliper * w / (2 * math.pi)
    mdot, Jdot = (law.mass_derivative(r) * rdot, law.polar_inertia_derivative(r) * rdot) \
        if fx.variable_mass else (0.0, 0.0)
    _, Om, _ = sys_.drive.kinematics(t, [])
    R = scene.drum.radius
    Fn = Ft = Tweb = 0.0
    if fx.contact:
        c = scene.contact
        delta, ddot = R + r - z, rdot - zd
        Fn = max(0.0, c.stiffness * delta + c.damping * ddot) if delta > 0 else 0.0
        vs = Om * R - w * r
        Fss = scene.friction.mu * Fn * math.tanh(vs / scene.friction.slip_velocity)
        Ft = y[5] if fx.slip_relaxation else Fss
    if fx.web_momentum:
        u = Om * R if fx.contact else w * r
        Tweb = law.mass_derivative(r) * rdot * u
    M = np.array([[m, m * e * math.cos(phi)], [m * e * math.cos(phi), J]])
    dM = np.array([[mdot, mdot * e * math.cos(phi)], [mdot * e * math.cos(phi), Jdot]])
    C = np.array([-m * e * math.sin(phi) * w**2, 0.0])
    G = np.array([m * g, m * g * e * math.cos(phi)])
    Q = np.array([Fn, r * (Ft + Tweb)])
    return np.linalg.solve(M, Q - dM @ np.array([zd, w]) - C - G), Ft


@pytest.mark.parametrize("toggle", [None, "variable_mass", "web_momentum", "imbalance",
                                    "slip_relaxation", "gravity"])
def test_pinocchio_equals_planar_equations(paper_scene, toggle) -> None:
    scene = paper_scene if toggle is None else paper_scene.replace(effects={toggle: False})
    sys_ = WinderSystem(scene)
    for t, y in random_states(sys_, np.random.default_rng(3), 20):
        dy = sys_.rhs(t, y)
        acc, _ = _planar_accel(scene, sys_, t, y)
        np.testing.assert_allclose(dy[2:4], acc, rtol=1e-11, atol=1e-9)


def test_drum_torque_rnea_equals_balance(paper_scene) -> None:
    """τ_d = J_d Ω̇ + R F_t (spec §5) from RNEA, on random states during the ramp."""
    sys_ = WinderSystem(paper_scene)
    rng = np.random.default_rng(4)
    y = sys_.initial_state()
    T = rng.uniform(0, 40, 10)
    Y = np.repeat(y[:, None], 10, axis=1)
    Y[3] = rng.uniform(0, 200, 10)
    Y[5] = rng.normal(0, 300, 10)
    ch = sys_.channels(T, Y)
    expected = paper_scene.drum.inertia * 0.5 / 0.5 + 0.5 * ch["friction_force"]
    np.testing.assert_allclose(ch["drum_torque"], expected, rtol=1e-12, atol=1e-9)


def test_static_equilibrium_at_start(paper_scene) -> None:
    scene = paper_scene.replace(effects={"imbalance": False})
    sys_ = WinderSystem(scene)
    y0 = sys_.initial_state()
    dy = sys_.rhs(0.0, y0)
    m0 = scene.roll.core_mass
    # round-off floor: δ = R + r − z loses ulp(z), i.e. k·ε·z/m of acceleration
    assert abs(dy[2]) < 4 * 2e7 * np.finfo(float).eps * y0[0] / m0
    ch = sys_.channels(np.array([0.0]), y0[:, None])
    # same round-off floor in force: k·ulp(z)
    assert abs(ch["normal_force"][0] - m0 * 9.81) < 4 * 2e7 * np.finfo(float).eps * y0[0]
    assert y0[0] == pytest.approx(0.5 + 0.075 - m0 * 9.81 / 2e7, rel=1e-15)


def _steady_scene(paper_scene, **effects) -> winder.Scene:
    """Drum at 20 m/s from t = 0, roll spun up to match, no imbalance."""
    return paper_scene.replace(effects={"imbalance": False, **effects},
                               drum={"drive": {"web_acceleration": 0.0}},
                               roll={"initial_speed": 20.0 / 0.075})


def test_constant_surface_speed_radius_law(paper_scene) -> None:
    scene = _steady_scene(paper_scene)
    res = winder.simulate(scene, t_end=30.0, output_step=0.05)
    h, v, rc = 160e-6, 20.0, 0.075
    t, r = res.t, res["radius"]
    closed = np.sqrt(rc**2 + h * v * t / math.pi)
    # closed form: holds up to the slip needed to carry the torque (|v_s| << v)
    assert np.max(np.abs(r - closed) / closed) < 2e-4
    # exact identity: ṙ = h φ̇ / 2π, so r = r_c + h φ / 2π (φ(0) = 0)
    np.testing.assert_allclose(r - rc, h * res["roll_angle"] / (2 * math.pi), rtol=1e-7,
                               atol=1e-12)
    # no slip in steady state: Ω R = ω r to within the slip that transmits the torque
    late = t > 2.0
    assert np.max(np.abs(res["slip_velocity"][late])) < 2e-3 * v


@pytest.mark.parametrize("web", [True, False])
def test_drum_torque_at_constant_web_speed(paper_scene, web) -> None:
    """e = 0, Ω̇ = 0: τ_d = R F_t and the roll's rotation equation
    J ω̇ + J̇ ω = r (F_t + ṁ Ω R [web]) give τ_d = (R/r)(J ω̇ + J̇ ω) − [web] R ṁ Ω R exactly;
    with no slip that is ≈ R J ω̇ / r with web momentum and R d(Jω)/dt / r without."""
    scene = _steady_scene(paper_scene, web_momentum=web)
    res = winder.simulate(scene, t_end=20.0, output_step=0.05)
    R = 0.5
    r, w, wd = res["radius"], res["roll_speed"], res["roll_accel"]
    J, Jd, md, Om = res["inertia"], res["inertia_rate"], res["mass_rate"], res["drum_speed"]
    exact = R / r * (J * wd + Jd * w) - (R * md * Om * R if web else 0.0)
    np.testing.assert_allclose(res["drum_torque"], exact, rtol=1e-9,
                               atol=1e-9 * np.max(np.abs(exact)))
    late = res.t > 3.0
    approx = R / r * J * wd if web else R / r * (J * wd + Jd * w)
    err = np.max(np.abs(res["drum_torque"][late] - approx[late])) / np.max(np.abs(approx[late]))
    assert err < 0.02
    if web:
        assert np.all(res["drum_torque"][late] < 0)  # the paper's negative drum torque
    else:
        assert np.all(res["drum_torque"][late] > 0)


def test_energy_conserved_without_dissipation(paper_scene) -> None:
    """No damping, friction, growth or drive: E = T + V_g + ½kδ² is constant, through
    lift-offs and impacts (events locate them)."""
    scene = paper_scene.replace(
        contact={"damping": 0.0}, friction={"mu": 0.0},
        paper={"density": 0.0, "caliper": 1e-12},  # growth would compress the nip: work
        drum={"drive": {"web_speed": 0.0, "web_acceleration": 0.0}},
        roll={"initial_speed": 150.0, "com_offset": 0.002},
        effects={"slip_relaxation": False})
    res = winder.simulate(scene, t_end=2.0, output_step=1e-3, method="DOP853", rtol=1e-12,
                          atol=1e-14)
    m, J, e, g, k = 30.0, 0.12, 0.002, 9.81, 2e7
    z, zd, w, phi = res["z"], res["z_dot"], res["roll_speed"], res["roll_angle"]
    delta = np.maximum(0.0, 0.5 + res["radius"] - z)
    E = (0.5 * m * zd**2 + m * e * np.cos(phi) * zd * w + 0.5 * J * w**2
         + m * g * (z + e * np.sin(phi)) + 0.5 * k * delta**2)
    assert np.any(res["normal_force"] == 0.0)  # it really lifts off
    assert np.max(np.abs(E - E[0])) / abs(E[0]) < 1e-8


def test_progress_in_a_log_is_line_per_report(paper_scene, capsys) -> None:
    """Oracle: when stderr is not a terminal, progress is whole lines (no carriage
    returns that would pile up in a CI log) and the last one reports 100 %."""
    winder.simulate(paper_scene, t_end=2.0, progress=True)
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = [line for line in err.splitlines() if "%" in line]
    assert lines and "100.0%" in lines[-1]
    assert "t =     2.00 s" in lines[-1]
