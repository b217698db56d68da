"""The sections' rotary inertia of a flexible drum (issue #32, item 7): ``flex.rotary_inertia``
(default true) against the Timoshenko frequency equation.

Drum: the issue's 6 m × Ø 1 m × 30 mm steel tube (E = 210 GPa, G = 80.8 GPa, shear
coefficient 0.5, ρ = 7850 kg/m³): ``EI = 2.26e9 N·m²``, ``kGA = 3.69e9 N``, ``m = ρAL =
4306 kg`` and ``J = 2ρIL = 1014 kg·m²`` (so the rotary inertia per length, ``J/(2L)``,
is the tube's ``ρI``); slenderness ``L/r = 17.5`` (``r = √(I/A)``).

The machine's frequencies are the eigenvalues ``±iω`` of its undamped state matrix at rest
over the bending states (deflections, their rates and, with the rotary inertia, the
sections' ``tilt`` and ``tilt_rate``), by central differences on the numeric path (exact:
the dynamics at rest are linear in them, gravity and nips off).

The oracles are the Timoshenko beam's frequency equation, with rotary inertia and shear
(``ρA ρI ω⁴/kGA − ω² (ρA + ρI κ² + ρA EI κ²/kGA) + EI κ⁴ = 0`` on stiff bearings,
``κ = kπ/L``; on elastic bearings or free the root of the 4 × 4 determinant of its
general solution) and, with the key off, the same without ``ρI``. The machine's
stiffness is exact and its masses (``m/N``, ``J/(2N)``) are lumped at the stations, so it
converges as ``N⁻²``: each case runs N = 8 and N = 16, checks the rate (the error falls by
4, measured 4.0–4.4) and the Richardson extrapolation ``(4 ω₁₆ − ω₈)/3`` against the
equation (measured ≤ 5e-5).
"""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest
from scipy.optimize import brentq

import winder
from winder.solve.system import MachineSystem

L, RO, WALL = 6.0, 0.5, 0.03  # [m]
E, G_SHEAR, RHO, KAPPA = 2.1e11, 8.08e10, 7850.0, 0.5
AREA = math.pi * (RO ** 2 - (RO - WALL) ** 2)  # [m²]
I_AREA = math.pi / 4 * (RO ** 4 - (RO - WALL) ** 4)  # [m⁴]
EI, KGA = E * I_AREA, KAPPA * G_SHEAR * AREA  # [N·m²], [N]
RHO_A, RHO_I = RHO * AREA, RHO * I_AREA  # [kg/m], [kg·m]
MASS, INERTIA = RHO_A * L, 2 * RHO_I * L  # [kg], [kg·m²]
GJ = 1.7e9  # [N·m²]


def scene(n: int, *, bearings: float, rotary: bool = True, shear: bool = True
          ) -> winder.Scene:
    beam = f"kGA = {KGA!r}" if shear else "shear = false"
    text = f"""
[scene]
name = "rotary"
duration = 0.01
output_step = 0.001

[effects]
gravity = false
contact = false
slip_relaxation = false

[[drum]]
name = "front"
radius = {RO}
inertia = {INERTIA!r}
mass = {MASS!r}
centre = [0.0, 0.0]
length = {L}
drive = {{ kind = "torque", torque = 0.0 }}
flex = {{ segments = {n}, EI = {EI!r}, {beam}, rotary_inertia = {str(rotary).lower()}, \
GJ = {GJ}, bearing_stiffness = {bearings!r}, damping_ratio = 0.0 }}
"""
    return winder.scene_from_dict(tomllib.loads(text), source="rotary.toml")


def frequencies(sys: MachineSystem, n: int, coord: str = "z", h: float = 1e-6
                ) -> np.ndarray:
    """The machine's bending ``ω`` [rad/s] along ``coord``, ascending, rigid modes (0)
    included: ``ω² = −λ²`` once per pair ``±iω`` of the state matrix (see the module
    text)."""
    segs = [f"front_s{i}" for i in range(n)]
    names = [f"{s}.{coord}" for s in segs] + [f"{s}.{coord}_dot" for s in segs]
    names += [k for s in segs for k in (f"{s}.tilt_{coord}", f"{s}.tilt_rate_{coord}")
              if k in sys.machine.state_names]
    idx = [sys.index(k) for k in names]
    y0 = sys.initial_state()
    A = np.empty((len(idx), len(idx)))
    for k, c in enumerate(idx):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        A[:, k] = (sys.rhs(0.0, a)[idx] - sys.rhs(0.0, b)[idx]) / (2 * h)
    lam = np.linalg.eigvals(A)
    return np.sqrt(np.clip(np.sort(-(lam * lam).real)[::2], 0.0, None))


# ---- the Timoshenko frequency equation ----------------------------------------------------
def pinned(k: int, rho_i: float, kga: float | None = KGA) -> float:
    """Mode ``k`` [rad/s] of the simply supported beam: the lower root ``ω²`` of
    ``ρA ρI ω⁴/kGA − ω² (ρA + ρI κ² + ρA EI κ²/kGA) + EI κ⁴ = 0``, ``κ = kπ/L`` (the modes
    ``w = sin κy``, ``ψ ∝ cos κy`` satisfy it exactly); ``kga`` None: no shear (Rayleigh's
    ``ω² = EI κ⁴/(ρA + ρI κ²)``)."""
    kap = k * math.pi / L
    if kga is None:
        return math.sqrt(EI * kap ** 4 / (RHO_A + rho_i * kap ** 2))
    a = RHO_A * rho_i / kga
    b = RHO_A + rho_i * kap ** 2 + RHO_A * EI * kap ** 2 / kga
    c = EI * kap ** 4
    w2 = c / b if a == 0.0 else (b - math.sqrt(b * b - 4 * a * c)) / (2 * a)
    return math.sqrt(w2)


def _determinant(w: float, rho_i: float, kb: float, kga: float) -> float:
    """The frequency equation of the Timoshenko beam on two bearings of stiffness ``kb``
    [N/m] (0: free–free): ``w = Σ c_j f_j``, ``f`` = cosh αy, sinh αy, cos βy, sin βy with
    ``α², −β²`` the roots ``s²`` of ``kGA EI s⁴ + (kGA ρI + ρA EI) ω² s² + ρA ω² (ρI ω² −
    kGA) = 0``, their ``ψ`` from ``ψ' = w'' + ρA ω² w/kGA``; the ends free of moment
    (``EI ψ' = 0``) with the shear ``Q = kGA (w' − ψ)`` on the bearing (``Q(0) = kb w(0)``,
    ``Q(L) = −kb w(L)``). Its rows scaled to unit length."""
    w2 = w * w
    a4, b2 = kga * EI, (kga * rho_i + RHO_A * EI) * w2
    c0 = RHO_A * w2 * (rho_i * w2 - kga)
    d = math.sqrt(b2 * b2 - 4 * a4 * c0)
    al, be = math.sqrt((-b2 + d) / (2 * a4)), math.sqrt((b2 + d) / (2 * a4))
    c = RHO_A * w2 / kga
    ra, rb = (al * al + c) / al, (c - be * be) / be

    def rows(y: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        ch, sh, co, si = math.cosh(al * y), math.sinh(al * y), math.cos(be * y), \
            math.sin(be * y)
        defl = np.array([ch, sh, co, si])
        slope = np.array([al * sh, al * ch, -be * si, be * co])
        psi = np.array([ra * sh, ra * ch, rb * si, -rb * co])
        moment = EI * np.array([ra * al * ch, ra * al * sh, rb * be * co, rb * be * si])
        return defl, moment, kga * (slope - psi)

    w0, m0, q0 = rows(0.0)
    wl, ml, ql = rows(L)
    M = np.array([m0, ml, q0 - kb * w0, ql + kb * wl])
    return float(np.linalg.det(M / np.linalg.norm(M, axis=1, keepdims=True)))


def on_bearings(rho_i: float, kb: float, modes: int = 2, kga: float = KGA) -> np.ndarray:
    """The first ``modes`` elastic frequencies [rad/s] of the beam on bearings ``kb``
    (0: free–free), the roots of :func:`_determinant` (bracketed on a fine grid, below the
    cut-off ``√(kGA/ρI)`` of the second spectrum)."""
    top = 1.5 * pinned(modes + 1, rho_i, kga)
    if rho_i > 0.0:
        top = min(top, 0.999 * math.sqrt(kga / rho_i))
    grid = np.linspace(1.0, top, 4000)
    f = [_determinant(w, rho_i, kb, kga) for w in grid]
    roots = [brentq(_determinant, grid[i], grid[i + 1], args=(rho_i, kb, kga), xtol=1e-13,
                    rtol=1e-15)
             for i in range(len(grid) - 1) if f[i] * f[i + 1] < 0.0]
    return np.array(roots[:modes])


def test_the_oracle_is_the_timoshenko_equation() -> None:
    """The determinant's roots: on bearings of 1e18 N/m the closed form of the simply
    supported beam (5e-9; measured 4.9e-10, the bearings' compliance), free–free without
    shear or rotary inertia Euler–Bernoulli's ``βL = 4.73004074, 7.85320462`` (1e-8 with
    kGA 1e6 times larger; measured 4.0e-7, what shear remains)."""
    for rho_i in (RHO_I, 0.0):
        got = on_bearings(rho_i, 1e18)
        want = [pinned(k, rho_i) for k in (1, 2)]
        assert np.max(np.abs(got / want - 1)) < 5e-9, (got, want)
    got = on_bearings(0.0, 0.0, kga=KGA * 1e6)
    want = np.array([4.73004074, 7.85320462]) ** 2 * math.sqrt(EI / (RHO_A * L ** 4))
    assert np.max(np.abs(got / want - 1)) < 1e-6, (got / want - 1)


# ---- the machine against it ----------------------------------------------------------------
#: (bearings [N/m], shear, the oracle's first two ω for the rotary inertia per length ``r``,
#: the bound on the extrapolation's error): the rotary inertia lowers the oracle's
#: frequencies 1.2 % and 2.3 % (stiff bearings), 0.61 % and 1.2 % (1e9 N/m), 5.2 % and
#: 6.6 % (free–free), 1.6 % and 5.9 % (no shear)
CASES = {
    "stiff bearings": (1e15, True, lambda r: [pinned(k, r) for k in (1, 2)], 5e-4),
    "bearings 1e9 N/m": (1e9, True, lambda r: on_bearings(r, 1e9), 4e-4),
    "free-free": (0.0, True, lambda r: on_bearings(r, 0.0), 2e-3),
    "no shear (Rayleigh)": (1e15, False, lambda r: [pinned(k, r, None) for k in (1, 2)],
                            5e-4),
}


@pytest.mark.parametrize("rotary", [True, False])
@pytest.mark.parametrize("case", sorted(CASES))
def test_bending_frequencies_follow_the_timoshenko_equation(case: str, rotary: bool
                                                            ) -> None:
    """First two bending frequencies at N = 8 and 16 against the frequency equation with
    the rotary inertia (key on) or without it (key off): the error falls at least as the
    lumping's ``N⁻²`` (by ≥ 3 from 8 to 16; measured 3.3–17, 4.0–4.1 from 16 to 32) and
    the extrapolation ``(4 ω₁₆ − ω₈)/3`` is within the case's bound of the equation.

    Measured (relative error of ω₁, ω₂ at N = 8 → 16; extrapolated), key on: stiff bearings
    −9.0e-4 → −2.2e-4 and −9.7e-3 → −2.4e-3 (4.2e-6, 6.5e-5); bearings 1e9 N/m −1.9e-3 →
    −4.8e-4 and −6.8e-3 → −1.7e-3 (3.7e-6, 3.8e-5); free–free +1.4e-2 → +3.5e-3 and
    +3.0e-3 → +9.0e-4 (−4.0e-5, 2.0e-4); no shear −2.0e-5 → −2.6e-6 and −4.2e-4 → −8.9e-5
    (3.1e-6, 2.1e-5). Key off, against the shear-only equation: stiff −9.4e-4 → −2.3e-4 and
    −1.07e-2 → −2.6e-3 (5.0e-6, 8.5e-5); the others alike (≤ 4.4e-4, free–free ω₂). Dropping
    the rotary inertia moves the limit by its whole effect (``CASES``), ≥ 3× each bound."""
    bearings, shear, oracle, bound = CASES[case]
    want = np.asarray(oracle(RHO_I if rotary else 0.0))
    rigid = 2 if bearings == 0.0 else 0
    got = {}
    for n in (8, 16):
        w = frequencies(MachineSystem(scene(n, bearings=bearings, rotary=rotary,
                                            shear=shear), backend="pinocchio"), n)
        assert np.all(w[:rigid] < 1e-6 * w[rigid]), w[:3]
        got[n] = w[rigid:rigid + 2]
    err = {n: got[n] / want - 1 for n in got}
    assert np.all(np.abs(err[16]) * 3 < np.abs(err[8])), err
    extrapolated = (4 * got[16] - got[8]) / 3
    assert np.max(np.abs(extrapolated / want - 1)) < bound, (extrapolated / want - 1, err)


def test_rotary_inertia_lowers_the_frequencies_as_measured() -> None:
    """The effect itself, at N = 16 on stiff bearings (the issue's measurement): the full
    Timoshenko frequencies lie 1.17 % and 2.30 % below the shear-only ones (the equation),
    and the machine's with the key on 1.16 % and 2.29 % below its own with the key off
    (1e-3 of each)."""
    full = np.array([pinned(k, RHO_I) for k in (1, 2)])
    shear_only = np.array([pinned(k, 0.0) for k in (1, 2)])
    assert np.allclose(full / shear_only - 1, [-0.01167, -0.02300], atol=1e-5)
    on, off = (frequencies(MachineSystem(scene(16, bearings=1e15, rotary=r),
                                         backend="pinocchio"), 16)[:2] for r in (True, False))
    assert np.allclose(on / off - 1, full / shear_only - 1, atol=1e-3), (on / off - 1)


def test_the_rotations_are_at_rest_in_the_static_balance() -> None:
    """The sections' states are their rotations beyond the static slope (0 at the start),
    so the balance of the condensed beam is the whole beam's: a drum sagging under gravity
    on its bearings starts at rest, every rate zero (1e-9 of g; measured ≤ 1e-12)."""
    n = 6
    sc = scene(n, bearings=1e9).replace(effects={"gravity": True, "contact": True})
    sys = MachineSystem(sc, backend="pinocchio")
    y = sys.initial_state()
    assert y[sys.index("front_s2.z")] < -1e-5  # it sags
    rates = sys.rhs(0.0, y)
    names = [f"front_s{i}.{k}" for i in range(n)
             for k in ("z_dot", "tilt_z", "tilt_rate_z", "x_dot", "tilt_x", "tilt_rate_x")]
    worst = max(abs(rates[sys.index(k)]) for k in names)
    assert worst < 1e-9 * 9.81, worst


def test_generated_code_matches_the_numeric_path() -> None:
    """The generated right-hand side (the one definition, compiled) equals the numeric
    path's at a perturbed state (deflections, rates and the sections' states) to 1e-9."""
    n = 3
    sc = scene(n, bearings=1e9).replace(effects={"gravity": True, "contact": True})
    gen, num = MachineSystem(sc), MachineSystem(sc, backend="pinocchio")
    assert gen.generated is not None
    y = gen.initial_state()
    rng = np.random.default_rng(3)
    for i in range(n):
        for k, scale in (("x", 1e-5), ("z_dot", 1e-3), ("tilt_z", 1e-6),
                         ("tilt_rate_x", 1e-3)):
            y[gen.index(f"front_s{i}.{k}")] += scale * rng.standard_normal()
    a, b = gen.rhs(0.0, y), num.rhs(0.0, y)
    assert np.max(np.abs(a - b) / (np.abs(b) + 1e-6)) < 1e-9


def test_every_state_has_its_unit() -> None:
    """The sections' states have their units for the plant and the CasADi model
    (``tilt_*`` [rad], ``tilt_rate_*`` [rad/s]), as every other state of the machine."""
    from winder.analysis.control import state_unit

    names = MachineSystem(scene(3, bearings=1e9), backend="pinocchio").machine.state_names
    assert {state_unit(n) for n in names if ".tilt_" in n} == {"rad", "rad/s"}
    assert [n for n in names if not state_unit(n)] == []
