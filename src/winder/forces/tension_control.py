"""Tension control at the unwind (machines.md §6, §11): the unwinding roll's torque holds
the tension of one span, ``span`` (its index from the unwinding roll, default 0: the first;
on a web line the load cell's), at its set-point ``T*`` [N].

The controller is the industrial one, PI on the span tension with the inertia
feed-forward, plus a tension-rate term, with its gains scheduled on the roll's inertia by
one rule, so that the closed loop keeps the same bandwidth over the whole diameter range
(the parent roll's inertia falls by 40× from full to empty)::

    τ = J(r) ω̇_ref − r T*  −  k_p e − k_i ∫e dt + k_d Ṫ,      e = T* − T

with ``ω_ref = v2 / r`` (the roll's speed at the web speed ``v2`` of the body it feeds,
its rate from that body's acceleration and the shrinking radius).

**The first span** (``span = 0``, the design of model.md §5): ``Ṫ`` is the span's own
tension rate. Linearised about the operating point the span and the roll give
``T'' = −g (δτ + r δT)`` with ``g = EA r / (L_s J)``; the gains

    k_d = 3 ω_c / g,   k_p = 3 ω_c² / g − r,   k_i = ω_c³ / g

put the three closed-loop poles at ``−ω_c``, for any radius (``ω_c`` is the scene's
``bandwidth`` [rad/s]).

**A span behind rollers** (``span = k > 0``). Its tension reaches the roll only through
the rollers between, each a mass on the spans' springs (the roller–span modes, lightly
damped by the transport); a rate term on that span's tension acts through their phase and
destabilises them (linearised: a pole at +4.97 1/s on a 1.5 + 1.5 m line at 5 m/s,
ω_c = 10 rad/s). The rate
is therefore taken where the torque acts, from the roll's own speed: below the roller
modes the rollers pass the tension, every span of the unwind's **tension zone** (spans
0 … m, up to the first that ends at a paced pull roll or at the entry drum) strains
together, and the paper balance of the zone gives

    C Ṫ = v_m − r ω − b C δT,     C = Σ_{i≤m} L_i / EA_i,     b = v_m / (EA_m C)

(``v_m`` the surface speed of the body ending the zone; ``C`` [m/N] its compliance;
``b`` [1/s] the transport's self-regulation; a dancer in the zone is refused by the
scene's checks: its damped carriage, not the unwind, sets the tension behind it). The
controller's rate is ``Ṫ_est = (v_m − r ω) / C``; with
``g = r / (J C)`` the gains

    k_d = (3 ω_c − b) / g,   k_p = 3 ω_c² / g − r − k_d b,   k_i = ω_c³ / g

put the three poles of that model at ``−ω_c``. The model has no bearing friction, so its
feed-forward is zero (the integral takes the rollers' drag). Channels: ``tension_error``
[N] (``e``) and the roll's ``NAME_torque`` [N·m].
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from winder._schema import Channel
from winder.forces._unwind import UnwindController

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, Web
    from winder.model.spans import Span

__all__ = ["TensionController", "tension_zone", "tension_gains"]


def tension_zone(spans: Sequence[Span]) -> list[Span]:
    """The spans an unwind's torque strains together (its tension zone): from the first
    up to the first that ends at a paced roller (a pull roll on a speed profile) or at the
    entry drum."""
    out = []
    for s in spans:
        out.append(s)
        if s.downstream is None or s.downstream.roles.paced:
            break
    return out


def tension_gains(bandwidth: Any, g: Any, r: Any, transport: Any = None
                  ) -> tuple[Any, Any, Any]:
    """``(k_p, k_i, k_d)`` [m, m/s, m·s] of the unwind's tension loop of bandwidth ω_c
    [rad/s] (three poles at −ω_c) for the plant gain ``g = r / (J C)`` [1/(kg·m)] (the
    roll's radius ``r`` [m] and inertia ``J`` [kg·m²], the compliance ``C`` [m/N] between
    it and the tension it holds) and the transport's rate ``b`` [1/s] (None: the first
    span's design, model.md §5; module docstring); numbers or CasADi symbols."""
    if transport is None:
        kd = 3.0 * bandwidth / g
        return 3.0 * bandwidth * bandwidth / g - r, bandwidth ** 3 / g, kd
    kd = (3.0 * bandwidth - transport) / g
    return 3.0 * bandwidth * bandwidth / g - r - kd * transport, bandwidth ** 3 / g, kd


class TensionController(UnwindController):
    """The unwind's tension controller, one per tension-controlled unwinding roll (on the
    span ``span`` of its web); state ``ROLL.tension_integral`` [N·s]."""

    name = "tension_control"
    CHANNELS = (Channel(name="tension_error", unit="N",
                        doc="the unwind controller's error T* − T"),)
    requires = frozenset({"span_rate"})
    provides = frozenset({"drive_torque"})
    HOLDS = "span"  # the drive key of what it holds (it changes the generated code)

    def declare(self, machine: Machine) -> None:
        for w in self.controlled(machine):
            b = w.unwind
            machine.parameter(f"{b.name}.tension_setpoint", b.part.drive.tension)
            machine.parameter(f"{b.name}.bandwidth", b.part.drive.bandwidth)
            machine.state(f"{b.name}.tension_integral", 0.0)
            machine.channel(self.CHANNELS[0], w.span_channel)

    @staticmethod
    def _control(ev: Evaluation, w: Web) -> None:
        b, first = w.unwind, w.spans[0]
        held = w.spans[b.part.drive.span]  # the load cell's span (machines.md §11)
        n = b.name
        u = ev.bodies[n]
        a = ev.bodies[(first.downstream or w.entry.a).name]  # the speed the unwind feeds
        T = ev.x(f"{held.key}tension")
        T_set = ev.p(f"{n}.tension_setpoint")
        wc = ev.p(f"{n}.bandwidth")
        e = T_set - T
        ev.set_rate(f"{n}.tension_integral", e)
        r, J = u.r, u.inertia
        if held.index == 0:  # the first span: its own rate (model.md §5)
            g = ev.p(f"{first.key}EA") * r / (ev.p(f"{first.key}length") * J)
            kp, ki, kd = tension_gains(wc, g, r)
            rate = ev.provided("span_rate", w.name)
        else:  # behind rollers: the zone's rate from the roll's own speed
            zone = tension_zone(w.spans)
            end = zone[-1].downstream or w.entry.a
            c = sum(ev.p(f"{s.key}length") / ev.p(f"{s.key}EA") for s in zone)
            v_end = ev.bodies[end.name].r * ev.bodies[end.name].speed
            kp, ki, kd = tension_gains(wc, r / (J * c), r,
                                       v_end / (ev.p(f"{zone[-1].key}EA") * c))
            rate = (v_end - r * u.speed) / c
        v2 = a.omega * a.r * a.body.sense
        a_dot = a.alpha_prescribed if a.alpha_prescribed is not None else 0.0
        v2_dot = a_dot * a.r * a.body.sense
        w_ref_dot = (v2_dot * r - v2 * u.r_dot) / (r * r)
        tau = (J * w_ref_dot - r * T_set - kp * e
               - ki * ev.x(f"{n}.tension_integral") + kd * rate)
        ev.provide("drive_torque", n, tau)
        ev.set_channel(f"{w.span_channel}tension_error", e)
