"""The MuJoCo model of the peers study (benchmarks/peers/) is a fair one.

With the mass held constant, MuJoCo stepping the winder and winder agree to the
integrators' accuracy, so that the study's differences measure the mass terms and not
two different machines. With the mass growing, MuJoCo's h → 0 limit (Richardson
extrapolation of two step sizes) is winder's answer when the missing term is added by
hand, and winder's ``variable_mass = false`` answer for the bare overwrite. On free spin
the overwrite breaks ``J ω = const`` by exactly the closed form's amount, the missing
term restores it, and the web flux on top of the overwrite counts the paper twice.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import winder

mujoco = pytest.importorskip(
    "mujoco", reason="MuJoCo is not installed (the `peers` extra: pip install -e '.[peers]')")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from peers.mujoco_winder import (  # noqa: E402
    MujocoWinder,
    initial_state,
    mass_properties,
    mjcf,
)

CHANNELS = ("roll_speed", "z", "normal_force", "drum_torque", "friction_force")


def scaled_errors(run, ref, channels=CHANNELS) -> dict[str, float]:
    """Largest deviation over the grid scaled by the reference's largest magnitude [-]."""
    return {c: float(np.max(np.abs(np.asarray(run[c]) - np.asarray(ref[c])))
                     / np.max(np.abs(np.asarray(ref[c])))) for c in channels}


def richardson(fine, coarse, channels=CHANNELS) -> dict[str, np.ndarray]:
    """First-order extrapolation ``2 x(h/2) − x(h)`` of two runs on the same grid."""
    return {c: 2.0 * fine[c] - coarse[c] for c in channels}


@pytest.fixture(scope="module")
def smooth() -> winder.Scene:
    return winder.load_scene(ROOT / "models" / "paper_winding_smooth.toml")


@pytest.fixture(scope="module")
def spin() -> winder.Scene:
    return winder.load_scene(ROOT / "models" / "free_spin.toml")


def spec_accel(scene: winder.Scene, q: tuple[float, float], v: tuple[float, float],
               r: float, Q: tuple[float, float], *, mass_terms: bool) -> np.ndarray:
    """Spec §3 by hand: ``M q̈ = Q − [(∂M/∂r ṙ) q̇] − C − G`` for ``q = (z, φ)``."""
    m, J, _ = mass_properties(scene, r)
    e = scene.roll.com_offset if scene.effects.imbalance else 0.0
    g = scene.scene.gravity if scene.effects.gravity else 0.0
    phi, w = q[1], v[1]
    c, s = math.cos(phi), math.sin(phi)
    M = np.array([[m, m * e * c], [m * e * c, J]])
    rdot = scene.paper.caliper * w / (2 * math.pi)
    md = 2 * math.pi * scene.paper.density * scene.roll.width * r * rdot
    dM = np.array([[md, md * e * c], [md * e * c, md * r * r]]) if mass_terms else 0 * M
    rhs = np.array(Q) - dM @ np.array(v) - np.array([-m * e * s * w * w, 0.0]) \
        - np.array([m * g, m * g * e * c])
    return np.linalg.solve(M, rhs)


@pytest.mark.parametrize("imbalance", [False, True])
def test_overwrite_takes_effect_on_simple_bodies(smooth, imbalance):
    """The roll's per-step mass overwrite reaches MuJoCo's dynamics (the compiler marks a
    centred roll "simple" and would keep its compile-time mass): after ``apply`` at
    another radius, MuJoCo's acceleration is spec §3's, and it is not without the
    non-simple declaration."""
    scene = smooth.replace(effects={"imbalance": imbalance, "web_momentum": False})
    mw = MujocoWinder(scene, "corrected")
    mw.reset()
    d, iz, ip = mw.data, mw.i_z, mw.i_phi
    d.qpos[iz], d.qpos[ip] = 1.3, 0.7
    d.qvel[iz], d.qvel[ip] = 0.02, 35.0
    r, ft = 0.62, 150.0  # far from the compiled radius 0.075 m
    mw.apply(50.0, r, ft)
    mujoco.mj_forward(mw.model, mw.data)
    Q = (0.0, r * ft)  # z = 1.3 m: off the drum, no normal force; F_t is the given state
    want = spec_accel(scene, (1.3, 0.7), (0.02, 35.0), r, Q, mass_terms=True)
    got = d.qacc[[iz, ip]]
    # measured: 1e-16 relative (round-off)
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))

    raw = mujoco.MjModel.from_xml_string(mjcf(scene))  # simple bodies left as compiled
    rd = mujoco.MjData(raw)
    rd.qpos[:], rd.qvel[:] = d.qpos, d.qvel
    roll = raw.body("roll").id
    raw.body_mass[roll], raw.body_inertia[roll] = mw.model.body_mass[roll], \
        mw.model.body_inertia[roll]
    rd.qfrc_applied[:] = d.qfrc_applied
    mujoco.mj_forward(raw, rd)
    stale = not np.allclose(rd.qacc[[iz, ip]], want, rtol=1e-6)
    simple = bool(raw.dof_simplenum[iz] or raw.dof_simplenum[ip])
    assert simple == (not imbalance)  # the compiler marks only the centred roll simple
    assert stale == simple


def test_initial_state_is_winders(smooth):
    ref = winder.simulate(smooth, t_end=0.01, output_step=0.01)
    got = initial_state(smooth)
    want = [ref[c][0] for c in ("z", "roll_angle", "z_dot", "roll_speed", "radius")]
    assert got == pytest.approx(want, rel=1e-15, abs=1e-15)


@pytest.mark.parametrize("integrator", ["Euler", "RK4"])
def test_constant_mass_agrees_with_winder(smooth, integrator):
    """Fairness: with the caliper at 1e-12 m (constant mass) the MuJoCo model and winder
    are the same machine. One second from a slipping start (ω 45 rad/s against 50 rad/s
    at the nip) on the compliant, relaxed, imbalanced nip: MuJoCo's error is first order
    in its step and its Richardson extrapolation lands on winder's answer."""
    scene = smooth.replace(paper={"caliper": 1e-12},
                           roll={"initial_radius": 0.4, "initial_speed": 45.0},
                           drum={"drive": {"web_acceleration": 0.0}})
    ref = winder.simulate(scene, t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    coarse = MujocoWinder(scene, "corrected").run(1.0, 2e-4, 0.01, integrator)
    fine = MujocoWinder(scene, "corrected").run(1.0, 1e-4, 0.01, integrator)
    e_fine = scaled_errors(fine, ref)
    e_extra = scaled_errors(richardson(fine, coarse), ref)
    # measured at dt 1e-4 (Euler / RK4): roll_speed 1.9e-5 / 1.8e-5, z 4.9e-8 / 3.5e-7,
    # normal_force 8.6e-5 / 6.7e-4, drum_torque and friction_force 2.9e-3 / 2.9e-3
    tol_fine = {"roll_speed": 2e-4, "z": 4e-6, "normal_force": 7e-3, "drum_torque": 3e-2,
                "friction_force": 3e-2}
    # measured extrapolated: roll_speed 1.1e-6 / 1.2e-6, z 1.5e-9 / 2.1e-8, normal_force
    # 3.1e-6 / 4.0e-5, drum_torque and friction_force 2.8e-4 / 2.7e-4
    tol_extra = {"roll_speed": 1.2e-5, "z": 2e-7, "normal_force": 4e-4, "drum_torque": 3e-3,
                 "friction_force": 3e-3}
    for c in CHANNELS:
        assert e_fine[c] < tol_fine[c], (c, e_fine[c])
        assert e_extra[c] < tol_extra[c], (c, e_extra[c])
        assert e_extra[c] < 0.2 * e_fine[c], (c, e_extra[c], e_fine[c])  # it converges


def test_mass_terms_limits(smooth):
    """With the roll growing from its core and the paper joining from rest (web momentum
    off), MuJoCo's h → 0 limit is winder's answer with the missing term added by hand
    (b), and winder's ``variable_mass = false`` answer for the bare overwrite (a): the
    overwrite's error is a model error, far above the step error."""
    scene = smooth.replace(effects={"web_momentum": False})
    kw = {"t_end": 10.0, "rtol": 1e-10, "atol": 1e-12, "output_step": 0.05}
    ref = winder.simulate(scene, **kw)
    ref_overwrite = winder.simulate(scene.replace(effects={"variable_mass": False}), **kw)
    gap = scaled_errors(ref_overwrite, ref)
    # measured gap: roll_speed 6.8e-4, z 5.9e-6, normal_force 1.7e-2, drum_torque 8.0e-3,
    # friction_force 3.3e-1
    assert gap["roll_speed"] > 5e-4 and gap["friction_force"] > 0.2
    for way, limit in (("corrected", ref), ("overwrite", ref_overwrite)):
        coarse = MujocoWinder(scene, way).run(10.0, 1e-3, 0.05)
        fine = MujocoWinder(scene, way).run(10.0, 5e-4, 0.05)
        e = scaled_errors(richardson(fine, coarse), limit)
        # measured (both ways): roll_speed 3.8e-6, z 1.6e-8, normal_force 3.1e-5,
        # drum_torque 1.7e-5, friction_force 7.0e-4
        tol = {"roll_speed": 4e-5, "z": 2e-7, "normal_force": 3e-4, "drum_torque": 2e-4,
               "friction_force": 7e-3}
        for c in CHANNELS:
            assert e[c] < tol[c], (way, c, e[c])
            assert e[c] < 0.1 * gap[c], (way, c, e[c], gap[c])


def test_free_spin_overwrite_breaks_angular_momentum(spin):
    """Free spin, paper from rest (``J ω = J₀ ω₀``). The bare overwrite keeps ω = ω₀, so
    ``r = r₀ + h ω₀ t/2π`` and ``J ω`` grows as ``J(r(t))/J₀`` (the closed form of the
    overwrite's own model); the missing term restores ``J ω = const`` (first order)."""
    T, w0, r0 = 60.0, spin.roll.initial_speed, spin.roll.initial_radius
    J0 = mass_properties(spin, r0)[1]
    a = MujocoWinder(spin, "overwrite").run(T, 0.01, 1.0)
    r_pred = r0 + spin.paper.caliper * w0 * a.t / (2 * math.pi)
    growth = np.array([mass_properties(spin, x)[1] for x in r_pred]) / J0
    # measured: ω exact, r to 1.1e-13 and J ω to 4.5e-13 relative (round-off over 6000
    # steps); J ω / J₀ ω₀ reaches 440 at 60 s
    assert np.max(np.abs(a["roll_speed"] / w0 - 1)) < 1e-13
    assert np.max(np.abs(a["radius"] / r_pred - 1)) < 1e-12
    assert np.allclose(a["inertia"] * a["roll_speed"] / (J0 * w0), growth, rtol=5e-12)
    assert growth[-1] > 100.0

    errs = []
    for dt in (0.02, 0.01):
        b = MujocoWinder(spin, "corrected").run(T, dt, 1.0)
        errs.append(np.max(np.abs(b["inertia"] * b["roll_speed"] / (J0 * w0) - 1)))
    # measured: 4.8e-3 at dt 0.02, 2.4e-3 at 0.01 (first order)
    assert errs[1] < 2.4e-2
    assert 1.8 < errs[0] / errs[1] < 2.2


def test_free_spin_web_flux_counted_twice(spin):
    """Free spin with the web flux at ``u = ω r``: ω stays constant (spec §3). The bare
    overwrite and the corrected way keep it; the flux added on top of the overwrite counts
    the arriving paper twice: ``J ω̇ = J̇ ω``, so ω grows in proportion to ``J``."""
    scene = spin.replace(effects={"web_momentum": True})
    T, w0, r0 = 3.0, scene.roll.initial_speed, scene.roll.initial_radius
    J0 = mass_properties(scene, r0)[1]
    for way in ("overwrite", "corrected"):
        run = MujocoWinder(scene, way).run(T, 0.01, 0.1)
        # measured: 0 (exact) for both
        assert np.max(np.abs(run["roll_speed"] / w0 - 1)) < 1e-13, way
    errs = []
    for dt in (2e-3, 1e-3):
        run = MujocoWinder(scene, "overwrite+flux").run(T, dt, 0.1)
        ratio = (run["roll_speed"] / w0) / (run["inertia"] / J0)
        errs.append(np.max(np.abs(ratio - 1)))
    assert run["roll_speed"][-1] > 2.0 * w0  # measured: 2.2 ω₀ at 3 s
    # measured: |ω/ω₀ ÷ J/J₀ − 1| 6.4e-4 at dt 2e-3, 3.2e-4 at 1e-3 (first order)
    assert errs[1] < 3e-3
    assert 1.8 < errs[0] / errs[1] < 2.2
