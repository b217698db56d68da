"""The Rosenbrock methods of ``solve/c/rosenbrock.c`` (RODAS3, RODAS4, the W-method
ROS34PW2) on the sparse LU of ``sparse_lu.h``.

Oracles: a linear stiff system with a closed form (``expm`` of the system augmented by the
forcing's own states), compiled as a machine of its own with the integrators' objects;
the order of convergence on it at fixed steps; the compiled DOPRI5 at a tight tolerance on
the shipped machines (the flexible two-drum winder's first 0.2 s, the landing roll's
contact events located at the times DOPRI5 locates them)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from linear_c import build, rhs_source
from linear_c import closed_form as linear_c_closed_form

import winder
from winder.solve import integrators as integ
from winder.solve.cint import ROSENBROCK, Kernels
from winder.solve.system import MachineSystem

#: A stiff linear machine x' = A x + b sin(w t): a chain of 6 states (a damped oscillator
#: at 3 rad/s, two fast damped modes -2e3 and -5e5 s^-1 coupled to it, a slow decay), its
#: Jacobian A written densely (column-major) with its structural zeros, and scaled by
#: 1 + p[0] (p[0] != 0: a wrong Jacobian, for the W-method).
N, W = 6, 2.0
A = np.zeros((N, N))
A[0, 1] = 1.0
A[1, 0], A[1, 1] = -9.0, -0.4
A[2, 1], A[2, 2] = 40.0, -2e3
A[3, 2], A[3, 3] = 3e3, -5e5
A[4, 3], A[4, 4] = 2e2, -1.0
A[5, 0], A[5, 4], A[5, 5] = 0.5, 0.3, -0.1
B = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.2])


def _c_source() -> str:
    jac = ", ".join(repr(float(A[r, c])) for c in range(N) for r in range(N))
    return ("#include <math.h>\n#include <string.h>\n"
            + rhs_source(A, B, W)
            + f"static const double JAC[{N * N}] = {{{jac}}};\n"
            "int lin_jac(const double* t, const double* x, const double* p, const double* m,"
            " double* out) {\n"
            f"  for (int k = 0; k < {N * N}; k++) out[k] = JAC[k] * (1.0 + p[0]);\n"
            "  return 0;\n}\n"
            "int lin_none(const double* t, const double* x, const double* p, const double* m,"
            " double* out) { out[0] = 0.0; return 0; }\n")


@pytest.fixture(scope="module")
def linear(tmp_path_factory) -> tuple[Kernels, np.ndarray]:
    """The linear machine's library, linked with the integrators as a machine's is."""
    return build(tmp_path_factory.mktemp("linear"), _c_source(),
                 ("lin_rhs", "lin_jac", "lin_none", "lin_none"), N)


X0 = np.array([1.0, 0.0, 0.5, -0.2, 0.1, 0.3])


def closed_form(t: float) -> np.ndarray:
    """x(t) (:func:`linear_c.closed_form`)."""
    return linear_c_closed_form(A, B, W, X0, t)


def _run(k: Kernels, fns: np.ndarray, method: str, t1: float, rtol: float, *,
         h: float = 0.0, max_step: float = math.inf, reuse: int | None = None,
         jac_error: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    y = X0.copy()
    stats = np.zeros(8, dtype=np.int64)
    order, default_reuse = ROSENBROCK[method]
    status, t, _, _ = k.rodas(fns, np.zeros((0, 5), dtype=np.int64), 0.0, t1, y,
                              np.array([jac_error]), np.zeros(0), rtol, rtol * 1e-2, h, max_step,
                              np.empty(0), np.empty((N, 0)), 0, 10**9, stats, order=order,
                              reuse=default_reuse if reuse is None else reuse)
    assert status == integ.DONE and t == t1
    return y, stats


# measured max |x - x_exact| at t = 2 s, rtol 1e-8: RODAS4 1.5e-8, RODAS3 1.2e-8,
# ROS34PW2 1.5e-8
@pytest.mark.parametrize("method,tol", [("RODAS4", 1.5e-7), ("RODAS3", 1.2e-7),
                                        ("ROS34PW2", 1.5e-7)])
def test_linear_stiff_system_against_its_closed_form(linear, method, tol) -> None:
    k, fns = linear
    y, stats = _run(k, fns, method, 2.0, 1e-8)
    assert np.max(np.abs(y - closed_form(2.0))) < tol
    # L-stable on the -5e5 mode: far fewer steps than an explicit method's 3.3/5e5 s
    assert stats[1] < 2.0 / (3.3 / 5e5) / 50
    assert stats[7] > 0 and stats[6] == 0  # the sparse LU ran, no dense fallback


# measured rates (log2 of the error ratio for h = 0.1, 0.05, 0.025 s): RODAS4 3.96, 3.98;
# RODAS3 2.93, 2.97; ROS34PW2 2.88, 2.95, and with its Jacobian 20 % wrong and kept 4 steps
# 2.86, 2.94 (a W-method); RODAS4 with that Jacobian falls to order 1 (1.10, 1.04)
@pytest.mark.parametrize("method,order,reuse,jac_error", [
    ("RODAS4", 4, 1, 0.0), ("RODAS3", 3, 1, 0.0), ("ROS34PW2", 3, 1, 0.0),
    ("ROS34PW2", 3, 4, 0.2), ("RODAS4", 1, 1, 0.2)])
def test_order_of_convergence(linear, method, order, reuse, jac_error) -> None:
    k, fns = linear
    exact = closed_form(1.6)
    errs = []
    for h in (0.1, 0.05, 0.025):  # fixed steps: no error control (rtol 1e6)
        y, stats = _run(k, fns, method, 1.6, 1e6, h=h, max_step=h, reuse=reuse,
                        jac_error=jac_error)
        assert stats[1] == round(1.6 / h)
        errs.append(np.max(np.abs(y[:2] - exact[:2])))
    rates = [math.log2(a / b) for a, b in zip(errs, errs[1:], strict=False)]
    assert all(abs(r - order) < 0.3 for r in rates), rates


def test_flexible_two_drum_winder_against_a_tight_dopri5(models_dir) -> None:
    """The first 0.2 s of the flexible two-drum winder (309 states, fast damped modes to
    -8.9e3 s^-1: the rider nip's friction relaxation; -1.0e5, the set's torsion at its core,
    before its own β_t, issue #33), RODAS4 at rtol 1e-6 against DOPRI5 at 1e-10."""
    scene = winder.load_scene(models_dir / "two_drum_winder_flexible.toml")
    kw = {"t_end": 0.2, "output_step": 0.01}
    ref = winder.simulate(scene, method="DOPRI5", rtol=1e-10, atol=1e-12, **kw)
    res = winder.simulate(scene, method="RODAS4", rtol=1e-6, atol=1e-8, **kw)
    assert res.meta["method"] == "RODAS4"
    # measured (largest deviation / largest magnitude): set_speed 1.8e-6, set_x 2.7e-7,
    # front_nip_normal_force 4.7e-9, front_twist 1.7e-6, set_radius 2.0e-12
    for ch, tol in (("set_speed", 1.8e-5), ("set_x", 2.7e-6),
                    ("front_nip_normal_force", 4.7e-8), ("front_twist", 1.7e-5),
                    ("set_radius", 2e-11)):
        err = float(np.max(np.abs(res[ch] - ref[ch])) / np.max(np.abs(ref[ch])))
        assert err < tol, (ch, err)


def _event_times(system: MachineSystem, y0: np.ndarray, method: str, t1: float
                 ) -> list[float]:
    """The times of the located events: one step per call (budget 7), the time a call
    returns where the event counter moved."""
    y, m = y0.copy(), system.modes.copy()
    stats = np.zeros(8, dtype=np.int64)
    t, h, times = 0.0, 0.0, []
    run = system.kernels.dopri5 if method == "DOPRI5" else (
        lambda *a: system.kernels.rodas(*a, order=ROSENBROCK[method][0]))
    while t < t1:
        before = int(stats[3])
        status, t, h, _ = run(system.fns, system.table, t, t1, y, system.params, m, 1e-9,
                              1e-11, h, math.inf, np.empty(0), np.empty((len(y), 0)), 0, 7,
                              stats)
        assert status in (integ.DONE, integ.PAUSED)
        if int(stats[3]) > before:
            times.append(t)
    return times


def test_contact_events_located_where_dopri5_locates_them(paper_scene) -> None:
    """Released 5 cm above contact, the roll lands, bounces and settles: RODAS4 locates
    the touch-downs and lift-offs at DOPRI5's times."""
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": 0.625})
    system = MachineSystem(scene)
    y0 = system.initial_state()
    ref = _event_times(system, y0, "DOPRI5", 1.0)
    got = _event_times(system, y0, "RODAS4", 1.0)
    assert len(ref) >= 5 and len(got) == len(ref)
    # measured: 8 events, largest difference 6.8e-11 s (the first touch-down: 0.1009637555
    # s, free fall from 5 cm)
    assert np.max(np.abs(np.array(got) - np.array(ref))) < 7e-10


def test_stepper_and_simulate_run_rodas4(models_dir) -> None:
    """The Stepper with RODAS4 ends where simulate with RODAS4 ends (the same kernel; the
    communication steps restart it), and auto is a valid choice there."""
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    res = winder.simulate(scene, method="RODAS4", t_end=0.5, output_step=0.5, rtol=1e-8,
                          atol=1e-10)
    sim = winder.Stepper(scene, method="RODAS4")
    for _ in range(5):
        sim.step(0.1)
    assert sim.method == "RODAS4"
    # measured: 4.7e-10 relative
    assert abs(sim.output("set_speed") / res["set_speed"][-1] - 1.0) < 4.7e-9
    with pytest.raises(winder.ArgumentError, match="not a Stepper method"):
        winder.Stepper(scene, method="RK45")


def test_spectral_radius_estimate() -> None:
    """auto's stiffness estimate on the linear machine: its eigenvalues are A's diagonal
    but the oscillator's (-5e5 the largest in modulus)."""
    from winder.solve.auto import spectral_radius

    exact = float(np.max(np.abs(np.linalg.eigvals(A))))
    assert exact == pytest.approx(5e5)
    # measured: 5.0e5 to 1e-12 relative (a dominant real eigenvalue, 60 iterations)
    assert spectral_radius(A) == pytest.approx(exact, rel=1e-9)


def test_auto_keeps_dopri5_where_its_step_is_the_accuracy(models_dir, monkeypatch) -> None:
    """The smooth paper scene: its probe is too short to measure, so auto keeps DOPRI5
    without building the Jacobian; with that rule off, DOPRI5's mean step over the probe
    is 3.9 times its stable step 3.3/rho (measured), so auto runs DOPRI5 and says why in
    meta["auto"]."""
    import winder.solve.auto as auto

    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml")
    res = winder.simulate(scene, method="auto", t_end=5.0, output_step=0.5)
    assert res.meta["method"] == "DOPRI5"
    if "nothing measurable" in res.meta["auto"]["reason"]:
        assert "rho" not in res.meta["auto"]["probe"]["DOPRI5"]
    monkeypatch.setattr(auto, "MIN_PROBE_CPU", 0.0)
    res = winder.simulate(scene, method="auto", t_end=5.0, output_step=0.5)
    assert res.meta["method"] == "DOPRI5"
    probe = res.meta["auto"]["probe"]["DOPRI5"]
    assert probe["h_mean"] > 2.0 * probe["h_stable"]
    assert "RODAS4" not in res.meta["auto"]["probe"]
