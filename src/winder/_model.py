"""The winder as a Pinocchio model: drum (revolute +y) and roll (prismatic z + revolute −y).

Joint frames coincide with the world at ``q = 0``; the roll's revolute axis is ``−y`` so
that positive roll speed moves its bottom surface towards ``+x`` (spec §1).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ._mass_law import PaperRollLaw
from ._scene import Scene

__all__ = ["WinderModel", "DRUM", "ROLL_Z", "ROLL"]

DRUM, ROLL_Z, ROLL = 1, 2, 3  # joint ids (fixed by construction)


class WinderModel:
    """Builds the Pinocchio model of a scene and holds the roll's mass law.

    Attributes
    ----------
    model: the :class:`pinocchio.Model` (q = (θ_d, z, φ), v = (Ω, ż, ω)).
    law: :class:`PaperRollLaw` of the roll, without imbalance (an effect adds it).
    """

    def __init__(self, scene: Scene) -> None:
        self.law = PaperRollLaw(core_radius=scene.roll.core_radius,
                                core_mass=scene.roll.core_mass,
                                core_inertia=scene.roll.core_inertia,
                                width=scene.roll.width, density=scene.paper.density,
                                com_offset=0.0)  # the imbalance effect sets it
        model = pin.Model()
        model.name = scene.name
        jd = model.addJoint(0, pin.JointModelRY(), pin.SE3.Identity(), "drum")
        Md, Jd, L = scene.drum.mass, scene.drum.inertia, scene.roll.width
        It = 0.5 * Jd + Md * L * L / 12.0  # hollow cylinder of the roll's width
        model.appendBodyToJoint(jd, pin.Inertia(Md, np.zeros(3), np.diag([It, Jd, It])),
                                pin.SE3.Identity())
        jz = model.addJoint(0, pin.JointModelPZ(), pin.SE3.Identity(), "roll_height")
        jr = model.addJoint(jz, pin.JointModelRevoluteUnaligned(np.array([0.0, -1.0, 0.0])),
                            pin.SE3.Identity(), "roll")
        model.appendBodyToJoint(jr, self.law.inertia(scene.roll.initial_radius),
                                pin.SE3.Identity())
        for name, jid in (("drum", jd), ("roll_axis", jz), ("roll", jr)):
            model.addFrame(pin.Frame(name + "_frame", jid, 0, pin.SE3.Identity(),
                                     pin.FrameType.OP_FRAME))
        model.gravity = pin.Motion.Zero()  # the gravity effect sets it
        assert (jd, jz, jr) == (DRUM, ROLL_Z, ROLL)
        self.model = model
        self.drum_radius = scene.drum.radius
        self.drum_inertia = Jd
