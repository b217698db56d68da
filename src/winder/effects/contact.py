"""Nip contact (spec §4): compliant normal force and load-dependent slip friction.

``δ = R + r − z``, ``δ̇ = ṙ − ż``; the normal force is never negative and zero for
``δ ≤ 0``. Friction ``F_ss = μ F_n tanh(v_s / v_ref)`` with ``v_s = Ω R − ω r``; with the
``slip_relaxation`` effect the friction is its relaxed state instead.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

from .._scene import CONTACT_LAWS, Scene
from ._base import Context, Effect

if TYPE_CHECKING:
    from .._system import WinderSystem

__all__ = ["ContactLaw", "LinearContact", "HuntCrossleyContact", "Contact", "make_contact_law"]


class ContactLaw(ABC):
    """Normal force of the nip as a function of penetration ``δ`` [m] and rate ``δ̇`` [m/s]."""

    @abstractmethod
    def force(self, delta: float, delta_dot: float) -> float:
        """``F_n`` [N], ``>= 0``; ``0`` when ``δ <= 0``."""

    @abstractmethod
    def tangent(self, delta: float, delta_dot: float) -> tuple[float, float]:
        """``(∂F_n/∂δ, ∂F_n/∂δ̇)`` where ``F_n > 0`` (tangent stiffness, damping)."""

    def static_penetration(self, load: float, delta_dot: float = 0.0) -> float:
        """``δ`` with ``F_n(δ, δ̇) = load`` [m] (``0`` for ``load <= 0``)."""
        if load <= 0.0:
            return 0.0
        hi = 1e-9
        while self.force(hi, delta_dot) < load:
            hi *= 2.0
            if hi > 1e3:
                raise ValueError(f"no penetration carries a load of {load} N")
        from scipy.optimize import brentq  # here: scipy costs start-up time elsewhere

        return brentq(lambda d: self.force(d, delta_dot) - load, 0.0, hi, xtol=1e-300,
                      rtol=8.9e-16)


class LinearContact(ContactLaw):
    """``F_n = max(0, k δ + c δ̇)`` [N]; ``k`` [N/m], ``c`` [N·s/m]."""

    def __init__(self, stiffness: float, damping: float) -> None:
        self.k, self.c = stiffness, damping

    def force(self, delta: float, delta_dot: float) -> float:
        if delta <= 0.0:
            return 0.0
        f = self.k * delta + self.c * delta_dot
        return f if f > 0.0 else 0.0

    def tangent(self, delta: float, delta_dot: float) -> tuple[float, float]:
        return self.k, self.c

    def static_penetration(self, load: float, delta_dot: float = 0.0) -> float:
        if load <= 0.0:
            return 0.0
        return max(0.0, (load - self.c * delta_dot) / self.k)


class HuntCrossleyContact(ContactLaw):
    """``F_n = max(0, k δ^p (1 + α δ̇))`` [N]; ``k`` [N/m^p], ``p`` [-], ``α`` [s/m]."""

    def __init__(self, stiffness: float, exponent: float, hc_damping: float) -> None:
        self.k, self.p, self.alpha = stiffness, exponent, hc_damping

    def force(self, delta: float, delta_dot: float) -> float:
        if delta <= 0.0:
            return 0.0
        f = self.k * delta**self.p * (1.0 + self.alpha * delta_dot)
        return f if f > 0.0 else 0.0

    def tangent(self, delta: float, delta_dot: float) -> tuple[float, float]:
        kd = self.k * self.p * delta ** (self.p - 1.0) * (1.0 + self.alpha * delta_dot)
        return kd, self.k * delta**self.p * self.alpha


def make_contact_law(scene: Scene) -> ContactLaw:
    """The scene's contact law (``[contact] law`` is one of :data:`CONTACT_LAWS`)."""
    c = scene.contact
    if c.law == "linear":
        return LinearContact(c.stiffness, c.damping)
    if c.law == "hunt_crossley":
        return HuntCrossleyContact(c.stiffness, c.exponent, c.hc_damping)
    raise ValueError(f"unknown contact law {c.law!r}; valid: {', '.join(CONTACT_LAWS)}")


class Contact(Effect):
    """Normal force and slip friction at the nip between drum and roll."""

    name = "contact"
    order = 20

    def __init__(self, scene: Scene) -> None:
        super().__init__(scene)
        self.law = make_contact_law(scene)
        f = scene.friction
        self.mu, self.v_ref = f.mu, f.slip_velocity
        self.relaxed = scene.effects.slip_relaxation

    def configure(self, system: WinderSystem) -> None:
        self.R = system.drum_radius

    def initial_height(self, mass: float, r: float, r_dot: float, g: float) -> float:
        """``z`` of static equilibrium ``F_n = m g`` with ``ż = 0`` [m] (spec §6)."""
        return self.R + r - self.law.static_penetration(mass * g, r_dot)

    def apply(self, ctx: Context) -> None:
        delta = self.R + ctx.r - ctx.z
        ddot = ctx.r_dot - ctx.z_dot
        fn = self.law.force(delta, ddot)
        vs = ctx.Omega * self.R - ctx.omega * ctx.r
        fss = self.mu * fn * math.tanh(vs / self.v_ref)
        ctx.penetration, ctx.penetration_rate = delta, ddot
        ctx.normal_force, ctx.slip_velocity, ctx.steady_friction = fn, vs, fss
        if not self.relaxed:
            ctx.friction_force = fss
