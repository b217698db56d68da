"""Imbalance: the roll's centre of mass sits at ``e`` (com_offset) from its axis (spec §1)."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from ._base import Effect

if TYPE_CHECKING:
    from .._system import WinderSystem


class Imbalance(Effect):
    """Moves the roll's centre of mass to ``(e, 0, 0)`` in the roll frame [m]; off → ``e = 0``."""

    name = "imbalance"
    order = 0

    def configure(self, system: WinderSystem) -> None:
        e = self.scene.roll.com_offset
        system.law = dataclasses.replace(system.law, com_offset=e)
        Y = system.model.inertias[system.roll_joint]
        Y.lever = np.array([e, 0.0, 0.0])
