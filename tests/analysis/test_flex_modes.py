"""``winder modes`` for flexible machines (issue #25): bending modes labelled by their shape
(the projection onto ``sin(nπ y/L)`` at the segment centres), torsion modes, the
crossings of the rotation harmonics with a bending mode.

Oracle of the labelled frequencies: a flexible drum (N segments, stiff bearings, no
damping, ``rotary_inertia = false``: the chain's masses are the segments') under a light
rigid roll free in ``z`` on a soft linear nip, one slice per segment: in ``z`` the machine
at its operating point is the linear chain

    M = diag(m_d/N, …, m_d/N, m_r(r)),   K = [[K_d + k_s I, −k_s 1], [−k_s 1ᵀ, N k_s]]

(``K_d`` the inverse of the closed-form flexibility at the stations, ``k_s = k/N``), whose
eigenvalues are solved here by hand; the drum's first bending mode is the one whose drum
part projects mostly onto ``sin(πy/L)``.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import winder
from winder.analysis.modes import mode_map
from winder.analysis.shapes import Shapes, orders, sine_basis, torsion_basis
from winder.model.beam import station_flexibility
from winder.model.machine import Machine

L, R, MD, EI, GJ, KB = 8.0, 0.5, 5740.0, 2.26e9, 1.7e9, 1e10
K_NIP = 1e6  # [N/m] soft: the drum's bending is nearly decoupled from the roll
RHO, RC, MC = 650.0, 0.05, 40.0
V = 41.7  # [m/s]
N = 8


def scene(n: int = N) -> winder.Scene:
    text = f"""
[scene]
name = "flexmodes"
duration = 30.0
output_step = 0.01

[effects]
imbalance = false

[paper]
density = {RHO}
caliper = 70e-6

[[drum]]
name = "drum"
radius = {R}
inertia = 1400.0
mass = {MD}
centre = [0.0, 0.0]
length = {L}
drive = {{ kind = "speed_profile", web_acceleration = 0.7, web_speed = {V} }}
flex = {{ segments = {n}, EI = {EI}, shear = false, rotary_inertia = false, GJ = {GJ}, \
bearing_stiffness = {KB}, damping_ratio = 0.0 }}

[[roll]]
name = "roll"
centre = [0.0, 0.6]
free = ["z"]
core_radius = {RC}
core_mass = {MC}
core_inertia = 0.1
width = {L}
initial_radius = {RC}

[[nip]]
name = "nip"
a = "drum"
b = "roll"
contact = {{ law = "linear", stiffness = {K_NIP}, damping = 0.0 }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[web]
entry_nip = "nip"
"""
    return winder.scene_from_dict(tomllib.loads(text), source="flexmodes.toml")


def roll_mass(r: float) -> float:
    return MC + RHO * math.pi * L * (r * r - RC * RC)


def chain_bend_z1(r: float, n: int = N) -> float:
    """The drum's first bending frequency [Hz] in the chain of the module text at roll
    radius ``r`` [m]."""
    ks = K_NIP / n
    K = np.zeros((n + 1, n + 1))
    K[:n, :n] = np.linalg.inv(station_flexibility(n, L, EI, None, KB)) + ks * np.eye(n)
    K[:n, n] = K[n, :n] = -ks
    K[n, n] = n * ks
    M = np.diag([MD / n] * n + [roll_mass(r)])
    w2, vec = np.linalg.eig(np.linalg.solve(M, K))
    first = [k for k in range(n + 1)
             if np.argmax(orders(vec[:n, k].real)) == 0 and
             np.sum(MD / n * vec[:n, k].real ** 2) > roll_mass(r) * vec[n, k].real ** 2]
    k = min(first, key=lambda k: w2[k].real)
    return math.sqrt(w2[k].real) / (2 * math.pi)


# ---- the shapes -----------------------------------------------------------------------------
@pytest.mark.parametrize("n", [2, 5, 8, 16])
def test_the_sine_basis_is_orthogonal_and_labels_sin_2_as_order_2(n: int) -> None:
    """``sin(nπ y_i/L)`` at the centres are orthogonal (DST-II); a shape built as
    ``sin(2πy/L)`` is order 2 with all its energy (measured 1e-16)."""
    phi = sine_basis(n)
    gram = phi @ phi.T
    assert np.max(np.abs(gram - np.diag(np.diag(gram)))) < 1e-12
    y = (np.arange(n) + 0.5) * L / n
    share = orders(np.sin(2 * np.pi * y / L) * (1 + 0.5j))
    assert int(np.argmax(share)) + 1 == 2 and abs(share[1] - 1) < 1e-12
    uniform = orders(np.ones(n))  # a rigid translation: order 1, 8/π² of it at large n
    assert int(np.argmax(uniform)) == 0
    for fixed in (False, True):
        t = torsion_basis(n, fixed)
        g = t @ t.T
        assert np.max(np.abs(g - np.diag(np.diag(g)))) < 1e-12


def test_shapes_map_segments_onto_orders() -> None:
    """The generalised coordinates of the drum of :func:`scene`: ``drum.bend.x1 … x8``,
    ``drum.bend.z1 … z8`` and ``roll.z``; ``Q`` orthonormal; a drum displacement
    ``sin(2πy/L)`` in z is all ``drum.bend.z2``."""
    m = Machine(scene())
    coords = [f"{b.name}.{c}" for b in m.bodies for c in b.free]
    sh = Shapes(m.bodies, coords, [b.name for b in m.bodies if not b.prescribed])
    assert sh.labels == [*(f"drum.bend.x{k}" for k in range(1, N + 1)),
                         *(f"drum.bend.z{k}" for k in range(1, N + 1)), "roll.z"]
    assert np.allclose(sh.Q @ sh.Q.T, np.eye(len(coords)), atol=1e-12)
    u = np.zeros(len(coords))
    y = (np.arange(N) + 0.5) * L / N
    u[[coords.index(f"drum_s{i}.z") for i in range(N)]] = np.sin(2 * np.pi * y / L)
    e = (sh.Q @ u) ** 2
    assert sh.labels[int(np.argmax(e))] == "drum.bend.z2"
    assert abs(e.max() / e.sum() - 1) < 1e-12


# ---- the map --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def flex_map():
    return mode_map(scene(), np.linspace(0.1, 0.5, 9))


def test_labelled_bend_z1_is_the_chains_first_bending_frequency(flex_map) -> None:
    """``drum.bend.z1`` of the map equals the chain's first bending frequency at every
    radius (measured 2.5e-9 relative); without the roll it is the drum's own frequency of
    the closed form in tests/parts/test_flex_drum.py, within 0.3 % (the soft nip: measured
    0.13 %)."""
    mm = flex_map
    assert mm.flexible and "drum.bend.z1" in mm.shown() and mm.main == "roll.z"
    got = mm.natural["drum.bend.z1"]
    want = np.array([chain_bend_z1(float(r)) for r in mm.radius])
    assert np.max(np.abs(got / want - 1)) < 3e-8, (got, want)
    assert np.allclose(mm.frequencies["drum.bend.z1"], got, rtol=1e-9)  # no damping
    F = station_flexibility(N, L, EI, None, KB)
    alone = np.sqrt(np.min(np.linalg.eigvals(np.linalg.inv(F) / (MD / N)).real)) / (2 * np.pi)
    assert np.max(np.abs(got / alone - 1)) < 3e-3
    assert mm.natural["drum.bend.z2"][0] > 3 * got[0]


def test_crossing_radius_is_the_closed_form() -> None:
    """Harmonic ``k`` meets ``drum.bend.z1`` at ``r = k v/(2π f_bend(r))`` (solved by
    fixed point on the chain's frequency); the map's crossing interpolates ``f − k f₁``
    linearly between radii 5 mm apart (measured 2.2e-4, 6.4e-5, 1.2e-5 for k = 1, 2, 3:
    the curvature of the harmonic ``1/r``; 0.7 % at 50 mm, falling as the step squared)."""
    mm = mode_map(scene(), np.arange(0.14, 0.48, 0.005))
    found = {h: rc for c, h, rc in mm.crossings() if c == "drum.bend.z1"}
    for k in (1, 2, 3):
        r = 0.3
        for _ in range(50):
            r = k * V / (2 * math.pi * chain_bend_z1(r))
        if not mm.radius[0] <= r <= mm.radius[-1]:
            assert f"{k}x" not in found
            continue
        assert abs(found[f"{k}x"] / r - 1) < 2e-3, (k, found, r)


def test_drum_torsion1_is_the_held_chains_first_mode(flex_map) -> None:
    """``drum.torsion1``: the chain of N − 1 disks ``J/N`` on springs ``GJ N/L`` held at the
    driven segment, ``ω₁ = 2 √(k_t/I_d) sin(π/(2(2N − 1)))``, within 3e-4 at the smallest
    radius (the light roll's friction and inertia couple in as it grows: measured 2.5e-5)."""
    kt, Id = GJ * N / L, 1400.0 / N
    want = 2 * math.sqrt(kt / Id) * math.sin(math.pi / (2 * (2 * N - 1))) / (2 * math.pi)
    got = flex_map.torsion["drum.torsion1"][0]
    assert abs(got / want - 1) < 3e-4, (got, want)
    assert "drum.torsion1" in flex_map.shown()


def test_twin_flexible_drums_each_have_their_torsion1() -> None:
    """models/two_drum_winder_flexible.toml at r = 0.3 m: the two equal drums share their
    first torsion modes through the set (each drum about 38 % of the energy); each is still
    labelled, ``front.torsion1`` and ``rear.torsion1``, near the chain held at its drive
    end, ``2 √(k_t/I_d) sin(π/(2(2N − 1)))`` = 200.37 Hz (the nips and the x bending at
    197 Hz pull them: measured 2.3e-4 and 8.6e-3)."""
    from pathlib import Path

    from winder.analysis.modes import modes_at

    path = Path(__file__).resolve().parents[2] / "models" / "two_drum_winder_flexible.toml"
    ms = {m.coordinate: m for m in modes_at(winder.load_scene(path), 0.3)}
    n, kt, Id = 8, 1.7e9 * 8 / 5.0, 600.0 / 8
    want = 2 * math.sqrt(kt / Id) * math.sin(math.pi / (2 * (2 * n - 1))) / (2 * math.pi)
    for drum in ("front", "rear"):
        m = ms[f"{drum}.torsion1"]
        assert m.kind == "torsion" and 0.0 < m.damping_ratio < 0.2
        assert abs(m.natural_frequency / want - 1) < 9e-2, (drum, m.natural_frequency, want)
    assert ms["front.bend.z1"].kind == "bending" and ms["set.bend.z1"].kind == "bending"


def test_free_flexible_bodies_add_no_zero_root() -> None:
    """The shipped flexible two-drum winder: a free flexible body's first segment angle
    (the set's, the rider's) is its reference, slow like a rigid body's angle, its other
    segments' angles the twists ``θ_i − θ_0`` (``fast_jacobian``), so no eigenvalue of the
    fast states is an exact zero (with ``θ_0`` among them: two roots of 1e-12–1e-11 1/s,
    1e-17 of the largest, labelled as slip or torsion modes; measured smallest |λ| /
    largest now: 5.4e-5 at r = 0.05 m, 4.3e-3 at 0.3 m). Identity: the eigenvalues are
    those of all the angles absolute, ``θ_0`` fast, but its zero roots (measured 2.6e-14
    of the largest); without the twist rows (``θ_0`` merely dropped) the rider's torsion
    falls from 235 to 16 Hz and this fails."""
    from winder.analysis.operating_point import _linearisation

    scene = winder.load_scene(Path(__file__).resolve().parents[2] / "models"
                              / "two_drum_winder_flexible.toml")
    for r in (0.05, 0.3):
        lam = np.abs([m.eigenvalue for m in winder.modes_at(scene, r)])
        assert lam.min() > 1e-6 * lam.max(), (r, np.sort(lam)[:3])
    lin = _linearisation(scene, "test", None, lo_open=False)
    y = lin.solve(0.3, "test")
    refs = sorted({ref for ref, _ in lin.twists.values() if ref is not None})
    assert len(refs) == 2  # the set's and the rider's θ_0
    fast = lin.fast + refs
    everything = np.linalg.eigvals(winder.jacobian(lin.system, lin.t, y)[np.ix_(fast, fast)])
    top = np.max(np.abs(everything))
    nonzero = everything[np.abs(everything) > 1e-9 * top]
    assert len(everything) - len(nonzero) == len(refs)
    got = np.linalg.eigvals(lin.fast_jacobian(y))
    # each root against its nearest one left (the two drums' roots agree to 1e-5: a sort
    # by rounded value may pair them crosswise)
    left = list(nonzero)
    for z in got:
        j = int(np.argmin(np.abs(np.array(left) - z)))
        assert abs(left.pop(j) - z) < 3e-13 * top, (z, top)
