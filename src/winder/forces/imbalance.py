"""Imbalance: a paper roll's centre of mass sits at ``e`` (com_offset) [m] on its own ``x``
axis (machines.md §1); off → ``e = 0``. It acts through the inertia of the model."""

from __future__ import annotations

from typing import TYPE_CHECKING

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["Imbalance"]


class Imbalance(ForceElement):
    """Moves each paper roll's centre of mass to ``(e, 0, 0)`` in its frame."""

    name = "imbalance"
    order = 0

    def declare(self, machine: Machine) -> None:
        for b in machine.rolls:
            machine.parameter(f"{b.name}.com_offset", b.part.com_offset)

    def apply(self, ev: Evaluation) -> None:
        for b in ev.machine.rolls:
            ev.bodies[b.name].e = ev.p(f"{b.name}.com_offset")
