"""Dancer control at the unwind (machines.md §11): the unwinding roll's torque holds a
dancer's carriage at its centre, ``d = 0``.

The web the unwind pays out beyond what the line takes goes into the dancer's two spans:
``2 ḋ ≈ v_1 − v_out`` (the spans' strain aside), and with the first span's tension fed
forward the roll obeys ``J ω̇ = δτ``, so that about the operating point ``d'' = g δτ``
with ``g = r / (2 J)``. The controller, PI on ``d`` with a rate term and the inertia and
tension feed-forward::

    τ = J(r) ω̇_ref − r T_0 − k_p d − k_i ∫d dt − k_d ḋ,
    k_d = 3 ω_c / g,   k_p = 3 ω_c² / g,   k_i = ω_c³ / g,

puts the three closed-loop poles of that model at ``−ω_c`` for any radius (``ω_c`` the
drive's ``bandwidth`` [rad/s], well below the dancer–span resonance); ``ω_ref = v / r``
with ``v`` the surface speed of the body the unwind feeds, ``T_0`` the first span's
tension (its load cell). State ``ROLL.position_integral`` [m·s]; channels
``dancer_error`` [m] (``d``) and the roll's ``NAME_torque`` [N·m].
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder._schema import Channel
from winder.forces._unwind import UnwindController

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, Web

__all__ = ["DancerController"]


class DancerController(UnwindController):
    """The unwind's dancer controller, one per dancer-controlled unwinding roll."""

    name = "dancer_control"
    CHANNELS = (Channel(name="dancer_error", unit="m",
                        doc="the dancer controller's error: the carriage position d "
                            "(set-point 0)"),)
    provides = frozenset({"drive_torque"})
    HOLDS = "dancer"  # the drive key of what it holds (it changes the generated code)

    def declare(self, machine: Machine) -> None:
        for w in self.controlled(machine):
            b = w.unwind
            machine.parameter(f"{b.name}.bandwidth", b.part.drive.bandwidth)
            machine.state(f"{b.name}.position_integral", 0.0)
            machine.channel(self.CHANNELS[0], w.span_channel)

    @staticmethod
    def _control(ev: Evaluation, w: Web) -> None:
        b, first = w.unwind, w.spans[0]
        n, dancer = b.name, b.part.drive.dancer
        u = ev.bodies[n]
        a = ev.bodies[(first.downstream or w.entry.a).name]  # the speed the unwind feeds
        d, d_dot = ev.x(f"{dancer}.position"), ev.x(f"{dancer}.position_dot")
        ev.set_rate(f"{n}.position_integral", d)
        wc = ev.p(f"{n}.bandwidth")
        r, J = u.r, u.inertia
        g = r / (2.0 * J)
        kd, kp, ki = 3.0 * wc / g, 3.0 * wc * wc / g, wc ** 3 / g
        v = a.omega * a.r * a.body.sense
        a_dot = a.alpha_prescribed if a.alpha_prescribed is not None else 0.0
        w_ref_dot = (a_dot * a.r * a.body.sense * r - v * u.r_dot) / (r * r)
        T0 = ev.mathns.fmax(ev.x(f"{first.key}tension"), 0.0)
        tau = J * w_ref_dot - r * T0 - kp * d - ki * ev.x(f"{n}.position_integral") \
            - kd * d_dot
        ev.provide("drive_torque", n, tau)
        ev.set_channel(f"{w.span_channel}dancer_error", d)
