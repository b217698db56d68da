"""Locked modes: the discrete states the integrators hold within a step and switch at
located events (winder-model §4, machines.md §1–§2).

Each mode slot has a typed :class:`ModeKind` (not a name suffix):

- :attr:`ModeKind.CONTACT` per nip: :data:`AUTO` (the clamped law), :data:`FREE` (no
  force), :data:`IN_CONTACT` (the unclamped law); switching functions ``NIP.contact``,
  ``NIP.overlap``, ``NIP.dx``, ``NIP.dz`` [m];
- :attr:`ModeKind.CORE` per wound roll (spec §2): :data:`CORE_AUTO`, :data:`WINDING`,
  :data:`AT_CORE`; switching functions ``ROLL.unwound`` (``r_c − r`` [m]) and
  ``ROLL.forward`` (its speed [rad/s]);
- :attr:`ModeKind.END` per unwinding roll: the run ends where ``ROLL.exhausted``
  (``r_c − r`` [m]) crosses zero.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any

__all__ = ["ModeKind", "ModeSlot", "AUTO", "FREE", "IN_CONTACT", "CORE_AUTO", "WINDING",
           "AT_CORE"]

AUTO, FREE, IN_CONTACT = -1, 0, 1
CORE_AUTO, WINDING, AT_CORE = -1, 0, 1


class ModeKind(enum.IntEnum):
    """The kind of a mode slot; its value is the slot's kind in the integrators' table."""

    CONTACT = 0
    CORE = 1
    END = 2

    @property
    def automatic(self) -> int:
        """The mode that lets the switching functions decide (how a run starts)."""
        return {ModeKind.CONTACT: AUTO, ModeKind.CORE: CORE_AUTO, ModeKind.END: 0}[self]

    @property
    def unloaded(self) -> int:
        """The mode under the applied forces alone (a nip open, the core automatic)."""
        return {ModeKind.CONTACT: FREE, ModeKind.CORE: CORE_AUTO, ModeKind.END: 0}[self]


@dataclass(frozen=True)
class ModeSlot:
    """A locked mode slot: ``name`` (``NIP.contact``, ``ROLL.core``, ``ROLL.end``), its
    ``kind``, the part it belongs to (``owner``), its switching functions and, for a
    roll's core or end, the radius state and the core-radius parameter the event lands
    on."""

    name: str
    kind: ModeKind
    owner: str
    switches: tuple[str, ...]
    state: str | None = None
    param: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.kind, ModeKind):
            raise TypeError(f"mode {self.name!r}: kind must be a ModeKind, got {self.kind!r}")
        if not self.switches:
            raise ValueError(f"mode {self.name!r}: at least one switching function")

    def table_row(self, machine: Any) -> tuple[int, ...]:
        """Its row of the integrators' mode table: ``(kind, g1, g2, state, param)`` for a
        core or end (``g2`` 0 without a second switch), ``(kind, g1, ..., g4)`` for a
        contact (indices into the switch, state and parameter vectors)."""
        g = [machine.switch_names.index(s) for s in self.switches]
        if self.state is None:
            return (int(self.kind), *g)
        g2 = g[1] if len(g) > 1 else 0
        return (int(self.kind), g[0], g2, machine.index(self.state),
                machine.param_index(self.param))
