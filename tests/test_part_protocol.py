"""The part protocol (issue #22): a body type defined only here, registered with one line,
builds a machine and simulates on both backends; a body hung off another body (its declared
parent); the force elements ordered by what they provide and require; channel units; typed
mode kinds."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import machines as mc
import numpy as np
import pytest

import winder
from winder.forces import FORCES, RUN_ORDER, ForceElement
from winder.model.element_order import ElementOrderError, order_elements
from winder.model.locked_modes import ModeKind
from winder.model.machine import Machine
from winder.parts import PARTS, DrumPart, RigidDisc
from winder.scene import Effects, Scene, SceneInfo, Solver
from winder.solve.system import MachineSystem

TAU = 30.0  # [N·m]
J_DISC = 4.0  # [kg·m²]


@dataclass(frozen=True)
class DiscPart:
    """A disc: radius [m], inertia [kg·m²], mass [kg], centre [m] (in its parent's frame),
    torque [N·m] (operation sense), parent (None: the world)."""

    name: str
    radius: float
    inertia: float
    mass: float
    centre: tuple[float, float]
    torque: float = 0.0
    parent: str | None = None
    sense: int = 1


class DiscBody(RigidDisc):
    """A disc on a fixed axis (or on its parent), driven by a constant torque."""

    table = "disc"
    role = "drum"

    def __init__(self, part: Any, placed: Any) -> None:
        super().__init__(part)
        self.centre = tuple(part.centre)
        self.parent = part.parent
        self.torque_inputs = (f"{self.name}.torque",)

    def declare(self, machine: Machine) -> None:
        super().declare(machine)
        machine.parameter(f"{self.name}.torque", self.part.torque)

    def drive_torque(self, ev: Any) -> Any:
        return ev.p(f"{self.name}.torque")


@dataclass(frozen=True)
class DiscScene(Scene):
    """A scene that also lists discs."""

    discs: tuple[DiscPart, ...] = ()


@pytest.fixture
def discs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(PARTS, "discs", DiscBody)  # the one registration line


def _scene(*parts: DiscPart, duration: float = 2.0) -> DiscScene:
    """The discs beside a drum standing still (a result's metadata names a drum)."""
    drum = DrumPart("drum", 0.5, 100.0, 500.0, (-3.0, 0.0))
    return DiscScene(scene=SceneInfo(name="discs", duration=duration, output_step=0.1,
                                     gravity=9.81),
                     effects=Effects(), drum=None, roll=None, paper=None, contact=None,
                     friction=None, solver=Solver(rtol=1e-10, atol=1e-12), drums=(drum,),
                     discs=parts)


@pytest.mark.parametrize("backend", ["compiled", "pinocchio"])
def test_new_body_type_simulates(discs: None, backend: str) -> None:
    """A disc under a constant torque: ``ω(t) = τ t / J``, ``angle = τ t² / 2J``
    (closed form), its torque channel the input, in its units."""
    scene = _scene(DiscPart("disc", 0.3, J_DISC, 50.0, (0.0, 1.0), torque=TAU))
    m = Machine(scene)
    assert [type(b).__name__ for b in m.bodies] == ["DrumBody", "DiscBody"]
    assert m.state_names == ["disc.theta", "disc.theta_dot"]  # the drum is prescribed
    assert m.channel_units["disc_speed"] == "rad/s"
    r = winder.simulate(scene, backend=backend)
    t = r.t
    assert t[-1] == pytest.approx(2.0)
    np.testing.assert_allclose(r["disc_speed"], TAU * t / J_DISC, rtol=0, atol=1e-8)
    np.testing.assert_allclose(r["disc_angle"], TAU * t**2 / (2 * J_DISC), rtol=0,
                               atol=1e-8)
    np.testing.assert_allclose(r["disc_torque"], TAU, rtol=1e-12)


def test_body_hangs_off_its_parent(discs: None) -> None:
    """A free disc pinned at ``d`` on a driven disc (the parent declared, not the world):
    the pinned disc keeps its absolute orientation (no torque on its pin), so the driven
    one turns as a rigid body of inertia ``J₁ + m₂ d²``: ``ω₁ = τ t / (J₁ + m₂ d²)`` and
    the pin's relative rate ``θ̇₂ = −ω₁``."""
    d, m2 = 0.5, 20.0
    scene = _scene(DiscPart("hub", 0.8, J_DISC, 60.0, (0.0, 2.0), torque=TAU),
                   DiscPart("planet", 0.1, 0.05, m2, (d, 0.0), parent="hub"))
    m = Machine(scene)
    model = m.model
    hub, planet = m.body["hub"], m.body["planet"]
    assert model.parents[planet.joints["theta"]] == hub.joints["theta"]
    assert model.parents[hub.joints["theta"]] == 0
    np.testing.assert_array_equal(model.jointPlacements[planet.joints["theta"]].translation,
                                  [d, 0.0, 0.0])
    sys_ = MachineSystem(scene, backend="pinocchio")
    sys_.params[m.param_index("gravity")] = 0.0
    sys_.params[m.param_index("planet.torque")] = 0.0
    f = sys_.rhs(0.0, sys_.initial_state())
    alpha = TAU / (J_DISC + m2 * d * d)
    assert f[m.index("hub.theta_dot")] == pytest.approx(alpha, rel=1e-12)
    assert f[m.index("planet.theta_dot")] == pytest.approx(-alpha, rel=1e-12)


# ---- provides / requires -----------------------------------------------------------------
def _element(name: str, provides: tuple[str, ...] = (), requires: tuple[str, ...] = (),
             uses: tuple[str, ...] = ()) -> ForceElement:
    cls = type(name, (ForceElement,), {"name": name, "provides": frozenset(provides),
                                       "requires": frozenset(requires),
                                       "uses": frozenset(uses)})
    return cls()


def test_order_follows_the_declarations() -> None:
    """Readers after their providers, whatever the given order; ties keep it."""
    a = _element("a", requires=("q",))
    b = _element("b", provides=("p",))
    c = _element("c", provides=("q",), uses=("p",))
    d = _element("d")
    e = _element("e", uses=("nobody",))  # used but not provided: no constraint
    order = [x.name for x in order_elements([a, b, c, d, e])]
    assert order == ["b", "c", "a", "d", "e"]
    assert [x.name for x in order_elements([d, c, a, b, e])] == ["d", "b", "c", "a", "e"]


def test_order_cycle_and_missing_provider_raise() -> None:
    x = _element("x", provides=("p",), requires=("q",))
    y = _element("y", provides=("q",), requires=("p",))
    with pytest.raises(ElementOrderError, match="cycle") as info:
        order_elements([x, _element("z"), y])
    assert "'x'" in str(info.value) and "'y'" in str(info.value)
    with pytest.raises(ElementOrderError, match="'w' requires 'span_rate'"):
        order_elements([_element("w", requires=("span_rate",))])
    assert isinstance(info.value, ValueError)  # a WinderError: ModelError


def test_machine_orders_its_force_elements() -> None:
    """The winder line: web_tension (span rate) before tension_control (drive torque);
    imbalance (com_offset) before variable_mass; contact before slip_relaxation; the rest
    in the run order of the effects (RUN_ORDER)."""
    m = Machine(winder.load_scene("models/winder_line.toml"))
    names = [f.name for f in m.forces]
    assert names.index("web_tension") < names.index("tension_control")
    assert names.index("imbalance") < names.index("variable_mass")
    assert names.index("contact") < names.index("slip_relaxation")
    registered = list(RUN_ORDER)
    assert set(registered) == set(FORCES)
    assert [n for n in names if n in registered] == \
        sorted((n for n in names if n in registered), key=registered.index)


# ---- units and mode kinds -----------------------------------------------------------------
UNITS = {"rad/s", "rad", "N·m", "rad/s²", "m", "m/s", "m/s²", "kg", "kg·m²", "kg/s",
         "kg·m²/s", "N", "N/s", "-", "s"}


@pytest.mark.parametrize("path", ["models/two_drum_winder.toml", "models/winder_line.toml",
                                  "models/paper_winding.toml"])
def test_channel_units(path: str) -> None:
    """Every channel the system returns has a unit (the same keys, in order), and the
    units follow the quantity (machines.md §9)."""
    sys_ = MachineSystem(winder.load_scene(path), backend="pinocchio")
    y = sys_.initial_state()
    channels = sys_.channels(np.array([0.0]), y[:, None])
    units = sys_.channel_units
    assert list(units) == list(channels)
    assert set(units.values()) <= UNITS
    assert units["t"] == "s"
    expect = {"_speed": "rad/s", "_angle": "rad", "_torque": "N·m", "_radius": "m",
              "_mass": "kg", "_inertia": "kg·m²", "_normal_force": "N",
              "_slip_velocity": "m/s", "_z_dot": "m/s", "_mass_rate": "kg/s",
              "_inertia_rate": "kg·m²/s", "span_tension": "N", "_penetration": "m"}
    for name, unit in units.items():
        for suffix, want in expect.items():
            if name.endswith(suffix) and not name.endswith("_web_speed") \
                    and name != "web_speed":
                assert unit == want, (name, unit)


def test_mode_kinds_are_typed() -> None:
    """Each mode slot carries its kind; the integrators' table rows come from it."""
    m = Machine(mc.two_drum())
    kinds = {mode.name: mode.kind for mode in m.modes}
    assert kinds == {"front_nip.contact": ModeKind.CONTACT,
                     "rear_nip.contact": ModeKind.CONTACT,
                     "set.core": ModeKind.CORE,
                     "rider_nip.contact": ModeKind.CONTACT}
    sys_ = MachineSystem(mc.two_drum(), backend="pinocchio")
    core = m.modes[m.mode_names.index("set.core")]
    row = sys_.table[m.mode_names.index("set.core")]
    assert list(row) == [int(ModeKind.CORE), m.switch_names.index("set.unwound"),
                         m.switch_names.index("set.forward"), m.index("set.radius"),
                         m.param_index("set.core_radius")]
    assert core.owner == "set"
    with pytest.raises(TypeError, match="ModeKind"):
        m.mode("x.contact", ("x.g",), "contact", owner="x")  # type: ignore[arg-type]


def test_growth_law_and_drive_length_are_the_bodies(paper_scene) -> None:
    """The analyses ask the body elements (#22 D18): a wound roll's radius after ``L`` of
    paper is ``√(r₀² + h L/π)`` (machines.md §1 integrated), a drum's web over ``T`` at
    ``v`` follows its ramp ``a_w``; the resonance map's end radius and the sweep bands'
    no-slip end radius both come from ``radius_after``."""
    import math

    from winder.analysis.modes import wound_length
    from winder.analysis.sweep_summary import end_radius
    from winder.parts import body_elements

    drum, roll = body_elements(paper_scene)
    r0, h = paper_scene.roll.initial_radius, paper_scene.paper.caliper
    assert roll.radius_after(0.0) == r0
    assert roll.radius_after(100.0) == pytest.approx(math.sqrt(r0**2 + h * 100.0 / math.pi),
                                                     rel=1e-15)
    assert roll.least_radius == paper_scene.roll.core_radius and not drum.radius_state
    a, v = paper_scene.drum.drive.web_acceleration, 20.0
    tr = v / a
    assert drum.web_length(tr / 2, v) == pytest.approx(a * (tr / 2) ** 2 / 2, rel=1e-15)
    assert drum.web_length(3 * tr, v) == pytest.approx(v * 3 * tr - v * tr / 2, rel=1e-15)
    assert wound_length(paper_scene, v) == drum.web_length(paper_scene.scene.duration, v)
    T = paper_scene.scene.duration
    vd = paper_scene.drum.drive.web_speed  # the bands: full speed from t = 0 (documented)
    assert end_radius(paper_scene) == pytest.approx(roll.radius_after(vd * T), rel=1e-14)
