"""The damping of a flexible body's torsion chain (issue #33): the damper ``c_t = β_t k_t``
between neighbouring segments is Rayleigh on the chain with its own ``β_t = 2ζ/ω_t1``,
``ω_t1`` the chain's first torsion frequency (held at segment 0 under a speed profile, else
free), no longer the bending's ``β = 2ζ/ω₁`` (:func:`winder.model.beam.torsion_damping`).

Oracle: the chain of ``N`` disks ``I_d`` on springs ``k_t = GJ N/L`` with ``C = β_t K``
(classical damping) has the closed-form modes ``ω_k = 2 √(k_t/I_d) sin((2k − 1)π/(2(2N −
1)))`` held at segment 0 (its ``N − 1`` free disks) and ``ω_k = 2 √(k_t/I_d) sin(kπ/(2N))``
free, each with ``Re λ_k = −β_t ω_k²/2``: the first has the damping ratio ``ζ``, mode ``k``
``ζ ω_k/ω_t1``. Measured on the machine's state matrix over the segments' angles and speeds
(central differences on the numeric path: exact, the torsion is linear in them):

- the shipped flexible winder's drum alone (5 m, polar inertia 600 kg·m², ``GJ`` = 1.7e9
  N·m², ζ = 0.02, 8 segments), speed profile (held: torsion 200.4–1875 Hz) and torque
  drive (free: 374.0–1880 Hz): every frequency and damping ratio within 1.4e-14 relative
  (tolerance 1e-13), the first mode's ζ within 1.4e-14; its top mode ζ = 0.187 (held) and
  0.101 (free);
- the shipped paper set (``GJ`` = 1e6 N·m², ζ = 0.05) on chucks, its nip open, at r = 0.1
  and 0.3 m (``β_t(r)`` from the segment's ``J(r)/N`` at run time: 292–1468 Hz and
  34.5–173.6 Hz): within 4.4e-15.

Mutation (``c_t = β k_t``, the bending's ``β``, as before): the first mode's ζ becomes
0.047 (held drum), 0.088 (free drum), 0.165 (set at 0.3 m), and at 0.1 m all but one of the
set's torsion modes are overdamped: all four tests fail.
"""

from __future__ import annotations

import math
import tomllib

import machines as mc
import numpy as np
import pytest

import winder
from winder.model.beam import torsion_damping, torsion_eigenvalue
from winder.solve.system import MachineSystem

N, L, MASS, INERTIA = 8, 5.0, 3000.0, 600.0  # [-], [m], [kg], [kg·m²]
EI, KGA, GJ, ZETA = 2.26e9, 3.7e9, 1.7e9, 0.02  # [N·m²], [N], [N·m²], [-]


def drum_system(drive: str) -> MachineSystem:
    text = f"""
[scene]
name = "twist"
duration = 0.01
output_step = 0.001

[effects]
gravity = false
contact = false
slip_relaxation = false

[[drum]]
name = "drum"
radius = 0.5
inertia = {INERTIA}
mass = {MASS}
centre = [0.0, 0.0]
length = {L}
drive = {drive}
flex = {{ segments = {N}, EI = {EI}, kGA = {KGA}, GJ = {GJ}, bearing_stiffness = 1e9, \
damping_ratio = {ZETA} }}
"""
    sc = winder.scene_from_dict(tomllib.loads(text), source="twist.toml")
    return MachineSystem(sc, backend="pinocchio")


def state_matrix(sys_: MachineSystem, names: list[str]) -> np.ndarray:
    """``∂ẏ/∂y`` over the states ``names`` at rest (:func:`machines.state_matrix`, step
    1e-6)."""
    return mc.state_matrix(sys_, names, h=1e-6)


def chain_modes(sys_: MachineSystem, segs: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The oscillating torsion modes of the segments ``segs``: natural frequencies [rad/s]
    (ascending) and damping ratios."""
    names = [f"{s}.theta" for s in segs] + [f"{s}.theta_dot" for s in segs]
    lam = np.linalg.eigvals(state_matrix(sys_, names))
    scale = float(np.max(np.abs(lam)))
    osc = lam[(lam.imag > 1e-9 * scale) & (np.abs(lam) > 1e-6 * scale)]  # no rigid pair
    osc = osc[np.argsort(np.abs(osc))]
    return np.abs(osc), -osc.real / np.abs(osc)


def closed_form(n: int, k_t: float, disk: float, zeta: float, held: bool
                ) -> tuple[np.ndarray, np.ndarray]:
    """The chain's frequencies [rad/s] and damping ratios (module text)."""
    k = np.arange(1, n if held else n)  # held: n − 1 free disks; free: n − 1 non-zero modes
    arg = (2 * k - 1) * np.pi / (2 * (2 * n - 1)) if held else k * np.pi / (2 * n)
    w = 2 * np.sqrt(k_t / disk) * np.sin(arg)
    omega_t1, c_t = torsion_damping(n, k_t, disk, zeta, held=held)
    assert omega_t1 == pytest.approx(w[0], rel=1e-14)
    return w, c_t / k_t * w / 2


@pytest.mark.parametrize("held", [True, False])
def test_drum_torsion_first_mode_has_the_damping_ratio(held: bool) -> None:
    drive = '{ kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }' if held \
        else '{ kind = "torque", torque = 0.0 }'
    sys_ = drum_system(drive)
    segs = [f"drum_s{i}" for i in range(1 if held else 0, N)]
    w, zeta = chain_modes(sys_, segs)
    want_w, want_zeta = closed_form(N, GJ * N / L, INERTIA / N, ZETA, held)
    assert np.allclose(w, want_w, rtol=1e-13, atol=0.0), (w, want_w)
    assert np.allclose(zeta, want_zeta, rtol=1e-13, atol=0.0), (zeta, want_zeta)
    assert abs(zeta[0] / ZETA - 1) < 1e-13, (zeta[0], ZETA)


def roll_system(r0: float) -> MachineSystem:
    """The shipped flexible winder's set (5 m, core 0.05 m, 40 kg, 0.1 kg·m², ``GJ`` = 1e6
    N·m², ζ = 0.05) of radius ``r0`` [m] on chucks 2 m above its drum (the nip open)."""
    text = f"""
[scene]
name = "rolltwist"
duration = 0.01
output_step = 0.001

[effects]
gravity = false
imbalance = false

[paper]
density = 650.0
caliper = 70e-6

[[drum]]
name = "drum"
radius = 0.5
inertia = 600.0
mass = 3000.0
centre = [0.0, 0.0]
drive = {{ kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }}

[[roll]]
name = "set"
centre = [0.0, {2.5 + r0}]
free = ["x", "z"]
core_radius = 0.05
core_mass = 40.0
core_inertia = 0.1
width = 5.0
initial_radius = {r0}
initial_speed = 0.0
flex = {{ segments = {N}, core_EI = 2.0e6, paper_E = 5.0e8, GJ = 1.0e6, \
damping_ratio = 0.05, support = "chucks" }}

[[nip]]
name = "nip"
a = "drum"
b = "set"
contact = {{ law = "linear", stiffness = 2.5e7, damping = 1.5e4 }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[web]
entry_nip = "nip"
"""
    sc = winder.scene_from_dict(tomllib.loads(text), source="rolltwist.toml")
    return MachineSystem(sc, backend="pinocchio")


@pytest.mark.parametrize("r0", [0.1, 0.3])
def test_paper_roll_torsion_damping_follows_its_inertia(r0: float) -> None:
    """``β_t(r)`` at run time: the segment's ``J(r)/N`` (``J = J_c + π ρ W (r⁴ − r_c⁴)/2``)."""
    sys_ = roll_system(r0)
    segs = [f"set_s{i}" for i in range(N)]
    disk = (0.1 + math.pi * 650.0 * 5.0 * (r0 ** 4 - 0.05 ** 4) / 2) / N
    ev = sys_.evaluate_numeric(0.0, sys_.initial_state(), outputs=False)
    assert float(ev.bodies["set_s0"].inertia) == pytest.approx(disk, rel=1e-12)
    w, zeta = chain_modes(sys_, segs)
    want_w, want_zeta = closed_form(N, 1.0e6 * N / 5.0, disk, 0.05, False)
    assert np.allclose(w, want_w, rtol=1e-13, atol=0.0), (w, want_w)
    assert np.allclose(zeta, want_zeta, rtol=1e-13, atol=0.0), (zeta, want_zeta)
    assert abs(zeta[0] / 0.05 - 1) < 1e-13, zeta[0]


def test_torsion_eigenvalue_is_the_chains() -> None:
    """``ν₁`` against the unit chain's Laplacian (free, and held: its first row and column
    taken out): measured 1e-16."""
    for n in (2, 3, 8, 17):
        lap = np.diag(np.r_[1.0, 2.0 * np.ones(n - 2), 1.0]) - np.eye(n, k=1) - np.eye(n, k=-1)
        free = np.sort(np.linalg.eigvalsh(lap))[1]
        held = np.sort(np.linalg.eigvalsh(lap[1:, 1:]))[0]
        assert torsion_eigenvalue(n, held=False) == pytest.approx(free, rel=1e-12)
        assert torsion_eigenvalue(n, held=True) == pytest.approx(held, rel=1e-12)
