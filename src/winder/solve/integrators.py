"""Compiled integrators over generated machines: adaptive Dormand–Prince 5(4) with located
mode switches, and classical fixed-step RK4.

``dopri5`` is Hairer's DOPRI5 (tableau, error estimate, 4th-order dense output and step
control of ``scipy``'s RK45) with the machine's *locked modes*: per nip the contact mode
(touching or not) and per wound roll the core mode of spec §2 stay fixed within a step.
When an accepted step ends on the other side of a switching function, the crossing is
located on the step's dense output (Illinois method, to ~1e-12 s), the step is cut there
and the integration restarts in the new mode. The discontinuity of a damped normal force
at touch-down and the kink at lift-off never fall inside a step. A roll unwinding to its
core lands exactly on ``r_c``.

The machine's functions are called through their addresses (:mod:`winder.model.ccall`):
``fns = [rhs, jac, out, sw]``. Mode slots are described by ``table`` rows ``(kind, g1,
g2, state, param)``: kind :data:`K_CONTACT` (``g1`` its switching function, ``g2``
its guard ``NIP.overlap``, then the guard's ``NIP.dx`` and ``NIP.dz`` in place of state
and param),
:data:`K_CORE` (``g1`` = ``r_c − r``, ``g2`` = speed, ``state`` the radius, ``param``
``r_c``) or :data:`K_END` (an unwinding roll: ``g1`` = ``r_c − r``; where it crosses
zero the roll has run out of web, the radius lands on ``r_c`` and the integration stops
with :data:`EXHAUSTED`).

Both functions integrate ``y`` in place, write samples at output times into a caller's
array and keep counters in ``stats = [nfev, accepted, rejected, events, stiff steps]``.
Status codes: :data:`DONE`, :data:`PAUSED` (the evaluation budget of this call is spent;
call again to resume), :data:`STEP_UNDERFLOW`, :data:`NON_FINITE`, :data:`EXHAUSTED`,
:data:`PENETRATED`.

The guard of every accepted step (:func:`guard_step`: DOPRI5 and ROS2 in
:func:`sample_and_switch`, RK4 after its non-finite check): where a nip's guard function
``NIP.overlap = δ − min(r_a, r_b)`` (the contact row's ``g2``) is positive or not a number
at the step's end or at an output sample inside it, or where the straight path of the
step (from its start to its end) takes it there (a step that jumps through the other
body), the first crossing of the bound is located, ``y`` moves there and the integration
stops with :data:`PENETRATED`: one body's axis inside the other means the integrator lost
the contact (a step or tolerance far too coarse for the nip), and every later number
would be wrong.
"""

from __future__ import annotations

import math

import numpy as np

from winder.model.ccall import call
from winder.model.locked_modes import AT_CORE, AUTO, FREE, IN_CONTACT, WINDING, ModeKind
from winder.solve._jit import njit

__all__ = ["dopri5", "rk4", "modes_of", "evaluate", "switches", "switch_buffer", "first_step",
           "sample_and_switch", "DONE", "PAUSED",
           "STEP_UNDERFLOW", "NON_FINITE", "EXHAUSTED", "PENETRATED", "CHUNK",
           "TIME_RESOLUTION", "beyond_bound", "guard_step",
           "K_CONTACT", "K_CORE", "K_END"]

DONE, PAUSED, STEP_UNDERFLOW, NON_FINITE, EXHAUSTED, PENETRATED = 0, 1, 2, 3, 4, 5
K_CONTACT, K_CORE, K_END = int(ModeKind.CONTACT), int(ModeKind.CORE), int(ModeKind.END)
#: The mode a :data:`K_END` slot switches to: the run ends (an unwinding roll at its core).
END = 9
#: The slot :func:`sample_and_switch` returns where a nip crossed its penetration bound.
GUARD = -2
F_RHS, F_JAC, F_OUT, F_SW = 0, 1, 2, 3
#: Shortest step [s] relative to ``max(1 s, |t|)``; below it the time is not resolved.
TIME_RESOLUTION = 1e-14
#: Evaluations per call of a caller that checks its budgets between calls (20–40 ms).
CHUNK = 200_000

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
def evaluate(fns: np.ndarray, which: int, tb: np.ndarray, t: float, y: np.ndarray,
             p: np.ndarray, m: np.ndarray, out: np.ndarray) -> None:
    """``out = f(t, y, p, m)`` for the generated function ``fns[which]``."""
    tb[0] = t
    call(fns[which], tb.ctypes.data, y.ctypes.data, p.ctypes.data, m.ctypes.data,
         out.ctypes.data)


@njit
def switches(fns: np.ndarray, tb: np.ndarray, t: float, y: np.ndarray, p: np.ndarray,
             m: np.ndarray, g: np.ndarray) -> None:
    """All switching functions at ``(t, y)`` into ``g``."""
    evaluate(fns, F_SW, tb, t, y, p, m, g)


@njit
def modes_of(fns: np.ndarray, table: np.ndarray, tb: np.ndarray, t: float, y: np.ndarray,
             p: np.ndarray, m: np.ndarray, g: np.ndarray, contact_auto: bool) -> None:
    """The modes a step starting at ``y`` runs in: a nip touching where its switching
    function is > 0; a roll at its core where ``r <= r_c`` and it does not turn
    forwards. ``contact_auto``: nips in :data:`AUTO` (the clamped law, for RK4)."""
    switches(fns, tb, t, y, p, m, g)
    for s in range(table.shape[0]):
        if table[s, 0] == K_CONTACT:
            if contact_auto:
                m[s] = AUTO
            else:
                m[s] = IN_CONTACT if g[table[s, 1]] > 0.0 else FREE
        elif table[s, 0] == K_END:
            m[s] = 0.0
        else:
            m[s] = AT_CORE if g[table[s, 1]] >= 0.0 and g[table[s, 2]] <= 0.0 else WINDING


@njit
def _dense(rc: np.ndarray, theta: float, out: np.ndarray) -> None:
    th1 = 1.0 - theta
    for i in range(out.shape[0]):
        out[i] = rc[0, i] + theta * (rc[1, i] + th1 * (rc[2, i] + theta
                                                       * (rc[3, i] + th1 * rc[4, i])))


@njit
def _switch_at(fns: np.ndarray, gi: int, tb: np.ndarray, t: float, y: np.ndarray,
               p: np.ndarray, m: np.ndarray, g: np.ndarray) -> float:
    switches(fns, tb, t, y, p, m, g)
    return g[gi]


@njit
def _locate(fns: np.ndarray, gi: int, new_pos: bool, rc: np.ndarray, t: float, hh: float,
            tb: np.ndarray, p: np.ndarray, m: np.ndarray, yt: np.ndarray,
            g: np.ndarray) -> float:
    """First ``θ`` in ``(0, 1]`` of an accepted step (dense output ``rc``) where switching
    function ``gi`` is on its new side (``g > 0`` if ``new_pos``, else ``g <= 0``);
    Illinois method to ~1e-12 s. The step's end is on the new side."""
    _dense(rc, 1.0, yt)
    gb = _switch_at(fns, gi, tb, t + hh, yt, p, m, g)
    _dense(rc, 0.0, yt)
    ga = _switch_at(fns, gi, tb, t, yt, p, m, g)
    if new_pos and ga > 0.0:  # the start belongs to the old side
        ga = -1e-300
    elif not new_pos and ga <= 0.0:
        ga = 1e-300
    ta, tb_ = 0.0, 1.0
    side = 0
    tol = 1e-12 * max(1.0, abs(t)) / hh
    for _ in range(100):
        if tb_ - ta <= tol:
            break
        th = (ta * gb - tb_ * ga) / (gb - ga)
        if not (ta < th < tb_):
            th = 0.5 * (ta + tb_)
        _dense(rc, th, yt)
        gv = _switch_at(fns, gi, tb, t + th * hh, yt, p, m, g)
        if (gv > 0.0) == new_pos:
            tb_, gb = th, gv
            if side == -1:
                ga *= 0.5
            side = -1
        else:
            ta, ga = th, gv
            if side == 1:
                gb *= 0.5
            side = 1
    return tb_


@njit
def _sliver(t: float, t1: float, y: np.ndarray, f: np.ndarray, t_out: np.ndarray,
            Y_out: np.ndarray, k: int) -> int:
    """Finish an interval shorter than the time resolution with one Euler step; samples."""
    for i in range(y.shape[0]):
        y[i] += (t1 - t) * f[i]
    while k < t_out.shape[0] and t_out[k] <= t1 + 1e-13 * max(1.0, abs(t1)):
        for i in range(y.shape[0]):
            Y_out[i, k] = y[i]
        k += 1
    return k


@njit
def _next_event(fns: np.ndarray, table: np.ndarray, rc: np.ndarray, t: float, hh: float,
                tb: np.ndarray, p: np.ndarray, m: np.ndarray, y1: np.ndarray,
                yt: np.ndarray, g: np.ndarray, located: bool) -> tuple[float, int, float]:
    """The first mode switch inside the step to ``y1``: ``(θ, slot, new mode)``, ``θ = 2``
    for none. ``located``: on the dense output ``rc`` (else at ``θ = 1``)."""
    switches(fns, tb, t + hh, y1, p, m, g)
    best, slot, new = 2.0, -1, 0.0
    for s in range(table.shape[0]):
        gi, pos, nm = -1, True, 0.0
        if table[s, 0] == K_CONTACT:
            if m[s] == IN_CONTACT and g[table[s, 1]] <= 0.0:
                gi, pos, nm = table[s, 1], False, FREE
            elif m[s] == FREE and g[table[s, 1]] > 0.0:
                gi, pos, nm = table[s, 1], True, IN_CONTACT
        elif table[s, 0] == K_END:
            if g[table[s, 1]] > 0.0:
                gi, pos, nm = table[s, 1], True, END
        else:
            if m[s] == WINDING and g[table[s, 1]] > 0.0:
                gi, pos, nm = table[s, 1], True, AT_CORE
            elif m[s] == AT_CORE and g[table[s, 2]] > 0.0:
                gi, pos, nm = table[s, 2], True, WINDING
        if gi >= 0:
            th = _locate(fns, gi, pos, rc, t, hh, tb, p, m, yt, g) if located else 1.0
            if th < best:
                best, slot, new = th, s, nm
    return best, slot, new


@njit
def beyond_bound(table: np.ndarray, g: np.ndarray) -> int:
    """The first contact slot whose guard function (``g2`` of its row, ``NIP.overlap``
    [m] in the switching functions ``g`` of one state) is beyond its bound: positive, or
    not a number. -1 for none."""
    for s in range(table.shape[0]):
        if table[s, 0] == K_CONTACT and not g[table[s, 2]] <= 0.0:
            return s
    return -1


@njit
def _beyond_at(fns: np.ndarray, table: np.ndarray, tb: np.ndarray, t: float,
               y: np.ndarray, p: np.ndarray, m: np.ndarray, g: np.ndarray) -> bool:
    """Whether a nip is beyond its penetration bound at ``(t, y)`` (:func:`beyond_bound`)."""
    switches(fns, tb, t, y, p, m, g)
    return beyond_bound(table, g) >= 0


@njit
def _first_beyond(fns: np.ndarray, table: np.ndarray, rc: np.ndarray, t: float, hh: float,
                  th_hi: float, tb: np.ndarray, p: np.ndarray, m: np.ndarray,
                  yt: np.ndarray, g: np.ndarray) -> float:
    """Where the nips beyond their penetration bound at ``θ_hi`` of a step (dense output
    ``rc``, length ``hh``) cross it: the first ``θ`` in ``(0, θ_hi]`` with the guard
    function > 0, by bisection to ~1e-18 of the step (``θ_hi`` for a non-finite one)."""
    best = th_hi
    for s in range(table.shape[0]):
        if table[s, 0] != K_CONTACT:
            continue
        gi = table[s, 2]
        _dense(rc, th_hi, yt)
        if not _switch_at(fns, gi, tb, t + th_hi * hh, yt, p, m, g) > 0.0:
            continue
        ta, tb_ = 0.0, th_hi
        for _ in range(60):
            th = 0.5 * (ta + tb_)
            _dense(rc, th, yt)
            if _switch_at(fns, gi, tb, t + th * hh, yt, p, m, g) > 0.0:
                tb_ = th
            else:
                ta = th
        best = min(best, tb_)
    return best


@njit
def _chord(fns: np.ndarray, table: np.ndarray, t: float, hh: float, y0: np.ndarray,
           y1: np.ndarray, g0: np.ndarray, tb: np.ndarray, p: np.ndarray, m: np.ndarray,
           yt: np.ndarray, g: np.ndarray) -> float:
    """``θ`` where the straight path of a step from ``y0`` to ``y1`` (switching functions
    ``g0``, ``g`` there; ``g`` is also the probes' buffer) first takes a nip beyond its
    penetration bound, 2 for none. Only where the centres come closer on that path than
    ``max(r_a, r_b)`` (from ``NIP.dx``, ``NIP.dz`` at both ends: a step that moves a body
    by about its radius) is the guard evaluated there."""
    best = 2.0
    for s in range(table.shape[0]):
        if table[s, 0] != K_CONTACT:
            continue
        x0, z0 = g0[table[s, 3]], g0[table[s, 4]]
        x1, z1 = g[table[s, 3]], g[table[s, 4]]
        dx, dz = x1 - x0, z1 - z0
        d2 = dx * dx + dz * dz
        bound = g[table[s, 2]] + math.sqrt(x1 * x1 + z1 * z1)  # max(r_a, r_b) at the end
        if not d2 > 0.0:
            continue
        th = min(1.0, max(0.0, -(x0 * dx + z0 * dz) / d2))  # closest approach
        cx, cz = x0 + th * dx, z0 + th * dz
        if not cx * cx + cz * cz < bound * bound:
            continue
        # probe halfway between entering the bound's circle and the closest approach
        # (which may be the other centre itself, where the nip has no normal)
        b2 = x0 * dx + z0 * dz
        disc = b2 * b2 - d2 * (x0 * x0 + z0 * z0 - bound * bound)
        th = 0.5 * (th + max(0.0, (-b2 - math.sqrt(max(disc, 0.0))) / d2))
        for i in range(y0.shape[0]):
            yt[i] = y0[i] + th * (y1[i] - y0[i])
        if _switch_at(fns, table[s, 2], tb, t + th * hh, yt, p, m, g) > 0.0:
            rl = np.zeros((5, y0.shape[0]))  # the straight path as a dense output
            for i in range(y0.shape[0]):
                rl[0, i] = y0[i]
                rl[1, i] = y1[i] - y0[i]
            best = min(best, _first_beyond(fns, table, rl, t, hh, th, tb, p, m, yt, g))
        switches(fns, tb, t + hh, y1, p, m, g)  # the probes overwrote g1
    return best


@njit
def guard_step(fns: np.ndarray, table: np.ndarray, rc: np.ndarray, t: float, hh: float,
               th_end: float, tb: np.ndarray, p: np.ndarray, m: np.ndarray,
               y0: np.ndarray, y1: np.ndarray, yt: np.ndarray, g: np.ndarray,
               g0: np.ndarray, t_out: np.ndarray, k: int, fresh: bool) -> float:
    """The guard of the kept part ``[0, θ_end]`` of an accepted step from ``(t, y0)`` to
    ``(t + hh, y1)`` with the dense output ``rc`` (cut at a mode switch at ``θ_end``; 1
    for none), whose output samples start at ``t_out[k]``: the first ``θ`` where a nip is
    beyond its penetration bound (:func:`beyond_bound`) at the kept part's end, at a
    sample inside it or on its straight path (a step that jumps through the other body:
    located on ``rc`` where a scan of it finds the crossing, else on that path), and
    ``y0`` moved there; ``θ = 2`` for none. ``g0``, ``g``: switching-function buffers
    (``g`` already holds them at ``y1`` where ``fresh``: no mode switch in the step)."""
    n = y0.shape[0]
    ye = y1
    if th_end < 1.0:
        ye = np.empty(n)
        _dense(rc, th_end, ye)
    best, straight = 2.0, False
    switches(fns, tb, t, y0, p, m, g0)
    if not (fresh and th_end >= 1.0):
        switches(fns, tb, t + th_end * hh, ye, p, m, g)
    if beyond_bound(table, g) >= 0:
        best = _first_beyond(fns, table, rc, t, hh, th_end, tb, p, m, yt, g)
        switches(fns, tb, t + th_end * hh, ye, p, m, g)
    th = _chord(fns, table, t, th_end * hh, y0, ye, g0, tb, p, m, yt, g)
    if th * th_end < best:  # where the dense output passes beyond, if it does
        best, straight = th * th_end, True
        for j in range(1, 65):
            tj = th_end * j / 64.0
            _dense(rc, tj, yt)
            if _beyond_at(fns, table, tb, t + tj * hh, yt, p, m, g):
                best = _first_beyond(fns, table, rc, t, hh, tj, tb, p, m, yt, g)
                straight = False
                break
    while k < t_out.shape[0] and t_out[k] <= t + min(best, th_end) * hh:
        th = max(0.0, (t_out[k] - t) / hh)
        _dense(rc, th, yt)
        if _beyond_at(fns, table, tb, t + th * hh, yt, p, m, g):
            th = _first_beyond(fns, table, rc, t, hh, th, tb, p, m, yt, g)
            if th < best:
                best, straight = th, False
            break
        k += 1
    if best <= 1.0:
        if straight:
            for i in range(n):
                y0[i] += best / th_end * (ye[i] - y0[i])
        else:
            _dense(rc, best, y0)
    return best


@njit
def switch_buffer(table: np.ndarray) -> np.ndarray:
    """A buffer for every switching function the mode ``table`` refers to."""
    size = 1
    for s in range(table.shape[0]):
        last = 5 if table[s, 0] == K_CONTACT else 3
        for c in range(1, last):
            size = max(size, int(table[s, c]) + 1)
    return np.empty(size)


@njit
def first_step(y: np.ndarray, f: np.ndarray, rtol: float, atol: float) -> float:
    """Hairer's starting step, first part, from the state ``y`` and its rate ``f``."""
    n = y.shape[0]
    d0 = d1 = 0.0
    for i in range(n):
        sk = atol + rtol * abs(y[i])
        d0 += (y[i] / sk) ** 2
        d1 += (f[i] / sk) ** 2
    d0, d1 = math.sqrt(d0 / n), math.sqrt(d1 / n)
    return 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1


@njit
def sample_and_switch(fns: np.ndarray, table: np.ndarray, rc: np.ndarray, t: float,
                      hh: float, t1: float, tb: np.ndarray, p: np.ndarray, m: np.ndarray,
                      y: np.ndarray, y1: np.ndarray, yt: np.ndarray, g: np.ndarray,
                      g0: np.ndarray, t_out: np.ndarray, Y_out: np.ndarray,
                      k: int) -> tuple[int, float, float, int]:
    """After an accepted step from ``(t, y)`` to ``y1`` with the dense output ``rc``: the
    first mode switch inside it (:func:`_next_event`), the output samples up to it (or to
    the step's end), and, at a switch, ``y`` moved to the crossing, landed exactly on the
    core where a roll reaches it. Where a nip crosses its penetration bound first
    (:func:`beyond_bound`), ``y`` moves to that crossing and the slot is :data:`GUARD`.
    Returns ``(slot or -1, new mode, end time, k)``."""
    n = y.shape[0]
    theta_end, slot, new_mode = _next_event(fns, table, rc, t, hh, tb, p, m, y1, yt, g,
                                            True)
    if theta_end > 1.0:
        theta_end = 1.0
    theta_guard = guard_step(fns, table, rc, t, hh, theta_end, tb, p, m, y, y1, yt, g, g0,
                             t_out, k, slot < 0)  # moves y to the crossing where it finds one
    if theta_guard <= theta_end:
        theta_end, slot = theta_guard, GUARD
    t_end = t + theta_end * hh
    while k < t_out.shape[0] and t_out[k] <= t_end + 1e-13 * max(1.0, abs(t_end)):
        if t_out[k] > t1 + 1e-13 * max(1.0, abs(t1)):
            break
        if slot == GUARD and t_out[k] >= t_end:
            break
        _dense(rc, min(theta_end, max(0.0, (t_out[k] - t) / hh)), yt)
        for i in range(n):
            Y_out[i, k] = yt[i]
        k += 1
    if slot >= 0:
        _dense(rc, theta_end, y)
        if new_mode == END or (table[slot, 0] == K_CORE and new_mode == AT_CORE):
            y[table[slot, 3]] = p[table[slot, 4]]  # land exactly on the core
    return slot, new_mode, t_end, k


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
