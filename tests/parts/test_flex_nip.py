"""Nips against a flexible drum, sliced (issue #25): one slice per segment, the nip's law
scaled by the slice's share of the length, its own friction state; the scene nip's total,
its line-load profile; the static balance with every segment's coordinates.

Oracle: a rigid roll (as long as the drum, free in z) resting on a flexible drum under
gravity is a linear problem in the roll's height ``z_r`` and the stations' deflections
``w`` (the nip linear, in contact everywhere, at rest):

    f_i = (k/N) (R + r − z_r + w_i)          slice force [N]
    Σ f_i = m_r g                            the roll
    F⁻¹ w = −(m_d/N) g − f                   the drum (F: the closed-form flexibility)

solved here by hand and compared with the machine's static balance.
"""

from __future__ import annotations

import tomllib
from typing import Any

import numpy as np
import pytest

import winder
from winder.model.beam import station_flexibility
from winder.model.machine import Machine
from winder.solve.system import MachineSystem

L, R, MD, EI, KGA, GJ, KB = 8.0, 0.5, 5740.0, 2.26e9, 3.7e9, 1.7e9, 1e10
K_NIP, C_NIP = 2.5e7, 1.5e4
RHO, RC, MC, R0 = 650.0, 0.05, 40.0, 0.3
G = 9.81


def scene_text(n: int, *, extra_flex: str = "", roll_width: float = L) -> str:
    return f"""
[scene]
name = "flexnip"
duration = 0.2
output_step = 0.002

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
drive = {{ kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }}
flex = {{ segments = {n}, EI = {EI}, kGA = {KGA}, GJ = {GJ}, bearing_stiffness = {KB}, \
damping_ratio = 0.02{extra_flex} }}

[[roll]]
name = "roll"
centre = [0.0, 0.8]
free = ["z"]
core_radius = {RC}
core_mass = {MC}
core_inertia = 0.1
width = {roll_width}
initial_radius = {R0}

[[nip]]
name = "nip"
a = "drum"
b = "roll"
contact = {{ law = "linear", stiffness = {K_NIP}, damping = {C_NIP} }}
friction = {{ mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }}

[web]
entry_nip = "nip"
"""


def scene(n: int, **kw: Any) -> winder.Scene:
    return winder.scene_from_dict(tomllib.loads(scene_text(n, **kw)), source="flexnip.toml")


def by_hand(n: int) -> tuple[float, np.ndarray, np.ndarray]:
    """``z_r`` [m], ``w`` [m] and the slice forces ``f`` [N] of the module text."""
    mr = MC + RHO * np.pi * L * (R0 ** 2 - RC ** 2)
    K = np.linalg.inv(station_flexibility(n, L, EI, KGA, KB))
    ks = K_NIP / n
    # unknowns [w_0 … w_{n−1}, z_r]
    A = np.zeros((n + 1, n + 1))
    rhs = np.zeros(n + 1)
    A[:n, :n] = K + ks * np.eye(n)
    A[:n, n] = -ks
    rhs[:n] = -MD / n * G - ks * (R + R0)
    A[n, :n] = ks
    A[n, n] = -n * ks
    rhs[n] = mr * G - n * ks * (R + R0)
    sol = np.linalg.solve(A, rhs)
    w, zr = sol[:n], sol[n]
    return zr, w, ks * (R + R0 - zr + w)


def test_a_nip_on_a_flexible_drum_is_sliced() -> None:
    m = Machine(scene(4))
    assert [n.name for n in m.nips] == [f"nip_s{i}" for i in range(4)]
    assert [n.a.name for n in m.nips] == [f"drum_s{i}" for i in range(4)]
    assert {n.b.name for n in m.nips} == {"roll"}
    assert m.param_values[m.param_index("nip_s1.stiffness")] == K_NIP / 4
    assert m.param_values[m.param_index("nip_s1.damping")] == C_NIP / 4
    assert [s for s in m.state_names if s.endswith(".friction")] == \
        [f"nip_s{i}.friction" for i in range(4)]
    assert m.webs[0].entry.name == "nip_s2"
    for ch, unit in (("nip_normal_force", "N"), ("nip_s3_normal_force", "N"),
                     ("nip_line_load_min", "N/m"), ("nip_line_load_max", "N/m"),
                     ("nip_line_load_mean", "N/m"), ("drum_twist", "rad")):
        assert m.channel_units[ch] == unit, ch


@pytest.mark.parametrize("n", [5, 8])
def test_static_slices_against_the_linear_closed_form(n: int) -> None:
    """The initial static balance: the roll's height, every segment's sag and every slice's
    force as solved by hand (to 1e-11), symmetric about mid-width; their sum is the roll's
    weight, as on a rigid drum; the line-load channels summarise the slices."""
    sys = MachineSystem(scene(n), backend="pinocchio")
    y = sys.initial_state()
    zr, w, f = by_hand(n)
    assert y[sys.index("roll.z")] == pytest.approx(zr, rel=1e-12)
    got_w = np.array([y[sys.index(f"drum_s{i}.z")] for i in range(n)])
    assert np.max(np.abs(got_w - w)) < 1e-12 * np.max(np.abs(w))  # measured 5e-14
    ev = sys.evaluate_numeric(0.0, y)
    got = np.array([ev.channels[f"nip_s{i}_normal_force"] for i in range(n)])
    assert np.max(np.abs(got / f - 1)) < 1e-11, (got, f)  # measured 7e-13
    assert np.max(np.abs(got - got[::-1])) < 1e-9 * got.max()  # symmetric
    weight = (MC + RHO * np.pi * L * (R0 ** 2 - RC ** 2)) * G
    assert ev.channels["nip_normal_force"] == pytest.approx(weight, rel=1e-9)
    h = L / n
    assert ev.channels["nip_line_load_min"] == pytest.approx(got.min() / h, rel=1e-12)
    assert ev.channels["nip_line_load_max"] == pytest.approx(got.max() / h, rel=1e-12)
    assert ev.channels["nip_line_load_mean"] == pytest.approx(weight / L, rel=1e-9)
    # the drum sags most at mid-width, so the rigid roll bears least there
    assert got[n // 2] < got[0] and got.max() / got.min() > 1.2


def test_a_flexible_winder_runs_and_keeps_its_total() -> None:
    """The single-drum winder on a flexible drum runs (generated code): the nip's total is
    the sum of its slices at every sample."""
    res = winder.simulate(scene(3), t_end=0.1)
    total = sum(res[f"nip_s{i}_normal_force"] for i in range(3))
    assert np.max(np.abs(res["nip_normal_force"] - total)) < 1e-9 * np.max(total)
    assert np.all(res["nip_line_load_min"] <= res["nip_line_load_max"])
    assert res["roll_speed"][-1] > 0.0


def _stiffened(text: str, factor: float) -> str:
    for key, value in (("EI", EI), ("kGA", KGA), ("GJ", GJ), ("bearing_stiffness", KB)):
        text = text.replace(f"{key} = {value}", f"{key} = {value * factor}")
    return text


def test_stiff_limit_reproduces_the_rigid_machine() -> None:
    """EI, kGA, GJ and the bearings × 1e6: the run (0.2 s of the start, rtol 1e-9) is the
    rigid drum's within 1e-6 (relative to each channel's largest value) on the roll's
    radius, speed and height, the drive segment's speed and the nip's total force
    (measured ≤ 2e-9), and within 1e-5 on the far segment's speed (its torsion still rings
    after the start: measured 1.2e-6)."""
    text = scene_text(3)
    rigid_text = text.split("length = ")[0] + "drive = " + text.split("drive = ")[1]
    rigid_text = rigid_text.split("flex = ")[0] + "[[roll]]" + rigid_text.split("[[roll]]")[1]
    rigid = winder.simulate(winder.scene_from_dict(tomllib.loads(rigid_text), source="r.toml"),
                            t_end=0.2, rtol=1e-9)
    flex = winder.simulate(winder.scene_from_dict(tomllib.loads(_stiffened(text, 1e6)),
                                                  source="f.toml"), t_end=0.2, rtol=1e-9)

    def err(a: str, b: str) -> float:
        return float(np.max(np.abs(rigid[a] - flex[b])) / np.max(np.abs(rigid[a])))

    for a, b in (("roll_radius", "roll_radius"), ("roll_speed", "roll_speed"),
                 ("roll_z", "roll_z"), ("drum_speed", "drum_s0_speed"),
                 ("nip_normal_force", "nip_normal_force")):
        assert err(a, b) < 1e-6, (a, err(a, b))
    assert err("drum_speed", "drum_s2_speed") < 1e-5


VALLEY = """
[scene]
name = "valley"
duration = 0.1
output_step = 0.01

[effects]
imbalance = false

[paper]
density = 650.0
caliper = 70e-6

[[drum]]
name = "front"
radius = 0.5
inertia = 600.0
mass = 3000.0
centre = [-0.525, 0.0]
length = 5.0
drive = { kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }
flex = { segments = 5, EI = 1.4e9, kGA = 2.3e9, GJ = 1.1e9, bearing_stiffness = 1e10 }

[[drum]]
name = "rear"
radius = 0.5
inertia = 600.0
mass = 3000.0
centre = [0.525, 0.0]
length = 5.0
drive = { kind = "speed_profile", web_acceleration = 0.7, web_speed = 41.7 }
flex = { segments = 5, EI = 1.4e9, kGA = 2.3e9, GJ = 1.1e9, bearing_stiffness = 1e10 }

[[roll]]
name = "set"
centre = [0.0, 0.4]
free = ["x", "z"]
core_radius = 0.05
core_mass = 40.0
core_inertia = 0.1
width = 5.0
initial_radius = 0.3

[[nip]]
name = "front_nip"
a = "front"
b = "set"
contact = { law = "linear", stiffness = 2.5e7, damping = 1.5e4 }
friction = { mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }

[[nip]]
name = "rear_nip"
a = "rear"
b = "set"
contact = { law = "linear", stiffness = 2.5e7, damping = 1.5e4 }
friction = { mu = 0.35, slip_velocity = 0.05, relaxation_length = 0.01, min_speed = 0.1 }

[web]
entry_nip = "rear_nip"
"""


def test_symmetric_two_drum_valley_at_rest() -> None:
    """A set in the valley of two equal flexible drums, at rest: the static balance solves
    every segment and the set; each nip's slices are symmetric about mid-width, the two
    nips mirror each other, and the slices' forces carry the set's weight (1e-9)."""
    sc = winder.scene_from_dict(tomllib.loads(VALLEY), source="valley.toml")
    sys = MachineSystem(sc, backend="pinocchio")
    y = sys.initial_state()
    ev = sys.evaluate_numeric(0.0, y)
    front = np.array([ev.channels[f"front_nip_s{i}_normal_force"] for i in range(5)])
    rear = np.array([ev.channels[f"rear_nip_s{i}_normal_force"] for i in range(5)])
    assert np.max(np.abs(front - front[::-1])) < 1e-9 * front.max()
    assert np.max(np.abs(front - rear)) < 1e-9 * front.max()
    assert abs(y[sys.index("set.x")]) < 1e-12
    lift = sum(float(ns.normal_force * ns.nz) for ns in ev.nips.values())
    mass = 40.0 + 650.0 * np.pi * 5.0 * (0.3 ** 2 - 0.05 ** 2)
    assert lift == pytest.approx(mass * 9.81, rel=1e-9)
    assert front[2] < front[0]  # the drums sag most at mid-width


def test_generated_code_matches_the_numeric_path() -> None:
    """The generated right-hand side and Pinocchio's numeric one agree at a state away
    from rest (deflected, twisted, moving segments; the roll turning and winding)."""
    sc = scene(3)
    gen, num = MachineSystem(sc), MachineSystem(sc, backend="pinocchio")
    assert gen.generated is not None
    y = gen.initial_state()
    rng = np.random.default_rng(25)
    for name in gen.state_names:
        i = gen.index(name)
        if name.startswith("drum_s"):
            y[i] += (1e-5 if name.endswith((".x", ".z")) else 1e-2) * rng.standard_normal()
    y[gen.index("roll.theta_dot")] = 20.0
    a, b = gen.rhs(0.5, y), num.rhs(0.5, y)
    assert np.max(np.abs(a - b) / (np.abs(b) + 1e-6)) < 1e-9


def test_the_flexible_two_drum_example_builds() -> None:
    """models/two_drum_winder_flexible.toml: every body in 8 segments, every nip sliced."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "models" / "two_drum_winder_flexible.toml"
    m = Machine(winder.load_scene(path))
    assert len(m.bodies) == 32 and len(m.nips) == 24
    for nip in ("front_nip", "rear_nip", "rider_nip"):
        assert m.channel_units[f"{nip}_line_load_max"] == "N/m"
