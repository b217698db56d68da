"""The part protocol (issue #22): a body type defined only here, registered with one line,
builds a machine and simulates on both backends; a body hung off another body (its declared
parent); the force elements ordered by what they provide and require; channel units; typed
mode kinds."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import machines as mc
import numpy as np
import pytest

import winder
from winder._schema import Key, Table
from winder.forces import FORCES, RUN_ORDER, ForceElement
from winder.model.element_order import ElementOrderError, order_elements
from winder.model.locked_modes import ModeKind
from winder.model.machine import Machine
from winder.parts import CENTRE, NAME, PARTS, Drawing, RigidDisc
from winder.scene import key_unit
from winder.scene.reference import reference
from winder.scene.schema import TABLES
from winder.solve.system import MachineSystem

TAU = 30.0  # [N·m]
J_DISC = 4.0  # [kg·m²]


@dataclass(frozen=True)
class DiscPart:
    """``[[disc]]``: keys, units and bounds: :data:`DISC_KEYS`."""

    name: str
    radius: float
    inertia: float
    mass: float
    centre: tuple[float, float]
    torque: float = 0.0
    parent: str | None = None
    sense: int = 1


#: The keys of ``[[disc]]``.
DISC_KEYS = Table((
    NAME,
    Key(name="radius", required=True, unit="m", lo=0.0, lo_open=True, hi=10.0,
        doc="disc radius"),
    Key(name="inertia", required=True, unit="kg·m²", lo=0.0, lo_open=True, hi=1e7,
        doc="polar inertia of the disc"),
    Key(name="mass", required=True, unit="kg", lo=0.0, lo_open=True, hi=1e6,
        doc="disc mass"),
    CENTRE,
    Key(name="torque", unit="N·m", hi=1e8, doc="the drive torque (operation sense)"),
    Key(name="parent", kind="ref", doc="the body it hangs off (its centre in that body's "
                                       "frame); none: the world"),
    Key(name="sense", kind="sense", doc="operation direction"),
))


class DiscBody(RigidDisc):
    """A disc on a fixed axis (or on its parent), driven by a constant torque."""

    table = "disc"
    role = "drum"
    KEYS = DISC_KEYS
    part_cls = DiscPart

    def __init__(self, part: Any, placed: Any) -> None:
        super().__init__(part)
        self.centre = tuple(part.centre)
        self.parent = part.parent
        self.torque_inputs = (f"{self.name}.torque",)

    @classmethod
    def initial_circle(cls, part: Any) -> Any:
        return None if part.parent else super().initial_circle(part)

    def declare(self, machine: Machine) -> None:
        super().declare(machine)
        machine.parameter(f"{self.name}.torque", self.part.torque)

    def drive_torque(self, ev: Any) -> Any:
        return ev.p(f"{self.name}.torque")

    def drawing(self) -> Drawing:
        return Drawing(colour="disc")  # not a colour of the viewer: it falls back


@pytest.fixture
def discs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(PARTS, "discs", DiscBody)  # the one registration line


#: The discs beside a drum standing still (a result's metadata names a drum).
HEAD = """
[scene]
name = "discs"
duration = 2.0
output_step = 0.1

[solver]
rtol = 1e-10
atol = 1e-12

[[drum]]
name = "drum"
radius = 0.5
inertia = 100.0
mass = 500.0
centre = [-3.0, 0.0]
drive = { kind = "speed_profile", web_speed = 0.0 }
"""
ONE_DISC = HEAD + f"""
[[disc]]
name = "disc"
radius = 0.3
inertia = {J_DISC}
mass = 50.0
centre = [0.0, 1.0]
torque = {TAU}
"""


def _scene(text: str) -> winder.Scene:
    return winder.scene_from_dict(tomllib.loads(text), source="discs.toml")


def test_new_body_type_loads_from_a_scene_file(discs: None, tmp_path: Path) -> None:
    """``[[disc]]`` is a table of a scene file at once: parsed against its keys into its
    dataclass, listed as ``scene.discs``, written back by ``to_dict`` and ``replace``."""
    path = tmp_path / "discs.toml"
    path.write_text(ONE_DISC, encoding="utf-8")
    scene = winder.load_scene(path)
    disc = DiscPart("disc", 0.3, J_DISC, 50.0, (0.0, 1.0), torque=TAU)
    assert scene.discs == (disc,)
    assert scene.bodies["discs"] == (disc,)
    assert [d.name for d in scene.drums] == ["drum"]
    assert scene.to_dict()["disc"] == [{"name": "disc", "radius": 0.3, "inertia": J_DISC,
                                        "mass": 50.0, "centre": [0.0, 1.0], "torque": TAU,
                                        "sense": 1}]
    assert winder.scene_from_dict(scene.to_dict(), source=str(path)) == scene
    assert scene.replace(disc={"disc": {"torque": 1.0}}).discs[0].torque == 1.0
    assert TABLES["disc[]"] is DISC_KEYS
    assert key_unit("disc.disc.torque") == "N·m"


def test_new_body_type_rejects_bad_keys(discs: None) -> None:
    """A bad value, an unknown key, a missing key: the standard messages, naming
    ``[disc 'disc']`` and the key (the same text as for a drum's)."""
    with pytest.raises(winder.SceneError) as bad:
        _scene(ONE_DISC.replace("radius = 0.3", "radius = -0.3"))
    with pytest.raises(winder.SceneError) as drum:
        _scene(ONE_DISC.replace("radius = 0.5", "radius = -0.3"))
    head = "discs.toml: [disc 'disc'] radius: "
    assert str(bad.value).startswith(head)
    assert str(bad.value)[len(head):] == \
        str(drum.value)[len("discs.toml: [drum 'drum'] radius: "):]
    with pytest.raises(winder.SceneError,
                       match=r"\[disc 'disc'\] colour: unknown key; valid keys: name, "
                             r"radius, inertia, mass, centre, torque, parent, sense"):
        _scene(ONE_DISC + 'colour = "red"\n')
    with pytest.raises(winder.SceneError, match=r"\[disc 'disc'\] mass: missing required"):
        _scene(ONE_DISC.replace("mass = 50.0\ncentre", "centre"))
    with pytest.raises(winder.SceneError,
                       match=r"\[disc 'disc'\] parent: 'nowhere' is not a body of the "
                             r"scene; valid names: drum, disc$"):
        _scene(ONE_DISC + 'parent = "nowhere"\n')
    with pytest.raises(winder.SceneError, match=r"'disc' is already the name of disc"):
        _scene(ONE_DISC + ONE_DISC[len(HEAD):])
    with pytest.raises(winder.SceneError, match=r"\[disc 'd2'\] centre: disc 'd2' .*overlaps "
                                                r"disc 'disc'"):
        _scene(ONE_DISC + ONE_DISC[len(HEAD):].replace('"disc"', '"d2"'))


def test_new_body_type_is_documented(discs: None) -> None:
    """The reference lists ``[[disc]]`` with its keys, after the built-in bodies."""
    text = reference()
    tables = [cls.table for cls in PARTS.values()]
    assert tables[-1] == "disc"
    assert ", ".join(f"`[[{t}]]`" for t in (*tables, "nip")) in text
    assert f"`BODY` is the name of any {', '.join(tables[:-1])} or disc" in text
    section = text[text.index("### `[[disc]]`"):text.index("### `[[nip]]`")]
    assert "| `torque` | number | N·m | \\|x\\| ≤ 1e8 | 0 | the drive torque" in section
    assert "| `radius` | number | m | (0, 10] | required | disc radius |" in section
    assert text.index("### `[[rider]]`") < text.index("### `[[disc]]`")


def test_new_body_type_is_drawn(discs: None) -> None:
    """The viewer draws a disc by its drawing spec (a cylinder as long as the machine;
    an unknown colour falls back to the drum's) and poses it by Pinocchio FK."""
    from winder.viewer import COLOURS, WinderGraph

    graph = WinderGraph(_scene(ONE_DISC))
    vis = _Recorder()
    graph.build(vis)
    shell = vis.objects["/winder/disc/shell"]
    assert shell[0] == pytest.approx((1.05 * graph.length, 0.3))
    assert shell[1] == COLOURS["drum"]
    T = graph.poses({"drum": (0.0, 0.0, 0.0), "disc": (0.0, 1.0, 0.4)})
    np.testing.assert_allclose(T["disc"][:3, 3], [0.0, 0.0, 1.0], atol=1e-15)


class _Recorder:
    """A stand-in for a meshcat visualizer: records each node's object (cylinder height
    and radius, colour)."""

    def __init__(self, path: str = "", objects: dict[str, Any] | None = None) -> None:
        self.path, self.objects = path, {} if objects is None else objects

    def __getitem__(self, name: str) -> _Recorder:
        return _Recorder(f"{self.path}/{name.strip('/')}", self.objects)

    def set_object(self, geometry: Any, material: Any) -> None:
        size = (geometry.height, geometry.radiusTop) if hasattr(geometry, "height") else None
        self.objects[self.path] = (size, material.color)

    def set_transform(self, T: Any) -> None:
        pass

    def set_property(self, key: str, value: Any) -> None:
        pass


@pytest.mark.parametrize("backend", ["compiled", "pinocchio"])
def test_new_body_type_simulates(discs: None, backend: str) -> None:
    """A disc under a constant torque: ``ω(t) = τ t / J``, ``angle = τ t² / 2J``
    (closed form), its torque channel the input, in its units."""
    scene = _scene(ONE_DISC)
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
    scene = _scene(HEAD + f"""
[[disc]]
name = "hub"
radius = 0.8
inertia = {J_DISC}
mass = 60.0
centre = [0.0, 2.0]
torque = {TAU}

[[disc]]
name = "planet"
radius = 0.1
inertia = 0.05
mass = {m2}
centre = [{d}, 0.0]
parent = "hub"
""")
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
