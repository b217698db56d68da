"""Web tension (machines.md §3, §5): the wound roll pulls the web in, force ``−T t`` at its
entry point ``p_b``; the drum the web wraps carries no net tension torque. ``T`` [N] is
``[web] tension``, or, with ``[web.span]``, the span's tension state

    dT/dt = ( EA (v2 − v1) + v1 T_in − v2 T ) / L_s

(``v1`` the unwinding roll's surface speed, ``v2`` the entry drum's ``u_a``), which also
pulls the unwinding roll along ``+t_u`` at its exit point ``p_u`` (operation torque
``+r_u T``). A slack web pushes nothing: the forces use ``max(T, 0)``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._base import ForceElement

if TYPE_CHECKING:
    from ..core.machine import Evaluation, Machine

__all__ = ["WebTension", "exit_point"]


def exit_point(ev: Evaluation) -> tuple[Any, Any, Any, Any]:
    """``(t_x, t_z, o_x, o_z)``: the unit direction ``t_u`` in which the web leaves the
    unwinding roll (towards the entry drum's centre) and the exit point ``p_u − c_u``
    [m], on the side where the roll's surface moves along ``+t_u`` when it turns in its
    operation sense."""
    m, M = ev.machine, ev.M
    u, a = ev.bodies[m.unwind.name], ev.bodies[m.entry.a.name]
    dx, dz = a.cx - u.cx, a.cz - u.cz
    d = M.sqrt(dx * dx + dz * dz)
    tx, tz = dx / d, dz / d
    s = u.body.sense
    return tx, tz, -s * tz * u.r, s * tx * u.r


class WebTension(ForceElement):
    """The web's tension on the wound roll (and on the unwinding roll of a span)."""

    name = "web_tension"
    order = 40

    def declare(self, machine: Machine) -> None:
        span = machine.span
        if span is not None:
            t0 = span.T_in if span.initial_tension is None else span.initial_tension
            machine.state("span.tension", t0)
            machine.parameter("span.length", span.length)
            machine.parameter("span.EA", span.EA)
            machine.parameter("span.T_in", span.T_in)
            machine.channel("span_tension")
        elif machine.entry is not None:
            machine.parameter("web.tension", machine.web.tension)

    def apply(self, ev: Evaluation) -> None:
        m = ev.machine
        entry = m.entry
        if entry is None:
            return
        ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
        if m.span is None:
            T = ev.p("web.tension")
        else:
            state = ev.x("span.tension")
            u = ev.bodies[m.unwind.name]
            v1, v2 = u.r * u.speed, ns.u_a
            ev.span_rate = (ev.p("span.EA") * (v2 - v1) + v1 * ev.p("span.T_in")
                            - v2 * state) / ev.p("span.length")
            ev.set_rate("span.tension", ev.span_rate)
            ev.set_channel("span_tension", state)
            T = ev.M.fmax(state, 0.0)
            tx, tz, ox, oz = exit_point(ev)
            ev.add_force(u.body.name, T * tx, T * tz, ox, oz)
        ev.add_force(b.body.name, -T * ns.tx, -T * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
