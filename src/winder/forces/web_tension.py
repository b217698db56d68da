"""Web tension (machines.md §3): the wound roll pulls the web in, force ``−T t`` at the
entry point ``p_b``; ``T`` [N] is ``[web] tension``. The drum the web wraps carries no
net tension torque."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._base import ForceElement

if TYPE_CHECKING:
    from ..core.machine import Evaluation, Machine

__all__ = ["WebTension"]


class WebTension(ForceElement):
    """Constant web tension on the wound roll at its entry nip."""

    name = "web_tension"
    order = 40

    def declare(self, machine: Machine) -> None:
        if machine.entry is not None:
            machine.parameter("web.tension", machine.web.tension)

    def apply(self, ev: Evaluation) -> None:
        entry = ev.machine.entry
        if entry is None:
            return
        ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
        T = ev.p("web.tension")
        ev.add_force(b.body.name, -T * ns.tx, -T * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
