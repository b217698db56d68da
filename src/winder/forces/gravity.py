"""Gravity: ``g`` [m/s²] along ``−z`` on every body, through Pinocchio's model gravity."""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["Gravity"]


class Gravity(ForceElement):
    """Sets the gravity of ABA/RNEA; in the static balance, each body's weight."""

    name = "gravity"
    doc = "gravity; off: g = 0"
    provides = frozenset({"gravity"})

    def declare(self, machine: Machine) -> None:
        machine.parameter("gravity", machine.scene.scene.gravity)

    def apply(self, ev: Evaluation) -> None:
        ev.provide("gravity", "", ev.p("gravity"))

    def static(self, ev: Evaluation) -> None:
        g = ev.p("gravity")
        for bs in ev.bodies.values():
            ev.add_force(bs.body.name, 0.0, -bs.mass * g)
