"""Variable mass: the spatial force ``−Ẏ v`` on every body whose mass properties change
(winder-model §3), in ABA and RNEA alike. Off → ``m(r)`` and ``J(r)`` still follow the
radius but ``Ẏ v`` is dropped (the naive "overwrite the inertia" model, for comparison)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation

__all__ = ["VariableMass", "inertia_times"]


def inertia_times(dyn: list[Any], v: list[Any]) -> list[Any]:
    """``Y v`` for the spatial inertia of the 10 dynamic parameters ``dyn`` (about the
    joint origin) and the spatial velocity ``v = [v; ω]``: ``[m v − (m c) × ω;
    (m c) × v + I_o ω]``."""
    m, cx, cy, cz = dyn[0], dyn[1], dyn[2], dyn[3]
    ixx, ixy, iyy, ixz, iyz, izz = dyn[4:10]
    vx, vy, vz, wx, wy, wz = v
    return [m * vx - (cy * wz - cz * wy), m * vy - (cz * wx - cx * wz),
            m * vz - (cx * wy - cy * wx),
            cy * vz - cz * vy + ixx * wx + ixy * wy + ixz * wz,
            cz * vx - cx * vz + ixy * wx + iyy * wy + iyz * wz,
            cx * vy - cy * vx + ixz * wx + iyz * wy + izz * wz]


class VariableMass(ForceElement):
    """``fext −= Ẏ v`` on every paper roll, ``Ẏ = dY/dr · ṙ``."""

    name = "variable_mass"
    doc = ("the −Ẏv force of mass that joins a body from rest; off: m(r) and J(r) still "
           "follow the radius, the term is dropped (the naive overwrite)")
    uses = frozenset({"com_offset"})
    provides = frozenset({"spatial_force"})

    def apply(self, ev: Evaluation) -> None:
        for b in ev.machine.variable_bodies:
            bs = ev.bodies[b.name]
            rate = ev.inertia_parameters(bs, rate=True)
            yv = inertia_times(rate, ev.joint_velocity(b.name))
            ev.add_spatial_force(b.name, [-f for f in yv])

    def static(self, ev: Evaluation) -> None:
        """No translational velocity in the static balance: nothing to add."""
