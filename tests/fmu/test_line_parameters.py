"""The FMU parameters of a web line of several spans (machines.md §11, issue #34): each
span's length and EA (``span{i}_length``, ``span{i}_EA``, the first span's ``T_in``), the
web's ``web_mu``, an idler's bearings and wrap, a dancer's damping; named from the spans'
indices and the parts' names. Oracle (the other path): the FMU with parameters set by the
host gives, step for step, what :class:`winder.Stepper` gives on the scene with the same
changes (the same generated code and integrator: bit for bit), and differs from the
unchanged scene."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import tomli_w

import winder

fmpy = pytest.importorskip("fmpy", reason="FMPy is installed with winder[fmu]")
from fmu_slave import slave  # noqa: E402

V, L, EA, T = 10.0, 3.0, 1.4e6, 1000.0  # [m/s, m, N, N]


def _line() -> dict[str, Any]:
    """parent → span 0 → guide → span 1 → dancer → span 2 → entry drum at V, the unwind
    holding the dancer (started 20 mm out) at its centre."""
    rollers = [{"name": "guide", "radius": 0.1, "inertia": 0.5, "centre": [4.5, -1.0],
                "wrap": math.pi / 2, "initial_speed": V / 0.1, "bearing_viscous": 0.01,
                "bearing_coulomb": 0.5},
               {"name": "dancer", "radius": 0.1, "inertia": 0.5, "mass": 5.0,
                "centre": [3.0, -2.0], "wrap": math.pi, "initial_speed": V / 0.1,
                "dancer": {"stiffness": 2e4, "damping": 500.0, "mass": 20.0,
                           "load": 2 * T + 2e4 * 0.02, "travel": [-0.2, 0.2]}}]
    return {
        "scene": {"name": "fmu_line", "duration": 0.5, "output_step": 0.01},
        "effects": {"contact": False, "gravity": False, "imbalance": False,
                    "slip_relaxation": False},
        "paper": {"density": 650.0, "caliper": 70e-6},
        "drum": [{"name": "entry", "radius": 0.5, "inertia": 600.0, "mass": 3000.0,
                  "centre": [0.0, 0.0],
                  "drive": {"kind": "speed_profile", "web_acceleration": 0.0,
                            "web_speed": V}}],
        "roll": [{"name": "set", "centre": [0.0, 0.6], "free": ["z"], "core_radius": 0.1,
                  "core_mass": 40.0, "core_inertia": 0.2, "width": 5.0,
                  "initial_radius": 0.1, "initial_speed": V / 0.1},
                 {"name": "parent", "kind": "unwinding", "centre": [6.0, 0.0], "free": [],
                  "core_radius": 0.4, "core_mass": 3000.0, "core_inertia": 300.0,
                  "width": 5.0, "initial_radius": 1.0, "initial_speed": V,
                  "drive": {"kind": "dancer_control", "dancer": "dancer",
                            "bandwidth": 5.0}}],
        "idler": rollers,
        "nip": [{"name": "entry_nip", "a": "entry", "b": "set",
                 "contact": {"law": "linear", "stiffness": 2.5e7, "damping": 1.5e4},
                 "friction": {"mu": 0.35, "slip_velocity": 0.05,
                              "relaxation_length": 0.01, "min_speed": 0.1}}],
        "web": {"entry_nip": "entry_nip", "span": [
            {"from": "parent", "length": L, "EA": EA, "T_in": T, "initial_tension": T,
             "to": "guide"},
            {"length": L, "EA": EA, "initial_tension": T, "to": "dancer"},
            {"length": L, "EA": EA, "initial_tension": T}]},
    }


#: FMU parameter → the same change in the scene (``Scene.replace``)
CHANGES = {
    "span1_length": (2.5, {"web": {"span": {"1": {"length": 2.5}}}}),
    "span2_EA": (1.1e6, {"web": {"span": {"2": {"EA": 1.1e6}}}}),
    "dancer_dancer_damping": (900.0, {"idler": {"dancer": {"dancer": {"damping": 900.0}}}}),
    "guide_bearing_viscous": (0.05, {"idler": {"guide": {"bearing_viscous": 0.05}}}),
    "web_mu": (0.5, {"web": {"mu": 0.5}}),
}
OUTPUTS = ("span0_tension", "span1_tension", "span2_tension", "dancer_position",
           "guide_load_cell", "guide_traction", "parent_torque")


@pytest.fixture(scope="module")
def line_fmu(tmp_path_factory):
    from winder.fmu.native import build_fmu

    d = tmp_path_factory.mktemp("line_fmu")
    path = d / "line.toml"
    path.write_text(tomli_w.dumps(_line()), encoding="utf-8")
    return build_fmu(path, d / "line.fmu"), winder.load_scene(path)


def test_line_parameters_are_named_from_spans_and_parts(line_fmu) -> None:
    from winder.fmu.parameters import fmu_parameters, parameter_value

    _, scene = line_fmu
    params = fmu_parameters(scene)
    spans = {n for n in params if n.startswith("span")}
    assert spans == {f"span{i}_{k}" for i in range(3) for k in ("length", "EA")} | \
        {"span0_T_in"}
    for name, (place, _) in params.items():
        if name.startswith("span"):
            i, key = int(name[4]), name.split("_", 1)[1]
            assert parameter_value(scene, place) == getattr(scene.web.spans[i], key)
    assert {"web_mu", "guide_wrap", "guide_bearing_viscous", "guide_bearing_coulomb",
            "dancer_dancer_damping"} <= set(params)


@pytest.mark.parametrize("name", list(CHANGES))
def test_a_parameter_set_through_the_fmu_is_the_scene_changed(name: str, line_fmu) -> None:
    path, scene = line_fmu
    value, change = CHANGES[name]
    changed, base = winder.Stepper(scene.replace(**change)), winder.Stepper(scene)
    dt, n = 0.01, 30
    moved = 0.0
    with slave(path, **{name: value}) as (fmu, refs, _):
        vrs = [refs[k] for k in OUTPUTS]
        for i in range(n):
            fmu.doStep(i * dt, dt)
            changed.step(dt)
            base.step(dt)
            got = fmu.getReal(vrs)
            want = [changed.output(k) for k in OUTPUTS]
            assert got == want, (i, dict(zip(OUTPUTS, np.subtract(got, want), strict=True)))
            moved = max(moved, max(abs(g - base.output(k))
                                   for g, k in zip(got, OUTPUTS, strict=True)))
    assert moved > 1e-6  # the change took
