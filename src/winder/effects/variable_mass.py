"""Variable mass: the spatial force ``−Ẏ v`` on the growing roll (spec §3).

Off → ``m(r)`` and ``J(r)`` still follow the radius but ``Ẏ v`` is dropped (the naive
"overwrite the inertia each step" model, kept for comparison).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._base import Context, Effect

if TYPE_CHECKING:
    from .._system import WinderSystem


class VariableMass(Effect):
    """Writes ``Ẏ = dY/dr · ṙ`` of the roll into the core's rate buffer; the core adds
    ``−Ẏ v`` to the roll's external force in ABA and RNEA."""

    name = "variable_mass"
    order = 10

    def configure(self, system: WinderSystem) -> None:
        self._law = system.law
        self._rate = system.vm.bind_rate(system.roll_joint)

    def apply(self, ctx: Context) -> None:
        self._law.rate_into(ctx.r, ctx.r_dot, self._rate)
