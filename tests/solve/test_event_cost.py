"""What the compiled DOPRI5 spends on switching functions (issue #33, events): counted by
the kernel where ``stats`` holds 8 counters (``[5]`` switch evaluations, ``[6]`` of them in
the events' root finding, ``[7]`` root findings).

The oracle is an identity of counts: outside the root finding, one call evaluates the
switches once for its modes and once at its first step's start, once at each accepted
step's end, twice per located event (the cut step's end again, the next step's start) and
once per output sample (the penetration guard); nothing else where no nip nears its bound.
Before, each located event also probed its step's dense output at 64 points, and each
step evaluated its start's switches again (its last step's end: the same bits).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import winder
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[2]


def _run(system: MachineSystem, t_end: float, n_stats: int, samples: int
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    y, m = system.initial_state(), system.modes.copy()
    t_out = np.linspace(0.0, t_end, samples)
    Y = np.empty((len(y), samples))
    stats = np.zeros(n_stats, dtype=np.int64)
    status, t, _, k = system.kernels.dopri5(system.fns, system.table, 0.0, t_end, y,
                                            system.params, m, 1e-6, 1e-8, 0.0, math.inf,
                                            t_out, Y, 0, 10**9, stats)
    assert (status, t, k) == (integ.DONE, t_end, samples)
    return y, Y, stats


@pytest.mark.parametrize(("scene", "t_end"), [("paper_winding", 60.0),
                                              ("two_drum_winder", 5.0)])
def test_switch_evaluations_follow_the_steps_and_events(scene: str, t_end: float) -> None:
    system = MachineSystem(winder.load_scene(ROOT / "models" / f"{scene}.toml"))
    samples = 11
    y, Y, stats = _run(system, t_end, 8, samples)
    nfev, accepted, rejected, events, _, sw, sw_locate, locates = map(int, stats)
    assert accepted > 1000 and rejected > 0 and events >= 1
    assert locates >= events and sw_locate >= 2 * locates  # each: both ends, then probes
    assert sw - sw_locate == 2 + accepted + 2 * events + samples
    # counting changes nothing: the same state and samples as with 5 counters
    y5, Y5, stats5 = _run(system, t_end, 5, samples)
    assert np.array_equal(y, y5) and np.array_equal(Y, Y5)
    assert np.array_equal(stats[:5], stats5)
    assert nfev == 6 * (accepted + rejected) + 1 + events
