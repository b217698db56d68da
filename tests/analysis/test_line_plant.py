"""The plant of a web line (issue #34): :func:`winder.casadi_model` and
:func:`winder.linearise` take the unwind's and a pull roll's torques as inputs and give
every span's tension, the rollers' load cells and the dancer's position as outputs.

The line: models/winder_line.toml's parent (r = 0.8 m, on a torque input) → span 0 → a
pull roll on a torque input → span 1 → a dancer → span 2 → the rear drum. Oracle: the
linearisation's DC gains against the closed form of the line's static balance (the parent
``τ_u + r T_0`` and the pull roll ``τ_p + R (T_1 − T_0)`` balanced, a roller passing
its tension on, the carriage ``k d = F − T_1 − T_2``, the load cell's
``sqrt(T_up² + T_down² − 2 T_up T_down cos β)`` differentiated at the operating point):

    ∂T_0/∂τ_u = ∂T_1/∂τ_u = ∂T_2/∂τ_u = −1/r,   ∂T_1/∂τ_p = ∂T_2/∂τ_p = −1/R,
    ∂T_0/∂τ_p = 0,   ∂d = −(∂T_1 + ∂T_2) / k.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import winder

MODEL = Path(__file__).resolve().parents[2] / "models" / "winder_line.toml"
R_U, R, K, BETA = 0.8, 0.1, 2e4, 0.6  # [m, m, N/m, rad]
INPUTS = ["parent_torque", "pull_torque"]
OUTPUTS = ["span0_tension", "span1_tension", "span2_tension", "pull_load_cell",
           "dancer_position", "dancer_load_cell"]


@pytest.fixture(scope="module")
def scene() -> winder.Scene:
    d = winder.load_scene(MODEL).to_dict()
    p = next(r for r in d["roll"] if r["name"] == "parent")
    p["initial_radius"], p["drive"] = R_U, {"kind": "torque", "torque": -1000.0 * R_U}
    d["idler"] = [
        {"name": "pull", "radius": R, "inertia": 0.3, "mass": 5.0, "centre": [1.8, -0.9],
         "wrap": BETA, "bearing_viscous": 0.01, "bearing_coulomb": 0.5,
         "drive": {"kind": "torque", "torque": 0.0}},
        {"name": "dancer", "radius": R, "inertia": 0.3, "mass": 5.0, "centre": [1.2, -1.6],
         "wrap": math.pi, "bearing_viscous": 0.01, "bearing_coulomb": 0.5,
         "dancer": {"stiffness": K, "damping": 2000.0, "load": 2000.0, "mass": 30.0,
                    "travel": [-0.15, 0.15]}}]
    sp = d["web"]["span"]
    d["web"]["span"] = [dict(sp, length=1.5, to="pull", T_in=1000.0),
                        {"length": 1.2, "EA": sp["EA"], "initial_tension": 1000.0,
                         "to": "dancer"},
                        {"length": 1.4, "EA": sp["EA"], "initial_tension": 1000.0}]
    return winder.scene_from_dict(d, source=str(MODEL))


def test_casadi_model_names_the_line_inputs_and_outputs(scene) -> None:
    model = winder.casadi_model(scene, inputs=INPUTS, outputs=OUTPUTS)
    assert list(model.input_names) == INPUTS
    assert list(model.output_names) == OUTPUTS
    assert list(model.input_units) == ["N·m", "N·m"]
    assert list(model.output_units) == ["N", "N", "N", "N", "m", "N"]
    every = winder.casadi_model(scene)
    assert set(INPUTS) <= set(every.input_names)


def test_line_dc_gains_are_the_static_balance(scene) -> None:
    import control

    plant = winder.linearise(scene, 0.3, inputs=INPUTS, outputs=OUTPUTS)
    assert max(np.linalg.eigvals(np.asarray(plant.A)).real) < 0.0
    G = np.asarray(control.dcgain(plant))
    op = dict(zip(plant.output_labels, plant.operating_point["y"], strict=True))
    t0, t1 = op["span0_tension"], op["span1_tension"]
    want = np.array([[-1 / R_U, 0.0], [-1 / R_U, -1 / R], [-1 / R_U, -1 / R], [0.0, 0.0],
                     [2 / (K * R_U), 2 / (K * R)], [0.0, 0.0]])
    cell = math.sqrt(t0**2 + t1**2 - 2 * t0 * t1 * math.cos(BETA))
    want[3] = ((t0 - t1 * math.cos(BETA)) * want[0] + (t1 - t0 * math.cos(BETA)) * want[1]) \
        / cell
    want[5] = want[1] + want[2]  # the dancer's wrap π: T_up + T_down
    err = np.abs(G - want) / np.abs(want).max(axis=0)
    # measured 3.0e-5 of each input's largest gain: the spans' strain (T/EA ~ 1e-3) and
    # the viscous drag at the strained speed
    assert err.max() < 3e-4, err
