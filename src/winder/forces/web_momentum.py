"""Web momentum (machines.md §3): the paper entering a wound roll at its entry nip brings
its momentum, force ``ṁ u_a t`` at ``p_b`` (``u_b`` instead of ``u_a`` with contact off)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._base import ForceElement

if TYPE_CHECKING:
    from ..core.machine import Evaluation, Machine

__all__ = ["WebMomentum"]


class WebMomentum(ForceElement):
    """Momentum flux of the entering web on the wound roll; channel ``web_force`` [N]."""

    name = "web_momentum"
    order = 40

    def declare(self, machine: Machine) -> None:
        if machine.entry is not None:
            machine.channel("web_force")

    def apply(self, ev: Evaluation) -> None:
        entry = ev.machine.entry
        if entry is None:
            return
        ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
        u = ns.u_a if ev.machine.scene.effects.contact else ns.u_b
        f = b.mass_rate * u
        ev.add_force(b.body.name, f * ns.tx, f * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
        ev.set_channel("web_force", f)
