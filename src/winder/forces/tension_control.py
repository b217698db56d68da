"""Tension control at the unwind (machines.md §6): the unwinding roll's torque holds the
span's tension at its set-point ``T*`` [N].

The controller is the industrial one, PI on the span tension with the inertia
feed-forward, plus a tension-rate term, with its gains scheduled on the roll's inertia by
one rule, so that the closed loop keeps the same bandwidth over the whole diameter range
(the parent roll's inertia falls by 40× from full to empty)::

    τ = J(r) ω̇_ref − r T*  −  k_p e − k_i ∫e dt + k_d dT/dt,      e = T* − T

with ``ω_ref = v2 / r`` (the roll's speed at the entry drum's web speed ``v2``, its rate
from the drum's acceleration and the shrinking radius). Linearised about the operating
point the span and the roll give ``T'' = −g (δτ + r δT)`` with ``g = EA r / (L_s J)``; the
gains

    k_d = 3 ω_c / g,   k_p = 3 ω_c² / g − r,   k_i = ω_c³ / g

put the three closed-loop poles at ``−ω_c``, for any radius (``ω_c`` is the scene's
``bandwidth`` [rad/s]). The model has no bearing friction, so its feed-forward is zero.
Channels: ``tension_error`` [N] (``e``) and the roll's ``NAME_torque`` [N·m]. On a web
line (machines.md §11) it holds the first span (the load cell's between the unwind and
its first roller), its feed-forward from the speed of the body the unwind feeds.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder._schema import Channel
from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, Web

__all__ = ["TensionController"]


class TensionController(ForceElement):
    """The unwind's tension controller, one per tension-controlled unwinding roll (on the
    span of its web); state ``ROLL.tension_integral`` [N·s]."""

    name = "tension_control"
    CHANNELS = (Channel(name="tension_error", unit="N",
                        doc="the unwind controller's error T* − T"),)
    requires = frozenset({"span_rate"})
    provides = frozenset({"drive_torque"})

    def declare(self, machine: Machine) -> None:
        for w in machine.webs:
            b = w.unwind
            if b is None or self.name not in b.drives:
                continue
            machine.parameter(f"{b.name}.tension_setpoint", b.part.drive.tension)
            machine.parameter(f"{b.name}.bandwidth", b.part.drive.bandwidth)
            machine.state(f"{b.name}.tension_integral", 0.0)
            machine.channel(self.CHANNELS[0], w.span_channel)

    def apply(self, ev: Evaluation) -> None:
        for w in ev.machine.webs:
            if w.unwind is not None and self.name in w.unwind.drives:
                self._control(ev, w)

    @staticmethod
    def _control(ev: Evaluation, w: Web) -> None:
        b, first = w.unwind, w.spans[0]  # it holds the first span (machines.md §11)
        k, n = first.key, b.name
        u = ev.bodies[n]
        a = ev.bodies[(first.downstream or w.entry.a).name]  # the speed the unwind feeds
        T = ev.x(f"{k}tension")
        T_set = ev.p(f"{n}.tension_setpoint")
        wc = ev.p(f"{n}.bandwidth")
        e = T_set - T
        ev.set_rate(f"{n}.tension_integral", e)
        r, J = u.r, u.inertia
        g = ev.p(f"{k}EA") * r / (ev.p(f"{k}length") * J)
        kd, kp, ki = 3.0 * wc / g, 3.0 * wc * wc / g - r, wc ** 3 / g
        v2 = a.omega * a.r * a.body.sense
        a_dot = a.alpha_prescribed if a.alpha_prescribed is not None else 0.0
        v2_dot = a_dot * a.r * a.body.sense
        w_ref_dot = (v2_dot * r - v2 * u.r_dot) / (r * r)
        tau = (J * w_ref_dot - r * T_set - kp * e
               - ki * ev.x(f"{n}.tension_integral")
               + kd * ev.provided("span_rate", w.name))
        ev.provide("drive_torque", n, tau)
        ev.set_channel(f"{w.span_channel}tension_error", e)
