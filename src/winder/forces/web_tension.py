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

from winder._schema import Channel
from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, Web

__all__ = ["WebTension", "exit_point"]


def exit_point(ev: Evaluation, web: Web) -> tuple[Any, Any, Any, Any]:
    """``(t_x, t_z, o_x, o_z)``: the unit direction ``t_u`` in which ``web`` leaves its
    unwinding roll (towards its entry drum's centre) and the exit point ``p_u − c_u``
    [m], on the side where the roll's surface moves along ``+t_u`` when it turns in its
    operation sense."""
    mathns = ev.mathns
    u, a = ev.bodies[web.unwind.name], ev.bodies[web.entry.a.name]
    dx, dz = a.cx - u.cx, a.cz - u.cz
    d = mathns.sqrt(dx * dx + dz * dz)
    tx, tz = dx / d, dz / d
    s = u.body.sense
    return tx, tz, -s * tz * u.r, s * tx * u.r


class WebTension(ForceElement):
    """Each web's tension on its wound roll (and on the unwinding roll of its span)."""

    name = "web_tension"
    doc = ("the web tension's pull on the wound roll at its entry nip (and on the unwinding "
           "roll)")
    CHANNELS = (Channel(name="span_tension", unit="N",
                        doc="web span tension T (a state; the forces use max(T, 0))"),)
    provides = frozenset({"span_rate"})

    def declare(self, machine: Machine) -> None:
        for w in machine.webs:
            span, k = w.span, w.span_key
            if span is not None:
                t0 = span.T_in if span.initial_tension is None else span.initial_tension
                machine.state(f"{k}span.tension", t0)
                machine.parameter(f"{k}span.length", span.length)
                machine.parameter(f"{k}span.EA", span.EA)
                machine.parameter(f"{k}span.T_in", span.T_in)
                machine.channel(self.CHANNELS[0], w.span_channel)
            else:
                machine.parameter(f"{w.key}web.tension", w.part.tension)

    def apply(self, ev: Evaluation) -> None:
        for w in ev.machine.webs:
            self._web(ev, w)

    @staticmethod
    def _web(ev: Evaluation, w: Web) -> None:
        ns, b = ev.nips[w.entry.name], ev.bodies[w.entry.b.name]
        if w.span is None:
            T = ev.p(f"{w.key}web.tension")
        else:
            k = w.span_key
            state = ev.x(f"{k}span.tension")
            u = ev.bodies[w.unwind.name]
            v1, v2 = u.r * u.speed, ns.u_a
            rate = (ev.p(f"{k}span.EA") * (v2 - v1) + v1 * ev.p(f"{k}span.T_in")
                    - v2 * state) / ev.p(f"{k}span.length")
            ev.provide("span_rate", w.name, rate)
            ev.set_rate(f"{k}span.tension", rate)
            ev.set_channel(f"{w.span_channel}span_tension", state)
            T = ev.mathns.fmax(state, 0.0)
            tx, tz, ox, oz = exit_point(ev, w)
            ev.add_force(u.body.name, T * tx, T * tz, ox, oz)
        if len(w.entries) == 1:
            ev.add_force(b.body.name, -T * ns.tx, -T * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
            return
        share = T / len(w.entries)  # a flexible roll: T/N on each slice
        for entry in w.entries:
            ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
            ev.add_force(b.body.name, -share * ns.tx, -share * ns.tz, -b.r * ns.nx,
                         -b.r * ns.nz)
