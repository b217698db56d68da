"""Gravity: ``g`` along ``−z`` on every body (spec §1); off → ``g = 0``."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ._base import Effect

if TYPE_CHECKING:
    from .._system import WinderSystem


class Gravity(Effect):
    """Sets the Pinocchio model's gravity to ``(0, 0, −g)`` [m/s²]; ABA/RNEA apply it."""

    name = "gravity"
    order = 0

    def configure(self, system: WinderSystem) -> None:
        g = self.scene.scene.gravity
        system.model.gravity = pin.Motion(np.array([0.0, 0.0, -g]), np.zeros(3))
        system.g = g
