"""meshcat scene graph of any machine of parts: every body as a cylinder along ``y`` with a
radial mark (so that rotation shows), drawn as its element's
:meth:`~winder.parts.BodyElement.drawing` says (a paper roll: core and paper), the web
into its entry nip as a strip of segments (on a winder line from the unwinding roll), a
floor and the far side frames of the fixed stands (drums, unwinding rolls, rollers). A
web line runs over its rollers (:mod:`._line`); a dancer's roller rides its carriage
along a guide rail on the near side whose two end stops mark the ends of its travel.

Placements of the bodies come from the Pinocchio model of the machine
(:class:`winder.model.machine.Machine`: per body prismatic ``x``/``z`` where free, then a
revolute joint about ``+y``), posed by forward kinematics, never from re-derived formulas.
A paper roll grows by scaling its ``paper`` node (meshcat scales via the ``scale``
property; set_transform's scale is dropped by animations in meshcat 0.3.2); so does each
web segment along its own ``x`` axis.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin
from winder.viewer._motion import Motion, dancer_axes, web_points

from winder.model.machine import Machine
from winder.scene.load import Scene

__all__ = ["WinderGraph", "COLOURS", "COM_MARKER_GAIN", "DEFLECTION_GAIN", "WEB_THICKNESS",
           "FOV", "Pose", "apply_poses"]

#: Colours (hex RGB) of the parts; the browser tests look for them.
COLOURS = {"drum": 0x3A6EA5, "paper": 0xF2E6C9, "core": 0x8B5A2B, "mark": 0xC0392B,
           "com": 0x27AE60, "floor": 0x9E9E9E, "frame": 0x555555, "rider": 0x7D3C98,
           "web": 0xD4AC0D, "idler": 0x95A5A6, "rail": 0x2C3E50, "stop": 0xE67E22}
#: The CoM offset (1 mm) is drawn this many times larger so that it can be seen.
COM_MARKER_GAIN = 100.0
#: The segments of a flexible body are drawn along its axis, their offsets from the
#: segments' mean (its bending) this many times larger so that they can be seen.
DEFLECTION_GAIN = 200.0
#: Drawn thickness of the web strip [m] (its centre line is the web's path).
WEB_THICKNESS = 0.02
#: Vertical field of view of meshcat's camera [deg] and the aspect the framing assumes.
FOV, _ASPECT = 75.0, 4.0 / 3.0

#: A pose command: ("transform", path, 4×4) or ("scale", path, [sx, sy, sz]); paths are
#: relative to the graph's root.
Pose = tuple[str, tuple[str, ...], object]


@dataclass
class WinderGraph:
    """Builds the meshcat objects of a scene and poses them from a :class:`Motion`.

    Parameters
    ----------
    scene: the scene (parts and sizes). ``root`` is the meshcat path of the machine.
    """

    scene: Scene
    root: str = "winder"

    def __post_init__(self) -> None:
        self.machine = Machine(self.scene)
        self.model = self.machine.model
        self.data = self.model.createData()
        #: How each body is drawn (:meth:`~winder.parts.BodyElement.drawing`), by name.
        self.drawings = {b.name: b.drawing() for b in self.machine.bodies}
        #: Length of the drums [m]: the widest body's width (a paper roll's; the span of a
        #: flexible body's segments along the axis).
        self.length = max((2.0 * abs(d.y) + d.width for d in self.drawings.values()
                           if d.width is not None), default=1.0)
        #: Bodies on stands (drums and unwinding rolls: fixed centres) or, without any,
        #: every body: the floor spans them and each stand gets a far side frame.
        self.fixed = [b for b in self.machine.bodies if not b.free]
        self.stands = self.fixed or self.machine.bodies
        #: Height of the floor [m]: 0.35 m below the lowest stand.
        self.floor_z = min(b.centre[1] - _radius0(b) for b in self.stands) - 0.35
        self.roller_widths: dict[str, float] = {}  # (set below: they take their web's)
        entry = self.machine.entry
        self.web_width = 1.12 * (self._web_width(entry.b) if entry is not None
                                 else self.length)
        #: Node of each web's strip (``web`` for the first) and its width [m]: 1.12 × the
        #: width of the roll it enters.
        self.web_nodes = [("web" if i == 0 else f"web-{w.name}",
                           1.12 * self._web_width(w.entry.b))
                          for i, w in enumerate(self.machine.webs)]
        #: The drawn length of each roller of a web line [m]: 1.1 × its web's strip, so that
        #: its ends (and their marks, its rotation) show beside the web that wraps it.
        self.roller_widths = {s.downstream.name: 1.1 * width
                              for w, (_, width) in zip(self.machine.webs, self.web_nodes,
                                                       strict=True)
                              for s in w.spans if s.downstream is not None}
        #: Segments of each web's strip (its path's points less one, :func:`web_points`).
        self.web_segments = [web_points(w) - 1 for w in self.machine.webs]
        #: The travel axis of each dancer's carriage (:func:`dancer_axes`), by name.
        self.dancer_axes = dancer_axes(self.machine)

    def _web_width(self, body: object) -> float:
        """The width [m] of the roll a web enters (a flexible roll: its whole width)."""
        flexible = getattr(body, "segment_of", None) is not None
        return float(body.length) if flexible else self._width(body.name)

    def _width(self, name: str) -> float:
        """The drawn length along ``y`` [m] of body ``name``: its own width, the width of
        the body it takes it from, else the machine's (1.05 × :attr:`length`); a roller of a
        web line :attr:`roller_widths`."""
        d = self.drawings[name]
        if name in self.roller_widths:
            return self.roller_widths[name]
        if d.width is not None:
            return d.width
        if d.width_of is not None and d.width_of in self.drawings:
            return self._width(d.width_of)
        return 1.05 * self.length if d.width_of is None else self.length

    # ---- objects --------------------------------------------------------------------
    def build(self, vis: meshcat.Visualizer) -> None:
        """Create all objects (unit-radius paper, unit-length web segments) and a camera
        on the machine's initial layout."""
        root, L = vis[self.root], self.length
        lam = g.MeshLambertMaterial
        # meshcat cylinders lie along their local y axis: the machine's cross axis
        for b in self.machine.bodies:
            node, d = root[b.name], self.drawings[b.name]
            if d.core_radius is not None:  # a paper roll: core, paper scaled by its radius
                w, rc = self._width(b.name), d.core_radius
                node["core"].set_object(g.Cylinder(1.08 * w, rc), lam(color=COLOURS["core"]))
                node["paper"].set_object(g.Cylinder(w, 1.0),
                                         lam(color=COLOURS.get(d.colour, COLOURS["paper"])))
                # a radial stripe on the face, child of the scaled paper: grows with it
                node["paper"]["mark"].set_object(g.Box([1.0, 1.01 * w, 0.06]),
                                                 lam(color=COLOURS["mark"]))
                node["paper"]["mark"].set_transform(_translation([0.5, 0.0, 0.0]))
                node["com"].set_object(g.Sphere(0.03), lam(color=COLOURS["com"]))
                e = d.com_offset if self.scene.effects.imbalance else 0.0
                node["com"].set_transform(_translation([COM_MARKER_GAIN * e, -0.56 * w, 0.0]))
                continue
            R = b.initial_radius
            length = self._width(b.name)
            colour = COLOURS.get(d.colour, COLOURS["drum"])
            node["shell"].set_object(g.Cylinder(length, R), lam(color=colour))
            node["mark"].set_object(g.Box([0.9 * R, 1.01 * length + 0.01, 0.04 * R]),
                                    lam(color=COLOURS["frame"]))
            node["mark"].set_transform(_translation([0.45 * R, 0.0, 0.0]))
        for (node, web_width), count in zip(self.web_nodes, self.web_segments, strict=True):
            for i in range(count):
                root[node][f"s{i:02d}"]["strip"].set_object(
                    g.Box([1.0, web_width, WEB_THICKNESS]), lam(color=COLOURS["web"]))
        for b in self.machine.bodies:
            if b.name in self.dancer_axes:
                self._build_carriage(root, b)
        # context: floor and the far side frames carrying the drum bearings (the near ones
        # would hide the nips from the camera)
        # (a base plate 0.5 m wider than the stands: the web comes in past its edge)
        x0 = min(b.centre[0] - _radius0(b) for b in self.stands) - 0.5
        x1 = max(b.centre[0] + _radius0(b) for b in self.stands) + 0.5
        root["floor"].set_object(g.Box([x1 - x0, 1.2 * L, 0.05]),
                                 lam(color=COLOURS["floor"]))
        root["floor"].set_transform(_translation([0.5 * (x0 + x1), 0.0, self.floor_z]))
        for b in self.fixed:
            if b.name in self.dancer_axes:  # on its carriage's rail, not a stand
                continue
            h = b.centre[1] - self.floor_z
            root["frame"][b.name].set_object(g.Box([0.25, 0.08, h]),
                                             lam(color=COLOURS["frame"]))
            root["frame"][b.name].set_transform(
                _translation([b.centre[0], 0.62 * L, self.floor_z + 0.5 * h]))
        vis["/Grid"].set_property("visible", False)
        vis["/Axes"].set_property("visible", False)
        self.set_camera(vis, self.initial_extent())

    def _build_carriage(self, root, b) -> None:
        """A dancer's guide rail along its travel axis ``e`` on the near side (from
        ``lo − R`` to ``hi + R``), an end stop across it at each end of its travel
        (``home + lo e``, ``home + hi e``) and the carriage block (node ``carriage``,
        posed with the roller's centre)."""
        lam = g.MeshLambertMaterial
        e = np.array(self.dancer_axes[b.name])
        lo, hi = b.roles.dancer.travel
        R, y = b.initial_radius, -0.56 * self._width(b.name)
        home = np.array(b.centre, dtype=float)
        turn = pin.utils.rotate("y", math.atan2(-e[1], e[0]))  # box x axis along e

        def place(node, at: np.ndarray) -> None:
            node.set_transform(pin.SE3(turn, np.array([at[0], y, at[1]])).homogeneous)
        rail = root["carriage-rail"][b.name]
        rail["rail"].set_object(g.Box([hi - lo + 2 * R, 0.04, 0.03]),
                                lam(color=COLOURS["rail"]))
        place(rail["rail"], home + 0.5 * (lo + hi) * e)
        for end, d in (("lo", lo), ("hi", hi)):
            rail[end].set_object(g.Box([0.02, 0.06, 3.0 * R]), lam(color=COLOURS["stop"]))
            place(rail[end], home + d * e)
        root["carriage"][b.name].set_object(g.Box([1.6 * R, 0.08, 1.6 * R]),
                                            lam(color=COLOURS["rail"]))

    def initial_extent(self) -> tuple[float, float, float, float]:
        """``(x_min, x_max, z_min, z_max)`` [m] of the bodies at their scene centres."""
        xs = [v for b in self.machine.bodies
              for v in (b.centre[0] - _radius0(b), b.centre[0] + _radius0(b))]
        zs = [v for b in self.machine.bodies
              for v in (b.centre[1] - _radius0(b), b.centre[1] + _radius0(b))]
        return min(xs), max(xs), min(zs), max(zs)

    def camera(self, extent: tuple[float, float, float, float]
               ) -> tuple[float, float, float]:
        """Camera ``(x, z, d)`` [m] framing ``extent`` (``x_min, x_max, z_min, z_max``
        [m]) and the floor at a 4:3 aspect: it sits at ``(x, −d, z)`` in the machine's
        coordinates and looks along ``+y`` with ``z`` up (vertical field of view 75°)."""
        x0, x1, z0, z1 = extent
        z0 = min(z0, self.floor_z)
        half = max(0.5 * (z1 - z0), 0.5 * (x1 - x0) / _ASPECT) * 1.1 + 0.1
        d = half / math.tan(math.radians(FOV / 2)) + 0.55 * self.length
        return 0.5 * (x0 + x1), 0.5 * (z0 + z1), d

    def set_camera(self, vis: meshcat.Visualizer,
                   extent: tuple[float, float, float, float]) -> None:
        """Point meshcat's camera as :meth:`camera` says. meshcat 0.3.2's orbit controls
        always aim at the world origin, so the machine (the root node) is shifted by
        ``(−x, 0, −z)`` and the camera sits at ``(0, −d, 0)``."""
        x, z, d = self.camera(extent)
        vis[self.root].set_transform(_translation([-x, 0.0, -z]))
        vis["/Cameras/default"].set_transform(np.eye(4))
        # the camera node is in three.js coordinates (y up): world (x, y, z) → (x, z, −y)
        vis["/Cameras/default/rotated/<object>"].set_property("position", [0.0, 0.0, d])

    # ---- poses ----------------------------------------------------------------------
    def poses(self, frame: dict[str, tuple[float, float, float]]) -> dict[str, np.ndarray]:
        """World placements (4×4) of the bodies from ``frame`` = body name → centre ``x``,
        ``z`` [m] and model angle ``θ`` about ``+y`` [rad], by Pinocchio FK."""
        q = np.zeros(self.model.nq)
        mean: dict[str, list[float]] = {}
        for b in self.machine.bodies:  # flexible bodies: their segments' mean centre
            if b.segment_of is not None:
                x, z, _ = frame[b.name]
                acc = mean.setdefault(b.segment_of, [0.0, 0.0, 0.0])
                acc[0], acc[1], acc[2] = acc[0] + x, acc[1] + z, acc[2] + 1.0
        for b in self.machine.bodies:
            x, z, theta = frame[b.name]
            if b.segment_of is not None:  # its bending, exaggerated
                mx, mz, n = mean[b.segment_of]
                x = mx / n + DEFLECTION_GAIN * (x - mx / n)
                z = mz / n + DEFLECTION_GAIN * (z - mz / n)
            for coord, value in (("x", x), ("z", z), ("theta", theta)):
                if coord in b.joints:
                    q[self.model.joints[b.joints[coord]].idx_q] = value
        pin.forwardKinematics(self.model, self.data, q)
        out = {}
        for b in self.machine.bodies:
            pose = self.data.oMi[b.joints["theta"]].homogeneous.copy()
            if b.name in self.dancer_axes:  # a carriage the model does not move: its d
                x, z, _ = frame[b.name]
                pose[0, 3], pose[2, 3] = x, z
            pose[1, 3] += self.drawings[b.name].y  # a segment's place along the axis
            out[b.name] = pose
        return out

    def pose_commands(self, m: Motion, k: int) -> list[Pose]:
        """What to set to show sample ``k`` of ``m``: body placements, paper scales, the
        web's segments (placement, and length as the ``x`` scale of the unit strip)."""
        bodies = m.bodies
        T = self.poses({n: (b.x[k], b.z[k], b.theta[k]) for n, b in bodies.items()})
        out: list[Pose] = []
        for b in self.machine.bodies:
            out.append(("transform", (b.name,), T[b.name]))
            if b.name in self.dancer_axes:
                c = T[b.name][:3, 3]
                out.append(("transform", ("carriage", b.name),
                            _translation([c[0], -0.56 * self._width(b.name), c[2]])))
            if b.radius_state:
                r = float(bodies[b.name].radius[k])
                out.append(("scale", (b.name, "paper"), [r, 1.0, r]))
        for (node, _), path in zip(self.web_nodes, m.web_paths(k), strict=True):
            for i, (p, q) in enumerate(zip(path[:-1], path[1:], strict=True)):
                d = q - p
                length = max(float(np.hypot(*d)), 1e-9)
                S = pin.SE3(pin.utils.rotate("y", math.atan2(-d[1], d[0])),
                            np.array([0.5 * (p[0] + q[0]), 0.0, 0.5 * (p[1] + q[1])]))
                out.append(("transform", (node, f"s{i:02d}"), S.homogeneous))
                out.append(("scale", (node, f"s{i:02d}", "strip"), [length, 1.0, 1.0]))
        return out

    def show(self, vis: meshcat.Visualizer, m: Motion, k: int) -> None:
        """Pose the graph at sample ``k`` of ``m`` (live view, snapshots)."""
        apply_poses(vis[self.root], self.pose_commands(m, k),
                    lambda node, v: node.set_property("scale", v))


def apply_poses(root, commands: list[Pose], scale: Callable[[object, list], None]) -> None:
    """Send ``commands`` below ``root`` (a visualizer or an animation frame); ``scale``
    sets a node's scale (the two APIs differ)."""
    for kind, path, value in commands:
        node = root
        for part in path:
            node = node[part]
        if kind == "transform":
            node.set_transform(value)
        else:
            scale(node, [float(v) for v in value])


def _radius0(b) -> float:
    return b.initial_radius


def _translation(p: list[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T
