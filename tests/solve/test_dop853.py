"""DOP853 in C (``solve/c/dop853.c``, method ``DOP853C``): Hairer's explicit method of
order 8 with scipy's tableau, error estimator and 7th-order dense output, under DOPRI5's
contract (events, guard, samples, budget).

Oracles: a linear machine with a closed form (``expm`` of the system augmented by the
forcing's own states), compiled as a machine of its own with the integrators' objects: its
end state, its output samples (the dense output), the observed orders of the step and of
the dense output at fixed steps, and the evaluation count (an identity: 12 a step, 3 more
on a step with a sample); scipy's DOP853 on the same system at the same fixed steps (the
same tableau); the compiled DOPRI5 at a tight tolerance on the shipped machines (the
landing roll's contact events located at DOPRI5's times, the two-drum winder's first
seconds)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from linear_c import build, rhs_source
from linear_c import closed_form as linear_c_closed_form
from scipy.integrate import DOP853

import winder
from winder.solve import integrators as integ
from winder.solve.cint import Kernels
from winder.solve.system import MachineSystem

#: A linear machine x' = A x + b sin(w t): a damped oscillator at 3 rad/s driven at 2
#: rad/s, a state it drives and a slow decay (no stiff mode: the explicit method's case).
N, W = 4, 2.0
A = np.zeros((N, N))
A[0, 1] = 1.0
A[1, 0], A[1, 1] = -9.0, -0.4
A[2, 1], A[2, 2] = 4.0, -2.0
A[3, 0], A[3, 2], A[3, 3] = 0.5, 0.3, -0.1
B = np.array([0.0, 1.0, 0.0, 0.2])
X0 = np.array([1.0, 0.0, 0.5, -0.2])


def _c_source() -> str:
    return ("#include <math.h>\n"
            + rhs_source(A, B, W)
            + "int lin_none(const double* t, const double* x, const double* p, const double* m,"
            " double* out) { out[0] = 0.0; return 0; }\n")


def rhs(t: float, x: np.ndarray) -> np.ndarray:
    return A @ x + B * math.sin(W * t)


@pytest.fixture(scope="module")
def linear(tmp_path_factory) -> tuple[Kernels, np.ndarray]:
    """The linear machine's library, linked with the integrators as a machine's is."""
    return build(tmp_path_factory.mktemp("linear853"), _c_source(),
                 ("lin_rhs", "lin_none", "lin_none", "lin_none"), N)


def closed_form(t: float) -> np.ndarray:
    """x(t) (:func:`linear_c.closed_form`)."""
    return linear_c_closed_form(A, B, W, X0, t)


def _run(k: Kernels, fns: np.ndarray, t1: float, rtol: float, *, h: float = 0.0,
         max_step: float = math.inf, t_out: np.ndarray | None = None,
         method: str = "dop853") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    y = X0.copy()
    stats = np.zeros(8, dtype=np.int64)
    t_out = np.empty(0) if t_out is None else t_out
    Y = np.zeros((N, len(t_out)))
    status, t, _, kk = getattr(k, method)(
        fns, np.zeros((0, 5), dtype=np.int64), 0.0, t1, y, np.zeros(1), np.zeros(0), rtol,
        rtol * 1e-2, h, max_step, t_out, Y, 0, 10**9, stats)
    assert status == integ.DONE and t == t1 and kk == len(t_out)
    return y, Y, stats


# measured max |x - x_exact| at t = 2 s: rtol 1e-8 6.4e-9 (11 / 16 / 24 steps at rtol
# 1e-6 / 1e-8 / 1e-10, DOPRI5 34 / 80 / 199)
def test_linear_system_against_its_closed_form(linear) -> None:
    k, fns = linear
    y, _, stats = _run(k, fns, 2.0, 1e-8)
    assert np.max(np.abs(y - closed_form(2.0))) < 6.4e-8
    _, _, ref = _run(k, fns, 2.0, 1e-8, method="dopri5")
    assert stats[1] < ref[1] / 3  # order 8: a third of DOPRI5's steps, or fewer


# measured at h = 0.2, 0.1, 0.05 s: end state errors 6.4e-9, 2.8e-11, 1.2e-13 (rates 7.83,
# 7.84), the dense output's largest error at mid-step samples 4.0e-8, 1.5e-10, 6.0e-13
# (rates 8.01, 7.99: a 7th-order polynomial, local error O(h^8)); scipy's DOP853 at the
# same steps ends within 5.1e-15 of it
def test_orders_of_the_step_and_of_the_dense_output(linear) -> None:
    k, fns = linear
    exact = closed_form(1.6)
    errs, dense_errs = [], []
    for h in (0.2, 0.1, 0.05):  # fixed steps: no error control (rtol 1e6)
        t_out = np.arange(0.5 * h, 1.6, h)  # mid-step samples
        y, Y, stats = _run(k, fns, 1.6, 1e6, h=h, max_step=h, t_out=t_out)
        steps = round(1.6 / h)
        # identity: 12 evaluations a step, 3 more where a sample needs the dense output
        assert stats[1] == steps and stats[0] == 1 + 12 * steps + 3 * steps
        errs.append(np.max(np.abs(y - exact)))
        dense_errs.append(max(np.max(np.abs(Y[:, j] - closed_form(t)))
                              for j, t in enumerate(t_out)))
        ref = DOP853(rhs, 0.0, X0, 1.6, rtol=1e6, atol=1e6, first_step=h, max_step=h)
        while ref.status == "running":
            ref.step()
        assert np.max(np.abs(ref.y - y)) < 5e-14
    for e in (errs, dense_errs):
        rates = [math.log2(a / b) for a, b in zip(e, e[1:], strict=False)]
        assert all(abs(r - 8.0) < 0.4 for r in rates), (e, rates)
    assert dense_errs[1] < 1.5e-9


def test_no_dense_output_without_samples_or_events(linear) -> None:
    """The 3 extra stages only where the dense output is used: none without samples."""
    k, fns = linear
    _, _, stats = _run(k, fns, 2.0, 1e-8)
    assert stats[0] == 1 + 12 * (stats[1] + stats[2])
    _, _, stats = _run(k, fns, 2.0, 1e-8, t_out=np.array([1.0]))
    assert stats[0] == 1 + 12 * (stats[1] + stats[2]) + 3


def _event_times(system: MachineSystem, y0: np.ndarray, method: str, t1: float
                 ) -> list[float]:
    """The times of the located events: one step per call (budget: 7 DOPRI5, 13 DOP853),
    the time a call returns where the event counter moved."""
    y, m = y0.copy(), system.modes.copy()
    stats = np.zeros(8, dtype=np.int64)
    t, h, times = 0.0, 0.0, []
    run = getattr(system.kernels, method)
    while t < t1:
        before = int(stats[3])
        status, t, h, _ = run(system.fns, system.table, t, t1, y, system.params, m, 1e-9,
                              1e-11, h, math.inf, np.empty(0), np.empty((len(y), 0)), 0,
                              7 if method == "dopri5" else 13, stats)
        assert status in (integ.DONE, integ.PAUSED)
        if int(stats[3]) > before:
            times.append(t)
    return times


def test_contact_events_located_where_dopri5_locates_them(paper_scene) -> None:
    """Released 5 cm above contact, the roll lands, bounces and settles: DOP853 locates
    the touch-downs and lift-offs (on its 7th-order dense output) at DOPRI5's times."""
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": 0.625})
    system = MachineSystem(scene)
    y0 = system.initial_state()
    ref = _event_times(system, y0, "dopri5", 1.0)
    got = _event_times(system, y0, "dop853", 1.0)
    assert len(ref) >= 5 and len(got) == len(ref)
    # measured: 8 events, largest difference 1.4e-9 s (the last lift-off, 0.2098119616 s;
    # DOPRI5 at rtol 1e-12 puts it 1e-10 s from DOPRI5's at 1e-9)
    assert np.max(np.abs(np.array(got) - np.array(ref))) < 1.4e-8


def test_two_drum_winder_against_a_tight_dopri5(models_dir) -> None:
    """The two-drum winder's first 3 s (the speed ramp, the set settling into the valley
    under the rider), DOP853C at rtol 1e-7 against DOPRI5 at rtol 1e-12, and the Stepper
    with DOP853C ending where simulate does."""
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    kw = {"t_end": 3.0, "output_step": 0.01}
    ref = winder.simulate(scene, method="DOPRI5", rtol=1e-12, atol=1e-14, **kw)
    res = winder.simulate(scene, method="DOP853C", rtol=1e-7, atol=1e-9, **kw)
    assert res.meta["method"] == "DOP853C"
    # measured (largest deviation / largest magnitude): set_speed 5.4e-8, set_x 2.2e-7,
    # set_z 3.7e-11, rear_nip_normal_force 4.2e-9, rider_nip_normal_force 9.1e-9,
    # set_radius 1.4e-12
    for ch, tol in (("set_speed", 5.4e-7), ("set_x", 2.2e-6), ("set_z", 3.7e-10),
                    ("rear_nip_normal_force", 4.2e-8), ("rider_nip_normal_force", 9.1e-8),
                    ("set_radius", 1.4e-11)):
        err = float(np.max(np.abs(res[ch] - ref[ch])) / np.max(np.abs(ref[ch])))
        assert err < tol, (ch, err)
    sim = winder.Stepper(scene, method="DOP853C", rtol=1e-7, atol=1e-9)
    for _ in range(6):
        sim.step(0.5)
    assert sim.method == "DOP853C"
    # measured: 1.4e-12 relative (the communication steps restart the integrator)
    assert abs(sim.output("set_speed") / res["set_speed"][-1] - 1.0) < 1.4e-11
