"""Web momentum (machines.md §3): paper entering a wound roll at its entry nip brings its
momentum, force ``ṁ u_a t`` at ``p_b`` (``u_b`` instead of ``u_a`` with contact off);
paper leaving an unwinding roll takes its own momentum with it (zero relative velocity),
force ``ṁ_u u_u t_u`` at the exit point ``p_u`` (``ṁ_u < 0``), so that a freely spinning
unwinding roll keeps its speed."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder._schema import Channel
from winder.forces._base import ForceElement
from winder.forces.web_tension import exit_point

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["WebMomentum"]


class WebMomentum(ForceElement):
    """Momentum flux of each web at its own entry nip and at its unwinding roll's exit
    point; channel ``web_force`` [N] (at the entry; ``WEB_web_force`` with several webs)."""

    name = "web_momentum"
    doc = ("the momentum flux ṁ u the web brings into a wound roll (and the leaving paper "
           "takes out of an unwinding one)")
    CHANNELS = (Channel(name="web_force", unit="N",
                        doc="web momentum force ṁ u on the wound roll"),)

    def declare(self, machine: Machine) -> None:
        for w in machine.webs:
            machine.channel(self.CHANNELS[0], w.channel)

    def apply(self, ev: Evaluation) -> None:
        m = ev.machine
        for w in m.webs:
            total: Any = 0.0
            for entry in w.entries:  # one; a flexible roll: each slice, its own ṁ_i
                ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
                u = ns.u_a if m.scene.effects.contact else ns.u_b
                f = b.mass_rate * u
                ev.add_force(b.body.name, f * ns.tx, f * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
                total = f if len(w.entries) == 1 else total + f
            ev.set_channel(f"{w.channel}web_force", total)
            if w.unwind is not None:
                un = ev.bodies[w.unwind.name]
                f = un.mass_rate * un.r * un.speed
                tx, tz, ox, oz = exit_point(ev, w)
                ev.add_force(un.body.name, f * tx, f * tz, ox, oz)
