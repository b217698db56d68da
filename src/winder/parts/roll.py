"""Paper rolls (machines spec §1, §8 ``[[roll]]``): bodies whose radius, mass and inertia
grow as paper is wound on."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RollPart", "ROLL_KINDS", "AXES"]

#: Kinds of paper roll; only ``wound`` is supported so far (``unwinding`` is rejected).
ROLL_KINDS = ("wound", "unwinding")
#: Translational axes a body can be free along, in this order.
AXES = ("x", "z")


@dataclass(frozen=True, kw_only=True)
class RollPart:
    """``[[roll]]``: a paper roll.

    name; kind ``"wound"``; centre ``(x, z)`` [m] (initial guess of the free coordinates,
    value of the fixed ones); free: the axes among ``("x", "z")`` (in that order) its
    centre moves along; sense ±1 (default −1); core_radius (0, 10] [m], core_mass
    (0, 1e6] [kg], core_inertia (0, 1e7] [kg·m²], width (0, 100] [m], initial_radius
    [core_radius, 10] [m], initial_speed ``|ω| <= 1e5`` [rad/s] (operation sense),
    com_offset ``0 <= e < min(r_c, √(J_c/m_c))`` [m], density [0, 1e5] [kg/m³] and
    caliper (0, 0.1] [m] (from ``[paper]`` unless given); initial_height [m]: only from
    the single-drum format's ``[roll] initial_height`` (a fixed initial centre ``z``,
    no static solve), else None.
    """

    name: str
    kind: str = "wound"
    centre: tuple[float, float]
    free: tuple[str, ...] = ("z",)
    sense: int = -1
    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    initial_radius: float
    initial_speed: float = 0.0
    com_offset: float = 0.0
    density: float
    caliper: float
    initial_height: float | None = None
