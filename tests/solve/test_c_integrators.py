"""The C integrators (:mod:`winder.solve.cint`, ``solve/c/``) reproduce the numba kernels
they replaced (issue #23): the same statuses, accepted and rejected steps, evaluations,
events and stiff-step counts, the same times (event and stop times included) and the same
states and samples to 1e-12 (in practice bit for bit), chunk by chunk, on the paper and
two-drum scenes, on every shipped scene and on scenes that exercise every located event:
contact lift-off and touch-down, the core events, the penetration guard (on the dense
output and on a step's straight path), the exhausted parent.

Oracle: the numba kernels' traces, recorded by this file with ``WINDER_RECORD_NUMBA=1``
while the numba kernels existed (commit "Record the numba kernels' traces", before they
were deleted) into ``data/kernel_traces/CASE.npz``: after every call the status, time,
next step, samples written, counters, modes and state, then the final state and the
samples."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import MODELS

import winder
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem

#: bit-level records of route cpp's code (conftest.route_cpp)
pytestmark = pytest.mark.usefixtures("route_cpp")

TRACES = Path(__file__).with_name("data") / "kernel_traces"
RECORD = os.environ.get("WINDER_RECORD_NUMBA", "") not in ("", "0")


def _case(request: pytest.FixtureRequest, label: str) -> Path:
    """``TEST[PARAMS]-LABEL-N.npz``: N counts the runs of one test."""
    n = getattr(request.node, "_winder_runs", 0) + 1
    request.node._winder_runs = n
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", f"{request.node.name}-{label}-{n}")
    return TRACES / f"{name}.npz"


def _save(path: Path, trace: list, y: np.ndarray, Y: np.ndarray) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = list(zip(*trace, strict=True))
    np.savez_compressed(path, status=np.array(rows[0], np.int64), t=np.array(rows[1]),
                        h=np.array(rows[2]), k=np.array(rows[3], np.int64),
                        stats=np.array(rows[4]), modes=np.array(rows[5]),
                        y=np.array(rows[6]), final=y, samples=Y)


def _agree(path: Path, trace: list, y: np.ndarray, Y: np.ndarray) -> None:
    """The C trace against the numba one recorded in ``path``."""
    if RECORD:
        _save(path, trace, y, Y)
        return
    ref = np.load(path)
    assert len(trace) == len(ref["status"]), ("calls", len(trace), len(ref["status"]))
    for i, row in enumerate(trace):
        assert row[0] == ref["status"][i], (i, "status", row[0], ref["status"][i])
        assert row[3] == ref["k"][i], (i, "samples")
        np.testing.assert_array_equal(row[4], ref["stats"][i], err_msg=f"call {i}: stats")
        np.testing.assert_array_equal(row[5], ref["modes"][i], err_msg=f"call {i}: modes")
        _close(ref["t"][i], row[1], f"call {i}: t")
        _close(ref["h"][i], row[2], f"call {i}: h")
        _close(ref["y"][i], row[6], f"call {i}: y")
    _close(ref["final"], y, "final state")
    _close(ref["samples"], Y, "samples")


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


def _kernel(system: MachineSystem, method: str):
    """The kernel that runs (the C one; the numba one while recording)."""
    if RECORD:
        from winder.solve.dopri5 import dopri5
        from winder.solve.rk4 import rk4
        from winder.solve.rosenbrock import ros2

        return {"DOPRI5": dopri5, "ROS2": ros2, "RK4": rk4}[method]
    return getattr(system.kernels, method.lower())


def _compare(request, system: MachineSystem, y0: np.ndarray, t1: float, rtol: float,
             atol: float, chunk: int, n_out: int = 101, method: str = "DOPRI5") -> list:
    trace, y, Y = _run(_kernel(system, method), system, y0, t1, rtol, atol, chunk, n_out)
    _agree(_case(request, method), trace, y, Y)
    return trace


def _system(scene: winder.Scene) -> tuple[MachineSystem, np.ndarray]:
    system = MachineSystem(scene)
    return system, system.initial_state()


@pytest.mark.parametrize("chunk", [integ.CHUNK, 5_000])
def test_paper_scene(request, paper_scene, chunk) -> None:
    system, y0 = _system(paper_scene)
    s = paper_scene.solver
    trace = _compare(request, system, y0, 5.0, s.rtol, s.atol, chunk)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] > 1000


@pytest.mark.parametrize("chunk", [integ.CHUNK, 5_000])
def test_two_drum_scene(request, models_dir, chunk) -> None:
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 2.0, scene.solver.rtol, scene.solver.atol, chunk)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] > 1000


def test_contact_events_bouncing(request, paper_scene) -> None:
    """The roll flies off and lands again (com_offset 5 mm): lift-off and touch-down
    located over and over (35 events in 8 s)."""
    scene = paper_scene.replace(roll={"com_offset": 0.005},
                                paper={"density": 0.0, "caliper": 1e-9})
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 8.0, 1e-6, 1e-8, integ.CHUNK)
    assert trace[-1][4][3] >= 30  # events


@pytest.mark.parametrize("chunk", [integ.CHUNK, 7])
def test_contact_events_landing(request, paper_scene, chunk) -> None:
    """Released 5 cm above contact: it lands, bounces and settles (8 events in 1 s).
    ``chunk`` 7: one step per call, so every event time is a returned time."""
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": 0.625})
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 1.0, 1e-6, 1e-8, chunk)
    assert trace[-1][4][3] >= 5


@pytest.mark.parametrize("chunk", [integ.CHUNK, 7])
def test_core_events(request, paper_scene, chunk) -> None:
    """A roll with 2 µm of paper turning backwards: it unwinds to its core (lands on it),
    turns there, and winds again when the drum turns it forwards."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 0.3, 1e-10, 1e-12, chunk)
    assert trace[-1][4][3] >= 2


def test_guard_on_a_step_through_the_drum(request, paper_scene) -> None:
    """Dropped from 20 m: a step jumps through the drum (its straight path), stopped
    there with PENETRATED."""
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare(request, system, y0, 3.0, 1e-8, 1e-10, integ.CHUNK, n_out=3)
    assert trace[-1][0] == integ.PENETRATED


def test_guard_without_error_control(request, paper_scene) -> None:
    """``atol = 1e300``: DOPRI5 steps the axis into the drum; the guard stops it."""
    system, y0 = _system(paper_scene.replace(roll={"com_offset": 0.0}))
    trace = _compare(request, system, y0, 0.5, 1e-6, 1e300, 10**7, n_out=51)
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


def _compare_rk4(request, system: MachineSystem, y0: np.ndarray, t1: float, step: float,
                 window: float, n_out: int = 101) -> list:
    trace, y, Y = _run_rk4(_kernel(system, "RK4"), system, y0, t1, step, window, n_out)
    _agree(_case(request, "RK4"), trace, y, Y)
    return trace


def test_rk4_paper_and_two_drum_scenes(request, paper_scene, models_dir) -> None:
    system, y0 = _system(paper_scene)
    trace = _compare_rk4(request, system, y0, 2.0, 1e-3, 0.7)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] >= 2000
    system, y0 = _system(winder.load_scene(models_dir / "two_drum_winder.toml"))
    trace = _compare_rk4(request, system, y0, 1.0, 1e-3, 0.3)
    assert trace[-1][0] == integ.DONE and trace[-1][4][1] >= 1000


def test_rk4_core_events(request, paper_scene) -> None:
    """The core events on the step's Hermite interpolant: lands on the core, winds again."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare_rk4(request, system, y0, 0.3, 1e-4, 0.05)
    assert trace[-1][4][3] >= 2


@pytest.mark.parametrize("step", [0.02, 0.05])
def test_rk4_guard(request, paper_scene, step) -> None:
    """Dropped from 20 m with coarse steps: the guard stops on the drum (PENETRATED)."""
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare_rk4(request, system, y0, 3.0, step, 1.0)
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


def test_exhausted_parent(request, short_parent) -> None:
    y0 = short_parent.initial_state()
    trace = _compare(request, short_parent, y0, 2.5, 1e-6, 1e-8, 5_000)
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0
    trace = _compare_rk4(request, short_parent, y0, 2.5, 1e-3, 0.5)
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0


#: Shipped scenes added after the numba kernels were deleted: no numba trace exists to
#: compare with (their runs are checked by tests/test_shipped_references.py).
NO_NUMBA_TRACE = {"two_drum_winder_flexible", "winder_line_dancer"}


@pytest.mark.parametrize("name", sorted(p.stem for p in MODELS.glob("*.toml")
                                        if p.stem not in NO_NUMBA_TRACE))
def test_every_shipped_scene(request, name) -> None:
    """The first half second of every shipped scene (but :data:`NO_NUMBA_TRACE`), DOPRI5 at
    its tolerances and RK4 at 1 ms; 0.2 s with ROS2."""
    scene = winder.load_scene(MODELS / f"{name}.toml")
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 0.5, scene.solver.rtol, scene.solver.atol, 5_000)
    assert trace[-1][0] == integ.DONE
    trace = _compare_rk4(request, system, y0, 0.5, 1e-3, 0.2)
    assert trace[-1][0] == integ.DONE
    trace = _compare(request, system, y0, 0.2, scene.solver.rtol, scene.solver.atol, 5_000,
                     method="ROS2")
    assert trace[-1][0] == integ.DONE


# ---- ROS2 -----------------------------------------------------------------------------

def test_ros2_scenes(request, paper_scene, models_dir) -> None:
    """The paper and two-drum scenes, and the landing (contact events), with ROS2."""
    system, y0 = _system(paper_scene)
    trace = _compare(request, system, y0, 2.0, 1e-6, 1e-8, 5_000, method="ROS2")
    assert trace[-1][0] == integ.DONE and trace[-1][4][4] > 100  # Jacobians
    system, y0 = _system(winder.load_scene(models_dir / "two_drum_winder.toml"))
    trace = _compare(request, system, y0, 0.5, 1e-6, 1e-8, 5_000, method="ROS2")
    assert trace[-1][0] == integ.DONE
    system, y0 = _system(paper_scene.replace(roll={"com_offset": 0.0,
                                                   "initial_height": 0.625}))
    trace = _compare(request, system, y0, 1.0, 1e-6, 1e-8, integ.CHUNK, method="ROS2")
    assert trace[-1][4][3] >= 5


def test_ros2_core_guard_and_end(request, paper_scene, short_parent) -> None:
    """The core events, the guard (dropped from 20 m) and the exhausted parent, ROS2."""
    rc = paper_scene.roll.core_radius
    scene = paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})
    system, y0 = _system(scene)
    trace = _compare(request, system, y0, 0.3, 1e-8, 1e-10, integ.CHUNK, method="ROS2")
    assert trace[-1][4][3] >= 2
    system, y0 = _system(paper_scene.replace(roll={"initial_height": 20.0}))
    trace = _compare(request, system, y0, 3.0, 1e-8, 1e-10, integ.CHUNK, n_out=3, method="ROS2")
    assert trace[-1][0] == integ.PENETRATED
    trace = _compare(request, short_parent, short_parent.initial_state(), 2.5, 1e-6, 1e-8, 5_000,
                     method="ROS2")
    assert trace[-1][0] == integ.EXHAUSTED and 1.8 < trace[-1][1] < 2.0
