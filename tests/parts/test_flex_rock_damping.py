"""The damping of a flexible body's sections' rocking (issue #33): the beam's Rayleigh
damping ``β K`` on the deflections (the rotations following them statically), ``β_φ K_ψψ``
on the rocking ``φ = ψ − T w`` with ``β_φ = 2ζ/ω_φ``, ``ω_φ² `` the least eigenvalue of
``K_ψψ/j_r`` (:mod:`winder.model.beam`, *damping of the rocking*).

Beam: the shipped flexible winder's rider (``models/two_drum_winder_flexible.toml``: 5 m,
1500 kg, ``J`` = 25 kg·m², ``EI`` = 3.64e7 N·m², ``kGA`` = 7.1e8 N, ζ = 0.05) in 8
segments, here on bearings of 1e8 N/m in ``x`` and ``z`` (first bending mode 20.5 Hz, the
rocking from 1.48 kHz). With ``β K̂`` on all coordinates (before) its rocking had damping
ratios 3.6–5 and eigenvalues down to −1.33e5 1/s, the fastest of the machine.

Oracles, on the machine's undamped and damped state matrices over the bending states at
rest (central differences on the numeric path: exact, the dynamics there are linear in them):

- the rocking with the deflections held (the ``(φ, ψ̇)`` block): ``j_r ψ̈ = −K_ψψ φ −
  β_φ K_ψψ ψ̇`` has the closed-form modes ``ω_k² = μ_k/j_r`` (``μ_k`` of ``K_ψψ``) with
  ``Re λ_k = −β_φ ω_k²/2``: its lowest has the damping ratio ζ (all three measured
  within 5e-15 relative; tolerance 1e-12);
- every eigenvalue of the whole bending block is within the undamped spectrum:
  ``|λ| ≤ ω_max`` = 13158 1/s (measured 0.999997 ``ω_max``; before: 10.1 ``ω_max``,
  −1.33e5 1/s);
- the low modes are those of ``β K̂`` (before): the first two bending orders (20.5 Hz,
  67.7 Hz) move by 1.7e-9 and 3.4e-7 in frequency (tolerance 4e-6) and by 3.4e-7 and
  6.0e-6 in damping ratio (tolerance 6e-5).
"""

from __future__ import annotations

import tomllib

import machines as mc
import numpy as np

import winder
from winder.model.beam import rotary_beam_matrices
from winder.solve.system import MachineSystem

N, L, MASS, INERTIA = 8, 5.0, 1500.0, 25.0  # [-], [m], [kg], [kg·m²]
EI, KGA, KB, ZETA = 3.64e7, 7.1e8, 1e8, 0.05  # [N·m²], [N], [N/m], [-]


def system(zeta: float) -> MachineSystem:
    text = f"""
[scene]
name = "rock"
duration = 0.01
output_step = 0.001

[effects]
gravity = false
contact = false
slip_relaxation = false

[[drum]]
name = "beam"
radius = 0.15
inertia = {INERTIA}
mass = {MASS}
centre = [0.0, 0.0]
length = {L}
drive = {{ kind = "torque", torque = 0.0 }}
flex = {{ segments = {N}, EI = {EI}, kGA = {KGA}, GJ = 2.8e7, bearing_stiffness = {KB}, \
damping_ratio = {zeta} }}
"""
    sc = winder.scene_from_dict(tomllib.loads(text), source="rock.toml")
    return MachineSystem(sc, backend="pinocchio")


def state_matrix(sys_: MachineSystem, names: list[str]) -> np.ndarray:
    """``∂ẏ/∂y`` over the states ``names`` at rest (:func:`machines.state_matrix`, step
    1e-7)."""
    return mc.state_matrix(sys_, names, h=1e-7)


SEGS = [f"beam_s{i}" for i in range(N)]
ROCK = [f"{s}.tilt_z" for s in SEGS] + [f"{s}.tilt_rate_z" for s in SEGS]
BEND = [f"{s}.z" for s in SEGS] + [f"{s}.z_dot" for s in SEGS] + ROCK


def low_modes(lam: np.ndarray, k: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """The ``k`` lowest oscillating modes: natural frequencies [rad/s], damping ratios."""
    osc = lam[lam.imag > 1e-6 * np.abs(lam)]
    osc = osc[np.argsort(np.abs(osc))][:k]
    return np.abs(osc), -osc.real / np.abs(osc)


def test_the_rockings_lowest_mode_has_the_damping_ratio() -> None:
    bm = rotary_beam_matrices(N, L, MASS, INERTIA, EI, KGA, KB, 0.0, ZETA, 1.0)
    jr = INERTIA / (2 * N)
    mu = np.linalg.eigvalsh(bm.K_pp)
    w = np.sqrt(mu / jr)  # the closed form
    lam = np.linalg.eigvals(state_matrix(system(ZETA), ROCK))
    lam = lam[np.argsort(np.abs(lam))][::2]
    assert np.allclose(np.abs(lam), w, rtol=1e-12, atol=0.0), (np.abs(lam), w)
    assert np.allclose(lam.real, -bm.beta_rock * w ** 2 / 2, rtol=1e-12, atol=0.0)
    zeta = -lam[0].real / abs(lam[0])
    assert abs(zeta - ZETA) < 1e-12 * ZETA, zeta


def test_no_eigenvalue_beyond_the_undamped_spectrum_and_low_modes_as_before() -> None:
    undamped = np.linalg.eigvals(state_matrix(system(0.0), BEND))
    w_max = float(np.max(np.abs(undamped)))
    lam = np.linalg.eigvals(state_matrix(system(ZETA), BEND))
    assert np.max(np.abs(lam)) <= (1 + 1e-6) * w_max, np.max(np.abs(lam)) / w_max
    # before: C = β K̂ on (w, ψ), assembled here from the same blocks (no bearing damping)
    bm = rotary_beam_matrices(N, L, MASS, INERTIA, EI, KGA, KB, 0.0, ZETA, 1.0)
    n2 = 2 * N
    Kh = np.zeros((n2, n2))
    wi, pi = slice(0, n2, 2), slice(1, n2, 2)
    Kh[wi, wi], Kh[wi, pi] = bm.K - bm.K_wp @ bm.T, bm.K_wp
    Kh[pi, wi], Kh[pi, pi] = bm.K_wp.T, bm.K_pp
    m = np.empty(n2)
    m[0::2], m[1::2] = MASS / N, INERTIA / (2 * N)
    A = np.block([[np.zeros((n2, n2)), np.eye(n2)],
                  [-Kh / m[:, None], -bm.beta * Kh / m[:, None]]])
    before = np.linalg.eigvals(A)
    assert np.max(np.abs(before)) > 5 * w_max  # the overdamped rocking it replaces
    (f0, z0), (f1, z1) = low_modes(before), low_modes(lam)
    assert abs(z0[0] - ZETA) < 1e-9  # before: classical damping, ζ₁ exact
    assert np.all(np.abs(f1 / f0 - 1) < 4e-6), f1 / f0 - 1
    assert np.all(np.abs(z1 / z0 - 1) < 6e-5), z1 / z0 - 1
