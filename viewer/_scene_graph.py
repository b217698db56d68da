"""meshcat scene graph of a winder: drum, roll (core, paper, face mark, CoM marker), floor.

Placements come from the Pinocchio model's joint frames (``data.oMi``), never from
re-derived formulas. The roll's paper grows by scaling its node (meshcat scales via the
``scale`` property; set_transform's scale is dropped by animations in meshcat 0.3.2).
"""

from __future__ import annotations

from dataclasses import dataclass

import meshcat
import meshcat.geometry as g
import numpy as np
import pinocchio as pin

from winder._model import DRUM, ROLL, WinderModel
from winder._scene import Scene

__all__ = ["WinderGraph", "COLOURS", "COM_MARKER_GAIN"]

#: Colours (hex RGB) of the parts; the browser test looks for them.
COLOURS = {"drum": 0x3A6EA5, "paper": 0xF2E6C9, "core": 0x8B5A2B, "mark": 0xC0392B,
           "com": 0x27AE60, "floor": 0x9E9E9E, "frame": 0x555555}
#: The CoM offset (1 mm) is drawn this many times larger so that it can be seen.
COM_MARKER_GAIN = 100.0


@dataclass
class WinderGraph:
    """Builds the meshcat objects of a scene and poses them from a state.

    Parameters
    ----------
    scene: the winder scene (sizes). ``root`` is the meshcat path of the winder.
    """

    scene: Scene
    root: str = "winder"

    def __post_init__(self) -> None:
        self.model = WinderModel(self.scene).model
        self.data = self.model.createData()

    # ---- objects --------------------------------------------------------------------
    def build(self, vis: meshcat.Visualizer) -> None:
        """Create all objects (unit-radius paper, scaled later) and the camera."""
        s, root = self.scene, vis[self.root]
        R, L = s.drum.radius, s.roll.width
        rc = s.roll.core_radius
        lam = g.MeshLambertMaterial
        # meshcat cylinders lie along their local y axis: the machine's cross axis
        root["drum"]["shell"].set_object(g.Cylinder(1.05 * L, R), lam(color=COLOURS["drum"]))
        root["drum"]["mark"].set_object(g.Box([0.9 * R, 1.06 * L, 0.04 * R]),
                                        lam(color=COLOURS["frame"]))
        root["drum"]["mark"].set_transform(_translation([0.45 * R, 0.0, 0.0]))
        root["roll"]["core"].set_object(g.Cylinder(1.08 * L, rc), lam(color=COLOURS["core"]))
        root["roll"]["paper"].set_object(g.Cylinder(L, 1.0), lam(color=COLOURS["paper"]))
        # a radial stripe on the face, child of the scaled paper: grows with the roll
        root["roll"]["paper"]["mark"].set_object(g.Box([1.0, 1.01 * L, 0.06]),
                                                 lam(color=COLOURS["mark"]))
        root["roll"]["paper"]["mark"].set_transform(_translation([0.5, 0.0, 0.0]))
        root["roll"]["com"].set_object(g.Sphere(0.03), lam(color=COLOURS["com"]))
        e = s.roll.com_offset if s.effects.imbalance else 0.0
        root["roll"]["com"].set_transform(
            _translation([COM_MARKER_GAIN * e, -0.56 * L, 0.0]))
        # context: floor and the far side frame carrying the drum bearing (the near one
        # would hide the nip from the camera)
        floor_z = -R - 0.35
        root["floor"].set_object(g.Box([4.0, 2.0 * L, 0.05]), lam(color=COLOURS["floor"]))
        root["floor"].set_transform(_translation([0.0, 0.0, floor_z]))
        root["frame"]["far"].set_object(g.Box([0.25, 0.08, -floor_z]),
                                        lam(color=COLOURS["frame"]))
        root["frame"]["far"].set_transform(_translation([0.0, 0.62 * L, floor_z / 2]))
        vis["/Grid"].set_property("visible", False)
        vis["/Axes"].set_property("visible", False)
        self.set_camera(vis)

    def set_camera(self, vis: meshcat.Visualizer, distance: float | None = None) -> None:
        """Look along the cross-machine axis (world ``y``) at the nip region."""
        s = self.scene
        top = s.drum.radius + 2.0 * 0.9  # roll top at full size (r ≈ 0.84 m)
        d = distance or 4.4
        # the camera node is in three.js coordinates (y up): world (x, y, z) → (x, z, −y)
        vis["/Cameras/default"].set_transform(_translation([0.0, 0.0, 0.5 * top]))
        vis["/Cameras/default/rotated/<object>"].set_property("position", [0.0, 0.0, d])

    # ---- poses ----------------------------------------------------------------------
    def poses(self, drum_angle: float, z: float, roll_angle: float
              ) -> tuple[np.ndarray, np.ndarray]:
        """World placements (4×4) of the drum and roll frames, from Pinocchio FK."""
        q = np.array([drum_angle, z, roll_angle])
        pin.forwardKinematics(self.model, self.data, q)
        return (self.data.oMi[DRUM].homogeneous.copy(),
                self.data.oMi[ROLL].homogeneous.copy())

    def show(self, vis: meshcat.Visualizer, *, drum_angle: float, z: float,
             roll_angle: float, radius: float) -> None:
        """Pose the graph at one state (live view, snapshots)."""
        Td, Tr = self.poses(drum_angle, z, roll_angle)
        root = vis[self.root]
        root["drum"].set_transform(Td)
        root["roll"].set_transform(Tr)
        root["roll"]["paper"].set_property("scale", [radius, 1.0, radius])


def _translation(p: list[float]) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T
