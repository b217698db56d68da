"""Slip relaxation (spec §4): the nip friction lags its steady value over a length ``σ``.

``dF_t/dt = (|Ω R| + v_min)/σ · (F_ss − F_t)``; off → ``F_t = F_ss``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._scene import Scene
from ._base import Context, Effect

if TYPE_CHECKING:
    from .._system import WinderSystem


class SlipRelaxation(Effect):
    """Adds the state ``friction_force`` ``F_t`` [N] (initially 0)."""

    name = "slip_relaxation"
    order = 25  # after contact, which computes F_ss
    states = ("friction_force",)

    def __init__(self, scene: Scene) -> None:
        super().__init__(scene)
        f = scene.friction
        self.sigma, self.v_min = f.relaxation_length, f.min_speed

    def initial_state(self, system: WinderSystem, ctx: Context) -> list[float]:
        return [0.0]  # spec §6: F_t = 0

    def configure(self, system: WinderSystem) -> None:
        self.R = system.drum_radius

    def apply(self, ctx: Context) -> None:
        ft = ctx.y[self.index]
        ctx.friction_force = ft
        rate = (abs(ctx.Omega * self.R) + self.v_min) / self.sigma
        ctx.dy[self.index] = rate * (ctx.steady_friction - ft)
