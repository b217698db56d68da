"""A flexible rider (issue #25): its arms hold its two ends in x (bearings in x), it rests
in z on the roll it rides through its sliced nip, its load spread over its segments.

Oracles: its x bending against the chain's closed form on two bearings, its z bending
free–free (``βL = 4.730, 7.853`` within 3 % at N = 12), and at rest on a rigid roll its
slices all carry ``(m g + L q)/N``: a free–free beam under a uniform load on uniform
springs translates without bending.
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import winder
from winder.model.beam import station_flexibility
from winder.model.machine import Machine
from winder.solve.system import MachineSystem

L, M, J = 5.0, 1500.0, 25.0  # [m], [kg], [kg·m²]
EI, KGA, GJ, KB = 3.64e7, 7.1e8, 2.8e7, 1e9  # Ø 0.3 m × 20 mm steel tube
Q = 3000.0  # line load [N/m]
G = 9.81


def scene_text(n: int, *, contact: bool = True, gravity: bool = True,
               shear: bool = True, rotary: bool = True) -> str:
    flag = str(contact).lower()
    beam = f"kGA = {KGA}" if shear else "shear = false"
    beam += "" if rotary else ", rotary_inertia = false"
    return f"""
[scene]
name = "rider"
duration = 0.1
output_step = 0.01

[effects]
imbalance = false
contact = {flag}
slip_relaxation = {flag}
gravity = {str(gravity).lower()}

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
centre = [0.0, 0.8]
free = ["z"]
core_radius = 0.05
core_mass = 40.0
core_inertia = 0.1
width = {L}
initial_radius = 0.3

[[rider]]
name = "rider"
rides = "set"
radius = 0.15
mass = {M}
inertia = {J}
x = 0.0
length = {L}
load = [[0.05, {Q}], [1.0, {Q}]]
flex = {{ segments = {n}, EI = {EI}, {beam}, GJ = {GJ}, bearing_stiffness = {KB}, \
damping_ratio = 0.0 }}

[[nip]]
name = "drum_nip"
a = "drum"
b = "set"
contact = {{ law = "linear", stiffness = 2.5e7, damping = 1.5e4 }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[[nip]]
name = "rider_nip"
a = "set"
b = "rider"
contact = {{ law = "linear", stiffness = 2.5e7, damping = 1.5e4 }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[web]
entry_nip = "drum_nip"
"""


def scene(n: int, **kw: bool) -> winder.Scene:
    return winder.scene_from_dict(tomllib.loads(scene_text(n, **kw)), source="rider.toml")


def frequencies(sys: MachineSystem, coord: str, n: int, h: float = 1e-3) -> np.ndarray:
    """``ω`` [rad/s] of the rider's ``coord`` block of the machine's Jacobian at rest."""
    y0 = sys.initial_state()
    cols = [sys.index(f"rider_s{j}.{coord}") for j in range(n)]
    rows = [sys.index(f"rider_s{i}.{coord}_dot") for i in range(n)]
    A = np.empty((n, n))
    for k, c in enumerate(cols):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        A[:, k] = (sys.rhs(0.0, a)[rows] - sys.rhs(0.0, b)[rows]) / (2 * h)
    return np.sqrt(np.clip(np.sort(np.linalg.eigvals(-A).real), 0.0, None))


def test_a_flexible_rider_is_n_segments_with_a_sliced_nip() -> None:
    m = Machine(scene(4))
    assert [b.name for b in m.bodies] == ["drum", "set", *(f"rider_s{i}" for i in range(4))]
    assert [n.name for n in m.nips] == ["drum_nip", *(f"rider_nip_s{i}" for i in range(4))]
    assert {n.a.name for n in m.nips[1:]} == {"set"}
    assert m.channel_units["rider_s2_z"] == "m" and m.channel_units["rider_twist"] == "rad"


def test_rider_bends_on_its_arms_in_x_and_free_in_z() -> None:
    """Euler–Bernoulli without rotary inertia, nip and gravity off. x: the chain on two
    bearings (closed form, 1e-12; measured 1e-13); z: free–free, two rigid modes then
    ``βL = 4.730, 7.853`` within 3 % at N = 12 (measured +1.09 %, +1.85 %). (With the
    rotary inertia: tests/parts/test_flex_rotary.py.)"""
    n = 12
    sys = MachineSystem(scene(n, contact=False, gravity=False, shear=False, rotary=False),
                        backend="pinocchio")
    F = station_flexibility(n, L, EI, None, KB)
    want = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.inv(F) / (M / n)).real))[:2]
    got = frequencies(sys, "x", n)[:2]
    assert np.max(np.abs(got / want - 1)) < 1e-12, (got, want)
    wz = frequencies(sys, "z", n)
    assert np.all(wz[:2] < 1e-3 * wz[2])
    for k, bl in enumerate((4.730, 7.853)):
        eb = bl ** 2 * math.sqrt(EI / (M / L * L ** 4))
        assert abs(wz[2 + k] / eb - 1) < 0.03, (k, wz[2 + k], eb)


@pytest.mark.parametrize("n", [3, 6])
def test_rider_at_rest_carries_its_load_evenly(n: int) -> None:
    """At rest on the rigid roll every slice carries ``(m g + L q)/N`` (1e-9; measured
    1e-13) and the rider does not bend; the roll's nip on the drum carries the roll and
    the rider."""
    sys = MachineSystem(scene(n), backend="pinocchio")
    y = sys.initial_state()
    ev = sys.evaluate_numeric(0.0, y)
    total = M * G + L * Q
    slices = np.array([ev.channels[f"rider_nip_s{i}_normal_force"] for i in range(n)])
    assert np.max(np.abs(slices / (total / n) - 1)) < 1e-9, slices
    z = np.array([y[sys.index(f"rider_s{i}.z")] for i in range(n)])
    assert np.ptp(z) < 1e-12
    roll = (40.0 + 650.0 * np.pi * L * (0.3 ** 2 - 0.05 ** 2)) * G
    assert ev.channels["drum_nip_normal_force"] == pytest.approx(roll + total, rel=1e-9)
    assert ev.channels["rider_nip_line_load_mean"] == pytest.approx(total / L, rel=1e-9)
