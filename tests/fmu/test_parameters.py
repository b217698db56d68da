"""The native FMU's parameters (winder.fmu.parameters): which scene keys a host sets, under
which names and units, landing on which part; and a closed form through the FMU."""

from __future__ import annotations

import numpy as np
import pytest

import winder

fmpy = pytest.importorskip("fmpy", reason="FMPy is installed with winder[fmu]")
from fmu_slave import slave  # noqa: E402

TORQUE_DRIVE = {"kind": "torque", "torque": 0.0, "web_speed": 0.0}


@pytest.fixture(scope="module")
def torque_scene(models_dir) -> winder.Scene:
    """The two-drum winder with both drums torque-driven (from rest; through the dict:
    ``replace`` merges into the drive, with no change of kind)."""
    data = winder.load_scene(models_dir / "two_drum_winder.toml").to_dict()
    for drum in data["drum"]:
        drum["drive"] = dict(TORQUE_DRIVE)
    return winder.scene_from_dict(data)


def test_parts_scene_with_parameters(torque_scene) -> None:
    """FMU parameter values land on the named part (the other parts keep theirs)."""
    from winder.fmu.parameters import FmuError, scene_with_parameters

    sc = scene_with_parameters(torque_scene, {"rear_nip_mu": 0.2, "set_com_offset": 1e-3,
                                              "front_web_speed": 3.0, "web_tension": 5.0})
    nips = {n.name: n for n in sc.nips}
    assert nips["rear_nip"].friction.mu == 0.2 and nips["front_nip"].friction.mu == 0.35
    assert sc.rolls[0].com_offset == 1e-3 and sc.web.tension == 5.0
    drums = {d.name: d for d in sc.drums}
    assert drums["front"].drive.web_speed == 3.0 and drums["rear"].drive.web_speed == 0.0
    assert drums["front"].drive.kind == "torque"
    with pytest.raises(FmuError, match="unknown FMU parameter 'mu'"):
        scene_with_parameters(torque_scene, {"mu": 0.2})
    with pytest.raises(FmuError, match="single-drum scenes only"):
        scene_with_parameters(torque_scene, {}, speed_profile=True)


def test_parameters_are_the_keys_declared_for_the_fmu(models_dir, monkeypatch) -> None:
    """A scene of parts' FMU parameters are its parts' keys declared with ``Key.fmu``
    (a drive's only for the kind that takes them), collected with no list per part kind:
    a key newly declared for the FMU is a parameter with its unit and value at once."""
    from dataclasses import replace

    from winder._schema import Table
    from winder.fmu.parameters import fmu_parameters, parameter_units, parameter_value
    from winder.parts.roll import RollBody

    scene = winder.load_scene(models_dir / "winder_line.toml")
    names = set(fmu_parameters(scene))
    assert {"front_web_acceleration", "set_width", "parent_bandwidth", "rider_nip_mu",
            "span_EA"} <= names
    assert not {"set_bandwidth", "web_tension", "rider_radius"} & names
    monkeypatch.setattr(RollBody, "KEYS", Table(tuple(  # the roll's own declaration
        replace(k, fmu="core_mass") if k.name == "core_mass" else k for k in RollBody.KEYS)))
    params = fmu_parameters(scene)
    assert set(params) == names | {"set_core_mass", "parent_core_mass"}
    assert parameter_units(scene)["set_core_mass"] == "kg"
    assert parameter_value(scene, params["set_core_mass"][0]) == scene.rolls[0].core_mass
    hc = winder.load_scene(models_dir / "two_drum_winder.toml")
    data = hc.to_dict()
    data["nip"][0]["contact"]["law"] = "hunt_crossley"
    units = parameter_units(winder.scene_from_dict(data))
    assert (units["front_nip_contact_stiffness"], units["rear_nip_contact_stiffness"]) == \
        ("N/m^p", "N/m")


def test_line_scene_with_span_parameters(models_dir) -> None:
    """FMU parameter values of the span and the controller land in the scene."""
    from winder.fmu.parameters import scene_with_parameters

    scene = winder.load_scene(models_dir / "winder_line_small.toml")
    sc = scene_with_parameters(scene, {"span_EA": 2e6, "span_length": 2.5,
                                       "parent_bandwidth": 5.0, "parent_width": 4.0})
    assert (sc.web.span.EA, sc.web.span.length, sc.web.span.T_in) == (2e6, 2.5, 0.0)
    parent = next(r for r in sc.rolls if r.name == "parent")
    assert parent.drive.bandwidth == 5.0 and parent.drive.tension == 1000.0
    assert parent.width == 4.0


def test_drums_follow_their_own_torque(torque_scene, tmp_path) -> None:
    """Contact off, so the nips are open: each drum turns under its own input alone,
    J Ω̇ = τ, Ω(t) = τ t / J from rest (measured error 0 to 1e-17: DOPRI5 is exact on a
    linear ramp). Gravity, web tension and rider load off too, so that the set and the
    rider, resting on nothing, have a static balance to start from. Opposite torques on
    the two inputs: each reaches its own drum only."""
    import tomli_w

    from winder.fmu.native import build_fmu

    scene = torque_scene.replace(effects={"contact": False, "slip_relaxation": False,
                                          "gravity": False, "web_tension": False,
                                          "rider_load": False})
    path = tmp_path / "open.toml"
    path.write_text(tomli_w.dumps(scene.to_dict()), encoding="utf-8")
    fmu_file = build_fmu(path, tmp_path / "open.fmu")
    J = {d.name: d.inertia for d in scene.drums}
    taus = {"front": 150.0, "rear": -90.0}
    dt, n = 0.01, 50
    with slave(fmu_file) as (fmu, refs, _):
        assert fmu.getReal([refs["front_speed"], refs["rear_speed"]]) == [0.0, 0.0]
        for name, tau in taus.items():
            fmu.setReal([refs[f"{name}_torque"]], [tau])
        for i in range(n):
            fmu.doStep(i * dt, dt)
            t = (i + 1) * dt
            for name, tau in taus.items():
                speed, accel = fmu.getReal([refs[f"{name}_speed"], refs[f"{name}_accel"]])
                np.testing.assert_allclose(speed, tau * t / J[name], rtol=1e-12, atol=1e-15)
                np.testing.assert_allclose(accel, tau / J[name], rtol=1e-12)
