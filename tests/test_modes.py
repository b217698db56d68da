"""Linearisation (Jacobian against finite differences), the √(k/m) identity, and the
resonance map against a simulation through a crossing."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

import winder
from winder._linearise import jacobian
from winder._modes import mode_map, modes_at
from winder._system import WinderSystem

# central-difference steps per state: z, φ, ż, ω, r, then drive/effect states
STEPS = {"z": 1e-9, "roll_angle": 1e-6, "z_dot": 1e-6, "roll_speed": 1e-5, "radius": 1e-7,
         "drum_angle": 1e-6, "drum_speed": 1e-5, "friction_force": 1e-2}


def _variants(paper_scene):
    return {
        "paper": paper_scene,
        "no_variable_mass": paper_scene.replace(effects={"variable_mass": False}),
        "steady_friction": paper_scene.replace(effects={"slip_relaxation": False}),
        "no_web": paper_scene.replace(effects={"web_momentum": False}),
        "torque_drive": paper_scene.replace(drum={"drive": {"kind": "torque",
                                                            "web_speed": 5.0}}),
        "hunt_crossley": paper_scene.replace(contact={"law": "hunt_crossley",
                                                      "stiffness": 5e9, "exponent": 1.5,
                                                      "hc_damping": 0.3}),
    }


@pytest.mark.parametrize("name", ["paper", "no_variable_mass", "steady_friction", "no_web",
                                  "torque_drive", "hunt_crossley"])
def test_jacobian_matches_finite_differences(paper_scene, name) -> None:
    scene = _variants(paper_scene)[name]
    system = WinderSystem(scene)
    if name == "torque_drive":
        system.set_drum_torque(150.0)
    rng = np.random.default_rng(5)
    y0 = system.initial_state()
    for _ in range(8):
        y = y0.copy()
        y[0] -= rng.uniform(1e-6, 3e-5)  # in contact (the force law is smooth there)
        y[1] = rng.uniform(-3, 3)
        y[2] = rng.normal(0, 0.01)
        y[3] = rng.uniform(5, 200)
        y[4] = rng.uniform(0.08, 0.8)
        y[5:] += rng.normal(0, 10, len(y) - 5)
        t = rng.uniform(0, 60)
        J = jacobian(system, t, y)
        fd = np.empty_like(J)
        for k, state in enumerate(system.state_names):
            h = STEPS[state]
            yp, ym = y.copy(), y.copy()
            yp[k] += h
            ym[k] -= h
            fd[:, k] = (system.rhs(t, yp) - system.rhs(t, ym)) / (2 * h)
        scale = np.max(np.abs(fd), axis=1, keepdims=True) + 1e-12
        np.testing.assert_allclose(J / scale, fd / scale, rtol=0, atol=2e-6)


def test_single_dof_frequency_is_sqrt_k_over_m(paper_scene) -> None:
    """Undamped linear nip, drum at rest: the bounce mode is ±i√(k/m) exactly."""
    k = 3.7e6
    scene = paper_scene.replace(contact={"stiffness": k, "damping": 0.0},
                                drum={"drive": {"web_speed": 0.0}})
    for r in (0.075, 0.3, 0.7):
        m = WinderSystem(scene).law.mass(r)
        bounce = modes_at(scene, r, web_speed=0.0)[0]
        assert bounce.kind == "bounce"
        assert bounce.frequency == pytest.approx(math.sqrt(k / m) / (2 * math.pi), rel=1e-12)
        assert abs(bounce.damping_ratio) < 1e-12


def test_damped_bounce_mode(paper_scene) -> None:
    """Linear nip with damping, drum at rest: λ = −c/2m ± i√(k/m − (c/2m)²)."""
    k, c = 2e7, 2e4
    scene = paper_scene.replace(drum={"drive": {"web_speed": 0.0}})
    m = WinderSystem(scene).law.mass(0.3)
    lam = modes_at(scene, 0.3, web_speed=0.0)[0].eigenvalue
    assert lam.real == pytest.approx(-c / (2 * m), rel=1e-9)
    assert abs(lam.imag) == pytest.approx(math.sqrt(k / m - (c / (2 * m)) ** 2), rel=1e-9)


def _crossing_scene(paper_scene) -> winder.Scene:
    """A heavy core on a soft nip at a constant 15 m/s: the roll's once-per-revolution
    excitation crosses the bounce mode near r = 0.27 m."""
    return paper_scene.replace(
        roll={"core_mass": 300.0, "com_offset": 2e-5, "initial_speed": 200.0},
        contact={"stiffness": 2e6, "damping": 2000.0},
        drum={"drive": {"web_acceleration": 0.0, "web_speed": 15.0}})


def test_simulated_vibration_peaks_at_predicted_critical_radius(paper_scene) -> None:
    scene = _crossing_scene(paper_scene)
    crit = mode_map(scene, np.linspace(0.075, 0.4, 120)).critical_radii(1)
    assert len(crit) == 1
    res = winder.simulate(scene, t_end=200.0, output_step=2e-3)
    from winder._plots import normal_force_envelope

    r, lo, hi, amp = normal_force_envelope(res, window=0.5)
    assert np.all(lo > 0)  # stays in contact: the linear picture applies
    r_peak = r[np.argmax(amp[2:]) + 2]
    assert r_peak == pytest.approx(crit[0], rel=0.02)
    assert np.max(amp) > 3 * np.median(amp)  # a real resonance peak


def test_modes_cli_writes_plot_and_csv(models_dir, tmp_path) -> None:
    png, csv = tmp_path / "campbell.png", tmp_path / "modes.csv"
    proc = subprocess.run([sys.executable, "-m", "winder", "modes",
                           str(models_dir / "paper_winding.toml"), "--plot", str(png),
                           "--csv", str(csv), "--points", "40"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "3x rotation meets the bounce mode at r = 0.11" in proc.stdout
    assert png.stat().st_size > 20_000
    table = np.genfromtxt(csv, delimiter=",", names=True)
    assert len(table) == 40
    np.testing.assert_allclose(table["critical_web_speed"],
                               2 * np.pi * table["radius"] * table["bounce_frequency"])


def test_pinocchio_jacobian_in_implicit_methods(models_dir) -> None:
    """BDF with the Pinocchio-derivative Jacobian solves the same problem as with finite
    differences (to the tolerance)."""
    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml")
    kw = {"t_end": 5.0, "output_step": 0.5, "method": "BDF", "rtol": 1e-8, "atol": 1e-10}
    a = winder.simulate(scene, jacobian="pinocchio", **kw)
    b = winder.simulate(scene, jacobian="fd", **kw)
    for k in ("radius", "roll_speed", "z", "normal_force"):
        np.testing.assert_allclose(a[k], b[k], rtol=1e-5, atol=1e-6 * np.max(np.abs(b[k])))
    with pytest.raises(winder.ArgumentError, match="valid: fd, pinocchio"):
        winder.simulate(scene, t_end=0.1, jacobian="exact")
