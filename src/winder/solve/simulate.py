"""Time integration of a scene: arguments, breakpoints, contact and core events, budgets,
progress."""

from __future__ import annotations

import functools
import math
import os
import time
import warnings
from types import MappingProxyType
from typing import Any

import numpy as np

from winder._args import real_argument
from winder._errors import ArgumentError, ArgumentTypeError, SimulationError
from winder.io.result import Result
from winder.model.locked_modes import CORE_AUTO
from winder.scene import naming_of
from winder.scene.load import Scene, load_scene
from winder.scene.schema import BACKENDS, MAX_SAMPLES, METHODS
from winder.solve import integrators as integ
from winder.solve.budgets import (
    _Guards,
    _Stop,
    budget_error,
    check_budgets,
    check_tolerances,
    default_max_rhs,
)
from winder.solve.cint import ROSENBROCK
from winder.solve.system import MachineSystem

__all__ = ["simulate", "DEFAULT_METHOD", "resolve_method", "COMPILED_METHODS", "MAX_SAMPLES",
           "check_tolerances", "check_budgets", "budget_error"]

#: What ``method="auto"`` picks (chosen from the work–precision study, docs/), per backend.
DEFAULT_METHOD = MappingProxyType({"compiled": "DOPRI5", "pinocchio": "LSODA"})
#: Methods that run entirely compiled (generated code only); DOP853C is DOP853 in C
#: (``solve/c/dop853.c``; "DOP853" is scipy's, step by step from Python); ROS2 is the
#: Rosenbrock method of ``solve/c/ros2.c`` (stiff machines, exact Jacobian).
COMPILED_METHODS = ("DOPRI5", "DOP853C", "ROS2", "RODAS3", "RODAS4", "ROS34PW2")
#: Largest output grid :func:`simulate` allocates (about 2 GB of channels at the limit).
#: Jacobians for scipy's implicit methods: ``exact`` (generated; ``pinocchio`` is its old
#: name) or ``fd`` (the integrator's finite differences).
JACOBIANS = ("exact", "fd", "pinocchio")


# ---- arguments ----------------------------------------------------------------------

def _check_choice(name: str, value: Any, valid: tuple[str, ...]) -> str:
    if not isinstance(value, str):
        raise ArgumentTypeError(f"{name} must be a string, one of {', '.join(valid)}; got "
                                f"{value!r} of type {type(value).__name__}")
    if value not in valid:
        raise ArgumentError(f"{name} = {value!r} is unknown; valid: {', '.join(valid)}")
    return value


def _check_bool(name: str, value: Any) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise ArgumentTypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def _as_scene(scene: Any, where: str = "") -> Scene:
    """``scene``, or the scene file at that path; ``where`` (a function's name) prefixes
    the error."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, str | os.PathLike):
        return load_scene(scene)
    raise ArgumentTypeError(f"{where + ': ' if where else ''}scene must be a winder.Scene or "
                            f"the path of a scene file (str or pathlib.Path), got "
                            f"{type(scene).__name__}: {scene!r:.80}")


def resolve_backend(backend: str | None, scene: Scene) -> str:
    """The backend to run: ``backend`` or ``[solver] backend``."""
    return _check_choice("backend", scene.solver.backend if backend is None else backend,
                         BACKENDS)


def resolve_method(method: str | None, scene: Scene, backend: str | None = None) -> str:
    """The method to run (``auto`` resolved per backend, :data:`DEFAULT_METHOD`)."""
    m = _check_choice("method", scene.solver.method if method is None else method, METHODS)
    b = resolve_backend(backend, scene)
    if m == "auto":
        return DEFAULT_METHOD[b]
    if m in COMPILED_METHODS and b != "compiled":
        raise ArgumentError(f"method = {m!r} needs backend 'compiled', got {b!r}; valid "
                            f"methods for backend {b!r}: "
                            + ", ".join(x for x in METHODS if x not in COMPILED_METHODS))
    return m


def _output_grid(t_s: float, T: float, dt: float, t_key: str, dt_key: str) -> np.ndarray:
    """Output times from ``t_s`` to ``T`` every ``dt`` (``T`` included); refuses more than
    :data:`MAX_SAMPLES` before allocating."""
    count = (T - t_s) / dt + 1.0
    if not count <= MAX_SAMPLES:
        raise ArgumentError(f"{t_key} = {T:g} s with {dt_key} = {dt:g} s asks for {count:.3g} "
                            f"output samples; the limit is {MAX_SAMPLES:,} samples: raise "
                            f"{dt_key} or shorten {t_key}")
    n_out = int(math.floor((T - t_s) / dt + 1e-9)) + 1
    t_out = np.minimum(t_s + np.arange(n_out) * dt, T)
    if t_out[-1] < T - 1e-12 * T:
        t_out = np.append(t_out, T)
    return t_out


# ---- the compiled paths ----------------------------------------------------------------

def _run_compiled(meth: str, system: MachineSystem, y: np.ndarray, t_out: np.ndarray,
                  Ys: np.ndarray, breaks: list[float], rtol: float, atol: float,
                  max_step: float | None, guards: _Guards, stats: np.ndarray,
                  at: list[Any]) -> int:
    """Integrate ``y`` in place with a compiled method in chunks of
    :data:`~winder.solve.integrators.CHUNK` evaluations (progress and budgets between chunks).
    Returns the samples written; ``at`` holds ``[t, step, samples]`` of the last chunk
    (for a budget error). Where an unwinding roll runs out of web the run ends there
    (:meth:`MachineSystem.ended`)."""
    t, h, k = float(t_out[0]), 0.0, 0
    hmax = math.inf if max_step is None else float(max_step)
    fns, table, p, modes = system.fns, system.table, system.params, system.modes.copy()
    lib = system.kernels  # the C integrators of the machine's library
    dopri5, rk4, ros2 = lib.dopri5, lib.rk4, lib.ros2
    runs = {"DOPRI5": dopri5, "DOP853C": lib.dop853, "ROS2": ros2, **{
        name: functools.partial(lib.rodas, order=order, reuse=reuse)
        for name, (order, reuse) in ROSENBROCK.items()}}
    for tb in breaks:
        while t < tb:
            budget = min(integ.CHUNK, guards.limit - int(stats[0]))
            if budget <= 0:
                raise _Stop("max_rhs")
            if meth in COMPILED_METHODS:
                run = runs[meth]
                status, t, h, k = run(fns, table, t, tb, y, p, modes, rtol, atol, h, hmax,
                                      t_out, Ys, k, budget, stats)
            else:  # RK4: chunks of budget/4 steps
                step = max_step or 1e-3
                t_next = min(tb, t + step * budget / 4)
                if tb - t_next < 1e-9 * step:
                    t_next = tb
                status, t, h, k = rk4(fns, table, t, t_next, y, p, modes, step, t_out,
                                            Ys, k, stats)
            at[:] = [t, h, k]
            guards.steps = int(stats[1])
            if meth in ("DOPRI5", "DOP853C"):
                guards.stiff_steps = int(stats[4])
            if status == integ.NON_FINITE or not np.all(np.isfinite(y)):
                raise guards.error(f"the state went non-finite with method {meth!r}; try a "
                                   "stiff method (method='Radau', 'BDF' or 'LSODA') or a "
                                   "tighter rtol", t, y)
            if status == integ.STEP_UNDERFLOW:
                raise guards.error(f"step size underflow with method {meth!r} (the problem "
                                   "is too stiff or discontinuous for it): try "
                                   "method='Radau' or 'LSODA'", t, y)
            if status == integ.PENETRATED:
                raise system.penetration_error(t, y, method=meth, max_step=max_step,
                                               atol=atol)
            if status == integ.EXHAUSTED:
                system.ended(t, y)
                return k
            guards.tick(t)
    return k


def _compiled_instead(meth: str, system: MachineSystem) -> tuple[str, str]:
    """For a run on a step-wise path: the stiff alternative and the sentence naming the
    compiled methods, for its budget error."""
    on = "" if system.generated is not None else " on backend='compiled' (--backend compiled)"
    where = ("step by step from Python" if system.generated is not None else
             "on the numeric Pinocchio backend, step by step from Python")
    return (f"method='ROS2'{on} (compiled, for stiff machines)",
            f"{meth} runs {where}, at 30 to 100 times the cost per evaluation of the "
            f"compiled methods: method='DOPRI5' (--method DOPRI5){on}, or method='ROS2' "
            "(--method ROS2) for a stiff machine, runs the scene compiled.")


# ---- simulate -----------------------------------------------------------------------

def simulate(scene: Scene | str | os.PathLike, *, t_end: float | None = None,
             method: str | None = None, rtol: float | None = None,
             atol: float | None = None, progress: bool = False,
             output_step: float | None = None, events: bool = True,
             max_step: float | None = None, max_rhs: int | None = None,
             max_wall: float | None = None, backend: str | None = None,
             t_start: float = 0.0, initial_state: np.ndarray | None = None,
             jacobian: str = "exact") -> Result:
    """Simulate a scene and return its result channels.

    Every argument is checked before any work: a bad one raises
    :class:`~winder.ArgumentError` (or :class:`~winder.ArgumentTypeError`) naming it, the
    value and the valid range.

    Parameters
    ----------
    scene: from :func:`winder.load_scene`, or the path of a scene file.
    t_end: end time [s], finite and > 0 (default: ``[scene] duration``).
    method: one of ``auto`` (compiled: DOPRI5 or RODAS4 by a short probe,
        :func:`winder.solve.auto.choose_method`, its numbers in ``meta["auto"]``; else
        :data:`DEFAULT_METHOD`), DOPRI5 (compiled Dormand–Prince with contact events),
        DOP853C (compiled DOP853, order 8: fewer evaluations at tight tolerances), RK4
        (fixed step ``max_step``, default 1 ms), ROS2 (compiled Rosenbrock on the exact
        Jacobian), RODAS4, RODAS3, ROS34PW2 (compiled Rosenbrock methods on the exact
        Jacobian factored on its sparsity, for machines with fast damped modes), or
        scipy's RK45, DOP853, Radau, BDF, LSODA, RK23; default ``[solver] method``.
    rtol, atol: tolerances, rtol finite in (0, 0.1], atol finite in (0, 1e-3] [state
        units] (default ``[solver]``).
    progress: print a progress bar on stderr.
    output_step: sampling of the result [s], finite > 0 (default ``[scene] output_step``);
        at most :data:`MAX_SAMPLES` samples.
    events: locate contact lift-off and touch-down and restart the integrator there. (The
        core events of spec §2, the roll unwinding to its core and turning forwards
        again, are located on every path.)
    max_step: largest step [s], finite > 0 (the step of RK4).
    max_rhs, max_wall: budgets: right-hand side evaluations (default ``[solver] max_rhs``,
        else the path's: 50 million on the compiled methods, 500 000 on scipy's methods,
        50 000 on the numeric backend, fewer for machines over 50 states:
        :func:`~winder.solve.budgets.default_max_rhs`) and wall-clock seconds (default
        ``[solver] max_wall``); reaching one raises :class:`~winder.BudgetExceeded` with
        the samples so far in ``.partial``.
    backend: ``compiled`` (the machine's generated C, default) or ``pinocchio``
        (``pin.aba`` on numbers with the same force elements); default ``[solver] backend``.
    t_start, initial_state: start the run at ``t_start`` [s] from a full state vector
        (order of ``MachineSystem.state_names``) instead of the static initial state.
    jacobian: for Radau, BDF and LSODA: ``exact`` (the generated Jacobian, default) or
        ``fd`` (the integrator's finite differences).

    Raises
    ------
    ArgumentError, ArgumentTypeError: a bad argument (nothing was run).
    BudgetExceeded: the run reached ``max_rhs`` or ``max_wall``.
    SimulationError: the integrator failed or a state went non-finite.
    """
    scene = _as_scene(scene)
    be = resolve_backend(backend, scene)
    meth = resolve_method(method, scene, be)
    _check_choice("jacobian", jacobian, JACOBIANS)
    progress, events = _check_bool("progress", progress), _check_bool("events", events)
    rtol, atol = check_tolerances(scene.solver.rtol if rtol is None else rtol,
                                  scene.solver.atol if atol is None else atol)
    given_rhs, wall_limit = check_budgets(
        scene.solver.max_rhs if max_rhs is None else max_rhs,
        scene.solver.max_wall if max_wall is None else max_wall)
    positive = "finite and > 0 [s]"
    t_key = "[scene] duration" if t_end is None else "t_end"
    T = real_argument(t_key, scene.scene.duration if t_end is None else t_end,
                      lambda v: math.isfinite(v) and v > 0.0, positive)
    dt_key = "[scene] output_step" if output_step is None else "output_step"
    dt = real_argument(dt_key, scene.scene.output_step if output_step is None else output_step,
                       lambda v: math.isfinite(v) and v > 0.0, positive)
    if max_step is not None:
        max_step = real_argument("max_step", max_step, lambda v: math.isfinite(v) and v > 0.0,
                                 positive)
    t_s = real_argument("t_start", t_start, lambda v: math.isfinite(v) and 0.0 <= v < T,
                        f"finite, >= 0 and < {t_key} = {T:g} [s]")
    t_out = _output_grid(t_s, T, dt, t_key, dt_key)
    system = MachineSystem(scene, backend=be)
    if initial_state is None:
        y0 = system.initial_state()
    else:
        try:
            y0 = np.array(initial_state, dtype=float)
        except (TypeError, ValueError):
            raise ArgumentTypeError(f"initial_state must be {system.n_states} numbers, got "
                                    f"{initial_state!r:.200}") from None
        if y0.shape != (system.n_states,) or not np.all(np.isfinite(y0)) \
                or any(y0[i] < rc for i, rc in system.radii) \
                or any(y0[i] > hi for i, hi in system.ceilings):
            given = ", ".join(f"{v:.9g}" for v in y0.ravel()[:20])
            cores = ", ".join([*(f"{system.state_names[i]} >= {rc:g} m"
                                 for i, rc in system.radii),
                               *(f"{system.state_names[i]} <= {hi:g} m"
                                 for i, hi in system.ceilings)])
            raise ArgumentError(f"initial_state = [{given}] is not valid: valid are "
                                f"{system.n_states} finite values "
                                f"({', '.join(system.state_names)}) with radii at or above "
                                f"their cores ({cores})")
    bar = None
    if progress:  # tqdm only where a bar is drawn (FMU hosts never import it)
        from winder.io.progress import Progress

        bar = Progress(T, scene.name)
    choice = None
    if system.generated is not None and \
            (scene.solver.method if method is None else method) == "auto":
        from winder.solve.auto import choose_method  # the probe: compiled runs only

        choice = choose_method(system, rtol, atol, t_s, y0, T)
        meth = choice.method
    compiled_run = system.generated is not None and meth in (*COMPILED_METHODS, "RK4")
    limit = given_rhs if given_rhs is not None else default_max_rhs(
        stepwise=not compiled_run, backend=system.backend, n_states=system.n_states)
    guards = _Guards(system.state_names, meth, limit=limit, max_wall=wall_limit, bar=bar,
                     t_start=t_s, t_end=T)
    if not compiled_run:  # what to change names the compiled methods
        guards.alternatives, guards.faster = _compiled_instead(meth, system)
    breaks = sorted({b for b in system.breakpoints if t_s < b < T} | {T})
    Ys = np.empty((len(y0), len(t_out)))
    stats = np.zeros(8, dtype=np.int64)
    at: list[Any] = [t_s, None, 0]
    try:
        try:
            if compiled_run:
                y = np.array(y0)
                filled = _run_compiled(meth, system, y, t_out, Ys, breaks, rtol, atol,
                                       max_step, guards, stats, at)
                system.nfev, n_events = int(stats[0]), int(stats[3])
            else:  # scipy's integrators only for the runs that use them
                from winder.solve.stepwise import run_stepwise

                filled, n_events = run_stepwise(system, meth, y0, t_s, t_out, Ys, breaks,
                                                rtol, atol, max_step, events, jacobian, guards)
        except _Stop as stop:
            system.set_core_mode(CORE_AUTO)  # channels: the core mode by the state
            if compiled_run:
                system.nfev = int(stats[0])
                t_at, h_at, filled = at
                y_at = y
            else:
                t_at, y_at, h_at, filled = stop.at  # type: ignore[attr-defined]
            partial = None
            if filled:
                system.clamp_radii(Ys[:, :filled])
                wall = time.perf_counter() - guards.wall0
                partial = Result(system.channels(t_out[:filled], Ys[:, :filled]),
                                 _meta(scene, system, meth, rtol, atol, wall, 0, t_s, T,
                                       partial=True), units=system.channel_units)
            if bar is not None:
                bar.update(t_at)
            raise guards.exceeded(stop.kind, t_at, y_at, h_at, system.nfev,
                                  partial) from None
        if bar is not None:
            bar.update(T)
    finally:
        if bar is not None:
            bar.close()
    if system.end is not None:  # an unwinding roll ran out of web: the result ends there
        t_end_at, y_end = system.end[0], system.end[1]
        t_out, Ys = t_out[:filled], Ys[:, :filled]
        if not filled or t_out[-1] < t_end_at:
            t_out = np.append(t_out, t_end_at)
            Ys = np.concatenate((Ys, y_end[:, None]), axis=1)
        filled = len(t_out)
    if filled != len(t_out):
        raise SimulationError(f"internal error: {filled} of {len(t_out)} output samples")
    wall = time.perf_counter() - guards.wall0
    system.set_core_mode(CORE_AUTO)  # channels: the core mode by the state
    system.clamp_radii(Ys)
    channels = system.channels(t_out, Ys)
    bad = [k for k, v in channels.items() if not np.all(np.isfinite(v))]
    if bad:
        raise SimulationError(f"non-finite values in result channels {bad}")
    meta = _meta(scene, system, meth, rtol, atol, wall, n_events, t_s, T)
    if choice is not None:
        meta["auto"] = {"method": choice.method, "reason": choice.reason,
                        "window": choice.window, "probe": choice.probe}
    slips = web_slips(system, t_out, channels)
    if slips:
        meta["slips"] = slips
    for text in slips:
        warnings.warn(text, WebSlipWarning, stacklevel=2)
    return Result(channels, meta, units=system.channel_units)


class WebSlipWarning(UserWarning):
    """A web would slip on a roller (its traction reached 1, machines.md §11)."""


def web_slips(system: MachineSystem, t: np.ndarray, channels: dict[str, Any]) -> list[str]:
    """One message per roller whose ``NAME_traction`` reaches 1 (the web would slip on it,
    machines.md §11), naming the first output time where it does."""
    out = []
    for b in system.machine.bodies:
        trace = channels.get(f"{b.name}_traction") if b.roles.roller else None
        if trace is None:
            continue
        hits = np.flatnonzero(np.asarray(trace) >= 1.0)
        if hits.size:
            i = int(hits[0])
            out.append(f"{b.table} {b.name!r}: the web would slip on it from t = {t[i]:.6g} s "
                       f"(traction {float(trace[i]):.4g} >= 1: the tension difference "
                       "exceeds the capstan limit (exp(mu wrap) - 1) min(T_up, T_down)); the "
                       "run carries on without slip")
    return out


def _meta(scene: Scene, system: MachineSystem, meth: str, rtol: float, atol: float,
          wall: float, n_events: int, t_s: float, T: float, *,
          partial: bool = False) -> dict[str, Any]:
    """The ``meta`` of a result; ``wall`` [s] is the integration's wall time."""
    eq = system.equilibrium if t_s == 0.0 else None
    return {"scene": scene.name, "source": scene.source, "method": meth,
            "backend": system.backend, "rtol": rtol, "atol": atol,
            "rhs_evaluations": system.nfev, "wall_time": wall, "events": n_events,
            "t_start": t_s, "t_end": T, "effects": list(scene.effects.enabled()),
            **naming_of(scene).result_meta(scene), "scene_dict": scene.to_dict(),
            "static_residual": None if eq is None else eq.residual,
            "ended": system.end[2] if system.end is not None else None,
            "static_scale": None if eq is None else eq.scale,
            "partial": partial}
