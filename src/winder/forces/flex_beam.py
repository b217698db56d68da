"""The elastic and damping forces of flexible bodies (issue #25): bending between the
segments of each flexible body through the condensed beam, its bearings and its Rayleigh
damping (:mod:`winder.model.beam`), and torsion between neighbouring segments.

Called for by every segment of a flexible body (its ``drives``: ``("flex_beam",)``), so a
machine without flexible bodies never builds it. Per flexible body ``NAME`` with segments
``NAME_s0 … NAME_s{N−1}`` (deflections ``u_i = c_i − c`` from its ``centre`` [m], rates
``u̇_i`` [m/s]; angles ``θ_i`` [rad] and rates ``θ̇_i`` [rad/s] about ``+y``):

    f_x,i = −Σ_j K_ij u_x,j − Σ_j C_ij u̇_x,j     (and the same in z)        [N]
    τ_i   = k_t (θ_{i+1} − θ_i) + c_t (θ̇_{i+1} − θ̇_i)  on i, its reaction on i + 1  [N·m]

with the run-time parameters ``NAME.flex.K_i_j`` [N/m], ``NAME.flex.C_i_j`` [N·s/m]
(``i ≤ j``, symmetric), ``NAME.flex.k_t`` [N·m/rad] and ``NAME.flex.c_t`` [N·m·s/rad]. The
torsion torques go in as spatial forces (they are not part of a segment's ``NAME_s{i}_torque``
channel, which keeps machines.md §9's meaning). Channel ``NAME_twist`` [rad]: the drive
end's angle minus the far end's, operation sense.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder._schema import Channel
from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["FlexBeam", "TWIST"]

#: A flexible body's twist.
TWIST = Channel(name="BODY_twist", unit="rad",
                doc="flexible drum: twist, angle of segment 0 (drive end) minus that of the "
                    "last segment, operation sense")


class FlexBeam(ForceElement):
    """Bending (condensed beam, bearings, Rayleigh damping) and torsion of flexible
    bodies."""

    name = "flex_beam"
    doc = "bending and torsion between the segments of a flexible body"
    provides = frozenset({"spatial_force"})
    CHANNELS = (TWIST,)

    def __init__(self) -> None:
        #: the segment bodies of each flexible body, by its name, drive end first
        self.groups: dict[str, list[Any]] = {}

    def declare(self, machine: Machine) -> None:
        from winder.model.beam import beam_matrices  # NumPy: not for checking a scene

        self.groups = {}
        for b in machine.bodies:
            if self.name in b.drives:
                self.groups.setdefault(b.drum, []).append(b)
        for body, segs in self.groups.items():
            segs.sort(key=lambda s: s.index)
            first = segs[0]
            flex, part, n = first.flex, first.part, len(segs)
            bm = beam_matrices(n, first.length, part.mass, flex.EI,
                               flex.kGA if flex.shear else None, flex.bearing_stiffness,
                               flex.bearing_damping, flex.damping_ratio, flex.GJ)
            for i in range(n):
                for j in range(i, n):
                    machine.parameter(f"{body}.flex.K_{i}_{j}", bm.K[i, j])
            for i in range(n):
                for j in range(i, n):
                    machine.parameter(f"{body}.flex.C_{i}_{j}", bm.C[i, j])
            machine.parameter(f"{body}.flex.k_t", bm.k_t)
            machine.parameter(f"{body}.flex.c_t", bm.c_t)
            machine.channel(TWIST, body)

    def structure_tag(self, machine: Machine) -> str:
        return ",".join(f"{body}:{len(segs)}" for body, segs in self.groups.items())

    def apply(self, ev: Evaluation) -> None:
        for body, segs in self.groups.items():
            n = len(segs)
            states = [ev.bodies[s.name] for s in segs]
            cx, cz = segs[0].centre
            ux = [bs.cx - cx for bs in states]
            uz = [bs.cz - cz for bs in states]

            def entry(kind: str, i: int, j: int, body: str = body) -> Any:
                return ev.p(f"{body}.flex.{kind}_{min(i, j)}_{max(i, j)}")

            for i, seg in enumerate(segs):
                fx: Any = 0.0
                fz: Any = 0.0
                for j, bs in enumerate(states):
                    k, c = entry("K", i, j), entry("C", i, j)
                    fx = fx - k * ux[j] - c * bs.vx
                    fz = fz - k * uz[j] - c * bs.vz
                ev.add_force(seg.name, fx, fz)
            kt, ct = ev.p(f"{body}.flex.k_t"), ev.p(f"{body}.flex.c_t")
            for i in range(n - 1):
                a, b = states[i], states[i + 1]
                tq = kt * (b.theta - a.theta) + ct * (b.omega - a.omega)
                ev.add_spatial_force(segs[i].name, [0.0, 0.0, 0.0, 0.0, tq, 0.0])
                ev.add_spatial_force(segs[i + 1].name, [0.0, 0.0, 0.0, 0.0, -tq, 0.0])
            ev.output(TWIST, body, segs[0].sense * (states[0].theta - states[-1].theta))
