"""Nip contact (machines.md §2, winder-model §4): compliant normal force and slip friction.

A nip against a flexible body is one machine nip per slice (:mod:`winder.model.slices`),
its stiffness and damping scaled by ``1/count`` here.

``F_n`` acts on ``b`` along ``+n`` and on ``a`` along ``−n`` through the centres, never
negative, zero for ``δ ≤ 0``: linear ``k δ + c δ̇`` or Hunt–Crossley
``k δ^p (1 + α δ̇)``. Friction ``F_ss = μ F_n tanh(v_s / v_ref)`` acts on ``b`` along
``+t`` at ``p_b = c_b − r_b n`` and on ``a`` along ``−t`` at ``p_a = c_a + r_a n``; with the
``slip_relaxation`` effect the friction is that effect's state instead.

Each nip has a locked contact mode (``AUTO`` the clamped law, ``FREE`` no force,
``IN_CONTACT`` the unclamped law, smoothly extended to ``δ < 0``) and a switching function
``min(δ, F_unclamped/k)`` [m], > 0 exactly where the clamped law gives ``F_n > 0``.

Each nip also has the guard function ``NIP.overlap = δ − min(r_a, r_b)`` [m]: > 0 where
the penetration reaches the smaller radius, i.e. the axis of one body lies inside the
other (the integrators stop the run there: no nip carries its load so, and the state no
longer describes a contact; see :func:`winder.solve.integrators.beyond_bound`), and the
centre of ``b`` relative to ``a``, ``NIP.dx`` and ``NIP.dz`` [m], for a step that jumps
through the other body between its ends.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder.forces._base import ForceElement
from winder.model.locked_modes import FREE, IN_CONTACT, ModeKind

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, NipState

__all__ = ["Contact", "unclamped_force", "normal_force", "push",
           "rest_penetration"]


def unclamped_force(mathns: Any, law: str, par: Any, delta: Any, delta_dot: Any) -> Any:
    """The contact law without its clamp [N]; ``par(key)`` reads the nip's parameters."""
    if law == "linear":
        return par("stiffness") * delta + par("damping") * delta_dot
    return par("stiffness") * delta * mathns.power_abs(delta, par("exponent") - 1.0) \
        * (1.0 + par("hc_damping") * delta_dot)


def normal_force(mathns: Any, mode: Any, delta: Any, f_unclamped: Any) -> Any:
    """``F_n`` [N] in the locked ``mode``."""
    auto = mathns.if_else(delta > 0.0, mathns.fmax(f_unclamped, 0.0), 0.0)
    return mathns.if_else(mode == IN_CONTACT, f_unclamped,
                     mathns.if_else(mode == FREE, 0.0, auto))


class Contact(ForceElement):
    """Normal force and slip friction at every nip."""

    name = "contact"
    doc = "the nips' normal and friction forces"
    provides = frozenset({"steady_friction"})
    relaxed = False

    def declare(self, machine: Machine) -> None:
        self.relaxed = machine.scene.effects.slip_relaxation
        for nip in machine.nips:
            c, f = nip.part.contact, nip.part.friction
            keys = ("stiffness", "damping") if c.law == "linear" else \
                ("stiffness", "exponent", "hc_damping")
            share = {"stiffness": 1.0 / nip.count, "damping": 1.0 / nip.count}  # a slice's
            for key in keys:
                machine.parameter(f"{nip.name}.{key}", getattr(c, key) * share.get(key, 1.0))
            machine.parameter(f"{nip.name}.mu", f.mu)
            machine.parameter(f"{nip.name}.slip_velocity", f.slip_velocity)
            machine.mode(f"{nip.name}.contact", tuple(
                f"{nip.name}.{g}" for g in ("contact", "overlap", "dx", "dz")),
                ModeKind.CONTACT, owner=nip.name)

    def structure_tag(self, machine: Machine) -> str:
        """Each nip's contact law (its code differs by law)."""
        return ",".join(f"{nip.name}:{nip.part.contact.law}" for nip in machine.nips)

    def apply(self, ev: Evaluation) -> None:
        mathns = ev.mathns
        for ns in ev.nips.values():
            nip = ns.nip
            law = nip.part.contact.law

            def par(key: str, nip: Any = nip) -> Any:
                return ev.p(f"{nip.name}.{key}")

            fu = unclamped_force(mathns, law, par, ns.delta, ns.delta_dot)
            ev.switches[f"{nip.name}.contact"] = mathns.fmin(ns.delta, fu / par("stiffness"))
            a, b = ev.bodies[nip.a.name], ev.bodies[nip.b.name]
            ev.switches[f"{nip.name}.overlap"] = ns.delta - mathns.fmin(a.r, b.r)
            ev.switches[f"{nip.name}.dx"] = b.cx - a.cx
            ev.switches[f"{nip.name}.dz"] = b.cz - a.cz
            fn = normal_force(mathns, ev.mode(f"{nip.name}.contact"), ns.delta, fu)
            ns.normal_force = fn
            ns.steady_friction = par("mu") * fn * mathns.tanh(ns.v_s / par("slip_velocity"))
            push(ev, ns, fn, 0.0)
            if not self.relaxed:
                ns.friction_force = ns.steady_friction
                push(ev, ns, 0.0, ns.friction_force)


def push(ev: Evaluation, ns: NipState, fn: Any, ft: Any) -> None:
    """``F_n`` [N] along ``+n`` and ``F_t`` [N] along ``+t`` on ``b`` at ``p_b``, the
    reaction on ``a`` at ``p_a`` (machines.md §2)."""
    a, b = ev.bodies[ns.nip.a.name], ev.bodies[ns.nip.b.name]
    fx = fn * ns.nx + ft * ns.tx
    fz = fn * ns.nz + ft * ns.tz
    ev.add_force(b.body.name, fx, fz, -b.r * ns.nx, -b.r * ns.nz)
    ev.add_force(a.body.name, -fx, -fz, a.r * ns.nx, a.r * ns.nz)


def rest_penetration(law: str, par: Any, load: float, delta_dot: float = 0.0) -> float:
    """``δ`` [m] at which the nip law ``law`` (parameters ``par(key)``) carries ``load`` [N]
    at rate ``delta_dot`` [m/s], in closed form: linear ``(F − c δ̇)/k``, Hunt–Crossley
    ``(F / (k (1 + α δ̇)))^(1/p)``; 0 where the load is not positive (or the damping alone
    carries it), ``inf`` where a Hunt–Crossley nip closing that fast carries no load."""
    if not load > 0.0:
        return 0.0
    k = par("stiffness")
    if law == "linear":
        return max((load - par("damping") * delta_dot) / k, 0.0)
    gain = 1.0 + par("hc_damping") * delta_dot
    return (load / (k * gain)) ** (1.0 / par("exponent")) if gain > 0.0 else float("inf")
