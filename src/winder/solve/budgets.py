"""A run's budgets and the pieces of the driver loop that :func:`winder.simulate` (its
compiled and step-wise paths) and the :class:`~winder.Stepper` share: the tolerance and
budget checks, the budget error that says why a run is slow, the guards that count
evaluations and wall time, and the driver's constants."""

from __future__ import annotations

import math
import time
from typing import Any, Protocol

import numpy as np

from winder._args import (
    ATOL_MAX,
    COMPILED_MAX_RHS,
    RTOL_MAX,
    STEPWISE_MAX_RHS,
    STEPWISE_STATES,
    real_argument,
)
from winder._errors import BudgetExceeded, SimulationError, state_text
from winder.io.result import Result

__all__ = ["check_tolerances", "check_budgets", "budget_error", "default_max_rhs",
           "COMPILED_MAX_RHS", "STEPWISE_MAX_RHS", "STEPWISE_STATES", "RAISE_SIMULATE"]

_WALL_EVERY = 256  # evaluations between wall-clock checks on the Python paths
_STEP_OVER = 1e-6  # [s] integrated without contact events after a grazing contact



# ---- arguments ----------------------------------------------------------------------

def check_tolerances(rtol: Any, atol: Any) -> tuple[float, float]:
    """Validated ``(rtol, atol)``: rtol finite in ``(0, RTOL_MAX]``, atol finite in
    ``(0, ATOL_MAX]``."""
    r = real_argument("rtol", rtol, lambda v: math.isfinite(v) and 0.0 < v <= RTOL_MAX,
                      f"finite, > 0 and <= {RTOL_MAX:g} (a relative tolerance, e.g. 1e-6)")
    a = real_argument("atol", atol, lambda v: math.isfinite(v) and 0.0 < v <= ATOL_MAX,
                      f"finite, > 0 and <= {ATOL_MAX:g} (an absolute tolerance in state units "
                      "[m, rad, N], e.g. 1e-8)")
    return r, a


def check_budgets(max_rhs: Any, max_wall: Any) -> tuple[int | None, float]:
    """Validated ``(max_rhs, max_wall)``: a whole number of evaluations ``>= 1`` (None: the
    path's default, :func:`default_max_rhs`) and a wall time ``> 0`` [s] (``inf`` for
    none)."""
    w = real_argument("max_wall", max_wall, lambda v: v > 0.0,
                   "> 0 (wall-clock seconds; inf for no limit)")
    if max_rhs is None:
        return None, w
    n = real_argument("max_rhs", max_rhs, lambda v: math.isfinite(v) and v >= 1 and v == int(v),
                   "a whole number >= 1 (right-hand side evaluations)")
    return int(n), w


def default_max_rhs(*, stepwise: bool, backend: str, n_states: int) -> int:
    """The evaluation budget of a run given none (``max_rhs`` and ``[solver] max_rhs``
    unset): :data:`COMPILED_MAX_RHS` on the compiled methods; on a step-wise path (scipy's
    methods, or the numeric backend) :data:`STEPWISE_MAX_RHS` of its ``backend``, times
    ``STEPWISE_STATES / n_states`` for a machine of more states."""
    if not stepwise:
        return COMPILED_MAX_RHS
    scale = min(1.0, STEPWISE_STATES / max(1, n_states))
    return max(1000, int(STEPWISE_MAX_RHS[backend] * scale))


class _Bar(Protocol):
    """A progress bar (:class:`winder.io.progress.Progress`)."""

    def update(self, t: float) -> None: ...

    def close(self) -> None: ...


# ---- progress and budgets -------------------------------------------------------------

#: How to raise each budget, from :func:`~winder.simulate` (``how`` of :func:`budget_error`).
RAISE_SIMULATE = {"max_rhs": "simulate(max_rhs=...), [solver] max_rhs, or --max-evals on the "
                             "command line",
                  "max_wall": "simulate(max_wall=...), [solver] max_wall, or --max-wall on "
                              "the command line"}


def budget_error(kind: str, limit: float, *, meth: str, t: float, t_start: float,
                 t_end: float, step: float | None, steps: int, stiff_steps: int | None,
                 nfev: int, wall: float, state: dict[str, float],
                 partial: Result | None = None, how: dict[str, str] = RAISE_SIMULATE,
                 alternatives: str = "method='Radau' or 'LSODA'",
                 faster: str | None = None) -> BudgetExceeded:
    """The :class:`~winder.BudgetExceeded` of a run that reached its budget ``kind``
    (``max_rhs`` or ``max_wall``) at ``t`` [s], naming the time, the last step [s] and the
    state, and saying which of three it is (``faster``: a last sentence naming a faster
    path, for the step-wise paths):

    - the step size collapsed (last step below 1e-3 of the mean step so far, or no
      progress): stiff or discontinuous here;
    - stiff: over a quarter of the accepted steps (``stiff_steps`` of ``steps``) at the
      stability limit (DOPRI5's stiffness test), with the projection below;
    - merely long: steady steps; the evaluations and wall time to reach ``t_end`` at the
      current rate.
    """
    name = "evaluation" if kind == "max_rhs" else "wall-clock"
    value = f"{int(limit)} evaluations" if kind == "max_rhs" else f"{limit:g} s"
    raise_it = f"raise {kind} ({how[kind]})"
    span, done = t_end - t_start, t - t_start
    where = state_text(state)
    h = f"{step:.3g} s" if step is not None else "none yet"
    msg = (f"{name} budget {kind} = {value} reached at t = {t:.6g} s of t_end = {t_end:g} s "
           f"with method {meth!r} after {nfev} evaluations and {wall:.3g} s (last step {h}; "
           f"state: {where}). ")
    mean_step = done / steps if steps else 0.0
    projection = ""
    if done > 0.0:
        projection = (f"at the current rate it needs about {nfev * span / done:.3g} "
                      f"evaluations and {wall * span / done:.3g} s in all to reach t_end")
    if done <= 0.0 or step is None or step < 1e-3 * mean_step:
        msg += (f"The step size collapsed (last step {h}, mean step {mean_step:.3g} s): the "
                f"problem is stiff or discontinuous near t = {t:.6g} s for this method; try "
                f"{alternatives}, a looser rtol, or check the scene there; or {raise_it}.")
    elif stiff_steps is not None and steps and stiff_steps > 0.25 * steps:
        msg += (f"The problem is stiff for {meth!r}: {100 * stiff_steps / steps:.0f} % of "
                f"its steps (mean {mean_step:.3g} s) are limited by stability, not accuracy; "
                f"{projection}. Try {alternatives}, or {raise_it}.")
    else:
        msg += (f"The run is long, not stiff (steady steps, mean {mean_step:.3g} s): "
                f"{projection}; {raise_it}.")
    if faster is not None:
        msg += f" {faster}"
    if partial is not None:
        msg += f" The samples up to t = {partial.t[-1]:.6g} s are in .partial."
    return BudgetExceeded(msg, time=t, state=state, step=step, partial=partial)


class _Stop(Exception):
    """Raised inside the right-hand side when a budget is spent (Python paths)."""

    def __init__(self, kind: str) -> None:
        super().__init__(kind)
        self.kind = kind


class _Guards:
    """The run's budgets (evaluations ``max_rhs``, wall clock ``max_wall``) and progress,
    shared by the scipy and the compiled paths."""

    def __init__(self, names: tuple[str, ...], meth: str, *, limit: int, max_wall: float,
                 bar: _Bar | None, t_start: float, t_end: float) -> None:
        self.names, self.meth = names, meth
        self.limit, self.max_wall, self.bar = limit, max_wall, bar
        self.t_start, self.t_end = t_start, t_end
        self.wall0 = time.perf_counter()
        self.steps = 0
        self.stiff_steps: int | None = None  # known for the compiled DOPRI5
        self.alternatives = "method='Radau' or 'LSODA'"  # for a stiff run, in its message
        self.faster: str | None = None  # a faster path, in the budget's message

    def state(self, y: np.ndarray) -> dict[str, float]:
        return dict(zip(self.names, map(float, y), strict=True))

    def error(self, msg: str, t: float, y: np.ndarray) -> SimulationError:
        state = self.state(y)
        return SimulationError(f"{msg} at t = {t:.6g} s (state: {state_text(state)})", time=t,
                               state=state)

    def wall_spent(self) -> bool:
        return time.perf_counter() - self.wall0 > self.max_wall

    def tick(self, t: float) -> None:
        """Progress and the wall clock (call after each step or chunk)."""
        if self.bar is not None:
            self.bar.update(t)
        if self.wall_spent():
            raise _Stop("max_wall")

    def exceeded(self, kind: str, t: float, y: np.ndarray, step: float | None, nfev: int,
                 partial: Result | None) -> BudgetExceeded:
        limit = self.limit if kind == "max_rhs" else self.max_wall
        return budget_error(kind, limit, meth=self.meth, t=t, t_start=self.t_start,
                            t_end=self.t_end, step=step, steps=self.steps,
                            stiff_steps=self.stiff_steps, nfev=nfev,
                            wall=time.perf_counter() - self.wall0, state=self.state(y),
                            partial=partial, alternatives=self.alternatives,
                            faster=self.faster)
