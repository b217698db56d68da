"""Slip relaxation (winder-model §4, machines.md §2): the friction force of each nip is a
state that follows the steady friction, ``dF_t/dt = (|u_a| + v_min)/σ · (F_ss − F_t)``,
``F_t(0) = 0``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder.forces._base import ForceElement
from winder.forces.contact import push

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["SlipRelaxation"]


class SlipRelaxation(ForceElement):
    """One friction state ``NIP.friction`` [N] per nip."""

    name = "slip_relaxation"
    doc = ("the friction force relaxes towards the steady slip force over relaxation_length "
           "(a state per nip); off: F_t = F_ss; needs contact")
    uses = frozenset({"steady_friction"})

    def declare(self, machine: Machine) -> None:
        for nip in machine.nips:
            f = nip.part.friction
            machine.parameter(f"{nip.name}.relaxation_length", f.relaxation_length)
            machine.parameter(f"{nip.name}.min_speed", f.min_speed)
            machine.state(f"{nip.name}.friction", 0.0)

    def apply(self, ev: Evaluation) -> None:
        mathns = ev.mathns
        for ns in ev.nips.values():
            n = ns.nip.name
            ft = ev.x(f"{n}.friction")
            ns.friction_force = ft
            ev.set_rate(f"{n}.friction", (mathns.fabs(ns.u_a) + ev.p(f"{n}.min_speed"))
                        / ev.p(f"{n}.relaxation_length") * (ns.steady_friction - ft))
            push(ev, ns, 0.0, ft)
