"""Paper rolls (machines spec §1, §6, §8 ``[[roll]]``): bodies whose radius, mass and
inertia grow as paper is wound on (``wound``) or shrink as it is paid off
(``unwinding``), and the drives of an unwinding roll."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RollPart", "ROLL_KINDS", "AXES", "UnwindTorqueDrive", "TensionControl",
           "UNWIND_DRIVE_KINDS"]

#: Kinds of paper roll: ``wound`` (radius grows) and ``unwinding`` (radius shrinks; fixed
#: centre, the start of a web span).
ROLL_KINDS = ("wound", "unwinding")
#: Drive kinds of an unwinding roll (no drive: it turns freely).
UNWIND_DRIVE_KINDS = ("torque", "tension_control")
#: Translational axes a body can be free along, in this order.
AXES = ("x", "z")


@dataclass(frozen=True)
class UnwindTorqueDrive:
    """``drive = { kind = "torque" }`` of an unwinding roll: a torque ``torque`` [N·m]
    (``|torque| <= 1e8``, operation sense: negative brakes), constant or an input."""

    kind: str = "torque"
    torque: float = 0.0


@dataclass(frozen=True, kw_only=True)
class TensionControl:
    """``drive = { kind = "tension_control" }`` of an unwinding roll: the unwind torque
    holds the span tension at ``tension`` (0, 1e7] [N]; ``bandwidth`` ω_c (0, 1e4]
    [rad/s] is the closed loop's bandwidth, from which the engine derives the gains by
    its rule."""

    kind: str = "tension_control"
    tension: float
    bandwidth: float = 10.0


@dataclass(frozen=True, kw_only=True)
class RollPart:
    """``[[roll]]``: a paper roll.

    name; kind ``"wound"`` or ``"unwinding"``; centre ``(x, z)`` [m] (initial guess of
    the free coordinates, value of the fixed ones); free: the axes among ``("x", "z")``
    (in that order) its centre moves along (an unwinding roll: none); sense ±1 (default
    −1); core_radius (0, 10] [m], core_mass (0, 1e6] [kg], core_inertia (0, 1e7]
    [kg·m²], width (0, 100] [m], initial_radius [core_radius, 10] [m], initial_speed
    ``|ω| <= 1e5`` [rad/s] (operation sense), com_offset
    ``0 <= e < min(r_c, √(J_c/m_c))`` [m], density [0, 1e5] [kg/m³] and caliper
    (0, 0.1] [m] (from ``[paper]`` unless given); initial_height [m]: only from the
    single-drum format's ``[roll] initial_height`` (a fixed initial centre ``z``, no
    static solve), else None; drive: an unwinding roll's :class:`UnwindTorqueDrive` or
    :class:`TensionControl`, None for a free one (a wound roll has none).
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
    drive: UnwindTorqueDrive | TensionControl | None = None
