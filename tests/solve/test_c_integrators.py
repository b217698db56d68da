"""The C integrators (:mod:`winder.solve.cint`, ``solve/c/integrators.c``) reproduce the
numba kernels (issue #23): the same statuses, accepted and rejected steps, evaluations,
events and stiff-step counts, the same times (event and stop times included) and the same
states and samples to 1e-12 (in practice bit for bit), chunk by chunk, on the paper and
two-drum scenes and on scenes that exercise every located event: contact lift-off and
touch-down, the core events, the penetration guard (on the dense output and on a step's
straight path).

Oracle: the numba kernel (:func:`winder.solve.dopri5.dopri5`), the reference until it is
deleted."""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest
from conftest import MODELS

import winder
from winder.solve import cint
from winder.solve import integrators as integ
from winder.solve.dopri5 import dopri5 as dopri5_numba
from winder.solve.rk4 import rk4 as rk4_numba
from winder.solve.rosenbrock import ros2 as ros2_numba
from winder.solve.system import MachineSystem


def _close(a: np.ndarray, b: np.ndarray, what: str) -> None:
    """To 1e-12 relative to max(1, |a|) (NaN where the other is NaN: unwritten samples)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, what
    assert np.array_equal(np.isnan(a), np.isnan(b)), what
    ok = ~np.isnan(a)
    scale = np.maximum(1.0, np.abs(a[ok]))
    assert np.all(np.abs(a[ok] - b[ok]) <= 1e-12 * scale), (
        what, float(np.max(np.abs(a[ok] - b[ok]) / scale)))


def _run(kernel, system: MachineSystem, y0: np.ndarray, t1: float, rtol: float,
         atol: float, chunk: int, n_out: int) -> tuple[list, np.ndarray, np.ndarray]:
    """Integrate in chunks of ``chunk`` evaluations as simulate does; the trace of
    ``(status, t, h, k, stats, modes)`` after every call, the final state and samples."""
    y, m = y0.copy(), system.modes.copy()
    t_out = np.linspace(0.0, t1, n_out)
    Y = np.full((len(y), n_out), np.nan)
    stats = np.zeros(5, dtype=np.int64)
    t, h, k, trace = 0.0, 0.0, 0, []
    while t < t1:
        status, t, h, k = kernel(system.fns, system.table, t, t1, y, system.params, m, rtol,
                                 atol, h, math.inf, t_out, Y, k, chunk, stats)
        trace.append((status, t, h, k, stats.copy(), m.copy(), y.copy()))
        if status != integ.DONE and status != integ.PAUSED:
            break
        assert len(trace) < 100_000
    return trace, y, Y


#: The adaptive kernels: numba (the reference) and C.
ADAPTIVE = {"DOPRI5": (dopri5_numba, cint.dopri5), "ROS2": (ros2_numba, cint.ros2)}


def _compare(system: MachineSystem, y0: np.ndarray, t1: float, rtol: float, atol: float,
             chunk: int, n_out: int = 101, method: str = "DOPRI5") -> list:
    reference, kernel = ADAPTIVE[method]
    a, ya, Ya = _run(reference, system, y0, t1, rtol, atol, chunk, n_out)
    kernel = partial(kernel, n_switches=system.generated.n_switches)
    b, yb, Yb = _run(kernel, system, y0, t1, rtol, atol, chunk, n_out)
    assert len(a) == len(b)
    for i, (ra, rb) in enumerate(zip(a, b, strict=True)):
        assert ra[0] == rb[0], (i, "status", ra[0], rb[0])
        assert ra[3] == rb[3], (i, "samples")
        np.testing.assert_array_equal(ra[4], rb[4], err_msg=f"call {i}: stats")
        np.testing.assert_array_equal(ra[5], rb[5], err_msg=f"call {i}: modes")
        _close(ra[1], rb[1], f"call {i}: t")
        _close(ra[2], rb[2], f"call {i}: h")
        _close(ra[6], rb[6], f"call {i}: y")
    _close(ya, yb, "final state")
    _close(Ya, Yb, "samples")
    return a


def _system(scene: winder.Scene) -> tuple[MachineSystem, np.ndarray]:
    system = MachineSystem(scene)
    return system, system.initial_state()


@pytest.mark.parametrize("chunk", [integ.CHUNK, 5_000])
def test_paper_scene(paper_scene, chunk) -> None:
    system, y0 = _system(paper_scene)
    s = paper_scene.solver
    trace = _compare(system, y0, 5.0, s.rtol, s.atol, chunk)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] > 1000


@pytest.mark.parametrize("chunk", [integ.CHUNK, 5_000])
def test_two_drum_scene(models_dir, chunk) -> None:
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    system, y0 = _system(scene)
    trace = _compare(system, y0, 2.0, scene.solver.rtol, scene.solver.atol, chunk)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] > 1000


def test_contact_events_bouncing(paper_scene) -> None:
    """The roll flies off and lands again (com_offset 5 mm): lift-off and touch-down
    located over and over (35 events in 8 s)."""
    scene = paper_scene.replace(roll={"com_offset": 0.005},
                                paper={"density": 0.0, "caliper": 1e-9})
    system, y0 = _system(scene)
    trace = _compare(system, y0, 8.0, 1e-6, 1e-8, integ.CHUNK)
    assert trace[-1][4][3] >= 30  # events


@pytest.mark.parametrize("chunk", [integ.CHUNK, 7])
def test_contact_events_landing(paper_scene, chunk) -> None:
    """Released 5 cm above contact: it lands, bounces and settles (8 events in 1 s).
    ``chunk`` 7: one step per call, so every event time is a returned time."""
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": 0.625})
    system, y0 = _system(scene)
    trace = _compare(system, y0, 1.0, 1e-6, 1e-8, chunk)
    assert trace[-1][4][3] >= 5


@pytest.mark.parametrize("chunk", [integ.CHUNK, 7])
def test_core_events(paper_scene, chunk) -> None:
    """A roll with 2 µm of paper turning backwards: it unwinds to its core (lands on it),
    turns there, and winds again when the drum turns it forwards."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare(system, y0, 0.3, 1e-10, 1e-12, chunk)
    assert trace[-1][4][3] >= 2


def test_guard_on_a_step_through_the_drum(paper_scene) -> None:
    """Dropped from 20 m: a step jumps through the drum (its straight path), stopped
    there with PENETRATED."""
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare(system, y0, 3.0, 1e-8, 1e-10, integ.CHUNK, n_out=3)
    assert trace[-1][0] == integ.PENETRATED


def test_guard_without_error_control(paper_scene) -> None:
    """``atol = 1e300``: DOPRI5 steps the axis into the drum; the guard stops it."""
    system, y0 = _system(paper_scene.replace(roll={"com_offset": 0.0}))
    trace = _compare(system, y0, 0.5, 1e-6, 1e300, 10**7, n_out=51)
    assert trace[-1][0] == integ.PENETRATED


# ---- RK4 ------------------------------------------------------------------------------

def _run_rk4(kernel, system: MachineSystem, y0: np.ndarray, t1: float, step: float,
             window: float, n_out: int) -> tuple[list, np.ndarray, np.ndarray]:
    """RK4 in windows of ``window`` seconds (as simulate chunks it): the trace after
    every call, the final state and samples."""
    y, m = y0.copy(), system.modes.copy()
    t_out = np.linspace(0.0, t1, n_out)
    Y = np.full((len(y), n_out), np.nan)
    stats = np.zeros(5, dtype=np.int64)
    t, k, trace = 0.0, 0, []
    while t < t1:
        t_next = min(t1, t + window)
        status, t, h, k = kernel(system.fns, system.table, t, t_next, y, system.params, m,
                                 step, t_out, Y, k, stats)
        trace.append((status, t, h, k, stats.copy(), m.copy(), y.copy()))
        if status != integ.DONE:
            break
    return trace, y, Y


def _compare_rk4(system: MachineSystem, y0: np.ndarray, t1: float, step: float,
                 window: float, n_out: int = 101) -> list:
    a, ya, Ya = _run_rk4(rk4_numba, system, y0, t1, step, window, n_out)
    kernel = partial(cint.rk4, n_switches=system.generated.n_switches)
    b, yb, Yb = _run_rk4(kernel, system, y0, t1, step, window, n_out)
    assert len(a) == len(b)
    for i, (ra, rb) in enumerate(zip(a, b, strict=True)):
        assert ra[0] == rb[0] and ra[3] == rb[3], (i, ra[:4], rb[:4])
        np.testing.assert_array_equal(ra[4], rb[4], err_msg=f"call {i}: stats")
        np.testing.assert_array_equal(ra[5], rb[5], err_msg=f"call {i}: modes")
        _close(ra[1], rb[1], f"call {i}: t")
        _close(ra[2], rb[2], f"call {i}: h")
        _close(ra[6], rb[6], f"call {i}: y")
    _close(ya, yb, "final state")
    _close(Ya, Yb, "samples")
    return a


def test_rk4_paper_and_two_drum_scenes(paper_scene, models_dir) -> None:
    system, y0 = _system(paper_scene)
    trace = _compare_rk4(system, y0, 2.0, 1e-3, 0.7)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] >= 2000
    system, y0 = _system(winder.load_scene(models_dir / "two_drum_winder.toml"))
    trace = _compare_rk4(system, y0, 1.0, 1e-3, 0.3)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] >= 1000


def test_rk4_core_events(paper_scene) -> None:
    """The core events on the step's Hermite interpolant: lands on the core, winds again."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare_rk4(system, y0, 0.3, 1e-4, 0.05)
    assert trace[-1][4][3] >= 2


@pytest.mark.parametrize("step", [0.02, 0.05])
def test_rk4_guard(paper_scene, step) -> None:
    """Dropped from 20 m with coarse steps: the guard stops on the drum (PENETRATED)."""
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare_rk4(system, y0, 3.0, step, 1.0)
    assert trace[-1][0] == integ.PENETRATED


@pytest.fixture(scope="module")
def short_parent(models_dir, tmp_path_factory) -> MachineSystem:
    """The small winder line with 0.1 mm of paper on the parent: it runs out at ≈ 1.9 s
    (the END slot: EXHAUSTED); three nips, a core and an end slot in one table."""
    text = (models_dir / "winder_line_small.toml").read_text()
    old = "initial_radius = 0.45   #"
    assert text.count(old) == 1
    path = tmp_path_factory.mktemp("short_parent") / "short_parent.toml"
    path.write_text(text.replace(old, "initial_radius = 0.4001 #"))
    return MachineSystem(winder.load_scene(path))


def test_exhausted_parent(short_parent) -> None:
    y0 = short_parent.initial_state()
    trace = _compare(short_parent, y0, 2.5, 1e-6, 1e-8, 5_000)
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0
    trace = _compare_rk4(short_parent, y0, 2.5, 1e-3, 0.5)
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0


@pytest.mark.parametrize("name", sorted(p.stem for p in MODELS.glob("*.toml")))
def test_every_shipped_scene(name) -> None:
    """The first half second of every shipped scene, DOPRI5 at its tolerances and RK4 at
    1 ms; 0.2 s with ROS2."""
    scene = winder.load_scene(MODELS / f"{name}.toml")
    system, y0 = _system(scene)
    trace = _compare(system, y0, 0.5, scene.solver.rtol, scene.solver.atol, 5_000)
    assert trace[-1][0] == integ.DONE
    trace = _compare_rk4(system, y0, 0.5, 1e-3, 0.2)
    assert trace[-1][0] == integ.DONE
    trace = _compare(system, y0, 0.2, scene.solver.rtol, scene.solver.atol, 5_000,
                     method="ROS2")
    assert trace[-1][0] == integ.DONE


# ---- ROS2 -----------------------------------------------------------------------------

def test_ros2_scenes(paper_scene, models_dir) -> None:
    """The paper and two-drum scenes, and the landing (contact events), with ROS2."""
    system, y0 = _system(paper_scene)
    trace = _compare(system, y0, 2.0, 1e-6, 1e-8, 5_000, method="ROS2")
    assert trace[-1][0] == integ.DONE and trace[-1][4][4] > 100  # Jacobians
    system, y0 = _system(winder.load_scene(models_dir / "two_drum_winder.toml"))
    trace = _compare(system, y0, 0.5, 1e-6, 1e-8, 5_000, method="ROS2")
    assert trace[-1][0] == integ.DONE
    system, y0 = _system(paper_scene.replace(roll={"com_offset": 0.0,
                                                   "initial_height": 0.625}))
    trace = _compare(system, y0, 1.0, 1e-6, 1e-8, integ.CHUNK, method="ROS2")
    assert trace[-1][4][3] >= 5


def test_ros2_core_guard_and_end(paper_scene, short_parent) -> None:
    """The core events, the guard (dropped from 20 m) and the exhausted parent, ROS2."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare(system, y0, 0.3, 1e-8, 1e-10, integ.CHUNK, method="ROS2")
    assert trace[-1][4][3] >= 2
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare(system, y0, 3.0, 1e-8, 1e-10, integ.CHUNK, n_out=3, method="ROS2")
    assert trace[-1][0] == integ.PENETRATED
    trace = _compare(short_parent, short_parent.initial_state(), 2.5, 1e-6, 1e-8, 5_000,
                     method="ROS2")
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0
