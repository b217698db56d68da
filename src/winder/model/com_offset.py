"""The bound of a paper roll's centre-of-mass offset (imbalance): plain arithmetic, no
Pinocchio, so that checking a scene stays light."""

from __future__ import annotations

import math

__all__ = ["max_com_offset"]


def max_com_offset(core_radius: float, core_mass: float, core_inertia: float) -> float:
    """Bound ``e_max`` [m] of a roll's centre-of-mass offset, ``0 <= e < e_max``.

    The centre of mass lies inside the core (``e < r_c``) and the core's inertia about it,
    ``J_core − m_core e²``, is positive (``e < √(J_core/m_core)``). Then the roll's inertia
    about its centre of mass ``J(r) − m(r) e²`` stays positive at every radius: the paper
    adds ``b(r)(½(r² + r_c²) − e²) > 0`` with ``b`` its mass."""
    return min(core_radius, math.sqrt(core_inertia / core_mass))
