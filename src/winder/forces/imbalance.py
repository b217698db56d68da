"""Imbalance: a paper roll's centre of mass sits at ``com_offset`` [m] on its own ``x``
axis (machines.md §1); off → 0. It acts through the inertia of the model."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine

__all__ = ["Imbalance"]


class Imbalance(ForceElement):
    """Moves each paper roll's centre of mass to ``(com_offset, 0, 0)`` in its frame."""

    name = "imbalance"
    doc = "the centre-of-mass offset com_offset; off: e = 0"
    provides = frozenset({"com_offset"})

    def declare(self, machine: Machine) -> None:
        for b in _offset(machine):
            machine.parameter(f"{b.name}.com_offset", b.part.com_offset)

    def apply(self, ev: Evaluation) -> None:
        for b in _offset(ev.machine):
            ev.bodies[b.name].com_offset = ev.p(f"{b.name}.com_offset")


def _offset(machine: Machine) -> list[Any]:
    """The bodies with a centre-of-mass offset (``com_offset`` not None: paper rolls)."""
    return [b for b in machine.bodies if b.com_offset is not None]
