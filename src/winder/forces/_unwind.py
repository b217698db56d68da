"""The base of an unwinding roll's drive controller (``tension_control``,
``dancer_control``): which webs' unwinds it drives, the structure tag of what it holds,
and its application to each of them."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from winder.forces._base import ForceElement

if TYPE_CHECKING:
    from winder.model.machine import Evaluation, Machine, Web

__all__ = ["UnwindController"]


class UnwindController(ForceElement):
    """A controller of the unwinding rolls whose drive kind is its ``name``.

    A subclass gives ``HOLDS`` (the drive's key naming what it holds: a span, a dancer;
    it changes the generated code) and ``_control(ev, web)`` (its torque on one web's
    unwind), and declares its parameters and states for each of :meth:`controlled`."""

    HOLDS: str

    def controlled(self, machine: Machine) -> list[Web]:
        """The webs whose unwinding roll this controller drives, in the machine's order."""
        return [w for w in machine.webs
                if w.unwind is not None and self.name in w.unwind.drives]

    def structure_tag(self, machine: Machine) -> str:
        """What each controlled unwind holds (``ROLL:VALUE``, it changes the generated
        code)."""
        return ",".join(f"{w.unwind.name}:{getattr(w.unwind.part.drive, self.HOLDS)}"
                        for w in self.controlled(machine))

    def apply(self, ev: Evaluation) -> None:
        for w in self.controlled(ev.machine):
            self._control(ev, w)

    @staticmethod
    def _control(ev: Evaluation, w: Web) -> Any:  # the subclasses give it
        raise NotImplementedError
