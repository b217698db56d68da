"""Time integration of a scene: breakpoints, contact events, guards, progress."""

from __future__ import annotations

import math
import sys
import time
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from . import _integrators as integ
from ._errors import SimulationError
from ._planar import PlanarSystem, pack, switch
from ._result import Result
from ._scene import BACKENDS, METHODS, Scene
from ._system import WinderSystem

__all__ = ["simulate", "DEFAULT_METHOD", "resolve_method", "COMPILED_METHODS"]

#: What ``method="auto"`` picks (chosen from the work–precision study, docs/), per backend.
DEFAULT_METHOD = MappingProxyType({"compiled": "DOPRI5", "pinocchio": "LSODA"})
#: Methods that run entirely compiled (planar backend only).
COMPILED_METHODS = ("DOPRI5",)
_CHUNK = 200_000  # evaluations per compiled call (progress, guards)
_STEP_OVER = 1e-6  # [s] integrated without event location after a grazing contact


def resolve_method(method: str | None, scene: Scene, backend: str | None = None) -> str:
    m = method or scene.solver.method
    if m not in METHODS:
        raise SimulationError(f"unknown method {m!r}; valid: {', '.join(METHODS)}")
    b = resolve_backend(backend, scene)
    if m == "auto":
        return DEFAULT_METHOD[b]
    if m in COMPILED_METHODS and b != "compiled":
        raise SimulationError(f"method {m!r} needs backend 'compiled', got {b!r}; valid "
                              f"methods for backend {b!r}: "
                              + ", ".join(x for x in METHODS if x not in COMPILED_METHODS))
    return m


def resolve_backend(backend: str | None, scene: Scene) -> str:
    b = backend or scene.solver.backend
    if b not in BACKENDS:
        raise SimulationError(f"unknown backend {b!r}; valid: {', '.join(BACKENDS)}")
    return b


class _Progress:
    """Progress on stderr: a one-line bar redrawn at most every 0.2 s on a terminal;
    one line every 5 s when stderr is a log file or pipe (no carriage returns there)."""

    def __init__(self, t_end: float, label: str) -> None:
        self.t_end, self.label = t_end, label
        self.start = self.last = time.perf_counter()
        self.tty = sys.stderr.isatty()

    def update(self, t: float) -> None:
        now = time.perf_counter()
        if now - self.last < (0.2 if self.tty else 5.0):
            return
        self.last = now
        frac = min(max(t / self.t_end, 0.0), 1.0)
        bar = "#" * int(30 * frac)
        line = (f"{self.label} [{bar:<30}] {100 * frac:5.1f}%  t = {t:8.2f} s"
                f"  {now - self.start:6.1f} s wall")
        sys.stderr.write(f"\r{line}" if self.tty else f"{line}\n")
        sys.stderr.flush()

    def close(self) -> None:
        self.last = -1e9
        self.update(self.t_end)
        if self.tty:
            sys.stderr.write("\n")


def _rk4(fun: Any, t0: float, t1: float, y0: np.ndarray, h: float,
         t_eval: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Classical fixed-step RK4 (real-time capable); output at ``t_eval`` by cubic
    Hermite interpolation within a step."""
    n = max(1, math.ceil((t1 - t0) / h - 1e-9))
    h = (t1 - t0) / n
    out = np.empty((len(y0), len(t_eval)))
    k = 0
    y, t = y0.astype(float), t0
    f0 = fun(t, y)
    nfev = 1
    for i in range(n):
        k1 = f0
        k2 = fun(t + h / 2, y + h / 2 * k1)
        k3 = fun(t + h / 2, y + h / 2 * k2)
        k4 = fun(t + h, y + h * k3)
        y1 = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t1_ = t0 + (i + 1) * h
        f1 = fun(t1_, y1)
        nfev += 4
        while k < len(t_eval) and t_eval[k] <= t1_ + 1e-12 * max(1.0, abs(t1_)):
            s = (t_eval[k] - t) / h
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
            out[:, k] = h00 * y + h10 * h * f0 + h01 * y1 + h11 * h * f1
            k += 1
        y, t, f0 = y1, t1_, f1
    return out, y, nfev


class _Guards:
    """The run's guards, shared by the scipy and the compiled paths: evaluation budget,
    wall clock and radius floor (one caliper below the core: the roll unwound); they also
    drive the progress bar. Each failure names the time and the state."""

    def __init__(self, scene: Scene, names: tuple[str, ...], meth: str, *, limit: int,
                 max_wall: float | None, bar: _Progress | None) -> None:
        self.names, self.meth = names, meth
        self.limit, self.max_wall, self.bar = limit, max_wall, bar
        self.core_radius = scene.roll.core_radius
        self.r_floor = scene.roll.core_radius - scene.paper.caliper
        self.wall0 = time.perf_counter()

    def error(self, msg: str, t: float, y: np.ndarray) -> SimulationError:
        state = dict(zip(self.names, map(float, y), strict=True))
        where = ", ".join(f"{n}={v:.6g}" for n, v in state.items())
        return SimulationError(f"{msg} at t = {t:.6g} s (state: {where})", time=t, state=state)

    def over_budget(self, t: float, y: np.ndarray) -> SimulationError:
        return self.error(f"more than {self.limit} right-hand side evaluations (max_rhs "
                          f"guard); the problem is stiffer than method {self.meth!r} can "
                          "handle: try method='Radau' or 'LSODA', a looser rtol or a larger "
                          "max_rhs", t, y)

    def tick(self, t: float, y: np.ndarray) -> None:
        """Progress and the wall-clock guard (call now and then, not every evaluation)."""
        if self.bar is not None:
            self.bar.update(t)
        if self.max_wall is not None and time.perf_counter() - self.wall0 > self.max_wall:
            raise self.error(f"wall-clock guard of {self.max_wall:g} s exceeded", t, y)

    def check_radius(self, t: float, y: np.ndarray) -> None:
        if y[4] < self.r_floor:
            raise self.error(f"radius {y[4]:.6g} m fell more than one caliper below the core "
                             f"radius {self.core_radius:g} m (the roll turned backwards and "
                             "unwound)", t, y)


def _run_compiled(meth: str, p: np.ndarray, y0: np.ndarray, t_out: np.ndarray,
                  Ys: np.ndarray, breaks: list[float], rtol: float, atol: float,
                  max_step: float | None, guards: _Guards) -> tuple[int, tuple[int, int]]:
    """Integrate with a compiled method in chunks of :data:`_CHUNK` evaluations (progress,
    guards between chunks). Returns samples written and ``(nfev, events)``."""
    stats = np.zeros(4, dtype=np.int64)
    y = np.array(y0, dtype=float)
    t, h, k = float(t_out[0]), 0.0, 0
    hmax = math.inf if max_step is None else float(max_step)
    for tb in breaks:
        while t < tb:
            budget = min(_CHUNK, guards.limit - int(stats[0]))
            if budget <= 0:
                raise guards.over_budget(t, y)
            if meth == "DOPRI5":
                status, t, h, k = integ.dopri5(t, tb, y, p, rtol, atol, h, hmax, t_out, Ys,
                                               k, budget, stats)
            else:  # RK4: chunks of budget/4 steps
                step = max_step or 1e-3
                t_next = min(tb, t + step * budget / 4)
                if tb - t_next < 1e-9 * step:
                    t_next = tb
                status, t, _, k = integ.rk4(t, t_next, y, p, step, t_out, Ys, k, stats)
            if status == integ.NON_FINITE or not np.all(np.isfinite(y)):
                raise guards.error(f"the state went non-finite with method {meth!r}; try a "
                                   "stiff method (method='Radau', 'BDF' or 'LSODA') or a "
                                   "tighter rtol", t, y)
            if status == integ.STEP_UNDERFLOW:
                raise guards.error(f"step size underflow with method {meth!r} (the problem "
                                   "is too stiff or discontinuous for it): try "
                                   "method='Radau' or 'LSODA'", t, y)
            guards.check_radius(t, y)
            guards.tick(t, y)
    return k, (int(stats[0]), int(stats[3]))


def simulate(scene: Scene, *, t_end: float | None = None, method: str | None = None,
             rtol: float | None = None, atol: float | None = None, progress: bool = False,
             output_step: float | None = None, events: bool = True,
             max_step: float | None = None, max_rhs: int | None = None,
             max_wall: float | None = None, backend: str | None = None,
             t_start: float = 0.0, initial_state: np.ndarray | None = None,
             jacobian: str = "fd") -> Result:
    """Simulate a scene and return its result channels.

    Parameters
    ----------
    scene: from :func:`winder.load_scene`.
    t_end: end time [s] (default: ``[scene] duration``).
    method: one of ``auto`` (:data:`DEFAULT_METHOD`), DOPRI5 (compiled Dormand–Prince
        with contact events), RK4 (fixed step ``max_step``, default 1 ms), or scipy's
        RK45, DOP853, Radau, BDF, LSODA, RK23; default ``[solver] method``.
    rtol, atol: tolerances (default ``[solver]``).
    progress: print a progress bar on stderr.
    output_step: sampling of the result [s] (default ``[scene] output_step``).
    events: locate contact lift-off and touch-down and restart the integrator there.
    max_step: largest step [s] (the step of RK4).
    max_rhs, max_wall: guards: right-hand side evaluations, wall-clock seconds; exceeding
        one raises :class:`~winder.SimulationError` naming time and state.
    backend: ``compiled`` (planar equations in numba, default) or ``pinocchio`` (ABA
        with the variable-mass terms); default ``[solver] backend``.
    t_start, initial_state: start the run at ``t_start`` [s] from a full state vector
        (order of ``WinderSystem.state_names``) instead of spec §6's initial state.
    jacobian: for Radau, BDF and LSODA: ``fd`` (the integrator's finite differences) or
        ``pinocchio`` (ABA derivatives and the chain rule, :mod:`winder._linearise`).

    Raises
    ------
    SimulationError: the integrator failed, a state went non-finite, or a guard tripped.
    """
    system = WinderSystem(scene)
    be = resolve_backend(backend, scene)
    planar = PlanarSystem(scene, system) if be == "compiled" else None
    T = scene.scene.duration if t_end is None else float(t_end)
    if not (math.isfinite(T) and T > 0):
        raise SimulationError(f"t_end must be finite and > 0, got {t_end!r}")
    meth = resolve_method(method, scene, be)
    rtol = scene.solver.rtol if rtol is None else float(rtol)
    atol = scene.solver.atol if atol is None else float(atol)
    dt = scene.scene.output_step if output_step is None else float(output_step)
    limit = scene.solver.max_rhs if max_rhs is None else int(max_rhs)
    t_s = float(t_start)
    if not (math.isfinite(t_s) and 0.0 <= t_s < T):
        raise SimulationError(f"t_start must be finite, >= 0 and < t_end = {T:g}, got "
                              f"{t_start!r}")
    n_out = int(math.floor((T - t_s) / dt + 1e-9)) + 1
    t_out = np.minimum(t_s + np.arange(n_out) * dt, T)
    if t_out[-1] < T - 1e-12 * T:
        t_out = np.append(t_out, T)
    if initial_state is None:
        y0 = system.initial_state()
    else:
        y0 = np.array(initial_state, dtype=float)
        if y0.shape != (system.n_states,) or not np.all(np.isfinite(y0)):
            raise SimulationError(f"initial_state must be {system.n_states} finite values "
                                  f"({', '.join(system.state_names)}), got {initial_state!r}")
    bar = _Progress(T, scene.name) if progress else None
    guards = _Guards(scene, system.state_names, meth, limit=limit, max_wall=max_wall, bar=bar)
    counter = planar if planar is not None else system
    rhs = counter.rhs

    def fun(t: float, y: np.ndarray) -> np.ndarray:
        if counter.nfev >= limit:
            raise guards.over_budget(t, y)
        if counter.nfev % 2000 == 0:
            guards.tick(t, y)
        guards.check_radius(t, y)
        return rhs(t, y)

    breaks = sorted({b for b in system.drive.breakpoints if t_s < b < T} | {T})
    use_events = events and system.contact is not None and meth != "RK4"
    compiled_run = planar is not None and meth in (*COMPILED_METHODS, "RK4")
    p_switch = planar.params if planar is not None else pack(scene)

    def gap(t: float, y: np.ndarray) -> float:  # min(δ, F_unclamped/k); > 0: F_n > 0
        return switch(t, y, p_switch)

    gap.terminal = True  # type: ignore[attr-defined]
    Ys = np.empty((len(y0), len(t_out)))
    filled = 0
    t0, y = t_s, y0
    n_events = 0
    expect = 0.0
    step_over_until = -math.inf
    events_lost: float | None = None
    options: dict[str, Any] = {"rtol": rtol, "atol": atol}
    if jacobian not in ("fd", "pinocchio"):
        raise SimulationError(f"unknown jacobian {jacobian!r}; valid: fd, pinocchio")
    if jacobian == "pinocchio" and meth in ("Radau", "BDF", "LSODA"):
        from ._linearise import jacobian as _jac

        jac_system = WinderSystem(scene)
        options["jac"] = lambda t, y: _jac(jac_system, t, y)
    if max_step is not None:
        options["max_step"] = max_step
    try:
        for tb in () if compiled_run else breaks:
            while t0 < tb:
                t_stop = tb if t0 >= step_over_until else min(tb, step_over_until)
                mask = (t_out >= t0) & (t_out <= t_stop)
                if filled:  # points already written (the start of a restarted segment)
                    mask[:filled] = False
                t_eval = t_out[mask]
                if meth == "RK4":
                    h = max_step or 1e-3
                    Yseg, y, _ = _rk4(fun, t0, tb, y, h, t_eval)
                    Ys[:, filled:filled + len(t_eval)] = Yseg
                    filled += len(t_eval)
                    t0 = tb
                    continue
                ev = None
                if use_events and t0 >= step_over_until:
                    if expect == 0.0:  # first segment: look for leaving the current side
                        expect = -1.0 if gap(t0, y) > 0.0 else 1.0
                    gap.direction = expect  # type: ignore[attr-defined]
                    ev = [gap]
                extra = not (len(t_eval) and t_eval[-1] == t_stop)
                te = np.append(t_eval, t_stop) if extra else t_eval
                try:
                    sol = solve_ivp(fun, (t0, t_stop), y, method=meth, t_eval=te, events=ev,
                                    **options)
                except ValueError as exc:
                    # scipy's root bracketing fails when a method's interpolant disagrees
                    # with its step ends (seen with LSODA): finish without event location
                    if ev is None or "different signs" not in str(exc):
                        raise
                    use_events, events_lost = False, t0
                    continue
                if sol.status < 0:
                    ys = np.asarray(sol.y, dtype=float).reshape(len(y0), -1)
                    t_bad, y_bad = (float(sol.t[-1]), ys[:, -1]) if ys.shape[1] else (t0, y)
                    raise guards.error(f"integrator {meth} failed: {sol.message}; try a stiff "
                                       "method (Radau, BDF) or a looser/tighter rtol", t_bad,
                                       y_bad)
                cols = np.asarray(sol.y, dtype=float).reshape(len(y0), -1)
                if sol.status == 0 and extra:
                    cols = cols[:, :-1]
                k = cols.shape[1]
                Ys[:, filled:filled + k] = cols
                filled += k
                if sol.status == 1:  # contact event: restart exactly there
                    n_events += 1
                    t_ev, y_ev = float(sol.t_events[0][0]), sol.y_events[0][0]
                    expect = -expect  # lift-off is followed by touch-down and vice versa
                    if t_ev - t0 <= 1e-10 * max(1.0, abs(t0)):
                        # grazing: the crossing is back at the restart point; step over
                        # a short stretch without event location, then re-arm
                        step_over_until, expect = t0 + _STEP_OVER, 0.0
                    t0, y = t_ev, y_ev
                else:
                    t0, y = t_stop, sol.y[:, -1]
        if compiled_run:
            filled, (planar.nfev, n_events) = _run_compiled(meth, planar.params, y, t_out,
                                                            Ys, breaks, rtol, atol, max_step,
                                                            guards)
    finally:
        if bar is not None:
            bar.close()
    if filled != len(t_out):
        raise SimulationError(f"internal error: {filled} of {len(t_out)} output samples")
    wall = time.perf_counter() - guards.wall0
    nfev = counter.nfev
    channels = counter.channels(t_out, Ys)
    bad = [k for k, v in channels.items() if not np.all(np.isfinite(v))]
    if bad:
        raise SimulationError(f"non-finite values in result channels {bad}")
    meta = {"scene": scene.name, "source": scene.source, "method": meth, "backend": be,
            "rtol": rtol, "atol": atol, "rhs_evaluations": nfev, "wall_time": wall,
            "events": n_events, "event_location_stopped_at": events_lost,
            "t_start": t_s, "t_end": T, "effects": list(scene.effects.enabled()),
            "drum_radius": scene.drum.radius, "scene_dict": scene.to_dict()}
    return Result(channels, meta)

