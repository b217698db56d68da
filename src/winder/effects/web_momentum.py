"""Web momentum: the arriving web brings the momentum flux ``ṁ u`` at the nip (spec §3).

``u = Ω R`` (the web runs over the drum); without contact, ``u = ω r``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._base import Context, Effect

if TYPE_CHECKING:
    from .._system import WinderSystem


class WebMomentum(Effect):
    """Adds ``T_web = ṁ u`` [N] along ``+x`` at the nip point of the roll."""

    name = "web_momentum"
    order = 30

    def configure(self, system: WinderSystem) -> None:
        self._over_drum = system.scene.effects.contact

    def apply(self, ctx: Context) -> None:
        u = ctx.Omega * ctx.drum_radius if self._over_drum else ctx.omega * ctx.r
        ctx.web_force = ctx.mass_rate * u
