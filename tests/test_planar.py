"""The compiled backend against the Pinocchio backend, closed forms and tighter solutions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import random_states, scene_variant, state_regions

import winder
from winder import _integrators as integ
from winder._planar import FREE, IN_CONTACT, N_AUX, PlanarSystem, evaluate, mode_of, switch
from winder._system import WinderSystem

VARIANTS = [None, "variable_mass", "web_momentum", "imbalance", "slip_relaxation", "gravity",
            "no_contact", "hunt_crossley", "torque", "hunt_crossley_torque"]
# Largest |compiled − Pinocchio| of one component (state derivative or channel) over the
# random states of a variant, relative to that component's largest |value|: measured
# 1.3e-13 (roll acceleration without contact; 4e-14 with the torque drive, ≤ 1e-14
# elsewhere), so 1.5e-12.
PATH_TOL = 1.5e-12


def _systems(paper_scene: winder.Scene, variant: str | None, n: int, seed: int):
    """Both paths of a variant (a free drum gets an input torque) and ``n`` random states
    that cover every region of the nip (checked here, so a change of the draw that loses
    a region fails instead of silently testing less)."""
    scene = scene_variant(paper_scene, variant)
    system = WinderSystem(scene)
    planar = PlanarSystem(scene, system)
    if scene.drum.drive.kind == "torque":
        system.set_drum_torque(-75.0)
        planar.set_drum_torque(-75.0)
    states = list(random_states(system, np.random.default_rng(seed), n))
    regions = state_regions(system, states)
    # at least 1/40 of the draw in each region (measured: 10/200 to 110/200 at seed 11)
    assert min(regions.values()) >= n // 40, regions
    return scene, system, planar, states


def _assert_paths_agree(got: np.ndarray, ref: np.ndarray, what: str) -> None:
    """Each component of ``got`` (states × components) within :data:`PATH_TOL` of the
    largest value of that component in ``ref``."""
    err = np.max(np.abs(got - ref), axis=0) / np.maximum(np.max(np.abs(ref), axis=0), 1e-300)
    assert np.all(err <= PATH_TOL), (what, err)


@pytest.mark.parametrize("variant", VARIANTS)
def test_compiled_rhs_equals_pinocchio(paper_scene, variant) -> None:
    """``dy/dt`` of the two paths on 200 states in and out of contact, pulling and pressing,
    opening and closing, slipping both ways."""
    _, system, planar, states = _systems(paper_scene, variant, 200, 11)
    ref = np.array([system.rhs(t, y) for t, y in states])
    got = np.array([planar.rhs(t, y) for t, y in states])
    _assert_paths_agree(got, ref, str(variant))


@pytest.mark.parametrize("variant", [None, "torque", "no_contact", "hunt_crossley_torque"])
def test_compiled_channels_equal_pinocchio(paper_scene, variant) -> None:
    """Every channel, including the RNEA drum torque, on the same kind of states."""
    _, system, planar, states = _systems(paper_scene, variant, 120, 12)
    t = np.array([s[0] for s in states])
    Y = np.stack([s[1] for s in states], axis=1)
    ref, got = system.channels(t, Y), planar.channels(t, Y)
    assert set(ref) == set(got)
    for name in ref:
        _assert_paths_agree(got[name][:, None], ref[name][:, None], name)


@pytest.mark.parametrize("variant", [None, "hunt_crossley", "torque"])
def test_contact_modes_against_pinocchio(paper_scene, variant) -> None:
    """The compiled integrator locks the nip in a mode per step. Against the Pinocchio
    path (the clamped law of spec §4): the switching function is positive exactly where
    the Pinocchio nip presses (F_n > 0); there the unclamped mode ``IN_CONTACT`` gives the
    Pinocchio derivative, elsewhere ``FREE`` does."""
    _, system, planar, states = _systems(paper_scene, variant, 200, 13)
    p = planar.params
    aux = np.empty(N_AUX)
    locked, ref = [], []
    for t, y in states:
        ref.append(system.rhs(t, y))
        pressing = system.ctx.normal_force > 0.0
        assert (switch(t, y, p) > 0.0) == pressing, (t, y)
        assert mode_of(t, y, p) == (IN_CONTACT if pressing else FREE)
        dy = np.empty(len(y))
        evaluate(t, y, p, IN_CONTACT if pressing else FREE, dy, aux)
        locked.append(dy)
    _assert_paths_agree(np.array(locked), np.array(ref), str(variant))


def test_dopri5_free_spin_closed_form(models_dir) -> None:
    """Free spin: J(r) ω = J₀ ω₀ and φ = 2π (r − r₀)/h exactly; DOPRI5 at 1e-10."""
    scene = winder.load_scene(models_dir / "free_spin.toml")
    res = winder.simulate(scene, t_end=100.0, method="DOPRI5", rtol=1e-10, atol=1e-12)
    L0 = res["inertia"][0] * res["roll_speed"][0]
    assert np.max(np.abs(res["inertia"] * res["roll_speed"] / L0 - 1)) < 1e-8
    phi = 2 * math.pi * (res["radius"] - res["radius"][0]) / scene.paper.caliper
    np.testing.assert_allclose(res["roll_angle"], phi, rtol=1e-9, atol=1e-9)


def test_dopri5_locates_touch_down(paper_scene) -> None:
    """A roll dropped from 2 cm falls freely (r, ω constant: no contact), so before
    touch-down z(t) = z₀ − g t²/2 exactly, and the samples right after the located event
    are in contact; the event is counted."""
    scene = paper_scene.replace(roll={"com_offset": 0.0, "initial_height": 0.595})
    res = winder.simulate(scene, t_end=0.2, method="DOPRI5", output_step=1e-3,
                          rtol=1e-9, atol=1e-12)
    gap0 = 0.595 - 0.5 - 0.075
    t_hit = math.sqrt(2 * gap0 / 9.81)
    before = res.t < t_hit
    np.testing.assert_allclose(res["z"][before], 0.595 - 0.5 * 9.81 * res.t[before] ** 2,
                               rtol=0, atol=1e-12)
    assert np.all(res["normal_force"][before] == 0.0)
    assert res["normal_force"][np.searchsorted(res.t, t_hit)] > 0.0
    assert res.meta["events"] >= 1


def test_dopri5_converges_through_bouncing(paper_scene) -> None:
    """Half a second of the bouncing phase (from t = 25 s, the roll airborne part of each
    turn): the error against a 1e-12 solution falls with the tolerance, and the
    discontinuities do not stall it."""
    scene = paper_scene
    y0 = winder.simulate(scene, t_end=25.0, method="DOPRI5", rtol=1e-10, atol=1e-13,
                         output_step=25.0)
    # restart from the state at 25 s with a tight and several loose tolerances
    from winder._planar import pack
    p = pack(scene)
    ystart = np.array([y0["z"][-1], y0["roll_angle"][-1], y0["z_dot"][-1],
                       y0["roll_speed"][-1], y0["radius"][-1], y0["friction_force"][-1]])

    def run(rtol: float) -> tuple[np.ndarray, int]:
        y = ystart.copy()
        stats = np.zeros(4, dtype=np.int64)
        t_out = np.array([25.5])
        Y = np.empty((6, 1))
        status, t, _, k = integ.dopri5(25.0, 25.5, y, p, rtol, rtol * 1e-3, 0.0, math.inf,
                                       t_out, Y, 0, 10**8, stats)
        assert status == integ.DONE and k == 1
        return y, int(stats[3])

    ref, events = run(1e-12)
    assert events >= 4  # it really bounces
    errs = [np.max(np.abs(run(tol)[0][:5] - ref[:5]) / (1e-6 + np.abs(ref[:5])))
            for tol in (1e-5, 1e-7, 1e-9)]
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-6


def test_compiled_and_pinocchio_runs_agree(paper_scene) -> None:
    """Whole runs (ramp breakpoint, lift-offs) with both backends and the same method."""
    kw = {"t_end": 21.0, "output_step": 0.25, "method": "LSODA", "rtol": 1e-8, "atol": 1e-10}
    a = winder.simulate(paper_scene, backend="compiled", **kw)
    b = winder.simulate(paper_scene, backend="pinocchio", **kw)
    for name in ("radius", "roll_speed", "z", "drum_torque"):
        np.testing.assert_allclose(a[name], b[name], rtol=1e-6, atol=1e-6, err_msg=name)


def test_rk4_fixed_step_order(models_dir) -> None:
    """RK4 on free spin: halving the step divides the error by ~16."""
    scene = winder.load_scene(models_dir / "free_spin.toml")
    errs = []
    for h in (0.04, 0.02):
        res = winder.simulate(scene, t_end=20.0, method="RK4", max_step=h, output_step=20.0)
        L = res["inertia"] * res["roll_speed"]
        errs.append(abs(L[-1] / L[0] - 1))
    assert 12 < errs[0] / errs[1] < 20
