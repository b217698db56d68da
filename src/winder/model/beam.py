"""A beam on two end bearings condensed onto N lumped segments (issue #25): the bending
stiffness, the bearings' damping and the Rayleigh coefficient of a flexible body.

The body of length ``L`` [m] is cut into ``N`` segments of length ``h = L/N``; segment
``i`` is a mass ``m/N`` at its centre, the station ``y_i = (i + ½) h``. Its deflection
``w_i`` (along ``x``, and separately the same way along ``z``) is its centre's offset from
the line of support.

**Stiffness: beam finite elements between the stations, condensed.** The nodes are the
two bearings (``y = 0`` and ``y = L``) and the ``N`` stations, each node with a deflection
``w`` and a slope ``ψ``; between neighbouring nodes one two-node Timoshenko element of
length ``l`` (``h/2`` at the ends, ``h`` between stations) with ``Φ = 12 EI / (kGA l²)``
(``Φ = 0``: Euler–Bernoulli)::

    k_e = EI / ((1 + Φ) l³) · [[ 12,   6l,          −12,  6l         ],
                               [ 6l,   (4 + Φ) l²,  −6l,  (2 − Φ) l² ],
                               [−12,  −6l,           12, −6l         ],
                               [ 6l,   (2 − Φ) l²,  −6l,  (4 + Φ) l² ]]

and a spring ``k_b`` (``bearing_stiffness``) on ``w`` of each bearing node. Only the
stations carry mass, so every other degree of freedom (the slopes and the bearings'
deflections) is condensed statically (Guyan): with ``r`` the stations' ``w`` and ``c`` the
rest, ``K = K_rr − K_rc K_cc⁻¹ K_cr`` [N/m] (N × N). This element is exact for a beam
loaded at its nodes (shear included), so ``K`` is the exact inverse of the beam's
flexibility at the stations: the discrete closed form of the chain is

    K⁻¹ = F,  F_ij = δ(y_i; load at y_j)  (bending + shear + the bearings' springs)

with, for a beam on two bearings (``a`` the load's station, ``b = L − a``, ``x ≤ a``)
``δ = x b (L² − b² − x²) / (6 EI L) + x b / (kGA L) + ((L − x) b + x a) / (k_b L²)``
(and its mirror for ``x > a``); the tests check the machine against it.

**Damping.** The bearings' dashpots ``c_b`` (``bearing_damping``) act on the condensed
bearing deflections ``w_b = T w`` (``T = −K_cc⁻¹ K_cr``, its bearing rows): projected
onto the stations, ``C_b = c_b Σ_ends t_endᵀ t_end``. The beam's own damping is
stiffness-proportional (Rayleigh, ``β K``) with ``β = 2 ζ / ω₁``: the first bending mode
(the lowest non-zero ``ω`` of ``K w = ω² (m/N) w``) has the damping ratio ``ζ``
(``damping_ratio``); the rigid-body modes of a free beam are not damped.

**Torsion** (:func:`torsion_damping`). Neighbouring segments are joined by a spring ``k_t =
GJ / h`` [N·m/rad]; a chain of ``N`` free disks ``I_d`` has ``ω_k = 2 √(k_t / I_d) sin(k π /
2N)``, held at its driven segment 0 (a speed profile) the ``N − 1`` others ``ω_k = 2 √(k_t /
I_d) sin((2k − 1) π / (2 (2N − 1)))``. Its damper ``c_t = β_t k_t`` between neighbours is
Rayleigh on the chain with its own ``β_t = 2ζ/ω_t1`` (issue #33), ``ω_t1`` the chain's first
torsion frequency (held or free as the body is driven): its first mode has the damping ratio
``ζ``, mode ``k`` ``ζ ω_k/ω_t1``. (The bending's ``β``, first used here too, gave the chain
``ζ ω_k/ω₁``: on the shipped paper set at its core 2.3 on its top modes, eigenvalues to
−1.0e5 1/s.)

**Rotary inertia** (issue #32, :func:`rotary_beam_matrices`). The cross-section's inertia
about a bending axis, ``j_r = J/(2N)`` [kg·m²] per station (half the segment's polar
inertia: a thin slice of a round section), acts on the section's rotation ``ψ``, which the
condensation above removes: a slope that follows the deflections statically cannot carry
it (folding ``j_r`` into the deflections' mass through ``ψ = T w``, Guyan, misses the
coupling of shear and rotary inertia, the ``ρA ρI ω⁴/kGA`` of the Timoshenko frequency
equation: it converges with ``N`` to a limit 4.5e-5 and 6.7e-4 above the first two
frequencies of a 6 m × Ø 1 m × 30 mm drum). So the stations keep their ``ψ`` as degrees
of freedom of mass ``j_r``; only the massless bearing nodes are condensed, which is exact,
giving ``K̂`` (2N × 2N, block tridiagonal) on the stations' ``(w, ψ)``, ``ω₁`` the lowest
non-zero ``ω`` of ``K̂ v = ω² diag(m/N, j_r) v`` and ``β = 2ζ/ω₁``. The states are
``φ = ψ − T w`` (the rotation beyond its static value for the deflections, ``T =
−K_ψψ⁻¹ K_ψw``: zero in any static balance, so the balance and the start are those of the
condensed beam) and the rotation rate ``s = ψ̇``:

    (m/N) ẅ = f − K w − K_wψ φ − C_ww ẇ − C_wψ s       (K = K_ww + K_wψ T, as above)
    j_r ṡ   =   − K_ψψ φ − C_ψw ẇ − C_ψψ s
    φ̇       = s − T ẇ

exactly the lumped-mass Timoshenko beam (the stiffness exact, the masses ``m/N`` and
``j_r`` lumped at the stations), which converges to the Timoshenko frequency equation
with rotary inertia as ``N⁻²``.

**Damping of the rocking** (issue #33). In ``(w, φ)`` the stiffness is block diagonal,
``½ wᵀ K w + ½ φᵀ K_ψψ φ``: the bending (the rotations following the deflections
statically) and the sections' rocking ``φ`` between the stations (``j_r φ̈ ≈ −K_ψψ φ``,
the Timoshenko beam's second spectrum, from ``ω_φ = √(μ₁(K_ψψ)/j_r)``, 1.1–1.5 kHz on the
shipped drums and rider). Each takes its own Rayleigh damping with the one ``ζ``: ``β K``
on the bending, ``β_φ K_ψψ`` on the rocking with ``β_φ = 2ζ/ω_φ``, so the dissipation is
``½ β ẇᵀ K ẇ + ½ β_φ φ̇ᵀ K_ψψ φ̇``. On ``(ẇ, ψ̇)`` (``φ̇ = ψ̇ − T ẇ``)::

    C_ww = (β − β_φ) K + β_φ K_ww + C_b,   C_wψ = β_φ K_wψ,   C_ψψ = β_φ K_ψψ

(``β_φ = β``: ``C = β K̂ + C_b``). One ``β K̂`` on all of ``(w, ψ)`` gave the rocking the
damping ratios ``β ω/2`` = 3.6–5 on the shipped rider (ω₁ = 20 Hz): overdamped, with
eigenvalues to −1.3e5 1/s, which held DOPRI5's step; now they oscillate with ζ at ``ω_φ``
(``ζ ω/ω_φ`` above), ``|λ|`` within the undamped spectrum, and the first two bending and
torsion orders keep their frequencies within 1.6e-5 and damping ratios within 6.5e-4 of
``β K̂`` (docs/model.md §9).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["BeamMatrices", "beam_matrices", "element_stiffness", "station_flexibility",
           "RotaryBeamMatrices", "rotary_beam_matrices", "torsion_eigenvalue",
           "torsion_damping"]


@dataclass(frozen=True)
class BeamMatrices:
    """The condensed matrices of a flexible body: ``K`` [N/m] and ``C`` [N·s/m] (N × N,
    on the stations' deflections, ``C = β K + C_b``), ``beta`` [s] the Rayleigh
    coefficient, ``omega1`` [rad/s] the first bending frequency (``0``: none),
    ``k_t`` [N·m/rad] the torsion spring between neighbouring segments (its damper:
    :func:`torsion_damping`)."""

    K: np.ndarray
    C: np.ndarray
    beta: float
    omega1: float
    k_t: float


def element_stiffness(EI: float, kGA: float | None, length: float) -> np.ndarray:
    """The 4 × 4 stiffness of a two-node Timoshenko element of ``length`` [m] on ``(w₁,
    ψ₁, w₂, ψ₂)`` [N/m, N, N·m]; ``kGA`` None: Euler–Bernoulli (``Φ = 0``)."""
    ll = length
    phi = 0.0 if kGA is None else 12.0 * EI / (kGA * ll * ll)
    return EI / ((1.0 + phi) * ll ** 3) * np.array([
        [12.0, 6 * ll, -12.0, 6 * ll],
        [6 * ll, (4 + phi) * ll * ll, -6 * ll, (2 - phi) * ll * ll],
        [-12.0, -6 * ll, 12.0, -6 * ll],
        [6 * ll, (2 - phi) * ll * ll, -6 * ll, (4 + phi) * ll * ll]])


def _assembled_stiffness(n: int, length: float, EI: float, kGA: float | None,
                         bearing_stiffness: float) -> np.ndarray:
    """The stiffness of the ``n + 2`` nodes (bearing, ``n`` stations at the segments'
    centres, bearing; ``(w, ψ)`` each) of a body of ``length`` [m]: its ``n + 1`` elements
    (half a segment at each end) and a bearing of ``bearing_stiffness`` [N/m] at each end."""
    h = length / n
    nodes = n + 2
    full = np.zeros((2 * nodes, 2 * nodes))
    for e, le in enumerate([h / 2, *([h] * (n - 1)), h / 2]):
        dofs = slice(2 * e, 2 * e + 4)
        full[dofs, dofs] += element_stiffness(EI, kGA, le)
    for d in (0, 2 * (nodes - 1)):
        full[d, d] += bearing_stiffness
    return full


def beam_matrices(n: int, length: float, mass: float, EI: float, kGA: float | None,
                  bearing_stiffness: float, bearing_damping: float, damping_ratio: float,
                  GJ: float) -> BeamMatrices:
    """The condensed matrices of a body of ``length`` [m] and ``mass`` [kg] in ``n`` ≥ 2
    segments (see the module text): ``EI`` [N·m²], ``kGA`` [N] (None: no shear),
    ``bearing_stiffness`` [N/m] and ``bearing_damping`` [N·s/m] per end and direction,
    ``damping_ratio`` [-] of the first bending mode, ``GJ`` [N·m²]."""
    if n < 2:
        raise ValueError(f"beam_matrices: n must be at least 2, got {n}")
    full = _assembled_stiffness(n, length, EI, kGA, bearing_stiffness)
    stations = n + 2  # bearing, n stations, bearing
    ends = (0, 2 * (stations - 1))
    kept = [2 * (i + 1) for i in range(n)]
    rest = [d for d in range(2 * stations) if d not in kept]
    Krr, Krc = full[np.ix_(kept, kept)], full[np.ix_(kept, rest)]
    Kcc = full[np.ix_(rest, rest)]
    T = -np.linalg.solve(Kcc, Krc.T)  # condensed dofs per unit station deflection
    K = Krr + Krc @ T
    K = 0.5 * (K + K.T)
    tb = T[[rest.index(d) for d in ends], :]
    Cb = bearing_damping * (tb.T @ tb)
    w2 = np.linalg.eigvalsh(K / (mass / n))
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    bending = w2[w2 > 1e-9 * scale]
    omega1 = float(np.sqrt(bending[0])) if bending.size else 0.0
    beta = 2.0 * damping_ratio / omega1 if omega1 > 0.0 else 0.0
    k_t = GJ / (length / n)
    return BeamMatrices(K, beta * K + Cb, beta, omega1, k_t)


def station_flexibility(n: int, length: float, EI: float, kGA: float | None,
                        bearing_stiffness: float) -> np.ndarray:
    """The closed form ``F`` [m/N] of the module text: the deflection at each station per
    unit load at each station of a beam on two bearings (bending, shear where ``kGA`` is
    given, and the bearings' springs ``k_b`` > 0)."""
    L, h = length, length / n
    y = (np.arange(n) + 0.5) * h
    F = np.empty((n, n))
    for i, x0 in enumerate(y):
        for j, a0 in enumerate(y):
            x, a = (x0, a0) if x0 <= a0 else (L - x0, L - a0)
            b = L - a
            F[i, j] = x * b * (L * L - b * b - x * x) / (6 * EI * L)
            if kGA is not None:
                F[i, j] += x * b / (kGA * L)
            F[i, j] += ((L - x0) * (L - a0) + x0 * a0) / (bearing_stiffness * L * L)
    return F


@dataclass(frozen=True)
class RotaryBeamMatrices:
    """The matrices of a flexible body with its sections' rotary inertia (see the module
    text), each N × N, ``w`` the stations' deflections, ``ψ`` their sections' rotations:
    ``K`` [N/m] the condensed stiffness (as :class:`BeamMatrices`), ``T`` [rad/m] the
    static rotations per deflection (``ψ = T w`` at rest), ``K_wp`` [N/rad] and ``K_pp``
    [N·m/rad] the blocks ``K_wψ``, ``K_ψψ`` of ``K̂``; ``C_ww`` [N·s/m], ``C_wp``
    [N·s/rad] and ``C_pp`` [N·m·s/rad] those of ``C`` (``C_ψw = C_wpᵀ``, the module
    text's *damping of the rocking*); ``beta`` [s], ``omega1`` [rad/s] and ``k_t``
    [N·m/rad] as :class:`BeamMatrices`; ``K_ww`` [N/m] the block
    ``K_ww`` of ``K̂`` (tridiagonal: ``K = K_ww + K_wψ T``); ``beta_rock`` [s] the
    rocking's Rayleigh coefficient ``2ζ/ω_φ``, ``omega_rock`` [rad/s] its ``ω_φ``."""

    K: np.ndarray
    T: np.ndarray
    K_wp: np.ndarray
    K_pp: np.ndarray
    C_ww: np.ndarray
    C_wp: np.ndarray
    C_pp: np.ndarray
    beta: float
    omega1: float
    k_t: float
    K_ww: np.ndarray
    beta_rock: float = 0.0
    omega_rock: float = 0.0


def rotary_beam_matrices(n: int, length: float, mass: float, inertia: float, EI: float,
                         kGA: float | None, bearing_stiffness: float,
                         bearing_damping: float, damping_ratio: float,
                         GJ: float) -> RotaryBeamMatrices:
    """The matrices of a body of ``length`` [m], ``mass`` [kg] and polar ``inertia``
    [kg·m²] in ``n`` ≥ 2 segments whose sections' rotations are degrees of freedom with
    the rotary inertia ``inertia/(2n)`` each (the module text; the other arguments as
    :func:`beam_matrices`)."""
    if n < 2:
        raise ValueError(f"rotary_beam_matrices: n must be at least 2, got {n}")
    full = _assembled_stiffness(n, length, EI, kGA, bearing_stiffness)
    nodes = n + 2  # bearing, n stations, bearing
    last = 2 * (nodes - 1)
    bearings = [0, 1, last, last + 1]
    stations = list(range(2, last))  # (w_0, ψ_0, w_1, ψ_1, ...)
    Kbb = full[np.ix_(bearings, bearings)]
    Ksb = full[np.ix_(stations, bearings)]
    Tb = -np.linalg.solve(Kbb, Ksb.T)  # the bearing nodes per unit station dof
    Kh = full[np.ix_(stations, stations)] + Ksb @ Tb
    Kh = 0.5 * (Kh + Kh.T)
    tb = Tb[[0, 2], :]  # the bearings' deflections
    Cb = bearing_damping * (tb.T @ tb)
    w, p = slice(0, 2 * n, 2), slice(1, 2 * n, 2)
    K_ww, K_wp, K_pp = Kh[w, w], Kh[w, p], Kh[p, p]
    T = -np.linalg.solve(K_pp, K_wp.T)
    K = K_ww + K_wp @ T
    K = 0.5 * (K + K.T)
    mdiag = np.empty(2 * n)
    mdiag[0::2], mdiag[1::2] = mass / n, inertia / (2 * n)
    scaled = Kh / np.sqrt(np.outer(mdiag, mdiag))
    w2 = np.linalg.eigvalsh(0.5 * (scaled + scaled.T))
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    bending = w2[w2 > 1e-9 * scale]
    omega1 = float(np.sqrt(bending[0])) if bending.size else 0.0
    beta = 2.0 * damping_ratio / omega1 if omega1 > 0.0 else 0.0
    j_r = inertia / (2 * n)
    omega_rock = float(np.sqrt(np.linalg.eigvalsh(K_pp)[0] / j_r))
    beta_rock = 2.0 * damping_ratio / omega_rock
    # β K on the deflections (the rotations following them statically), β_φ K_ψψ on the
    # rocking φ = ψ − T w, written on (ẇ, ψ̇): the module text
    C = beta_rock * Kh + Cb
    C_ww = C[w, w] + (beta - beta_rock) * K
    k_t = GJ / (length / n)
    return RotaryBeamMatrices(K, T, K_wp, K_pp, C_ww, C[w, p], C[p, p], beta, omega1,
                              k_t, K_ww, beta_rock, omega_rock)


def torsion_eigenvalue(n: int, *, held: bool) -> float:
    """``ν₁`` [-]: the least non-zero eigenvalue of the torsion chain of ``n`` ≥ 2 disks at
    unit ``k_t`` and unit disk inertia (its first frequency ``ω_t1 = √(ν₁ k_t/I_d)``):
    ``4 sin²(π/(2n))`` free, ``4 sin²(π/(2 (2n − 1)))`` held at segment 0 (the module text)."""
    if n < 2:
        raise ValueError(f"torsion_eigenvalue: n must be at least 2, got {n}")
    angle = math.pi / (2 * (2 * n - 1)) if held else math.pi / (2 * n)
    return 4.0 * math.sin(angle) ** 2


def torsion_damping(n: int, k_t: float, disk_inertia: float, damping_ratio: float, *,
                    held: bool) -> tuple[float, float]:
    """The torsion chain's own Rayleigh damping (the module text): ``(ω_t1, c_t)``, its first
    frequency [rad/s] and the damper ``c_t = β_t k_t`` [N·m·s/rad] between neighbours,
    ``β_t = 2ζ/ω_t1``, for ``n`` segments of polar inertia ``disk_inertia`` [kg·m²] joined
    by ``k_t`` [N·m/rad], ``held`` at segment 0 (a speed profile) or free."""
    omega = math.sqrt(torsion_eigenvalue(n, held=held) * k_t / disk_inertia)
    return omega, 2.0 * damping_ratio / omega * k_t
