"""Web tension (machines.md §3, §5): the wound roll pulls the web in, force ``−T t`` at its
entry point ``p_b``; the drum the web wraps carries no net tension torque. ``T`` [N] is
``[web] tension``, or, with ``[web.span]``, the span's tension state

    dT/dt = ( EA (v2 − v1) + v1 T_in − v2 T ) / L_s

(``v1`` the unwinding roll's surface speed, ``v2`` the entry drum's ``u_a``), which also
pulls the unwinding roll along ``+t_u`` at its exit point ``p_u`` (operation torque
``+r_u T``). A slack web pushes nothing: the forces use ``max(T, 0)``.

A web line (``[[web.span]]``, machines.md §11) has one tension state per span ``i``, with
transport of strain (``ε_i = T_i / EA_i``, ``ε_{−1} = T_in / EA_0``)::

    L_i dε_i/dt = v_out,i − v_in,i + v_in,i ε_{i−1} − v_out,i ε_i

(``v_in,i`` the surface speed of the body upstream, the unwinding roll or a roller,
``v_out,i`` that downstream, a roller or the entry drum's ``u_a``; a span at a dancer is
``L_i + d`` long and gains ``+ḋ``); with one span this is §5's equation, to round-off. A
dancer's carriage: ``m_d d̈ = F_load − k d − c ḋ − (T_up + T_down)``. The unwinding
roll is pulled by the first span, the wound roll by the last, and each roller between
spans ``i − 1`` and ``i`` turned by ``R (max(T_i, 0) − max(T_{i−1}, 0))`` (operation
sense); the rollers' tensions and the web's ``mu`` go to their load-cell and traction
channels (``"roller_tensions"``).
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
    unwinding roll (towards the centre of its first roller, else of its entry drum) and
    the exit point ``p_u − c_u`` [m], on the side where the roll's surface moves along
    ``+t_u`` when it turns in its operation sense."""
    mathns = ev.mathns
    first = web.spans[0].downstream if web.spans else None
    u = ev.bodies[web.unwind.name]
    a = ev.bodies[(first if first is not None else web.entry.a).name]
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
                        doc="web span tension T (a state; the forces use max(T, 0)); "
                            "span{i}_tension of a line's spans"),
                Channel(name="BODY_position", unit="m",
                        doc="a dancer's carriage position d (0 at its centre; both spans "
                            "lengthen with d)"),
                Channel(name="BODY_position_dot", unit="m/s",
                        doc="a dancer's carriage speed ḋ"))
    provides = frozenset({"span_rate", "roller_tensions"})

    def declare(self, machine: Machine) -> None:
        for w in machine.webs:
            if w.span is None:
                machine.parameter(f"{w.key}web.tension", w.part.tension)
                continue
            t_in = w.span.T_in
            for s in w.spans:
                span, k = s.part, s.key
                t0 = t_in if span.initial_tension is None else span.initial_tension
                machine.state(f"{k}tension", t0)
                machine.parameter(f"{k}length", span.length)
                machine.parameter(f"{k}EA", span.EA)
                if s.index == 0:
                    machine.parameter(f"{k}T_in", span.T_in)
                if len(w.spans) == 1:
                    machine.channel(self.CHANNELS[0], w.span_channel)
                else:
                    machine.channel(Channel(name=f"span{s.index}_tension", unit="N",
                                            doc=f"tension of span {s.index}"),
                                    w.span_channel)
            if len(w.spans) > 1:
                machine.parameter(f"{w.key}web.mu", w.part.mu)
            for s in w.spans[1:]:
                if s.upstream.roles.dancer is not None:
                    for ch in self.CHANNELS[1:]:
                        machine.channel(ch, s.upstream.name)

    def apply(self, ev: Evaluation) -> None:
        for w in ev.machine.webs:
            self._web(ev, w)

    @staticmethod
    def _web(ev: Evaluation, w: Web) -> None:
        ns, b = ev.nips[w.entry.name], ev.bodies[w.entry.b.name]
        if w.span is None:
            T = ev.p(f"{w.key}web.tension")
        else:
            T = WebTension._spans(ev, w, ns.u_a)
        if len(w.entries) == 1:
            ev.add_force(b.body.name, -T * ns.tx, -T * ns.tz, -b.r * ns.nx, -b.r * ns.nz)
            return
        share = T / len(w.entries)  # a flexible roll: T/N on each slice
        for entry in w.entries:
            ns, b = ev.nips[entry.name], ev.bodies[entry.b.name]
            ev.add_force(b.body.name, -share * ns.tx, -share * ns.tz, -b.r * ns.nx,
                         -b.r * ns.nz)

    @staticmethod
    def _spans(ev: Evaluation, w: Web, v_entry: Any) -> Any:
        """Each span's transport of strain, the first span's pull on the unwinding roll,
        the rollers' torques; returns the last span's ``max(T, 0)`` [N]."""
        fmax = ev.mathns.fmax
        u = ev.bodies[w.unwind.name]
        states = [ev.x(f"{s.key}tension") for s in w.spans]
        for s, state in zip(w.spans, states, strict=True):
            k, i = s.key, s.index
            up = ev.bodies[s.upstream.name]
            v1 = up.r * up.speed
            v2 = v_entry if s.downstream is None else \
                ev.bodies[s.downstream.name].r * ev.bodies[s.downstream.name].speed
            inflow = ev.p(f"{k}T_in") if i == 0 else \
                states[i - 1] * ev.p(f"{k}EA") / ev.p(f"{w.spans[i - 1].key}EA")
            ends = [b.name for b in (s.upstream, s.downstream)
                    if b is not None and b.roles.dancer is not None]
            if ends:  # a dancer's travel lengthens its spans: L + d, rate ḋ
                length = ev.p(f"{k}length") + sum(ev.x(f"{n}.position") for n in ends)
                l_dot = sum(ev.x(f"{n}.position_dot") for n in ends)
                rate = (ev.p(f"{k}EA") * (v2 - v1 + l_dot) + v1 * inflow - v2 * state) \
                    / length
            else:
                rate = (ev.p(f"{k}EA") * (v2 - v1) + v1 * inflow - v2 * state) \
                    / ev.p(f"{k}length")
            if i == 0:
                ev.provide("span_rate", w.name, rate)
            ev.provide("span_rate", f"{w.name}#{i}", rate)
            ev.set_rate(f"{k}tension", rate)
            ev.set_channel(f"{s.channel}tension", state)
        pulls = [fmax(state, 0.0) for state in states]
        tx, tz, ox, oz = exit_point(ev, w)
        ev.add_force(u.body.name, pulls[0] * tx, pulls[0] * tz, ox, oz)
        if len(w.spans) > 1:
            mu = ev.p(f"{w.key}web.mu")
            for s in w.spans[1:]:  # the roller at its upstream end
                roller = s.upstream
                t_up, t_down = pulls[s.index - 1], pulls[s.index]
                bs = ev.bodies[roller.name]
                ev.add_torque(roller.name, roller.sense * bs.r * (t_down - t_up))
                ev.provide("roller_tensions", roller.name, (t_up, t_down, mu))
                if roller.roles.dancer is not None:  # m_d d̈ = F − k d − c ḋ − (T_up + T_down)
                    n = roller.name
                    d, d_dot = ev.x(f"{n}.position"), ev.x(f"{n}.position_dot")
                    ev.output(WebTension.CHANNELS[1], n, d)
                    ev.output(WebTension.CHANNELS[2], n, d_dot)
                    ev.set_rate(f"{n}.position_dot",
                                (ev.p(f"{n}.dancer_load") - ev.p(f"{n}.dancer_stiffness") * d
                                 - ev.p(f"{n}.dancer_damping") * d_dot - (t_up + t_down))
                                / ev.p(f"{n}.dancer_mass"))
        return pulls[-1]
