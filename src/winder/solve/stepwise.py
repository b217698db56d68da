"""The step-wise paths of :func:`winder.simulate`: scipy's solvers (RK45, DOP853, Radau,
BDF, LSODA, RK23) and a Python RK4, one step at a time, with the contact events and the
core events of spec §2 located on each step's interpolant. Imported only by runs that use
them (scipy's integrators cost a noticeable part of a command's start-up)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.integrate import BDF, DOP853, LSODA, RK23, RK45, DenseOutput, OdeSolver, Radau
from scipy.optimize import brentq

from winder.model.locked_modes import AT_CORE, WINDING
from winder.solve import integrators as integ
from winder.solve.budgets import _STEP_OVER, _WALL_EVERY, _Guards, _Stop
from winder.solve.system import MachineSystem

__all__ = ["run_stepwise"]

_SCIPY = {"RK45": RK45, "DOP853": DOP853, "Radau": Radau, "BDF": BDF, "LSODA": LSODA,
          "RK23": RK23}
_IMPLICIT = ("Radau", "BDF", "LSODA")


class _HermiteDense(DenseOutput):
    """Cubic Hermite interpolant of one RK4 step."""

    def __init__(self, t_old: float, t: float, y0: np.ndarray, f0: np.ndarray,
                 y1: np.ndarray, f1: np.ndarray) -> None:
        super().__init__(t_old, t)
        self.y0, self.f0, self.y1, self.f1 = y0, f0, y1, f1

    def _call_impl(self, t: np.ndarray) -> np.ndarray:
        h = self.t - self.t_old
        s = (np.asarray(t, dtype=float) - self.t_old) / h
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
        return (np.multiply.outer(self.y0, h00) + np.multiply.outer(h * self.f0, h10)
                + np.multiply.outer(self.y1, h01) + np.multiply.outer(h * self.f1, h11))


class _RK4(OdeSolver):
    """Classical fixed-step RK4 as a scipy solver: steps of at most ``max_step`` evenly
    dividing ``[t0, t_bound]``; dense output by cubic Hermite interpolation."""

    def __init__(self, fun: Callable, t0: float, y0: np.ndarray, t_bound: float, *,
                 max_step: float = 1e-3, **_: Any) -> None:
        super().__init__(fun, t0, y0, t_bound, vectorized=False)
        self.n_steps = max(1, math.ceil((t_bound - t0) / max_step - 1e-9))
        self.h = (t_bound - t0) / self.n_steps
        self.t_first, self.i = t0, 0
        self.f = self.fun(self.t, self.y)
        self._last: tuple[np.ndarray, ...] = ()

    def _step_impl(self) -> tuple[bool, str | None]:
        t, y, f0 = self.t, self.y, self.f
        self.i += 1
        t1 = self.t_bound if self.i >= self.n_steps else self.t_first + self.i * self.h
        h = t1 - t
        k2 = self.fun(t + h / 2, y + h / 2 * f0)
        k3 = self.fun(t + h / 2, y + h / 2 * k2)
        k4 = self.fun(t + h, y + h * k3)
        y1 = y + h / 6 * (f0 + 2 * k2 + 2 * k3 + k4)
        f1 = self.fun(t1, y1)
        self._last = (y, f0, y1, f1)
        self.t, self.y, self.f = t1, y1, f1
        return True, None

    def _dense_output_impl(self) -> DenseOutput:
        return _HermiteDense(self.t_old, self.t, *self._last)


#: An event of a segment: switching function ``g(t, y)`` and which side is new
#: (``True``: ``g > 0``; ``False``: ``g <= 0``); the step's end on the new side fires it.
_Event = tuple[Callable[[float, np.ndarray], float], bool]


def _on_new_side(g: float, new_pos: bool) -> bool:
    return g > 0.0 if new_pos else g <= 0.0


def _locate(event: _Event, sol: DenseOutput, ta: float, tb: float,
            y_end: np.ndarray) -> tuple[float, np.ndarray]:
    """Time and state of an event within a step ``[ta, tb]`` whose end is on the new side:
    the root of ``g`` on the step's interpolant (the step's end where the interpolant does
    not change sides)."""
    g, new_pos = event

    def on_sol(t: float) -> float:
        return g(t, sol(t))

    ga, gb = on_sol(ta), on_sol(tb)
    if _on_new_side(ga, new_pos):
        return ta, sol(ta)
    if not _on_new_side(gb, new_pos):
        return tb, y_end
    eps = np.finfo(float).eps
    t_ev = brentq(on_sol, ta, tb, xtol=4 * eps * max(1.0, abs(tb)), rtol=4 * eps)
    return t_ev, sol(t_ev)


class _Beyond(Exception):
    """A nip crossed its penetration bound at ``(t, y)`` within an accepted step."""

    def __init__(self, t: float, y: np.ndarray) -> None:
        super().__init__(t)
        self.t, self.y = t, y


def _guard(system: MachineSystem, bounds: list[tuple[int, int, int]], solver: OdeSolver,
           sol: DenseOutput | None, y_a: np.ndarray, g_a: np.ndarray | None, t_b: float,
           y_b: np.ndarray, t_s: np.ndarray, y_s: np.ndarray) -> np.ndarray | None:
    """The guard of every accepted step (as the compiled integrators',
    :func:`~winder.solve.integrators.guard_step`), on its kept part from its start
    ``y_a`` to ``(t_b, y_b)`` (the step's end or its first event): where a nip's
    ``NIP.overlap`` is beyond its bound at that end, at an output sample inside it (times
    ``t_s``, states the columns of ``y_s``), or on
    the straight path between (closest approach from ``NIP.dx``, ``NIP.dz``), raise
    :class:`_Beyond` at the crossing. ``bounds``: the switching functions ``(overlap, dx,
    dz)`` of each nip; ``g_a``: all of them at the start (None: evaluated here); ``sol``:
    the step's dense output, if made already. Returns them at ``(t_b, y_b)``, the next
    step's ``g_a``."""
    if not bounds:
        return None
    t_a = float(solver.t_old)

    def over(t: float, y: np.ndarray, go: int) -> float:
        return float(system.switches(t, y)[go])

    def beyond(go: int, t_c: float, y_c: np.ndarray) -> _Beyond:
        """At the crossing of ``go`` on the interpolant before ``t_c``, on its far side."""
        t_x, y_x = _locate((lambda t, y: over(t, y, go), True), sol, t_a, t_c, y_c)
        for _ in range(64):
            if over(t_x, y_x, go) > 0.0 or t_x >= t_c:
                break
            t_x = min(t_c, float(np.nextafter(t_x, math.inf)))
            y_x = y_c if t_x == t_c else sol(t_x)
        return _Beyond(t_x, np.array(y_x, dtype=float))

    for t_c, y_c in [*zip(map(float, t_s), y_s.T, strict=True), (t_b, y_b)]:
        g = system.switches(t_c, y_c)
        crossed = [go for go, _, _ in bounds if not g[go] <= 0.0]
        if not crossed:
            continue
        if not all(np.isfinite(g[go]) for go in crossed) or t_c <= t_a:
            raise _Beyond(t_c, np.array(y_c, dtype=float))
        sol = sol or solver.dense_output()
        raise min((beyond(go, t_c, y_c) for go in crossed), key=lambda e: e.t)
    g1 = g  # at (t_b, y_b), the loop's last point
    # as floats: the arithmetic below, once per nip and step, is IEEE either way
    f0 = (system.switches(t_a, y_a) if g_a is None else g_a).tolist()
    f1 = g1.tolist()
    h = t_b - t_a

    def line(theta: float) -> np.ndarray:
        return y_a + theta * (y_b - y_a)

    for go, gx, gz in bounds:  # the straight path: a step that jumps through the body
        x0, z0, x1, z1 = f0[gx], f0[gz], f1[gx], f1[gz]
        dx, dz = x1 - x0, z1 - z0
        d2 = dx * dx + dz * dz
        if not d2 > 0.0:
            continue
        th = min(1.0, max(0.0, -(x0 * dx + z0 * dz) / d2))  # closest approach
        bound = f1[go] + math.hypot(x1, z1)  # max(r_a, r_b)
        if not math.hypot(x0 + th * dx, z0 + th * dz) < bound:
            continue
        b2 = x0 * dx + z0 * dz  # probe between entering that circle and the closest approach
        disc = b2 * b2 - d2 * (x0 * x0 + z0 * z0 - bound * bound)
        th = 0.5 * (th + max(0.0, (-b2 - math.sqrt(max(disc, 0.0))) / d2))
        if not over(t_a + th * h, line(th), go) > 0.0:
            continue
        sol = sol or solver.dense_output()
        for q in np.linspace(0.0, 1.0, 65)[1:]:  # where the interpolant passes beyond
            y_q = sol(t_a + q * h)
            if over(t_a + q * h, y_q, go) > 0.0:
                raise beyond(go, t_a + q * h, y_q)
        th = brentq(lambda q, go=go: over(t_a + q * h, line(q), go), 0.0, th,
                    xtol=4 * np.finfo(float).eps)
        while not over(t_a + th * h, line(th), go) > 0.0:  # on the far side of the root
            th = np.nextafter(th, 2.0)
        raise _Beyond(t_a + th * h, line(th))
    return g1


def _segment(make: Callable[[float, np.ndarray, float], OdeSolver], t0: float,
             y0: np.ndarray, t_stop: float, events: list[_Event], t_out: np.ndarray,
             Ys: np.ndarray, filled: int, guards: _Guards, meth: str,
             system: MachineSystem, bounds: list[tuple[int, int, int]]
             ) -> tuple[float, np.ndarray, int, int]:
    """Integrate from ``t0`` until ``t_stop`` or the first event; samples into ``Ys``.
    Returns ``(t, y, filled, event index or -1)``. A spent budget raises :class:`_Stop`
    carrying the last accepted ``(t, y, step)``; a nip beyond its penetration bound
    (switching functions ``bounds``) raises :class:`_Beyond`."""
    while filled < len(t_out) and t_out[filled] <= t0:
        Ys[:, filled] = y0
        filled += 1
    solver = None
    y_a = np.array(y0, dtype=float)  # the start of the step
    g_a = None  # the switching functions there, once known
    try:
        solver = make(t0, y0, t_stop)
        while True:
            message = solver.step()
            if solver.status == "failed":
                raise guards.error(f"integrator {meth} failed: {message}; try a stiff "
                                   "method (Radau, BDF) or a looser/tighter rtol",
                                   float(solver.t), solver.y)
            guards.steps += 1
            t_a, t_b, y_b = float(solver.t_old), float(solver.t), solver.y
            hit, t_lim, y_lim, sol = -1, t_b, y_b, None
            for i, (g, new_pos) in enumerate(events):
                if _on_new_side(g(t_b, y_b), new_pos):
                    sol = sol or solver.dense_output()
                    t_ev, y_ev = _locate(events[i], sol, t_a, t_b, y_b)
                    if hit < 0 or t_ev < t_lim:
                        hit, t_lim, y_lim = i, t_ev, y_ev
            start = filled
            while filled < len(t_out) and t_out[filled] <= t_lim:
                if t_out[filled] == t_b:
                    Ys[:, filled] = y_b
                else:
                    sol = sol or solver.dense_output()
                    Ys[:, filled] = sol(t_out[filled])
                filled += 1
            g_a = _guard(system, bounds, solver, sol, y_a, g_a, t_lim, y_lim,
                         t_out[start:filled], Ys[:, start:filled])
            y_a = np.array(y_b, dtype=float)
            if hit >= 0:
                return t_lim, np.array(y_lim, dtype=float), filled, hit
            if solver.status == "finished":
                return t_b, np.array(y_b, dtype=float), filled, -1
            guards.tick(t_b)
    except _Stop as stop:
        t, y = (float(solver.t), solver.y) if solver is not None else (t0, y0)
        step = solver.step_size if solver is not None else None
        stop.at = (t, np.array(y, dtype=float), step, filled)  # type: ignore[attr-defined]
        raise


def run_stepwise(system: MachineSystem, meth: str, y0: np.ndarray, t_s: float,
                 t_out: np.ndarray, Ys: np.ndarray, breaks: list[float], rtol: float,
                 atol: float, max_step: float | None, events: bool, jacobian: str,
                 guards: _Guards) -> tuple[int, int]:
    """scipy's solvers and RK4, one step at a time: contact events of every nip (restart
    at lift-off and touch-down, stepping over grazing contacts) and core events of every
    wound roll (spec §2: land on the core, ``ṙ = 0`` locked until the roll turns
    forwards); an unwinding roll reaching its core ends the run there
    (:meth:`MachineSystem.ended`). Returns ``(samples, events)``."""
    rhs, limit = system.rhs, guards.limit

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        n = system.nfev
        if n >= limit:
            raise _Stop("max_rhs")
        if n % _WALL_EVERY == 0 and guards.wall_spent():
            raise _Stop("max_wall")
        return rhs(t, y)

    options: dict[str, Any] = {"rtol": rtol, "atol": atol}
    if max_step is not None:
        options["max_step"] = max_step
    if meth == "RK4":
        cls: Any = _RK4
        options = {"max_step": max_step or 1e-3}
    else:
        cls = _SCIPY[meth]
    if jacobian != "fd" and meth in _IMPLICIT:
        options["jac"] = system.jac

    def make(t0: float, y: np.ndarray, t1: float) -> OdeSolver:
        return cls(fun, t0, y, t1, **options)

    def switch(gi: int) -> Callable[[float, np.ndarray], float]:
        return lambda t, y: float(system.switches(t, y)[gi])

    table = system.table
    cores = [s for s in range(len(table)) if table[s, 0] == integ.K_CORE]
    contacts = [s for s in range(len(table)) if table[s, 0] == integ.K_CONTACT]
    ends = [s for s in range(len(table)) if table[s, 0] == integ.K_END]
    bounds = [(int(table[s, 2]), int(table[s, 3]), int(table[s, 4])) for s in contacts]
    contact_events = events and system.scene.effects.contact and meth != "RK4"
    filled, n_events, t0, y = 0, 0, t_s, np.array(y0, dtype=float)
    g = system.switches(t0, y)
    for s in cores:
        system.modes[s] = AT_CORE if g[table[s, 1]] >= 0.0 and g[table[s, 2]] <= 0.0 \
            else WINDING
    step_over_until = -math.inf
    touching: dict[int, bool] = {}  # contact side per nip slot; empty: read from the state
    for tb in breaks:
        while t0 < tb:
            stepping_over = t0 < step_over_until
            t_stop = min(tb, step_over_until) if stepping_over else tb
            evs: list[_Event] = []
            slots: list[int] = []
            for s in cores:
                gi = table[s, 1] if system.modes[s] == WINDING else table[s, 2]
                evs.append((switch(gi), True))
                slots.append(s)
            for s in ends:  # an unwinding roll running out of web ends the run
                evs.append((switch(table[s, 1]), True))
                slots.append(s)
            if contact_events and not stepping_over:
                if not touching:
                    g = system.switches(t0, y)
                    touching = {s: bool(g[table[s, 1]] > 0.0) for s in contacts}
                for s in contacts:  # the event leaves the current side
                    evs.append((switch(table[s, 1]), not touching[s]))
                    slots.append(s)
            try:
                t1, y, filled, hit = _segment(make, t0, y, t_stop, evs, t_out, Ys, filled,
                                              guards, meth, system, bounds)
            except _Beyond as stop:
                raise system.penetration_error(stop.t, stop.y, method=meth,
                                               max_step=max_step, atol=atol) from None
            if hit >= 0:
                n_events += 1
                s = slots[hit]
                if table[s, 0] == integ.K_END:
                    y[table[s, 3]] = system.params[table[s, 4]]
                    system.ended(t1, y)
                    return filled, n_events
                if table[s, 0] == integ.K_CORE:  # land on the core, or leave it
                    if system.modes[s] == WINDING:
                        y[table[s, 3]] = system.params[table[s, 4]]
                        system.modes[s] = AT_CORE
                    else:
                        system.modes[s] = WINDING
                else:  # contact event: restart exactly there
                    touching[s] = not touching[s]  # lift-off is followed by touch-down
                    if t1 - t0 <= 1e-10 * max(1.0, abs(t0)):
                        # grazing: the crossing is back at the restart point; step over a
                        # short stretch without contact events, then re-arm
                        step_over_until, touching = t0 + _STEP_OVER, {}
            t0 = t1
    return filled, n_events
