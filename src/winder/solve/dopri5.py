"""Compiled adaptive Dormand–Prince 5(4) over a generated machine, with located mode
switches.

``dopri5`` is Hairer's DOPRI5 (tableau, error estimate, 4th-order dense output and step
control of ``scipy``'s RK45) with the machine's locked modes and their located switches
(:mod:`winder.solve.integrators`: the mode table, the event location and the penetration
guard it shares with RK4 and ROS2).
"""

from __future__ import annotations

import math

import numpy as np

from winder.solve._jit import njit
from winder.solve.integrators import (
    DONE,
    END,
    EXHAUSTED,
    F_RHS,
    GUARD,
    NON_FINITE,
    PAUSED,
    PENETRATED,
    STEP_UNDERFLOW,
    TIME_RESOLUTION,
    _sliver,
    evaluate,
    first_step,
    modes_of,
    sample_and_switch,
    switch_buffer,
)

__all__ = ["dopri5"]

# Dormand–Prince 5(4) tableau
C2, C3, C4, C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
A71, A73, A74, A75, A76 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = (71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525,
                          -1 / 40)
D1, D3, D4 = -12715105075 / 11282082432, 87487479700 / 32700410799, -10690763975 / 1880347072
D5, D6, D7 = 701980252875 / 199316789632, -1453857185 / 822651844, 69997945 / 29380423



@njit
def dopri5(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
           p: np.ndarray, m: np.ndarray, rtol: float, atol: float, h: float,
           max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int, budget: int,
           stats: np.ndarray) -> tuple[int, float, float, int]:
    """Integrate ``y`` from ``t0`` to ``t1``. Samples at ``t_out[k:]`` up to ``t1`` go to
    the columns of ``Y_out``. ``h <= 0`` picks the first step. Stops after ``budget``
    evaluations with :data:`PAUSED`. Modes ``m`` start from the state (:func:`modes_of`)
    and switch at located events. Returns ``(status, t, h, k)``."""
    n = y.shape[0]
    k1, k2, k3, k4 = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    k5, k6, k7 = np.empty(n), np.empty(n), np.empty(n)
    yt, y1 = np.empty(n), np.empty(n)
    rc = np.empty((5, n))
    tb = np.empty(1)
    g, g0 = switch_buffer(table), switch_buffer(table)
    t = t0
    modes_of(fns, table, tb, t, y, p, m, g, False)
    evaluate(fns, F_RHS, tb, t, y, p, m, k1)
    nfev = 1
    if h <= 0.0:
        h = first_step(y, k1, rtol, atol)
    rejected_last = False
    status = DONE
    while t < t1:
        if nfev >= budget:
            status = PAUSED
            break
        hh = min(h, max_step)
        if t + 1.01 * hh >= t1:
            hh = t1 - t
            if hh < TIME_RESOLUTION * max(1.0, abs(t)):  # a sliver is left
                k = _sliver(t, t1, y, k1, t_out, Y_out, k)
                t = t1
                break
        if hh < TIME_RESOLUTION * max(1.0, abs(t)):
            status = STEP_UNDERFLOW
            break
        for i in range(n):
            yt[i] = y[i] + hh * A21 * k1[i]
        evaluate(fns, F_RHS, tb, t + C2 * hh, yt, p, m, k2)
        for i in range(n):
            yt[i] = y[i] + hh * (A31 * k1[i] + A32 * k2[i])
        evaluate(fns, F_RHS, tb, t + C3 * hh, yt, p, m, k3)
        for i in range(n):
            yt[i] = y[i] + hh * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
        evaluate(fns, F_RHS, tb, t + C4 * hh, yt, p, m, k4)
        for i in range(n):
            yt[i] = y[i] + hh * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
        evaluate(fns, F_RHS, tb, t + C5 * hh, yt, p, m, k5)
        for i in range(n):
            yt[i] = y[i] + hh * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i]
                                 + A65 * k5[i])
        evaluate(fns, F_RHS, tb, t + hh, yt, p, m, k6)
        for i in range(n):
            y1[i] = y[i] + hh * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i]
                                 + A76 * k6[i])
        evaluate(fns, F_RHS, tb, t + hh, y1, p, m, k7)
        nfev += 6
        err = 0.0
        for i in range(n):
            sk = atol + rtol * max(abs(y[i]), abs(y1[i]))
            ei = hh * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i]
                       + E7 * k7[i])
            err += (ei / sk) ** 2
        err = math.sqrt(err / n)
        if not math.isfinite(err):
            stats[2] += 1
            h = 0.1 * hh
            if h < 1e-14 * max(1.0, abs(t)):
                status = NON_FINITE
                break
            rejected_last = True
            continue
        if err > 1.0:
            stats[2] += 1
            h = hh * max(0.2, 0.9 * err ** -0.2)
            rejected_last = True
            continue
        # accepted. Stiffness test of Hairer's DOPRI5: h·|λ| from the last two stages
        if stats.shape[0] > 4:
            stnum = stden = 0.0
            for i in range(n):
                stnum += (k7[i] - k6[i]) ** 2
                stden += (y1[i] - yt[i]) ** 2
            if stden > 0.0 and hh * hh * stnum > 3.25 ** 2 * stden:
                stats[4] += 1
        for i in range(n):  # dense output coefficients
            dyi = y1[i] - y[i]
            bspl = hh * k1[i] - dyi
            rc[0, i] = y[i]
            rc[1, i] = dyi
            rc[2, i] = bspl
            rc[3, i] = dyi - hh * k7[i] - bspl
            rc[4, i] = hh * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i]
                             + D7 * k7[i])
        slot, new_mode, t_end, k = sample_and_switch(fns, table, rc, t, hh, t1, tb, p, m, y,
                                                     y1, yt, g, g0, t_out, Y_out, k)
        stats[1] += 1
        if slot == GUARD:  # a nip beyond its penetration bound: stop at the crossing
            t = t_end
            status = PENETRATED
            break
        if slot >= 0:  # event: restart at the crossing in the new mode
            t = t_end
            if new_mode == END:
                status = EXHAUSTED
                break
            m[slot] = new_mode
            evaluate(fns, F_RHS, tb, t, y, p, m, k1)
            nfev += 1
            stats[3] += 1
            h = hh
            rejected_last = False
            continue
        for i in range(n):
            y[i] = y1[i]
            k1[i] = k7[i]
        t = t + hh if t + hh < t1 else t1
        fac = 0.9 * max(err, 1e-10) ** -0.2
        fac = min(fac, 1.0) if rejected_last else min(fac, 10.0)
        h = hh * max(0.2, fac)
        rejected_last = False
    stats[0] += nfev
    return status, t, h, k
