"""Oracle tests of the winder model (spec §§1-6) against closed forms and identities."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import random_states, scene_variant, state_regions, to_machine, to_old
from scipy.optimize import brentq

import winder
from winder.solve.system import MachineSystem

DRUM_TORQUE = -75.0  # input torque of the free drum in these tests [N·m]


def _spec_rhs(scene: winder.Scene, t: float, y: np.ndarray) -> tuple[np.ndarray, float]:
    """Spec §§2-5 written out by hand from the scene's numbers (no winder code): ``dy/dt``
    of ``(z, φ, ż, ω, r, [θ_d, Ω], [F_t])`` and the drum torque τ_d [N·m]. The roll's rows
    are M(q,r) q̈ = Q − (∂M/∂r ṙ) q̇ − C − G with q = (z, φ)."""
    z, phi, zd, w, r = y[:5]
    fx, ro, pa, co, fr, dr = (scene.effects, scene.roll, scene.paper, scene.contact,
                              scene.friction, scene.drum)
    R, free = dr.radius, dr.drive.kind == "torque"
    e = ro.com_offset if fx.imbalance else 0.0
    g = scene.scene.gravity if fx.gravity else 0.0
    rpl = pa.density * math.pi * ro.width
    m = ro.core_mass + rpl * (r**2 - ro.core_radius**2)
    J = ro.core_inertia + 0.5 * rpl * (r**4 - ro.core_radius**4)
    rdot = pa.caliper * w / (2 * math.pi)
    mdot = 2 * math.pi * pa.density * ro.width * r * rdot
    mdot_vm, Jdot_vm = (mdot, mdot * r * r) if fx.variable_mass else (0.0, 0.0)
    if free:
        Om, Omd = y[6], math.nan
    else:
        a, v = dr.drive.web_acceleration, dr.drive.web_speed
        Om, Omd = (a * t / R, a / R) if a > 0 and a * t < v else (v / R, 0.0)
    Fn = Ft = 0.0
    dy = np.zeros(len(y))
    if fx.contact:
        delta, ddot = R + r - z, rdot - zd
        if delta > 0:
            law = (co.stiffness * delta + co.damping * ddot if co.law == "linear"
                   else co.stiffness * delta**co.exponent * (1 + co.hc_damping * ddot))
            Fn = max(0.0, law)
        vs = Om * R - w * r
        Ft = Fss = fr.mu * Fn * math.tanh(vs / fr.slip_velocity)
        if fx.slip_relaxation:
            Ft = y[-1]
            dy[-1] = (abs(Om * R) + fr.min_speed) / fr.relaxation_length * (Fss - Ft)
    Tweb = mdot * (Om * R if fx.contact else w * r) if fx.web_momentum else 0.0
    c = math.cos(phi)
    M = np.array([[m, m * e * c], [m * e * c, J]])
    dM = np.array([[mdot_vm, mdot_vm * e * c], [mdot_vm * e * c, Jdot_vm]])
    C = np.array([-m * e * math.sin(phi) * w**2, 0.0])
    G = np.array([m * g, m * g * e * c])
    Q = np.array([Fn, r * (Ft + Tweb)])
    dy[:5] = (zd, w, *np.linalg.solve(M, Q - dM @ np.array([zd, w]) - C - G), rdot)
    if free:  # J_d Ω̇ = τ − R F_t
        tau = DRUM_TORQUE
        dy[5], dy[6] = Om, (tau - R * Ft) / dr.inertia
    else:  # inverse dynamics of the prescribed drum
        tau = dr.inertia * Omd + R * Ft
    return dy, tau


SPEC_VARIANTS = [None, "variable_mass", "web_momentum", "imbalance", "slip_relaxation",
                 "gravity", "no_contact", "hunt_crossley", "torque", "hunt_crossley_torque"]


@pytest.mark.parametrize("variant", SPEC_VARIANTS)
def test_pinocchio_equals_spec_equations(paper_scene, variant) -> None:
    """The Pinocchio path (ABA with −Ẏv, RNEA for the drum torque) against spec §§2-5
    written out by hand, on states in and out of contact, pulling and pressing, slipping
    both ways, with either drive and either contact law."""
    scene = scene_variant(paper_scene, variant)
    sys_ = MachineSystem(scene, backend="pinocchio")
    if scene.drum.drive.kind == "torque":
        sys_.set_input("drum.torque", DRUM_TORQUE)
    states = list(random_states(sys_, np.random.default_rng(3), 150))
    regions = state_regions(sys_, states)
    assert min(regions.values()) >= 150 // 40, regions  # every region of the nip drawn
    got = np.array([to_old(sys_, sys_.rhs(t, y)) for t, y in states])
    spec = [_spec_rhs(scene, t, to_old(sys_, y)) for t, y in states]
    ref = np.array([d for d, _ in spec])
    # each component relative to its largest value: measured 1.1e-12 (roll acceleration
    # without contact, where it is a small difference), ≤ 3e-15 elsewhere
    err = np.max(np.abs(got - ref), axis=0) / np.maximum(np.max(np.abs(ref), axis=0), 1e-300)
    assert np.all(err < 1e-11), err
    t = np.array([s[0] for s in states])
    ch = sys_.channels(t, np.stack([s[1] for s in states], axis=1))
    tau = np.array([x for _, x in spec])
    # relative to the largest torque: measured 3.8e-16
    err_tau = np.max(np.abs(ch["drum_torque"] - tau)) / np.max(np.abs(tau))
    assert err_tau < 4e-15, err_tau


def test_drum_torque_rnea_equals_balance(paper_scene) -> None:
    """τ_d = J_d Ω̇ + R F_t (spec §5) from RNEA, on random states during the ramp."""
    sys_ = MachineSystem(paper_scene)
    rng = np.random.default_rng(4)
    y = sys_.initial_state()
    T = rng.uniform(0, 40, 10)
    Y = np.repeat(y[:, None], 10, axis=1)
    Y[sys_.index("roll.theta_dot")] = -rng.uniform(0, 200, 10)
    Y[sys_.index("nip.friction")] = rng.normal(0, 300, 10)
    ch = sys_.channels(T, Y)
    expected = paper_scene.drum.inertia * 0.5 / 0.5 + 0.5 * ch["friction_force"]
    np.testing.assert_allclose(ch["drum_torque"], expected, rtol=1e-12, atol=1e-9)


def test_static_equilibrium_at_start(paper_scene) -> None:
    scene = paper_scene.replace(effects={"imbalance": False})
    sys_ = MachineSystem(scene)
    y0 = to_old(sys_, sys_.initial_state())
    dy = to_old(sys_, sys_.rhs(0.0, to_machine(sys_, y0)))
    m0 = scene.roll.core_mass
    # round-off floor: δ = R + r − z loses ulp(z), i.e. k·ε·z/m of acceleration
    assert abs(dy[2]) < 4 * 2e7 * np.finfo(float).eps * y0[0] / m0
    ch = sys_.channels(np.array([0.0]), to_machine(sys_, y0)[:, None])
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


def _kelvin_voigt_bounce(v0: float, m: float, k: float, c: float, g: float):
    """One bounce of a mass ``m`` [kg] landing at ``v0`` [m/s] on the spring-damper
    ``F = max(0, k δ + c δ̇)`` under gravity, in closed form: the contact phase solves
    ``m δ̈ = m g − k δ − c δ̇`` from ``δ = 0, δ̇ = v0``; it ends at lift-off where
    ``k δ + c δ̇`` falls to 0 (not at δ = 0: the clamp), and the flight that follows is a
    parabola ``δ̈ = g``. Returns ``s ↦ (δ, F)`` over the bounce, the time of the next
    touchdown (``s`` from this touchdown) and the landing speed there [SI]."""
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    wd, ds = wn * math.sqrt(1 - zeta**2), m * g / k
    A, B = -ds, (v0 - zeta * wn * ds) / wd

    def contact(s: float) -> tuple[float, float]:
        ex, co, si = math.exp(-zeta * wn * s), math.cos(wd * s), math.sin(wd * s)
        return (ds + ex * (A * co + B * si),
                ex * ((wd * B - zeta * wn * A) * co - (zeta * wn * B + wd * A) * si))

    def law(s: float) -> float:
        d, dd = contact(s)
        return k * d + c * dd

    grid = np.linspace(1e-9, 2 * math.pi / wd, 20001)
    i = int(np.argmax([law(s) < 0 for s in grid]))
    s_lift = brentq(law, grid[i - 1], grid[i], xtol=1e-16)
    d1, v1 = contact(s_lift)
    root = math.sqrt(v1 * v1 - 2 * g * d1)
    u_gap, u_next = (-v1 - root) / g, (-v1 + root) / g  # δ = 0 going up, coming down
    # the flight is clean: δ < 0 before the unclamped law k δ + c δ̇ turns positive
    assert u_gap < -2 * (k * v1 + c * g) / (k * g)

    def delta(s: float) -> tuple[float, float]:
        if s < s_lift:
            d, dd = contact(s)
            return d, max(0.0, k * d + c * dd)
        u = s - s_lift
        return d1 + v1 * u + 0.5 * g * u * u, 0.0

    return delta, s_lift + u_next, root


def test_impact_and_rebound_closed_form(paper_scene) -> None:
    """A roll (no imbalance, not turning, drum at rest: no friction, no growth) dropped
    2 cm onto the linear nip: free fall, a damped contact that lets go where the force
    reaches zero (the clamp), a flight, a second impact and flight, all in closed form
    (:func:`_kelvin_voigt_bounce`). Checks the nip law, its clamp, gravity and the
    located touch-down and lift-off events of the default integrator."""
    R, rc, m, g, k, c, gap = 0.5, 0.075, 30.0, 9.81, 2e7, 2e4, 0.02
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": R + rc + gap},
                                drum={"drive": {"web_speed": 0.0, "web_acceleration": 0.0}})
    t_hit = math.sqrt(2 * gap / g)
    first, s_next, v_next = _kelvin_voigt_bounce(g * t_hit, m, k, c, g)
    second, s_third, _ = _kelvin_voigt_bounce(v_next, m, k, c, g)
    t_end = t_hit + s_next + 0.9 * s_third

    res = winder.simulate(scene, t_end=t_end, output_step=1e-5, rtol=1e-10, atol=1e-13)
    exact = []
    for t in res.t:
        if t < t_hit:
            exact.append((gap - 0.5 * g * t * t, 0.0))
        else:
            d, f = first(t - t_hit) if t < t_hit + s_next else second(t - t_hit - s_next)
            exact.append((-d, f))
    gap_exact, force_exact = np.array(exact).T
    assert np.sum(res["normal_force"] > 0) > 100 and res.meta["events"] >= 4
    # measured 7.6e-13 m of z (the first rebound is 2.5 mm) and 7.1e-10 of the peak force
    np.testing.assert_allclose(res["z"], R + rc + gap_exact, rtol=0, atol=1e-11)
    np.testing.assert_allclose(res["normal_force"], force_exact, rtol=0,
                               atol=7e-9 * force_exact.max())


def test_slip_friction_spin_up_closed_form(paper_scene) -> None:
    """A roll at rest put on a drum running at 20 m/s (no imbalance, growth negligible):
    it rests at F_n = m g, slips grossly (v_s ≫ v_ref, so tanh = 1) and the friction
    relaxes to μ m g with the time constant τ = σ / (Ω R + v_min) (spec §4). In closed
    form F_t = μ m g (1 − e^(−t/τ)), J ω = r μ m g (t − τ (1 − e^(−t/τ))) and the drum
    torque is τ_d = R F_t (spec §5, Ω̇ = 0)."""
    scene = paper_scene.replace(effects={"imbalance": False}, paper={"caliper": 1e-15},
                                drum={"drive": {"web_acceleration": 0.0}},
                                roll={"initial_speed": 0.0})
    res = winder.simulate(scene, t_end=2.0, output_step=0.01, rtol=1e-11, atol=1e-13)
    m, J, r, R, g = 30.0, 0.12, 0.075, 0.5, 9.81
    mu, sigma, v_min, v = 0.3, 0.01, 0.1, 20.0
    tau, t = sigma / (v + v_min), res.t
    f = mu * m * g
    ft = f * (1 - np.exp(-t / tau))
    w = r * f / J * (t - tau * (1 - np.exp(-t / tau)))
    assert np.min(res["slip_velocity"]) > 200 * scene.friction.slip_velocity  # gross slip
    # measured: ω 1.1e-12 of its final value (the lag τ shifts it by 2.5e-4), F_t and τ_d
    # 2.7e-11 of μ m g, F_n 1.6e-11 of m g
    np.testing.assert_allclose(res["roll_speed"], w, rtol=0, atol=1e-11 * w[-1])
    np.testing.assert_allclose(res["friction_force"], ft, rtol=0, atol=3e-10 * f)
    np.testing.assert_allclose(res["drum_torque"], R * ft, rtol=0, atol=3e-10 * R * f)
    np.testing.assert_allclose(res["normal_force"], m * g, rtol=2e-10)


def test_progress_in_a_log_is_line_per_report(paper_scene, capsys) -> None:
    """Oracle: when stderr is not a terminal, progress is whole lines (no carriage
    returns that would pile up in a CI log) and the last one reports 100 %."""
    winder.simulate(paper_scene, t_end=2.0, progress=True)
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = [line for line in err.splitlines() if "%" in line]
    assert lines and "100.0%" in lines[-1]
    assert "t =     2.00 s" in lines[-1]
