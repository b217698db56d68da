"""simulate(method="ROS2"): the compiled Rosenbrock method on the exact Jacobian, against
the compiled DOPRI5 at a tight tolerance (the other code path)."""

from __future__ import annotations

import numpy as np
import pytest

import winder


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def test_ros2_matches_dopri5_on_the_smooth_paper_scene(models_dir) -> None:
    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml")
    kw = {"t_end": 10.0, "output_step": 0.1}
    ref = winder.simulate(scene, method="DOPRI5", rtol=1e-11, atol=1e-13, **kw)
    res = winder.simulate(scene, method="ROS2", rtol=1e-8, atol=1e-10, **kw)
    assert res.meta["method"] == "ROS2"
    # measured: radius 7.3e-12, roll_speed 1.5e-8, z 7.8e-12, normal_force 2.0e-7
    for ch, tol in (("radius", 7e-11), ("roll_speed", 1.5e-7), ("z", 8e-11),
                    ("normal_force", 2e-6)):
        assert _rel(res[ch], ref[ch]) < tol, ch


def test_ros2_locates_the_nip_events_of_the_two_drum_winder(models_dir) -> None:
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    kw = {"t_end": 3.0, "output_step": 0.01}
    ref = winder.simulate(scene, method="DOPRI5", rtol=1e-10, atol=1e-12, **kw)
    res = winder.simulate(scene, method="ROS2", rtol=1e-7, atol=1e-9, **kw)
    assert res.meta["events"] == ref.meta["events"]
    # measured: set_z 1.0e-9, set_speed 1.1e-5, rear_nip_normal_force 2.0e-7 (1 event each)
    for ch, tol in (("set_z", 1e-8), ("set_speed", 1.1e-4), ("rear_nip_normal_force", 2e-6)):
        assert _rel(res[ch], ref[ch]) < tol, ch


def test_ros2_needs_the_compiled_backend(paper_scene) -> None:
    with pytest.raises(winder.ArgumentError, match="method = 'ROS2' needs backend 'compiled'"):
        winder.simulate(paper_scene, method="ROS2", backend="pinocchio", t_end=1.0)


def test_ros2_is_stable_on_a_stiff_nip(models_dir) -> None:
    """Nip stiffness 1e12 N/m: ROS2 (L-stable) needs ~2 000 evaluations for 2 s where
    DOPRI5 is held to steps of ~1e-5 s by stability (~2 million evaluations at rtol
    1e-10); the two agree."""
    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml").replace(
        contact={"stiffness": 1e12, "damping": 1e5})
    kw = {"t_end": 2.0, "output_step": 0.01}
    res = winder.simulate(scene, method="ROS2", rtol=1e-6, atol=1e-8, max_rhs=20_000, **kw)
    with pytest.raises(winder.BudgetExceeded):
        winder.simulate(scene, method="DOPRI5", max_rhs=20_000, **kw)
    ref = winder.simulate(scene, method="DOPRI5", rtol=1e-10, atol=1e-12, max_rhs=10**8, **kw)
    # measured: normal_force 8.9e-6, roll_speed 2.1e-6, z 2.8e-11, radius 2.1e-10
    for ch, tol in (("normal_force", 9e-5), ("roll_speed", 2e-5), ("z", 3e-10),
                    ("radius", 2e-9)):
        assert _rel(res[ch], ref[ch]) < tol, ch
