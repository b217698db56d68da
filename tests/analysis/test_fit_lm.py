"""The fit's Levenberg–Marquardt: the Rosenbrock valley's minimum, a linear problem's
closed-form optimum with and without an active bound, and its stopping reasons."""

from __future__ import annotations

import numpy as np

from winder.analysis.fit_lm import levenberg_marquardt

INF = np.array([np.inf, np.inf])


def rosenbrock(x):
    r = np.array([1.0 - x[0], 10.0 * (x[1] - x[0] ** 2)])
    J = np.array([[-1.0, 0.0], [-20.0 * x[0], 10.0]])
    return r, J


def test_rosenbrock_minimum():
    """Unit weights: the standard errors are O(1), so it stops within 1e-6 of them
    (measured 1.1e-7)."""
    sol = levenberg_marquardt(rosenbrock, np.array([-1.2, 1.0]), -INF, INF)
    assert sol.converged and "standard error" in sol.message
    np.testing.assert_allclose(sol.x, [1.0, 1.0], rtol=1e-6)


def test_linear_least_squares_and_an_active_bound():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(30, 2))
    b = A @ np.array([2.0, -1.0]) + 0.1 * rng.normal(size=30)
    free = np.linalg.lstsq(A, b, rcond=None)[0]

    def fun(x):
        return A @ x - b, A

    sol = levenberg_marquardt(fun, np.zeros(2), -INF, INF)
    np.testing.assert_allclose(sol.x, free, rtol=1e-12)
    # x1 held at 0 from below: the optimum of x0 alone, the gradient pushing x1 outwards
    sol = levenberg_marquardt(fun, np.zeros(2), np.array([-np.inf, 0.0]), INF)
    x0 = float(A[:, 0] @ b / (A[:, 0] @ A[:, 0]))
    np.testing.assert_allclose(sol.x, [x0, 0.0], rtol=1e-12, atol=1e-15)
    assert sol.converged


def test_budget_stops_unconverged():
    sol = levenberg_marquardt(rosenbrock, np.array([-1.2, 1.0]), -INF, INF,
                              max_evaluations=3)
    assert not sol.converged and sol.evaluations == 3 and "max_evaluations" in sol.message


def test_a_failing_trial_is_a_rejected_step():
    """The simulation fails beyond x = 2 (the optimum of the cost, 3, lies there): the
    steps into it are rejected and the fit stops at the edge instead of raising."""
    def fun(x):
        if x[0] > 2.0:
            raise RuntimeError("no solution there")
        return np.array([x[0] - 3.0]), np.array([[1.0]])

    sol = levenberg_marquardt(fun, np.array([0.0]), np.array([-np.inf]), np.array([np.inf]),
                              failures=(RuntimeError,))
    assert sol.converged and 1.9 < sol.x[0] <= 2.0
