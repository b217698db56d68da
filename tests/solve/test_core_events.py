"""The core floor in the compiled integrators (winder-model §2): the integration state
itself, not the sampled result (whose radii are clamped to ``r_c``), lands exactly on the
core at the core event and stays there while the roll turns backwards; a step starting at
the core turning backwards runs in the core mode."""

from __future__ import annotations

import numpy as np
import pytest

import winder
from winder.model.locked_modes import AT_CORE, WINDING
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem


def _unwinding_scene(paper_scene: winder.Scene) -> winder.Scene:
    """The paper scene with 2 µm of paper on the core, turning backwards at 5 rad/s: it
    unwinds to the core in ~16 ms (ṙ = h ω / 2π) and turns there until the drum's ramp
    turns it forwards."""
    rc = paper_scene.roll.core_radius
    return paper_scene.replace(roll={"initial_radius": rc + 2e-6, "initial_speed": -5.0})


def _backwards_window(scene: winder.Scene) -> float:
    """The middle of the time the roll turns backwards at its core."""
    res = winder.simulate(scene, t_end=0.1, output_step=1e-4, rtol=1e-10, atol=1e-12)
    at = (res["radius"] == scene.roll.core_radius) & (res["roll_speed"] < 0)
    assert at.sum() > 10 and not at[0]
    return float(np.median(res.t[at]))


def _core_slot(system: MachineSystem) -> int:
    return int(np.flatnonzero(system.table[:, 0] == integ.K_CORE)[0])


@pytest.mark.parametrize("method", ["dopri5", "rk4"])
def test_integrators_land_on_the_core(paper_scene, method) -> None:
    """Integrated from the start into the backwards turn at the core: the state's radius
    is r_c exactly (the event sets it; ṙ = 0 after) and the core mode is on. Without the
    landing the state stays where the event was located, a round-off below r_c."""
    scene = _unwinding_scene(paper_scene)
    t_mid = _backwards_window(scene)
    system = MachineSystem(scene)
    y = system.initial_state()
    m = system.modes.copy()
    stats = np.zeros(5, dtype=np.int64)
    t_out, Y_out = np.empty(0), np.empty((len(y), 0))
    if method == "dopri5":
        status, t, _, _ = system.kernels.dopri5(system.fns, system.table, 0.0, t_mid, y,
                                                system.params, m, 1e-10, 1e-12, 0.0, np.inf,
                                                t_out, Y_out, 0, 10**8, stats)
    else:
        status, t, _, _ = system.kernels.rk4(system.fns, system.table, 0.0, t_mid, y,
                                             system.params, m, 1e-4, t_out, Y_out, 0, stats)
    assert status == integ.DONE and t == t_mid
    assert stats[3] >= 1  # the core event happened
    assert m[_core_slot(system)] == AT_CORE
    assert y[system.index("roll.radius")] == scene.roll.core_radius


def test_start_mode_at_the_core(paper_scene) -> None:
    """A step starting at the core turning backwards runs in the core mode (ṙ = 0); turning
    forwards, or above the core, it winds (spec §2)."""
    system = MachineSystem(paper_scene)
    rc = paper_scene.roll.core_radius
    slot = _core_slot(system)
    for r, speed, mode in ((rc, -5.0, AT_CORE), (rc, 5.0, WINDING), (rc + 1e-3, -5.0, WINDING)):
        y = system.initial_state()
        y[system.index("roll.radius")] = r
        y[system.index("roll.theta_dot")] = -speed  # the roll's sense is −1
        m = system.modes.copy()
        system.kernels.modes(system.fns, system.table, 0.0, y, system.params, m,
                             contact_auto=False)
        assert m[slot] == mode, (r, speed)
