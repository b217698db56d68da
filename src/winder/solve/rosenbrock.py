"""A compiled Rosenbrock method for stiff machines: Shampine & Reichelt's ROS2 (MATLAB's
``ode23s``) on the generated exact Jacobian.

L-stable, order 2 with an order-3 error estimate; each step costs one Jacobian, one LU
of ``W = I − h d J`` and three right-hand sides (``d = 1/(2 + √2)``). The time derivative
of the right-hand side (the drive's ramp) is a forward difference. The locked modes and
their located switches are those of :func:`winder.solve.dopri5.dopri5`: the step's
interpolant ``y + h θ(1−θ)/(1−2d) k1 + h θ(θ−2d)/(1−2d) k2`` is written in DOPRI5's
dense-output form, so event location is shared.
"""

from __future__ import annotations

import math

import numpy as np

from winder.solve._jit import njit
from winder.solve.integrators import (
    DONE,
    END,
    EXHAUSTED,
    F_JAC,
    F_RHS,
    GUARD,
    NON_FINITE,
    PAUSED,
    PENETRATED,
    STEP_UNDERFLOW,
    TIME_RESOLUTION,
    evaluate,
    first_step,
    modes_of,
    sample_and_switch,
    switch_buffer,
)

__all__ = ["ros2"]

D = 1.0 / (2.0 + math.sqrt(2.0))
E32 = 6.0 + math.sqrt(2.0)


@njit
def _lu(A: np.ndarray, piv: np.ndarray) -> bool:
    """In-place LU with partial pivoting; False if singular."""
    n = A.shape[0]
    for k in range(n):
        p = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                big, p = abs(A[i, k]), i
        if big == 0.0 or not math.isfinite(big):
            return False
        piv[k] = p
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            A[i, k] *= inv
            f = A[i, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
    return True


@njit
def _solve(LU: np.ndarray, piv: np.ndarray, b: np.ndarray) -> None:
    n = LU.shape[0]
    for k in range(n):
        p = piv[k]
        if p != k:
            b[k], b[p] = b[p], b[k]
    for i in range(n):
        s = b[i]
        for j in range(i):
            s -= LU[i, j] * b[j]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= LU[i, j] * b[j]
        b[i] = s / LU[i, i]


@njit
def ros2(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
         p: np.ndarray, m: np.ndarray, rtol: float, atol: float, h: float, max_step: float,
         t_out: np.ndarray, Y_out: np.ndarray, k: int, budget: int,
         stats: np.ndarray) -> tuple[int, float, float, int]:
    """Integrate ``y`` from ``t0`` to ``t1`` (arguments and results as
    :func:`~winder.solve.dopri5.dopri5`; ``stats[4]`` counts Jacobians)."""
    n = y.shape[0]
    f0, f1, f2 = np.empty(n), np.empty(n), np.empty(n)
    k1, k2, k3 = np.empty(n), np.empty(n), np.empty(n)
    ft, dfdt = np.empty(n), np.empty(n)
    yt, y1 = np.empty(n), np.empty(n)
    jac = np.empty(n * n)
    W = np.empty((n, n))
    piv = np.empty(n, dtype=np.int64)
    rc = np.zeros((5, n))
    tb = np.empty(1)
    g, g0 = switch_buffer(table), switch_buffer(table)
    t = t0
    modes_of(fns, table, tb, t, y, p, m, g, False)
    evaluate(fns, F_RHS, tb, t, y, p, m, f0)
    nfev = 1
    if h <= 0.0:
        h = first_step(y, f0, rtol, atol)
    status = DONE
    fresh = False  # Jacobian at (t, y) is current
    while t < t1:
        if nfev >= budget:
            status = PAUSED
            break
        hh = min(h, max_step)
        if t + 1.01 * hh >= t1:
            hh = t1 - t
        if hh < TIME_RESOLUTION * max(1.0, abs(t)):
            if t1 - t < TIME_RESOLUTION * max(1.0, abs(t)):
                for i in range(n):
                    y[i] += (t1 - t) * f0[i]
                t = t1
                break
            status = STEP_UNDERFLOW
            break
        if not fresh:
            evaluate(fns, F_JAC, tb, t, y, p, m, jac)
            dt = 1e-7 * max(1.0, abs(t))
            evaluate(fns, F_RHS, tb, t + dt, y, p, m, ft)
            for i in range(n):
                dfdt[i] = (ft[i] - f0[i]) / dt
            nfev += 1
            stats[4] += 1
            fresh = True
        hd = hh * D
        for i in range(n):
            for j in range(n):
                W[i, j] = -hd * jac[i + n * j]  # column-major
            W[i, i] += 1.0
        if not _lu(W, piv):
            h = 0.5 * hh
            stats[2] += 1
            continue
        for i in range(n):
            k1[i] = f0[i] + hd * dfdt[i]
        _solve(W, piv, k1)
        for i in range(n):
            yt[i] = y[i] + 0.5 * hh * k1[i]
        evaluate(fns, F_RHS, tb, t + 0.5 * hh, yt, p, m, f1)
        for i in range(n):
            k2[i] = f1[i] - k1[i]
        _solve(W, piv, k2)
        for i in range(n):
            k2[i] += k1[i]
            y1[i] = y[i] + hh * k2[i]
        evaluate(fns, F_RHS, tb, t + hh, y1, p, m, f2)
        for i in range(n):
            k3[i] = f2[i] - E32 * (k2[i] - f1[i]) - 2.0 * (k1[i] - f0[i]) + hd * dfdt[i]
        _solve(W, piv, k3)
        nfev += 2
        err = 0.0
        for i in range(n):
            sk = atol + rtol * max(abs(y[i]), abs(y1[i]))
            err += (hh / 6.0 * (k1[i] - 2.0 * k2[i] + k3[i]) / sk) ** 2
        err = math.sqrt(err / n)
        if not math.isfinite(err):
            stats[2] += 1
            h = 0.1 * hh
            if h < 1e-14 * max(1.0, abs(t)):
                status = NON_FINITE
                break
            continue
        if err > 1.0:
            stats[2] += 1
            h = hh * max(0.2, 0.8 * err ** (-1.0 / 3.0))
            continue
        for i in range(n):  # the interpolant in DOPRI5's dense-output form
            rc[0, i] = y[i]
            rc[1, i] = hh * k2[i]
            rc[2, i] = hh * (k1[i] - k2[i]) / (1.0 - 2.0 * D)
        slot, new_mode, t_end, k = sample_and_switch(fns, table, rc, t, hh, t1, tb, p, m, y,
                                                     y1, yt, g, g0, t_out, Y_out, k)
        stats[1] += 1
        fresh = False
        if slot == GUARD:  # a nip beyond its penetration bound: stop at the crossing
            t = t_end
            status = PENETRATED
            break
        if slot >= 0:
            t = t_end
            if new_mode == END:
                status = EXHAUSTED
                break
            m[slot] = new_mode
            evaluate(fns, F_RHS, tb, t, y, p, m, f0)
            nfev += 1
            stats[3] += 1
            continue
        for i in range(n):
            y[i] = y1[i]
            f0[i] = f2[i]
        t = t + hh if t + hh < t1 else t1
        h = hh * min(5.0, max(0.2, 0.8 * max(err, 1e-10) ** (-1.0 / 3.0)))
    stats[0] += nfev
    return status, t, h, k


