"""A flexible wound roll (issue #25): N segments sharing one radius state, each with its
share of ``m(r)``, ``J(r)`` and of the ``−Ẏv`` terms, bending with ``EI(r) = core_EI +
paper_E·π(r⁴ − r_c⁴)/4`` and no bearings (carried by its nips) or on chucks, twisting
with ``GJ``.

Oracles: world linear and angular momentum of a free-flying growing roll are conserved
(their rates vanish at any state, to 1e-9, only with ``−Ẏv`` on every segment); its
free–free bending frequencies follow ``EI(r)`` and ``m(r)``; at rest on a flexible drum
the slices solve the linear problem by hand; stiff, it is the rigid roll; on chucks it
sags and vibrates as the beam on two bearings of the drum's oracle.
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

W, RC, MC, JC, RHO = 5.0, 0.05, 40.0, 0.1, 650.0
CORE_EI, PAPER_E, GJ = 2.0e6, 5.0e8, 1.0e6
G = 9.81


def roll_text(n: int, *, r0: float = 0.3, free: str = '["z"]', damping: float = 0.0,
              core_ei: float = CORE_EI, paper_e: float = PAPER_E, gj: float = GJ,
              speed: float = 0.0) -> str:
    return f"""
[[roll]]
name = "roll"
centre = [0.0, {0.5 + r0}]
free = {free}
core_radius = {RC}
core_mass = {MC}
core_inertia = {JC}
width = {W}
initial_radius = {r0}
initial_speed = {speed}
flex = {{ segments = {n}, core_EI = {core_ei}, paper_E = {paper_e}, GJ = {gj}, \
damping_ratio = {damping} }}
"""


def scene_text(n: int, *, effects: str = "imbalance = false", drum: str = "", **kw: Any
               ) -> str:
    return f"""
[scene]
name = "flexroll"
duration = 0.2
output_step = 0.002

[effects]
{effects}

[paper]
density = {RHO}
caliper = 70e-6

[[drum]]
name = "drum"
radius = 0.5
inertia = 1400.0
mass = 5740.0
centre = [0.0, 0.0]
drive = {{ kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }}
{drum}
{roll_text(n, **kw)}
[[nip]]
name = "nip"
a = "drum"
b = "roll"
contact = {{ law = "linear", stiffness = 2.5e7, damping = 1.5e4 }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[web]
entry_nip = "nip"
"""


def scene(n: int, **kw: Any) -> winder.Scene:
    return winder.scene_from_dict(tomllib.loads(scene_text(n, **kw)), source="flexroll.toml")


def mass(r: float) -> float:
    return MC + RHO * math.pi * W * (r * r - RC * RC)


def ei(r: float) -> float:
    return CORE_EI + PAPER_E * math.pi * (r ** 4 - RC ** 4) / 4


def test_a_flexible_roll_is_n_segments_sharing_one_radius() -> None:
    m = Machine(scene(4))
    assert [b.name for b in m.bodies] == ["drum", *(f"roll_s{i}" for i in range(4))]
    assert [s for s in m.state_names if s.endswith("radius")] == ["roll.radius"]
    assert m.mode_names.count("roll.core") == 1
    assert [n.name for n in m.nips] == [f"nip_s{i}" for i in range(4)]
    assert [e.name for e in m.webs[0].entries] == [f"nip_s{i}" for i in range(4)]
    assert m.channel_units["roll_s2_radius"] == "m" and m.channel_units["roll_twist"] == "rad"
    sys = MachineSystem(scene(4, speed=20.0), backend="pinocchio")
    ev = sys.evaluate_numeric(0.0, np.array(sys.machine.state_initial))
    assert ev.channels["roll_radius"] == ev.channels["roll_s3_radius"] == 0.3
    assert ev.channels["roll_mass"] == pytest.approx(mass(0.3), rel=1e-14)
    assert ev.channels["roll_speed"] == pytest.approx(20.0, rel=1e-14)


def test_segments_of_both_flexible_bodies_of_a_nip_must_match() -> None:
    drum_flex = "length = 5.0\nflex = { segments = 3, EI = 1e9, kGA = 1e9, GJ = 1e9 }"
    with pytest.raises(SceneError) as err:
        scene(4, drum=drum_flex)
    assert "flexroll.toml" in str(err.value) and "nip 'nip'" in str(err.value)
    assert "] b: 'roll' has 4 segments" in str(err.value)


FLYING = ("variable_mass = true\nweb_momentum = false\nweb_tension = false\ngravity = false"
          "\nimbalance = false\ncontact = false\nslip_relaxation = false")


def momentum_rates(sys: MachineSystem, y: np.ndarray, n: int) -> tuple[float, float, float,
                                                                        float]:
    """``dP_x/dt, dP_z/dt`` [N] and ``dH_y/dt`` [N·m] of the roll's segments about the
    world origin at ``y``, and the scale of the mass-rate terms ``ṁ v``, ``J̇ ω`` [N, N·m]
    (what ``−Ẏv`` balances)."""
    ev = sys.evaluate_numeric(0.0, y)
    dy = sys.rhs(0.0, y)
    px = pz = hy = scale = 0.0
    for i in range(n):
        s = f"roll_s{i}"
        bs = ev.bodies[s]
        m, J, md, Jd = (float(v) for v in (bs.mass, bs.inertia, bs.mass_rate,
                                             bs.inertia_rate))
        x, z = y[sys.index(f"{s}.x")], y[sys.index(f"{s}.z")]
        vx, vz, w = (y[sys.index(f"{s}.{c}_dot")] for c in ("x", "z", "theta"))
        ax, az, al = (dy[sys.index(f"{s}.{c}_dot")] for c in ("x", "z", "theta"))
        px += md * vx + m * ax
        pz += md * vz + m * az
        hy += Jd * w + J * al + md * (z * vx - x * vz) + m * (z * ax - x * az)
        scale = max(scale, abs(md * vx), abs(md * vz), abs(Jd * w))
    return px, pz, hy, scale


@pytest.mark.parametrize("variable_mass", [True, False])
def test_free_flying_growing_roll_conserves_momentum(variable_mass: bool) -> None:
    """Free flight (gravity, contact and the web's forces off), winding (each segment
    turning at its own speed, the radius growing with their mean), deflected and moving:
    ``dP/dt = 0`` and ``dH_y/dt = 0`` to 1e-9 of the largest term with ``−Ẏv`` on every
    segment (measured 5e-12: round-off of the beam forces); without it, dP/dt ≈ 1.0 N,
    0.5 N and dH/dt ≈ −92 N·m here, 4 × the largest ``ṁ v``, ``J̇ ω``."""
    n = 4
    flag = str(variable_mass).lower()
    effects = FLYING.replace("variable_mass = true", f"variable_mass = {flag}")
    sys = MachineSystem(scene(n, effects=effects, free='["x", "z"]', r0=0.4),
                        backend="pinocchio")
    y = sys.initial_state()
    rng = np.random.default_rng(25)
    for i in range(n):
        for c, size in (("x", 1e-3), ("z", 1e-3), ("x_dot", 0.3), ("z_dot", 0.3),
                        ("theta", 0.1)):
            y[sys.index(f"roll_s{i}.{c}")] += size * rng.standard_normal()
        y[sys.index(f"roll_s{i}.theta_dot")] = -80.0 + rng.standard_normal()
    px, pz, hy, scale = momentum_rates(sys, y, n)
    worst = max(abs(px), abs(pz), abs(hy)) / scale
    if variable_mass:
        assert worst < 1e-9, (px, pz, hy, scale)
    else:
        assert worst > 0.1, (px, pz, hy, scale)


def frequencies(sys: MachineSystem, n: int, h: float = 1e-4) -> np.ndarray:
    y0 = sys.initial_state()
    cols = [sys.index(f"roll_s{j}.z") for j in range(n)]
    rows = [sys.index(f"roll_s{i}.z_dot") for i in range(n)]
    A = np.empty((n, n))
    for k, c in enumerate(cols):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        A[:, k] = (sys.rhs(0.0, a)[rows] - sys.rhs(0.0, b)[rows]) / (2 * h)
    return np.sqrt(np.clip(np.sort(np.linalg.eigvals(-A).real), 0.0, None))


def test_bending_follows_ei_of_the_radius() -> None:
    """Free–free (contact and gravity off), N = 12: ``βL = 4.730, 7.853`` with
    ``EI(r)``, ``m′ = m(r)/L`` within 3 % (measured +1.09 %, +1.85 %), and between two
    radii the frequencies scale as ``√(EI(r)/m(r))`` (1e-9; measured ≤ 1e-12)."""
    n = 12
    off = "gravity = false\ncontact = false\nslip_relaxation = false\nimbalance = false"
    w = {r: frequencies(MachineSystem(scene(n, effects=off, r0=r), backend="pinocchio"), n)
         for r in (0.3, 0.6)}
    for k, bl in enumerate((4.730, 7.853)):
        want = bl ** 2 * math.sqrt(ei(0.3) / (mass(0.3) / W * W ** 4))
        assert abs(w[0.3][2 + k] / want - 1) < 0.03, (k, w[0.3][2 + k], want)
    ratio = math.sqrt(ei(0.6) * mass(0.3) / (ei(0.3) * mass(0.6)))
    assert np.max(np.abs(w[0.6][2:4] / w[0.3][2:4] / ratio - 1)) < 1e-9


def test_flexible_roll_on_a_flexible_drum_at_rest() -> None:
    """Both flexible (N = 5), at rest: the slices as solved by hand (the drum's closed-form
    flexibility, the roll's free–free chain ``EI(r) K₁``), to 1e-9; symmetric; their sum
    the roll's weight."""
    n, L, EId, KGA, KB, MD = 5, W, 2.26e9, 3.7e9, 1e10, 5740.0
    drum = f"length = {L}\nflex = {{ segments = {n}, EI = {EId}, kGA = {KGA}, GJ = 1e9, " \
        f"bearing_stiffness = {KB} }}"
    sys = MachineSystem(scene(n, drum=drum), backend="pinocchio")
    y = sys.initial_state()
    ev = sys.evaluate_numeric(0.0, y)
    got = np.array([ev.channels[f"nip_s{i}_normal_force"] for i in range(n)])
    Kd = np.linalg.inv(station_flexibility(n, L, EId, KGA, KB))
    Kr = ei(0.3) * beam_matrices(n, L, float(n), 1.0, None, 0.0, 0.0, 0.0, 1.0).K
    ks, c = 2.5e7 / n, 0.5 + 0.3
    # unknowns [w_d, w_r]: f = ks (c − w_r + w_d); Kd w_d = −qd − f; Kr w_r = −qr + f
    A = np.block([[Kd + ks * np.eye(n), -ks * np.eye(n)],
                  [-ks * np.eye(n), Kr + ks * np.eye(n)]])
    rhs = np.concatenate([np.full(n, -MD / n * G - ks * c), np.full(n, -mass(0.3) / n * G
                                                                    + ks * c)])
    sol = np.linalg.solve(A, rhs)
    f = ks * (c - sol[n:] + sol[:n])
    assert np.max(np.abs(got / f - 1)) < 1e-9, (got, f)
    assert np.max(np.abs(got - got[::-1])) < 1e-9 * got.max()
    assert ev.channels["nip_normal_force"] == pytest.approx(mass(0.3) * G, rel=1e-9)


def test_stiff_flexible_roll_is_the_rigid_roll() -> None:
    """core_EI, paper_E and GJ × 1e6 (and damped): 0.2 s of winding from standstill at
    rtol 1e-9 reproduce the rigid roll within 1e-6 on its radius, mean speed, height and
    the nip's total force (measured 1e-14, 9e-10, 2e-13, 5e-10); each segment's speed
    within 1e-5 (measured 6.6e-7: its torsion rings after the start)."""
    rigid_text = scene_text(3).split("flex = ")[0] + "[[nip]]" + \
        scene_text(3).split("[[nip]]")[1]
    rigid = winder.simulate(winder.scene_from_dict(tomllib.loads(rigid_text), source="r.toml"),
                            t_end=0.2, rtol=1e-9)
    stiff = scene_text(3, core_ei=CORE_EI * 1e6, paper_e=PAPER_E * 1e6, gj=GJ * 1e6,
                       damping=0.05)
    flex = winder.simulate(winder.scene_from_dict(tomllib.loads(stiff), source="f.toml"),
                           t_end=0.2, rtol=1e-9)
    def err(a: str, got: np.ndarray) -> float:
        return float(np.max(np.abs(rigid[a] - got)) / np.max(np.abs(rigid[a])))

    mean_speed = sum(flex[f"roll_s{i}_speed"] for i in range(3)) / 3
    for a, got in (("roll_radius", flex["roll_s0_radius"]), ("roll_speed", mean_speed),
                   ("roll_z", flex["roll_s1_z"]),
                   ("nip_normal_force", flex["nip_normal_force"])):
        assert err(a, got) < 1e-6, (a, err(a, got))
    for i in range(3):  # each segment: its torsion still rings after the start
        assert err("roll_speed", flex[f"roll_s{i}_speed"]) < 1e-5


def _generated_matches_numeric(sc: winder.Scene, rate: str, scale: float) -> None:
    """The generated right-hand side equals the numeric Pinocchio path's to 1e-9 at the
    initial state with each segment's ``z`` and ``rate`` perturbed (``scale`` the rate's)."""
    gen, num = MachineSystem(sc), MachineSystem(sc, backend="pinocchio")
    assert gen.generated is not None
    y = gen.initial_state()
    rng = np.random.default_rng(7)
    for i in range(3):
        y[gen.index(f"roll_s{i}.z")] += 1e-5 * rng.standard_normal()
        y[gen.index(f"roll_s{i}.{rate}")] += scale * rng.standard_normal()
    a, b = gen.rhs(0.1, y), num.rhs(0.1, y)
    assert np.max(np.abs(a - b) / (np.abs(b) + 1e-6)) < 1e-9


def test_generated_code_matches_the_numeric_path() -> None:
    _generated_matches_numeric(scene(3, damping=0.05, speed=20.0), "theta_dot", 1.0)


# ---- a roll on chucks --------------------------------------------------------------------
KC = 1e10  # [N/m] each chuck


def chucked(n: int, r0: float = 0.3, damping: float = 0.0, speed: float = 0.0,
            effects: str = "imbalance = false") -> winder.Scene:
    """The roll of :func:`scene` on chucks 2.2 m above its nip's touching height (the nip
    stays open: no contact), free in ``x`` and ``z``."""
    text = scene_text(n, r0=r0, free='["x", "z"]', damping=damping, speed=speed,
                      effects=effects)
    text = text.replace(f"centre = [0.0, {0.5 + r0}]", f"centre = [0.0, {2.7 + r0}]")
    text = text.replace(f"damping_ratio = {damping} }}",
                        f'damping_ratio = {damping}, support = "chucks", '
                        f"chuck_stiffness = {KC} }}")
    return winder.scene_from_dict(tomllib.loads(text), source="flexroll.toml")


@pytest.mark.parametrize("n", [5, 11])
def test_roll_on_chucks_sags_as_the_beam_formula(n: int) -> None:
    """Gravity on, its nip open: the static balance puts a roll on stiff chucks in the sag
    of the drum's oracle (tests/parts/test_flex_drum.py) with ``EI(r)``, ``q = m(r) g/L``:
    midspan ``5qL⁴/(384 EI) (1 + 2/(5N²) + 1/(5N⁴)) + qL/(2 k_c)``, every station
    ``F · (qL/N)`` (measured ≤ 1.4e-12 at N = 11); ``x`` stays on the chucks' line."""
    r0 = 0.3
    sys = MachineSystem(chucked(n, r0), backend="pinocchio")
    y = sys.initial_state()
    z0 = 2.7 + r0
    q = mass(r0) * G / W
    want = 5 * q * W ** 4 / (384 * ei(r0)) * (1 + 2 / (5 * n * n) + 1 / (5 * n ** 4)) \
        + q * W / (2 * KC)
    sag = z0 - y[sys.index(f"roll_s{n // 2}.z")]
    assert abs(sag / want - 1) < 2e-11, (sag, want)
    F = station_flexibility(n, W, ei(r0), None, KC)
    stations = z0 - np.array([y[sys.index(f"roll_s{i}.z")] for i in range(n)])
    assert np.max(np.abs(stations / (F @ np.full(n, q * W / n)) - 1)) < 2e-11
    assert np.max(np.abs([y[sys.index(f"roll_s{i}.x")] for i in range(n)])) < 1e-12
    ev = sys.evaluate_numeric(0.0, y)
    assert float(ev.channels["nip_normal_force"]) == 0.0


def test_roll_on_chucks_bends_with_ei_of_the_radius() -> None:
    """Its bending frequencies at two radii: the chain on chucks ``K(EI) = F⁻¹`` (the
    Woodbury form of the stiffness is exact: measured 7e-14) with ``m(r)/N``."""
    n = 6
    off = "gravity = false\ncontact = false\nslip_relaxation = false\nimbalance = false"
    for r in (0.2, 0.5):
        text = scene_text(n, r0=r, effects=off).replace(
            "damping_ratio = 0.0 }", f'damping_ratio = 0.0, support = "chucks", '
            f"chuck_stiffness = {KC} }}")
        sc = winder.scene_from_dict(tomllib.loads(text), source="flexroll.toml")
        got = frequencies(MachineSystem(sc, backend="pinocchio"), n)
        F = station_flexibility(n, W, ei(r), None, KC)
        want = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.inv(F) / (mass(r) / n)).real))
        assert np.max(np.abs(got / want - 1)) < 1e-12, (r, got, want)


def test_chuck_stiffness_needs_chucks() -> None:
    text = scene_text(3).replace("damping_ratio = 0.0 }", "damping_ratio = 0.0, "
                                 "chuck_stiffness = 1e9 }")
    with pytest.raises(SceneError, match=r"chuck_stiffness.*support = 'chucks'"):
        winder.scene_from_dict(tomllib.loads(text), source="flexroll.toml")


def test_generated_code_on_chucks_matches_the_numeric_path() -> None:
    _generated_matches_numeric(chucked(3, damping=0.05, speed=20.0), "x_dot", 1e-3)
