"""The units of the result channels (``MachineSystem.channel_units``): every channel of
every shipped scene has one, it is a unit winder knows, and it is dimensionally right:
checked by hand for a few, and by the identities between channels (a rate is its quantity
per second, a surface speed an angular speed times a radius, a torque a force times a
length)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import winder
from winder.model.units import DIMENSIONS, dimensions, fmi_name
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[2]
SCENES = sorted(p.stem for p in (ROOT / "models").glob("*.toml"))
N = {"kg": 1, "m": 1, "s": -2}  # the newton, by hand


def _sub(a: dict[str, int], b: dict[str, int]) -> dict[str, int]:
    out = {k: a.get(k, 0) - b.get(k, 0) for k in {*a, *b}}
    return {k: v for k, v in out.items() if v}


def _add(a: dict[str, int], b: dict[str, int]) -> dict[str, int]:
    return _sub(a, {k: -v for k, v in b.items()})


@pytest.fixture(scope="module", params=SCENES)
def units(request) -> tuple[str, dict[str, str]]:
    scene = winder.load_scene(ROOT / "models" / f"{request.param}.toml")
    return request.param, MachineSystem(scene, backend="pinocchio").channel_units


def test_every_channel_of_a_shipped_scene_has_a_known_unit(units) -> None:
    """The channels with units are exactly the scene's result channels (those of its saved
    reference result), each unit in the table of :mod:`winder.model.units`."""
    name, u = units
    with np.load(ROOT / "tests" / "data" / "shipped" / f"{name}.npz") as saved:
        assert set(u) == set(saved.files) - {"__meta__"}
    assert all(unit in DIMENSIONS for unit in u.values()), u


def test_units_by_hand_and_by_identity(units) -> None:
    _, u = units
    dim = {k: dimensions(v) for k, v in u.items()}
    assert dim["t"] == {"s": 1}
    checked = 0
    for ch, d in dim.items():
        base = ch[:-len("_inertia_rate")] if ch.endswith("inertia_rate") else None
        if ch.endswith("normal_force") or ch.endswith("friction_force") or \
                ch.endswith("span_tension") or ch.endswith("web_force"):
            assert d == N, ch
        elif ch.endswith("_speed") and not ch.endswith("web_speed"):
            assert d == {"rad": 1, "s": -1}, ch  # an angular speed
        elif ch.endswith("slip_velocity") or ch.endswith("web_speed"):
            assert d == {"m": 1, "s": -1}, ch
        elif base is not None:
            inertia = "inertia" if ch == "inertia_rate" else f"{base}_inertia"
            assert d == {"kg": 1, "m": 2, "s": -1}, ch  # kg·m²/s by hand
            assert d == _sub(dim[inertia], dim["t"])  # and J per second
        elif ch.endswith("mass_rate"):
            assert d == _sub(dim[ch[:-len("_rate")]], dim["t"]) == {"kg": 1, "s": -1}
        elif ch.endswith("_dot"):  # NAME_x_dot, NAME_z_dot, z_dot: the position per second
            assert d == _sub(dim[ch[:-len("_dot")]], dim["t"]) == {"m": 1, "s": -1}, ch
        elif ch.endswith("_accel"):  # a speed per second
            speed = ch[:-len("_accel")] + ("_dot" if ch[:-len("_accel")][-1] in "xz"
                                           else "_speed")
            assert d == _sub(dim[speed], dim["t"]), ch
        elif ch.endswith("torque"):  # a force times a length
            assert d == _add(N, {"m": 1}) == dimensions("N·m"), ch
        else:
            continue
        checked += 1
    assert checked >= len(u) // 2
    if "web_speed" in u:  # the surface speed: an angular speed times a radius, per radian
        speed = "drum_speed" if "drum_speed" in u else next(k for k in u if k.endswith(
            "_speed") and k != "web_speed")
        radius = "radius" if "radius" in u else next(k for k in u if k.endswith("_radius"))
        assert dim["web_speed"] == _sub(_add(dim[speed], dim[radius]), {"rad": 1})


def test_fmi_names_are_ascii() -> None:
    assert fmi_name("kg·m²/s") == "kg.m2/s" and fmi_name("N·m") == "N.m"
    assert fmi_name("m/s²") == "m/s2" and fmi_name("-") == "1"
    assert all(fmi_name(u).isascii() for u in DIMENSIONS)
    assert len({fmi_name(u) for u in DIMENSIONS}) == len(DIMENSIONS)
    with pytest.raises(winder.ModelError, match="furlong"):
        dimensions("furlong")
