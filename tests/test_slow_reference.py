"""Slow reference runs (``make test-slow``): whole cycles against independent solutions."""

from __future__ import annotations

import numpy as np
import pytest

import winder

pytestmark = pytest.mark.slow


def test_full_smooth_cycle_both_backends(models_dir) -> None:
    """The 700 s smooth cycle: the default method (compiled DOPRI5) against scipy's LSODA
    at a tight tolerance (an independent integrator); and its first 20 s on the numeric
    Pinocchio path (``pin.aba`` on numbers: independent dynamics code) against the
    generated code."""
    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml")
    fast = winder.simulate(scene, output_step=1.0)
    # scipy's LSODA needs more than its default budget (300 000 evaluations) here
    ref = winder.simulate(scene, output_step=1.0, method="LSODA", rtol=1e-9, atol=1e-11,
                          max_rhs=10**9)
    # largest difference relative to the channel's largest value, measured: radius 1.2e-13,
    # roll_speed 3.7e-11, z 1.9e-11, normal_force 1.3e-8, drum_torque 8.7e-8
    tolerances = {"radius": 1e-12, "roll_speed": 6e-10, "z": 1e-10, "normal_force": 3e-7,
                  "drum_torque": 8e-7}
    for k, tol in tolerances.items():
        err = np.max(np.abs(fast[k] - ref[k])) / np.max(np.abs(ref[k]))
        assert err < tol, (k, err)
    kw = {"t_end": 20.0, "output_step": 0.5, "method": "LSODA", "rtol": 1e-9, "atol": 1e-11,
          "max_rhs": 10**9}
    numeric = winder.simulate(scene, backend="pinocchio", **kw)
    generated = winder.simulate(scene, **kw)
    # the same integrator on both paths, whose steps part by round-off: measured
    # normal_force 4.3e-9, drum_torque 6.4e-11, roll_speed 5.1e-12, radius 4.4e-13
    for k in tolerances:
        err = np.max(np.abs(numeric[k] - generated[k])) / np.max(np.abs(generated[k]))
        assert err < 5e-8, (k, err)


def test_full_paper_cycle_converges(models_dir) -> None:
    """The 700 s paper cycle with ~3000 contact events: the slow quantities (radius, mass,
    roll speed after the bouncing) agree between rtol 1e-6 and 1e-10. The bouncing itself
    is chaotic (individual impacts diverge), so only its integral effect is compared."""
    scene = winder.load_scene(models_dir / "paper_winding.toml")
    a = winder.simulate(scene, output_step=1.0)
    b = winder.simulate(scene, output_step=1.0, rtol=1e-10, atol=1e-12)
    # measured relative differences: radius 5.9e-7, mass 1.2e-6, late roll speed 4.1e-8
    np.testing.assert_allclose(a["radius"], b["radius"], rtol=6e-6)
    np.testing.assert_allclose(a["mass"], b["mass"], rtol=1.2e-5)
    late = a.t > 200  # after the bouncing phase the roll rides the drum smoothly
    np.testing.assert_allclose(a["roll_speed"][late], b["roll_speed"][late], rtol=4e-7)
