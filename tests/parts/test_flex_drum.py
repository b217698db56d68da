"""A flexible drum (issue #25, phase 1): N segment bodies of the one model joined by a
condensed beam, bearings and torsion springs; its keys, errors and channels; oracles for
its bending and torsion frequencies and its static sag.

The frequencies are the machine's own: the Jacobian ``∂ẏ/∂y`` of the whole machine at rest
(Pinocchio's ABA with the force element ``flex_beam``, on the numeric path), by central
differences with a large step, which is exact here (the dynamics at rest are linear in the
deflections and angles, gravity off). The bending block ``∂ẍ_i/∂x_j = −(M⁻¹K)_ij`` gives
``ω²``; the torsion block ``∂θ̈_i/∂θ_j`` likewise.

Drum: Ø 1 m steel tube, 30 mm wall, 8 m long (issue #25: about 44 Hz).
"""

from __future__ import annotations

import math
import tomllib
from typing import Any

import numpy as np
import pytest

import winder
from winder._errors import SceneError
from winder.model.beam import beam_matrices, station_flexibility
from winder.model.machine import Machine
from winder.solve.system import MachineSystem

L = 8.0  # [m]
MASS = 5740.0  # [kg]
INERTIA = 1400.0  # [kg·m²]
EI = 2.26e9  # [N·m²]
KGA = 3.7e9  # [N]
GJ = 1.7e9  # [N·m²]
MPL = MASS / L  # m′ [kg/m]
G = 9.81  # [m/s²]


def scene_text(n: int, *, shear: bool = True, bearings: float = 1e15, damping: float = 0.0,
               gravity: bool = False, contact: bool = False, extra: str = "",
               drive: str = '{ kind = "torque", torque = 0.0 }', rotary: bool = True) -> str:
    kga = f", kGA = {KGA}" if shear else ""
    kga += "" if rotary else ", rotary_inertia = false"
    return f"""
[scene]
name = "flex"
duration = 0.01
output_step = 0.001

[effects]
gravity = {str(gravity).lower()}
contact = {str(contact).lower()}
slip_relaxation = {str(contact).lower()}

[[drum]]
name = "front"
radius = 0.5
inertia = {INERTIA}
mass = {MASS}
centre = [0.0, 0.0]
length = {L}
drive = {drive}
flex = {{ segments = {n}, EI = {EI}, shear = {str(shear).lower()}{kga}, GJ = {GJ}, \
bearing_stiffness = {bearings}, damping_ratio = {damping} }}
{extra}"""


def scene(n: int, **kw: Any) -> winder.Scene:
    return winder.scene_from_dict(tomllib.loads(scene_text(n, **kw)), source="flex.toml")


def system(n: int, **kw: Any) -> MachineSystem:
    return MachineSystem(scene(n, **kw), backend="pinocchio")


def block(sys: MachineSystem, coord: str, n: int, h: float = 1e-3) -> np.ndarray:
    """``∂(rate of NAME_s{i}.{coord}_dot)/∂(NAME_s{j}.{coord})`` at rest, the indices from
    the state names."""
    y0 = sys.initial_state()
    cols = [sys.index(f"front_s{j}.{coord}") for j in range(n)]
    rows = [sys.index(f"front_s{i}.{coord}_dot") for i in range(n)]
    out = np.empty((n, n))
    for k, c in enumerate(cols):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        out[:, k] = (sys.rhs(0.0, a)[rows] - sys.rhs(0.0, b)[rows]) / (2 * h)
    return out


def state_matrix(sys: MachineSystem, names: list[str], h: float = 1e-6) -> np.ndarray:
    """``∂ẏ/∂y`` over the states ``names`` at rest, by central differences."""
    y0 = sys.initial_state()
    idx = [sys.index(k) for k in names]
    out = np.empty((len(idx), len(idx)))
    for k, c in enumerate(idx):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        out[:, k] = (sys.rhs(0.0, a)[idx] - sys.rhs(0.0, b)[idx]) / (2 * h)
    return out


def bending_states(sys: MachineSystem, coord: str, n: int, body: str = "front") -> list[str]:
    """The states of the bending along ``coord``: the segments' deflections and rates and,
    with the rotary inertia, their sections' ``tilt_{coord}`` and ``tilt_rate_{coord}``."""
    segs = [f"{body}_s{i}" for i in range(n)]
    names = [f"{s}.{coord}" for s in segs] + [f"{s}.{coord}_dot" for s in segs]
    tilt = [f"{s}.{k}_{coord}" for s in segs for k in ("tilt", "tilt_rate")]
    return names + [k for k in tilt if k in sys.machine.state_names]


def frequencies(sys: MachineSystem, coord: str, n: int) -> np.ndarray:
    """The machine's ``ω`` [rad/s] of ``coord`` (``x``, ``z`` or ``theta``), ascending: the
    eigenvalues ``±iω`` of the undamped motion's state matrix (bending: with the sections'
    rotations where the rotary inertia is on), ``ω² = −λ²`` once per pair."""
    if coord == "theta":
        w2 = np.linalg.eigvals(-block(sys, coord, n)).real
        return np.sqrt(np.clip(np.sort(w2), 0.0, None))
    lam = np.linalg.eigvals(state_matrix(sys, bending_states(sys, coord, n)))
    w2 = np.sort(-(lam * lam).real)[::2]
    return np.sqrt(np.clip(w2, 0.0, None))


def closed_form(n: int, kga: float | None, bearings: float) -> np.ndarray:
    """``ω`` [rad/s] of the chain from the closed-form flexibility at the stations (beam on
    two bearings, :func:`station_flexibility`) and the lumped masses ``m/N``."""
    F = station_flexibility(n, L, EI, kga, bearings)
    return np.sqrt(np.sort(np.linalg.eigvals(np.linalg.inv(F) / (MASS / n)).real))


def euler_bernoulli(k: int) -> float:
    """Simply supported Euler–Bernoulli beam: ``(kπ)² √(EI/(m′L⁴))`` [rad/s]."""
    return (k * math.pi) ** 2 * math.sqrt(EI / (MPL * L ** 4))


def timoshenko(k: int) -> float:
    """Simply supported Timoshenko beam without rotary inertia (the segments have none about
    x or z): ``ω² = EI κ⁴ / (m′ (1 + EI κ²/kGA))``, ``κ = kπ/L`` [rad/s]."""
    kap = k * math.pi / L
    return math.sqrt(EI * kap ** 4 / (MPL * (1 + EI * kap * kap / KGA)))


# ---- scene --------------------------------------------------------------------------------
def test_a_flexible_drum_is_n_segment_bodies_with_their_channels() -> None:
    m = Machine(scene(4))
    names = [b.name for b in m.bodies]
    assert names == [f"front_s{i}" for i in range(4)]
    for i in range(4):
        for ch, unit in (("x", "m"), ("z", "m"), ("angle", "rad"), ("speed", "rad/s")):
            assert m.channel_units[f"front_s{i}_{ch}"] == unit
        assert m.param_values[m.param_index(f"front_s{i}.mass")] == MASS / 4
        assert m.param_values[m.param_index(f"front_s{i}.inertia")] == INERTIA / 4
    assert m.channel_units["front_twist"] == "rad"
    # the drum's input, as the rigid drum's (issue 32, item 4)
    assert [b.torque_inputs for b in m.bodies] == [("front.torque",), (), (), ()]
    # each segment: prismatic x, z, revolute y
    assert [m.model.joints[j].shortname() for j in range(1, 4)] == \
        ["JointModelPX", "JointModelPZ", "JointModelRY"]


def test_a_rigid_drum_is_unchanged() -> None:
    """No ``flex``: one body, no beam, and ``to_dict`` writes no new key."""
    text = scene_text(4).split("flex = ")[0].replace(f"length = {L}\n", "")
    sc = winder.scene_from_dict(tomllib.loads(text), source="rigid.toml")
    assert sc.drums[0].flex is None and sc.drums[0].length is None
    assert "flex" not in sc.to_dict()["drum"][0]
    assert "length" not in sc.to_dict()["drum"][0]
    m = Machine(sc)
    assert [b.name for b in m.bodies] == ["front"]
    assert "flex_beam" not in [f.name for f in m.forces]


def test_flex_round_trips_through_to_dict() -> None:
    sc = scene(5)
    again = winder.scene_from_dict(sc.to_dict(), source="flex.toml")
    assert again == sc and again.drums[0].flex.segments == 5


@pytest.mark.parametrize(("change", "where", "what"), [
    (lambda t: t.replace(f"length = {L}\n", ""), "[drum 'front'] length",
     "missing required key"),
    (lambda t: t.replace("segments = 6", "segments = 6.5"), "[drum 'front.flex'] segments",
     "not an integer"),
    (lambda t: t.replace("segments = 6", "segments = 1"), "[drum 'front.flex'] segments",
     ""),
    (lambda t: t.replace(f", kGA = {KGA}", ""), "[drum 'front.flex'] kGA",
     "missing required key"),
    (lambda t: t.replace(f"EI = {EI}", "EI = -1.0"), "[drum 'front.flex'] EI", ""),
    (lambda t: t.replace("GJ", "GJJ"), "[drum 'front.flex'] GJJ", "unknown key"),
])
def test_bad_flex_values_name_the_file_and_key(change: Any, where: str, what: str) -> None:
    with pytest.raises(SceneError) as err:
        winder.scene_from_dict(tomllib.loads(change(scene_text(6))), source="flex.toml")
    text = str(err.value)
    assert text.startswith("flex.toml: "), text
    assert where.split("] ")[1] in text and what in text, text


# ---- oracles -------------------------------------------------------------------------------
@pytest.mark.parametrize("shear", [False, True])
@pytest.mark.parametrize("n", [4, 10])
def test_simply_supported_drum_matches_the_chains_closed_form(n: int, shear: bool) -> None:
    """First two bending frequencies, in x and in z, against the discrete closed form of the
    chain: bearings 1e10 N/m (finite, in the closed form too); measured error ≤ 4e-14.
    Without the rotary inertia (the chain's masses are the segments')."""
    sys = system(n, shear=shear, bearings=1e10, rotary=False)
    want = closed_form(n, KGA if shear else None, 1e10)[:2]
    for coord in ("x", "z"):
        got = frequencies(sys, coord, n)[:2]
        assert np.max(np.abs(got / want - 1)) < 1e-12, (coord, got, want)


#: The relative error of ω₁, ω₂ against Euler–Bernoulli, by N (measured; the report's table).
CONVERGENCE = {}


@pytest.mark.parametrize("n", [10, 12, 16, 24])
def test_bending_converges_to_euler_bernoulli(n: int) -> None:
    """Stiff bearings, no shear: within 2 % of ``(kπ)² √(EI/(m′L⁴))`` for k = 1, 2 at
    N ≥ 10 (issue #25), and the error falls with N as ``N⁻⁴`` (the stiffness is exact, the
    mass lumping is not; measured at N = 10: 7e-6 and 1.2e-4, bound 1e-3 · (10/N)⁴)."""
    got = frequencies(system(n, shear=False, rotary=False), "z", n)[:2]
    err = [got[k] / euler_bernoulli(k + 1) - 1 for k in range(2)]
    CONVERGENCE[n] = err
    assert max(abs(e) for e in err) < 0.02, (n, err)
    assert max(abs(e) for e in err) < 1e-3 * (10 / n) ** 4, (n, err)
    smaller = [m for m in CONVERGENCE if m < n]
    if smaller:
        prev = CONVERGENCE[max(smaller)]
        assert all(abs(e) < abs(p) for e, p in zip(err, prev, strict=True)), CONVERGENCE


@pytest.mark.parametrize("n", [12, 24])
def test_shear_follows_the_timoshenko_frequency_equation(n: int) -> None:
    """Shear on, ``rotary_inertia = false``: within 2 % of the Timoshenko frequencies
    without rotary inertia at N = 12, converging as ``N⁻²`` (measured 0.025 % and 0.32 % at
    N = 12; bound 2 % · (12/N)²); they lie 4.4 % and 15 % below Euler–Bernoulli's for this
    drum. With the rotary inertia: tests/parts/test_flex_rotary.py."""
    got = frequencies(system(n, shear=True, rotary=False), "x", n)[:2]
    for k in range(2):
        assert abs(got[k] / timoshenko(k + 1) - 1) < 0.02 * (12 / n) ** 2, \
            (k, got[k], timoshenko(k + 1))
    assert timoshenko(1) < 0.96 * euler_bernoulli(1)


def test_free_free_drum() -> None:
    """No bearings: two rigid-body modes, then ``βL = 4.730, 7.853`` within 3 % at N = 12
    (issue #25; measured +1.09 % and +1.85 %)."""
    n = 12
    w = frequencies(system(n, shear=False, bearings=0.0, rotary=False), "z", n)
    assert np.all(w[:2] < 1e-3 * w[2])
    for k, bl in enumerate((4.730, 7.853)):
        want = bl ** 2 * math.sqrt(EI / (MPL * L ** 4))
        assert abs(w[2 + k] / want - 1) < 0.03, (k, w[2 + k], want)


@pytest.mark.parametrize("n", [5, 11])
@pytest.mark.parametrize("shear", [False, True])
def test_static_sag_under_gravity(n: int, shear: bool) -> None:
    """The initial static balance (spec §7) includes every segment: the drum starts in its
    sag. Midspan station (odd N) against ``5qL⁴/(384 EI) (1 + 2/(5N²) + 1/(5N⁴))`` plus the
    shear term ``qL²/(8 kGA) (1 + 1/N²)`` and the bearings' ``qL/(2 k_b)``: the continuous
    beam's sag times the lumping error of N point loads ``qL/N`` (exact for the chain)."""
    kb = 1e10
    sys = system(n, shear=shear, bearings=kb, gravity=True, contact=True)
    y = sys.initial_state()
    q = MPL * G
    bending = 5 * q * L ** 4 / (384 * EI) * (1 + 2 / (5 * n * n) + 1 / (5 * n ** 4))
    shearing = q * L * L / (8 * KGA) * (1 + 1 / n ** 2) if shear else 0.0
    want = bending + shearing + q * L / (2 * kb)
    sag = -y[sys.index(f"front_s{n // 2}.z")]
    assert abs(sag / want - 1) < 1e-10, (sag, want)  # measured ≤ 1e-13
    # every station against the closed form F · (qL/N)
    F = station_flexibility(n, L, EI, KGA if shear else None, kb)
    stations = -np.array([y[sys.index(f"front_s{i}.z")] for i in range(n)])
    assert np.max(np.abs(stations / (F @ np.full(n, q * L / n)) - 1)) < 1e-10
    # and the lumping error against the continuous beam (1 + 2/(5N²)) is what it says
    continuous = 5 * q * L ** 4 / (384 * EI)
    assert 0.0 < bending / continuous - 1 < 0.5 / n ** 2


@pytest.mark.parametrize("n", [2, 8, 16])
def test_torsion_chain_of_disks(n: int) -> None:
    """Free torsion chain of N disks ``I_d = J/N`` joined by ``k_t = GJ/(L/N)``:
    ``ω_k = 2 √(k_t/I_d) sin(kπ/2N)``, k = 0 … N−1: the non-zero ones to 1e-12 relative
    (measured ≤ 2.5e-15; issue #25 asks 1e-9)."""
    w2 = np.sort(np.linalg.eigvals(-block(system(n), "theta", n)).real)
    kt, Id = GJ / (L / n), INERTIA / n
    want = 2 * np.sqrt(kt / Id) * np.sin(np.arange(n) * np.pi / (2 * n))
    assert abs(w2[0]) < 1e-9 * want[-1] ** 2, w2  # the rigid rotation
    assert np.max(np.abs(np.sqrt(w2[1:]) / want[1:] - 1)) < 1e-12, (np.sqrt(w2[1:]), want)


def test_damping_ratio_of_the_first_bending_mode() -> None:
    """``damping_ratio`` ζ: the first bending mode of the machine decays with ζ (with the
    sections' rotary inertia, the default, and without)."""
    n, zeta = 8, 0.02
    for rotary in (True, False):
        sys = system(n, shear=True, bearings=1e10, damping=zeta, rotary=rotary)
        lam = np.linalg.eigvals(state_matrix(sys, bending_states(sys, "x", n)))
        first = min(lam, key=lambda s: abs(s))
        assert abs(-first.real / abs(first) - zeta) < 1e-6, (rotary, first)


def test_a_speed_profile_drum_drives_segment_zero_and_twists() -> None:
    """A speed-profile drive prescribes segment 0 alone; the others follow through the
    torsion springs, so the drum twists while it accelerates (generated code path). Once
    the start transient has decayed, spring k of the chain carries the inertia of the
    ``N − k`` segments beyond it: twist ``= α I_d N (N − 1) / (2 k_t)`` [rad], ``α =
    a_w / R``. ζ = 0.2: the chain's first torsion mode has it (its own ``β_t``, issue #33),
    so the start's ring has decayed by 0.2 s (measured twist 4.6e-5, speed 7.4e-7; with
    ζ = 0.05 it still rang at 7.1e-4 and 2.1e-6)."""
    drive = '{ kind = "speed_profile", web_acceleration = 5.0, web_speed = 40.0 }'
    sc = scene(3, drive=drive, damping=0.2)
    m = Machine(sc)
    assert [b.prescribed for b in m.bodies] == [True, False, False]
    res = winder.simulate(sc, t_end=0.2)
    twist = res["front_twist"]
    alpha, n = 5.0 / 0.5, 3
    want = alpha * (INERTIA / n) * n * (n - 1) / (2 * GJ / (L / n))
    assert np.all(np.isfinite(twist))
    assert abs(twist[-1] / want - 1) < 1e-3, (twist[-1], want)
    assert res["front_s2_speed"][-1] == pytest.approx(alpha * 0.2, rel=1e-6)


def test_beam_matrices_rayleigh_beta() -> None:
    bm = beam_matrices(6, L, MASS, EI, KGA, 1e10, 0.0, 0.03, GJ)
    assert bm.beta == pytest.approx(2 * 0.03 / bm.omega1, rel=1e-15)
    assert bm.k_t == pytest.approx(GJ / (L / 6))
