from __future__ import annotations

import math
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import winder

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"

# `make mutants` runs the suite against a mutated copy of the sources: make sure the copy,
# not the installed package, is what the tests import.
_MUTANT_SRC = os.environ.get("WINDER_MUTANT_SRC")
if _MUTANT_SRC and not Path(winder.__file__).resolve().is_relative_to(
        Path(_MUTANT_SRC).resolve()):
    raise pytest.UsageError(f"WINDER_MUTANT_SRC={_MUTANT_SRC} but winder was imported from "
                            f"{winder.__file__}")


# Scene variants of the paper scene, shared by the path comparisons and the oracles.
HUNT_CROSSLEY = {"law": "hunt_crossley", "stiffness": 5e9, "exponent": 1.5, "hc_damping": 0.3}
TORQUE_DRIVE = {"drive": {"kind": "torque", "web_speed": 5.0, "torque": 120.0}}


def scene_variant(paper_scene: winder.Scene, name: str | None) -> winder.Scene:
    """The paper scene (``None``), with the Hunt–Crossley nip, the torque drive, both, no
    nip (``no_contact``), or one effect (its ``[effects]`` name) switched off."""
    if name is None:
        return paper_scene
    if name == "no_contact":
        return paper_scene.replace(effects={"contact": False, "slip_relaxation": False})
    if name == "hunt_crossley":
        return paper_scene.replace(contact=HUNT_CROSSLEY)
    if name == "torque":
        return paper_scene.replace(drum=TORQUE_DRIVE)
    if name == "hunt_crossley_torque":
        return paper_scene.replace(contact=HUNT_CROSSLEY, drum=TORQUE_DRIVE)
    return paper_scene.replace(effects={name: False})


@pytest.fixture(scope="session")
def paper_scene() -> winder.Scene:
    return winder.load_scene(MODELS / "paper_winding.toml")


@pytest.fixture(scope="session")
def models_dir() -> Path:
    return MODELS


def _signed_log(rng: np.random.Generator, lo: float, hi: float) -> float:
    """A magnitude log-uniform in ``[lo, hi]`` with a random sign."""
    return float(rng.choice((-1.0, 1.0)) * 10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))


#: The single-drum state in the order of the old planar kernel (``z, φ, ż, ω, r, [θ_d,
#: Ω], [F_t]``, the order the hand-written spec equations of the tests use) and where each
#: lives in the machine's named state, with its sign (the roll's sense is −1: θ = −φ).
OLD_LAYOUT = (("z", "roll.z", 1.0), ("roll_angle", "roll.theta", -1.0),
              ("z_dot", "roll.z_dot", 1.0), ("roll_speed", "roll.theta_dot", -1.0),
              ("radius", "roll.radius", 1.0), ("drum_angle", "drum.theta", 1.0),
              ("drum_speed", "drum.theta_dot", 1.0), ("friction_force", "nip.friction", 1.0))


def old_names(system) -> list[str]:
    """The old-layout names of a single-drum system's states, in the old order."""
    return [old for old, new, _ in OLD_LAYOUT if new in system.state_names]


def to_old(system, y: np.ndarray) -> np.ndarray:
    """A machine state (or its derivative) of a single-drum scene in the old layout."""
    return np.array([s * y[system.index(new)] for _, new, s in OLD_LAYOUT
                     if new in system.state_names])


def to_machine(system, y_old: np.ndarray) -> np.ndarray:
    """The inverse of :func:`to_old`."""
    y = np.empty(system.n_states)
    pairs = [(new, s) for _, new, s in OLD_LAYOUT if new in system.state_names]
    for value, (new, s) in zip(y_old, pairs, strict=True):
        y[system.index(new)] = s * value
    return y


def prescribed_drum_speed(scene: winder.Scene, t: float) -> float:
    """``Ω(t)`` [rad/s] of the single-drum scene's speed profile (spec §5)."""
    d = scene.drum
    a, v = d.drive.web_acceleration, d.drive.web_speed
    return (min(a * t, v) if a > 0 else v) / d.radius


def random_states(system, rng: np.random.Generator, n: int) -> Iterator[tuple[float, np.ndarray]]:
    """``n`` random ``(t, y)`` for a single-drum ``MachineSystem`` that reach every branch
    of the nip and the drive: penetration ``δ`` and its rate ``δ̇`` of both signs over
    five decades each (so out of contact, in contact, and where ``δ > 0`` but the law would
    pull), slip ``v_s = Ω R − ω r`` of both signs from creep to gross slip, any angle,
    radii over the whole cycle, times on the ramp and after it, any relaxed friction. Use
    :func:`state_regions` to count what was drawn."""
    scene = system.scene
    names = old_names(system)
    R, rc = scene.drum.radius, scene.roll.core_radius
    h2pi = scene.paper.caliper / (2.0 * math.pi)
    y0 = to_old(system, system.initial_state())
    for _ in range(n):
        t = float(rng.uniform(0.0, 60.0))
        y = y0.copy()
        r = float(rng.uniform(rc, 0.85))
        if "drum_speed" in names:
            y[names.index("drum_angle")] = rng.uniform(-10.0, 10.0)
            y[names.index("drum_speed")] = rng.uniform(-5.0, 45.0)
            Om = y[names.index("drum_speed")]
        else:
            Om = prescribed_drum_speed(scene, t)
        w = (Om * R - _signed_log(rng, 1e-4, 3.0)) / r
        delta, ddot = _signed_log(rng, 1e-7, 3e-3), _signed_log(rng, 1e-4, 30.0)
        y[:5] = (R + r - delta, rng.uniform(-math.pi, math.pi), h2pi * w - ddot, w, r)
        if "friction_force" in names:
            y[names.index("friction_force")] = rng.normal(0.0, 300.0)
        yield t, to_machine(system, y)


def state_regions(system, states: list[tuple[float, np.ndarray]]) -> dict[str, int]:
    """How many of ``states`` lie in each region of the nip law (spec §4), from the scene's
    parameters: ``out`` (δ ≤ 0), ``pulling`` (δ > 0 but the unclamped law < 0: the clamp
    acts), ``pressing`` (F_n > 0), ``out_law_positive`` (δ ≤ 0 where the unclamped linear
    law would push), the signs of ``δ̇`` and of the slip."""
    scene = system.scene
    c, R = scene.contact, scene.drum.radius
    h2pi = scene.paper.caliper / (2.0 * math.pi)
    names = old_names(system)
    out = dict.fromkeys(("out", "pulling", "pressing", "out_law_positive", "closing",
                         "opening", "slip+", "slip-"), 0)
    for t, y_machine in states:
        y = to_old(system, y_machine)
        z, zd, w, r = y[0], y[2], y[3], y[4]
        delta, ddot = R + r - z, h2pi * w - zd
        law = (c.stiffness * delta + c.damping * ddot if c.law == "linear"
               else c.stiffness * abs(delta) ** c.exponent * (1 + c.hc_damping * ddot))
        if delta <= 0:
            out["out"] += 1
            out["out_law_positive"] += int(law > 0)
        else:
            out["pulling" if law <= 0 else "pressing"] += 1
        out["closing" if ddot > 0 else "opening"] += 1
        Om = (y[names.index("drum_speed")] if "drum_speed" in names
              else prescribed_drum_speed(scene, t))
        out["slip+" if Om * R - w * r > 0 else "slip-"] += 1
    return out


# ---- the generated code's route for bit-level records ---------------------------------------
@pytest.fixture(scope="module")
def route_cpp() -> Iterator[None]:
    """Route ``cpp`` of the generated code for a module's tests (``pytestmark =
    pytest.mark.usefixtures("route_cpp")``): the recorded traces and shipped references are
    records of that route's code to the last bit, and an adaptive integrator turns the
    routes' round-off (8e-16 of each output, tests/model/test_routes.py) into differences at
    its tolerance. The default route ``py`` is the same expressions (that test)."""
    from winder.model.backends import ROUTE_ENV
    from winder.model.pin_casadi import generator_path, unavailable_reason

    if generator_path(build=False) is None:
        pytest.skip(f"route cpp: {unavailable_reason()} (make pin-casadi builds it)")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(ROUTE_ENV, "cpp")
        yield


def without_build_lines(err: str) -> str:
    """``err`` without the lines a first run prints while it builds a machine's code (they
    depend on the cache, not on what a test checks)."""
    import re

    return re.sub(r"(?m)^winder: (building .*|compiling .*|.*'s (code|Jacobian) built in .*)\n",
                  "", err)
