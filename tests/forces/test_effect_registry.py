"""A new effect is its module plus one registration line (issue #22): the worked example of
:class:`winder.forces.ForceElement` (a viscous bearing drag ``τ = −c ω`` with its own
setting ``c``), defined only here and registered in ``FORCES``, is a key of ``[effects]``,
a table ``[effects.bearing_drag]``, a section of the scene reference, and its physics is
the closed form of a drum spinning down: ``J ω̇ = −c ω`` → ``ω(t) = ω0 exp(−c t / J)``.
Off (its default here), it is never instantiated."""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

import winder
from winder._schema import Key
from winder.forces import FORCES, RUN_ORDER, ForceElement, force_elements
from winder.model.machine import Machine
from winder.scene import Effects
from winder.scene.reference import reference
from winder.scene.schema import EFFECT_NAMES, EFFECTS_KEYS, effect_names

J = 40.0  # drum inertia [kg·m²]
R = 0.5  # drum radius [m]
V0 = 5.0  # initial surface speed [m/s]: ω0 = V0 / R = 10 rad/s
C = 8.0  # drag coefficient [N·m·s/rad]: decay rate c / J = 0.2 /s


class BearingDrag(ForceElement):
    """Viscous drag in every body's bearings."""

    name = "bearing_drag"
    doc = "a viscous torque −c ω in every body's bearings"
    default = False  # off unless a scene switches it on
    settings = (Key(name="c", unit="N·m·s/rad", lo=0.0, hi=1e6, default=0.0,
                    doc="drag coefficient c"),)
    provides = frozenset({"spatial_force"})
    made: ClassVar[int] = 0  # instances (the test of "off costs nothing")

    def __init__(self) -> None:
        type(self).made += 1

    def declare(self, machine: Any) -> None:
        machine.parameter("bearing_drag.c", machine.scene.effects.setting(self.name, "c"))

    def apply(self, ev: Any) -> None:
        c = ev.p("bearing_drag.c")
        for name, bs in ev.bodies.items():  # [f; τ] in the joint frame, τ_y
            ev.add_spatial_force(name, [0.0, 0.0, 0.0, 0.0, -c * bs.omega, 0.0])


@pytest.fixture
def registered(monkeypatch: pytest.MonkeyPatch) -> type[BearingDrag]:
    """The one registration line, for this test only."""
    monkeypatch.setitem(FORCES, "bearing_drag", BearingDrag)
    monkeypatch.setattr(BearingDrag, "made", 0)
    return BearingDrag


def _scene(tmp_path: Path, effects: str) -> Path:
    path = tmp_path / "spin_down.toml"
    path.write_text(f"""
[scene]
name = "spin_down"
duration = 2.0
output_step = 0.1

[effects]
contact = false
slip_relaxation = false
{effects}

[[drum]]
name = "drum"
centre = [0.0, 0.0]
radius = {R}
inertia = {J}
mass = 200.0
drive = {{ kind = "torque", torque = 0.0, web_speed = {V0} }}

[solver]
rtol = 1e-10
atol = 1e-12
""", encoding="utf-8")
    return path


#: The ``[effects]`` keys machines.md §8 binds, in its order (a registered effect may follow).
SPEC_EFFECTS = ("variable_mass", "web_momentum", "web_tension", "gravity", "imbalance",
                "contact", "slip_relaxation", "rider_load")


def test_the_effects_are_the_registry_in_spec_order() -> None:
    assert tuple(n for n in EFFECT_NAMES if n in SPEC_EFFECTS) == SPEC_EFFECTS
    assert EFFECT_NAMES == tuple(FORCES) == effect_names() == EFFECTS_KEYS.names()
    assert set(RUN_ORDER) == set(FORCES)
    assert all(k.default is True for k in EFFECTS_KEYS)  # the built-in ones are on
    assert EFFECTS_KEYS["gravity"].doc == FORCES["gravity"].doc == "gravity; off: g = 0"


def test_registered_effect_is_a_key_with_its_setting(registered, tmp_path) -> None:
    assert effect_names()[-1] == "bearing_drag" and "bearing_drag" in EFFECTS_KEYS
    s = winder.load_scene(_scene(tmp_path, f"[effects.bearing_drag]\nc = {C}"))
    assert s.effects.bearing_drag and s.effects.setting("bearing_drag", "c") == C
    assert s.effects.enabled()[-1] == "bearing_drag"
    assert s.effects.to_dict()["bearing_drag"] == {"enabled": True, "c": C}
    assert s.replace(effects={"bearing_drag": {"c": 1.0}}).effects.setting(
        "bearing_drag", "c") == 1.0
    plain = winder.load_scene(_scene(tmp_path, "bearing_drag = true"))
    assert plain.effects.setting("bearing_drag", "c") == 0.0  # its declared default
    off = winder.load_scene(_scene(tmp_path, ""))
    assert not off.effects.bearing_drag  # its default: off
    assert Effects(bearing_drag=True).bearing_drag and not Effects().bearing_drag
    with pytest.raises(winder.SceneError,
                       match=r"\[effects.bearing_drag\] c: must be >= 0 and <= 1e\+06"):
        winder.load_scene(_scene(tmp_path, "[effects.bearing_drag]\nc = -1.0"))
    with pytest.raises(winder.SceneError, match=r"valid keys: .*rider_load, bearing_drag$"):
        winder.load_scene(_scene(tmp_path, "bearing_drags = true"))


def test_registered_effect_is_documented(registered) -> None:
    text = reference()
    assert ("| `bearing_drag` | boolean | - |  | false | a viscous torque −c ω in every "
            "body's bearings |") in text
    assert "### `[effects.bearing_drag]`" in text
    assert "| `c` | number | N·m·s/rad | [0, 1e6] | 0 | drag coefficient c |" in text


def test_an_effect_that_is_off_is_not_instantiated(registered, tmp_path) -> None:
    s = winder.load_scene(_scene(tmp_path, ""))
    m = Machine(s)
    assert "bearing_drag" not in [f.name for f in m.forces]
    winder.simulate(s, backend="pinocchio", t_end=0.2)
    assert registered.made == 0
    on = winder.load_scene(_scene(tmp_path, "bearing_drag = true"))
    assert [f.name for f in force_elements(on.effects, [])][-1] == "bearing_drag"
    assert registered.made == 1


@pytest.mark.parametrize("backend", ["pinocchio", "compiled"])
def test_bearing_drag_spins_a_drum_down_exponentially(registered, tmp_path, monkeypatch,
                                                      backend) -> None:
    """``J ω̇ = −c ω``: ``ω(t) = ω0 exp(−c t / J)`` and the drum's torque channel (its
    joint torque, no drive) is ``−c ω``; the compiled code is generated afresh."""
    monkeypatch.setenv("WINDER_CACHE_DIR", str(tmp_path / "cache"))
    s = winder.load_scene(_scene(tmp_path, f"[effects.bearing_drag]\nc = {C}"))
    res = winder.simulate(s, backend=backend)
    t, w = res["t"], res["drum_speed"]
    omega = V0 / R * np.exp(-C * t / J)
    assert t[-1] == pytest.approx(2.0)
    np.testing.assert_allclose(w, omega, rtol=1e-8, atol=0.0)
    np.testing.assert_allclose(res["drum_accel"], -C * omega / J, rtol=1e-6, atol=1e-9)
    free = winder.simulate(_scene(tmp_path, "bearing_drag = true"), backend=backend)
    np.testing.assert_allclose(free["drum_speed"], V0 / R, rtol=1e-12)  # c = 0: no drag
