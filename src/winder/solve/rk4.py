"""Compiled classical fixed-step RK4 over a generated machine (for real-time stepping):
the clamped nip law without contact event location; the core events of spec §2 located
on the step's cubic Hermite interpolant; the penetration guard of
:mod:`winder.solve.integrators`.
"""

from __future__ import annotations

import math

import numpy as np

from winder.model.locked_modes import AT_CORE
from winder.solve._jit import njit
from winder.solve.integrators import (
    DONE,
    END,
    EXHAUSTED,
    F_RHS,
    NON_FINITE,
    PENETRATED,
    TIME_RESOLUTION,
    _next_event,
    _sliver,
    _switch_at,
    evaluate,
    guard_step,
    modes_of,
    switch_buffer,
)

__all__ = ["rk4"]


@njit
def _hermite(y0: np.ndarray, f0: np.ndarray, y1: np.ndarray, f1: np.ndarray, h: float,
             s: float, out: np.ndarray) -> None:
    """Cubic Hermite interpolant of a step of length ``h`` at ``s`` in ``[0, 1]``."""
    h00, h10 = 2 * s ** 3 - 3 * s ** 2 + 1, s ** 3 - 2 * s ** 2 + s
    h01, h11 = -2 * s ** 3 + 3 * s ** 2, s ** 3 - s ** 2
    for i in range(out.shape[0]):
        out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]


@njit
def rk4(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
        p: np.ndarray, m: np.ndarray, h: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
        stats: np.ndarray) -> tuple[int, float, float, int]:
    """Classical RK4 with steps of at most ``h`` evenly dividing ``[t0, t1]`` (the clamped
    nip law, no contact event location: for real-time stepping). The core events of
    spec §2 are located on the step's cubic Hermite interpolant; the step is cut there
    and the rest of the interval divided again. Samples by the same interpolant.
    Returns ``(status, t, h, k)``."""
    n = y.shape[0]
    k1, k2, k3, k4 = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    yt, y1 = np.empty(n), np.empty(n)
    rc = np.empty((5, n))
    tb = np.empty(1)
    g, g0 = switch_buffer(table), switch_buffer(table)
    modes_of(fns, table, tb, t0, y, p, m, g, True)
    evaluate(fns, F_RHS, tb, t0, y, p, m, k1)
    nfev = 1
    t = t0
    hh = h
    status = DONE
    while t < t1 and status == DONE:
        if t1 - t < TIME_RESOLUTION * max(1.0, abs(t)):
            k = _sliver(t, t1, y, k1, t_out, Y_out, k)
            t = t1
            break
        steps = max(1, int(math.ceil((t1 - t) / h - 1e-9)))
        ts = t
        hh = (t1 - ts) / steps
        for j in range(steps):
            tn = t1 if j == steps - 1 else ts + (j + 1) * hh
            hs = tn - t
            for i in range(n):
                yt[i] = y[i] + 0.5 * hs * k1[i]
            evaluate(fns, F_RHS, tb, t + 0.5 * hs, yt, p, m, k2)
            for i in range(n):
                yt[i] = y[i] + 0.5 * hs * k2[i]
            evaluate(fns, F_RHS, tb, t + 0.5 * hs, yt, p, m, k3)
            for i in range(n):
                yt[i] = y[i] + hs * k3[i]
            evaluate(fns, F_RHS, tb, t + hs, yt, p, m, k4)
            for i in range(n):
                y1[i] = y[i] + hs / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            evaluate(fns, F_RHS, tb, tn, y1, p, m, k2)  # f at the step end (next k1)
            nfev += 4
            stats[1] += 1
            ok = True
            for i in range(n):
                if not math.isfinite(y1[i]):
                    ok = False
            if not ok:
                status = NON_FINITE
                break
            # core events (spec §2): first point of the interpolant on the new side
            _, slot, new_mode = _next_event(fns, table, np.empty((5, n)), t, hs, tb, p, m,
                                            y1, yt, g, False)
            theta = 1.0
            if slot >= 0:
                gi = table[slot, 1] if new_mode in (AT_CORE, END) else table[slot, 2]
                ta, tb_ = 0.0, 1.0
                for _ in range(60):
                    th = 0.5 * (ta + tb_)
                    _hermite(y, k1, y1, k2, hs, th, yt)
                    if _switch_at(fns, gi, tb, t + th * hs, yt, p, m, g) > 0.0:
                        tb_ = th
                    else:
                        ta = th
                theta = tb_
            for i in range(n):  # the step's cubic Hermite in DOPRI5's dense form
                rc[0, i] = y[i]
                rc[1, i] = y1[i] - y[i]
                rc[2, i] = hs * k1[i] - rc[1, i]
                rc[3, i] = rc[1, i] - hs * k2[i] - rc[2, i]
                rc[4, i] = 0.0
            theta_guard = guard_step(fns, table, rc, t, hs, theta, tb, p, m, y, y1, yt, g,
                                     g0, t_out, k, slot < 0)
            if theta_guard <= theta:  # stopped where the first nip crosses its bound
                t = t + theta_guard * hs
                status = PENETRATED
                break
            t_end = t + theta * hs
            while k < t_out.shape[0] and t_out[k] <= t_end + 1e-13 * max(1.0, abs(t_end)):
                _hermite(y, k1, y1, k2, hs, min(theta, max(0.0, (t_out[k] - t) / hs)), yt)
                for i in range(n):
                    Y_out[i, k] = yt[i]
                k += 1
            if slot < 0:
                for i in range(n):
                    y[i] = y1[i]
                    k1[i] = k2[i]
                t = tn
                continue
            _hermite(y, k1, y1, k2, hs, theta, yt)
            for i in range(n):
                y[i] = yt[i]
            if new_mode in (AT_CORE, END):
                y[table[slot, 3]] = p[table[slot, 4]]  # land exactly on the core
            t = t_end if theta < 1.0 else tn
            if new_mode == END:
                status = EXHAUSTED
                break
            m[slot] = new_mode
            evaluate(fns, F_RHS, tb, t, y, p, m, k1)
            nfev += 1
            stats[3] += 1
            break  # divide the rest of the interval again
    stats[0] += nfev
    return status, t, hh, k
