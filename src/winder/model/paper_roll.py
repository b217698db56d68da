"""A paper roll's mass and inertia and the bound of its centre-of-mass offset (imbalance):
plain arithmetic, no NumPy, no Pinocchio, so that checking a scene stays light."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["max_com_offset", "paper_roll_mass"]


def max_com_offset(core_radius: float, core_mass: float, core_inertia: float) -> float:
    """Bound ``e_max`` [m] of a roll's centre-of-mass offset, ``0 <= e < e_max``.

    The centre of mass lies inside the core (``e < r_c``) and the core's inertia about it,
    ``J_core − m_core e²``, is positive (``e < √(J_core/m_core)``). Then the roll's inertia
    about its centre of mass ``J(r) − m(r) e²`` stays positive at every radius: the paper
    adds ``b(r)(½(r² + r_c²) − e²) > 0`` with ``b`` its mass."""
    return min(core_radius, math.sqrt(core_inertia / core_mass))


def paper_roll_mass(r: Any, core_radius: Any, core_mass: Any, core_inertia: Any,
                    k: Any) -> tuple[Any, Any, Any, Any]:
    """``(m, J, dm/dr, dJ/dr)`` of a paper roll of radius ``r`` [m] (winder-model §2):
    ``k = π ρ L`` [kg/m³·m]; ``J`` about the roll axis [kg·m²]. Plain arithmetic: floats
    or CasADi symbols (the generated code of every machine uses it)."""
    rc2, r2 = core_radius * core_radius, r * r
    return (core_mass + k * (r2 - rc2), core_inertia + 0.5 * k * (r2 * r2 - rc2 * rc2),
            2.0 * k * r, 2.0 * k * r2 * r)
