"""Rider load (machines.md §4): a vertical force ``−L · q(r_w)`` [N] at each rider's
centre; ``q`` [N/m] the line-load schedule over the ridden roll's radius (linear between
its points, constant beyond them), ``L`` the ridden roll's width."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder._schema import Channel, Key
from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["RiderLoad", "line_load"]


def line_load(mathns: Any, r: Any, points: list[tuple[Any, Any]]) -> Any:
    """``q(r)`` [N/m]: piecewise linear through ``points`` ``(radius, load)``, held
    constant beyond the first and the last."""
    q = points[-1][1]
    for (r0, q0), (r1, q1) in reversed(list(zip(points[:-1], points[1:], strict=True))):
        q = mathns.if_else(r < r1, q0 + (q1 - q0) * (r - r0) / (r1 - r0), q)
    return mathns.if_else(r < points[0][0], points[0][1], q)


class RiderLoad(ForceElement):
    """The applied load of every rider roll with a load schedule."""

    name = "rider_load"
    doc = "the riders' applied line load; off: only their weight"
    CHANNELS = (Channel(name="RIDER_load", unit="N",
                        doc="applied rider load L·q(r), acting downwards (−z)", whole="sum"),)
    settings = (Key(name="scale", unit="-", lo=0.0, hi=100.0, default=1.0,
                    doc="factor on every rider's line-load schedule (1: as given; 0: only "
                        "the riders' weight)"),)

    def declare(self, machine: Machine) -> None:
        from winder.model.slices import segments_of

        #: the body whose radius each rider's schedule reads: the roll, or a flexible
        #: roll's segment 0 (they share one radius)
        self.ridden: dict[str, str] = {}
        groups = segments_of(machine.bodies)
        scale = machine.scene.effects.setting(self.name, "scale")
        for b in _riders(machine):
            for i, (r, q) in enumerate(b.load):
                machine.parameter(f"{b.name}.load_radius_{i}", r)
                machine.parameter(f"{b.name}.line_load_{i}", q * scale)
            machine.channel(self.CHANNELS[0], b.name)
            ridden = b.roles.rides
            self.ridden[b.name] = groups[ridden][0].name if ridden in groups else ridden

    def apply(self, ev: Evaluation) -> None:
        for b in _riders(ev.machine):
            n = b.name
            pts = [(ev.p(f"{n}.load_radius_{i}"), ev.p(f"{n}.line_load_{i}"))
                   for i in range(len(b.load))]
            roll = ev.bodies[self.ridden[n]]
            f = ev.p(f"{b.roles.rides}.width") * line_load(ev.mathns, roll.r, pts) \
                if pts else 0.0
            seg = b.segment
            if seg is not None:  # a flexible rider's segment: its share
                f = f / seg.segments
            ev.add_force(n, 0.0, -f)
            ev.set_channel(f"{n}_load", f)


def _riders(machine: Machine) -> list[Any]:
    """The bodies that ride another under a line-load schedule (``rides``, ``load``)."""
    return [b for b in machine.bodies if b.roles.rides is not None]
