"""What the compiled integrators share: the locked modes of a generated machine, their
located switches, the penetration guard, the status codes and the call of the generated
functions. The integrators are :func:`~winder.solve.dopri5.dopri5` (adaptive
Dormand–Prince 5(4), :mod:`winder.solve.dopri5`), :func:`~winder.solve.rk4.rk4`
(classical fixed-step RK4, :mod:`winder.solve.rk4`) and
:func:`~winder.solve.rosenbrock.ros2` (:mod:`winder.solve.rosenbrock`).

The *locked modes*: per nip the contact mode (touching or not) and per wound roll the core
mode of spec §2 stay fixed within a step. When an accepted step ends on the other side of
a switching function, the crossing is located on the step's dense output (Illinois
method, to ~1e-12 s; :func:`sample_and_switch`), the step is cut there and the
integration restarts in the new mode. The discontinuity of a damped normal force at
touch-down and the kink at lift-off never fall inside a step. A roll unwinding to its
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

Every integrator integrates ``y`` in place, writes samples at output times into a
caller's array and keeps counters in ``stats = [nfev, accepted, rejected, events, stiff
steps]``. Status codes: :data:`DONE`, :data:`PAUSED` (the evaluation budget of this call
is spent; call again to resume), :data:`STEP_UNDERFLOW`, :data:`NON_FINITE`,
:data:`EXHAUSTED`, :data:`PENETRATED`.

The guard of every accepted step (:func:`guard_step`: DOPRI5 and ROS2 in
:func:`sample_and_switch`, RK4 after its non-finite check): where a nip's guard function
``NIP.overlap = δ − min(r_a, r_b)`` (the contact row's ``g2``) is positive or not a number
at the step's end or at an output sample inside it, or where the straight path of the
step (from its start to its end) takes it there (a step that jumps through the other
body), the first crossing of the bound is located, ``y`` moves there and the integration
stops with :data:`PENETRATED`: one body's axis inside the other means the integrator lost
the contact (a step or tolerance far too coarse for the nip), and every later number
would be wrong."""

from __future__ import annotations

import math

import numpy as np

from winder.model.ccall import call
from winder.model.locked_modes import AT_CORE, AUTO, FREE, IN_CONTACT, WINDING, ModeKind
from winder.solve._jit import njit

__all__ = ["modes_of", "evaluate", "switches", "switch_buffer", "first_step",
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
