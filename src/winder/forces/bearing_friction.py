"""Bearing friction (machines.md §11): a passive torque in the bearings of every body whose
roles say its bearings carry one (:attr:`~winder.model.roles.Roles.bearing_torques`, an
idler roller), viscous and Coulomb, operation sense::

    τ = − c_v ω − τ_c tanh(ω / 0.1 rad/s)

with ``c_v`` = ``NAME.bearing_viscous`` [N·m·s/rad] and ``τ_c`` = ``NAME.bearing_coulomb``
[N·m], the body's own parameters. Called for by such a body (its ``drives``) where either
is not zero, so a machine without drag never builds it. The torque goes in as a spatial
force: it is not part of the body's ``NAME_torque`` channel.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation

__all__ = ["BearingFriction", "COULOMB_SPEED"]

#: [rad/s] the speed scale of the Coulomb torque's tanh
COULOMB_SPEED = 0.1


class BearingFriction(ForceElement):
    """Viscous and Coulomb drag in the bearings of the bodies that declare it."""

    name = "bearing_friction"
    provides = frozenset({"spatial_force"})

    def apply(self, ev: Evaluation) -> None:
        for b in ev.machine.bodies:
            if not b.roles.bearing_torques or self.name not in b.drives:
                continue
            n, bs = b.name, ev.bodies[b.name]
            w = bs.speed
            tau = -ev.p(f"{n}.bearing_viscous") * w \
                - ev.p(f"{n}.bearing_coulomb") * ev.mathns.tanh(w / COULOMB_SPEED)
            ev.add_spatial_force(n, [0.0, 0.0, 0.0, 0.0, b.sense * tau, 0.0])
