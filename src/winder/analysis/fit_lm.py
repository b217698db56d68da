"""The optimiser of :func:`winder.fit` and :func:`winder.fit_modes`: Levenberg–Marquardt
with bounds (a projected step: components at a bound that the gradient pushes outwards
are held), on residuals and their exact Jacobian from one evaluation.

It stops when the step is small against the parameters' standard errors (``step_tol`` of
each, from ``(JᵀJ)⁻¹`` of the weighted problem: further steps change nothing a measurement
can tell), or small against the parameters themselves (``rel_tol``: noise-free data), or
when no step lowers the cost any more (a step below 1e-2 of every standard error, or the
damping grown past 1e12: the cost is at the floor of the integration's own error), or
after ``max_evaluations``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["LMResult", "levenberg_marquardt"]


@dataclass(frozen=True)
class LMResult:
    """``x`` the optimum, ``r`` and ``J`` there, ``iterations`` (accepted steps),
    ``evaluations``, ``converged`` and why (``message``)."""

    x: np.ndarray
    r: np.ndarray
    J: np.ndarray
    iterations: int
    evaluations: int
    converged: bool
    message: str


def levenberg_marquardt(fun: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
                        x0: np.ndarray, lo: np.ndarray, hi: np.ndarray, *,
                        max_evaluations: int = 100, step_tol: float = 1e-6,
                        rel_tol: float = 1e-10,
                        failures: tuple[type[BaseException], ...] = ()) -> LMResult:
    """Minimise ``½|r(x)|²`` with ``lo <= x <= hi``; ``fun(x) → (r, J)`` (module
    docstring). An exception of a type in ``failures`` at a trial point (the simulation
    failed there, or an event entered the window) rejects the step, as a higher cost
    would; at ``x0`` it is raised."""
    x = np.clip(np.asarray(x0, dtype=float), lo, hi)
    r, J = fun(x)
    evaluations, iterations, lam = 1, 0, 1e-6
    cost = 0.5 * float(r @ r)
    while True:
        g, H = J.T @ r, J.T @ J
        free = ~(((x <= lo) & (g > 0)) | ((x >= hi) & (g < 0)))
        std = np.sqrt(np.abs(np.diag(np.linalg.pinv(H, rcond=1e-14))))
        scale = np.where(np.diag(H) > 0, np.diag(H), 1.0)
        while True:
            step = np.zeros_like(x)
            if np.any(free):
                A = H[np.ix_(free, free)] + lam * np.diag(scale[free])
                step[free] = -np.linalg.lstsq(A, g[free], rcond=None)[0]
            trial = np.clip(x + step, lo, hi)
            step = trial - x
            if np.all(np.abs(step) <= step_tol * std):
                return LMResult(x, r, J, iterations, evaluations, True,
                                f"the step is below {step_tol:g} of every standard error")
            if np.all(np.abs(step) <= rel_tol * np.maximum(np.abs(x), 1e-300)):
                return LMResult(x, r, J, iterations, evaluations, True,
                                f"the step is below {rel_tol:g} of every parameter")
            if evaluations >= max_evaluations:
                return LMResult(x, r, J, iterations, evaluations, False,
                                f"stopped after {evaluations} evaluations (max_evaluations)")
            evaluations += 1
            try:
                r_new, J_new = fun(trial)
                new = 0.5 * float(r_new @ r_new)
            except failures:
                new = np.inf
            if new < cost:
                x, r, J, cost = trial, r_new, J_new, new
                lam = max(lam / 3.0, 1e-12)
                iterations += 1
                break
            lam *= 10.0
            if lam > 1e12 or np.all(np.abs(step) <= 1e-2 * std):
                return LMResult(x, r, J, iterations, evaluations, True,
                                "no step lowers the cost (it is at its floor: the "
                                "integration's own error)")
