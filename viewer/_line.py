"""The drawn path of a web line (machines spec §11): from the unwinding roll over each
roller into the winder's entry nip, as straight spans tangent to the circles, on the side
each body's surface carries the web forward, and arcs around the rollers.

A body of sense ``s`` turning in its operation sense moves its surface point at angle
``α`` (from ``+x`` towards ``+z``) along ``s (sin α, −cos α)`` (spec §1: ``θ̇ > 0`` moves
the top towards ``+x``, clockwise in the x–z plane seen with ``x`` right and ``z`` up).
So where the web touches a circle travelling along the unit direction ``u``, the contact
point is ``c + r s ⊥u`` with ``⊥u = (−u_z, u_x)`` (``u`` turned by +90°): the circle lies
on the web's right for ``s = +1``, on its left for ``s = −1``. A span between a circle
``1`` and a circle ``2`` is then the one tangent for which both contact points move
along it: an outer tangent where ``s₁ = s₂``, a crossed one where they differ
(:func:`span_tangent`).

A dancer's carriage moves along the fixed unit axis ``e`` in which both of its spans
lengthen (:func:`dancer_axis`): away from the resultant of its two spans' pulls, taken on
the scene's layout with every carriage at its centre; its roller is drawn at
``centre + d e``, ``d`` its ``NAME_position`` channel. Where its two spans are parallel
(the wrap π the model requires, machines spec §11) each lengthens by exactly ``d``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["Circle", "span_tangent", "roller_arc", "line_path", "dancer_axis",
           "ROLLER_ARC_POINTS"]

#: Points on the web's arc around each roller (its first: where the web arrives, its last:
#: where it leaves).
ROLLER_ARC_POINTS = 7


@dataclass(frozen=True)
class Circle:
    """A body as the web sees it: centre ``(x, z)`` [m], radius ``r`` [m] and sense
    ``s`` (±1, spec §1) of the rotation that carries the web forward."""

    x: float
    z: float
    r: float
    s: int

    @property
    def c(self) -> np.ndarray:
        return np.array([self.x, self.z], dtype=float)


def _perp(u: np.ndarray) -> np.ndarray:
    """``u`` turned by +90° in the x–z plane: ``(−u_z, u_x)``."""
    return np.array([-u[1], u[0]])


def span_tangent(a: Circle, b: Circle) -> tuple[np.ndarray, np.ndarray]:
    """Where the web leaves circle ``a`` and where it meets circle ``b`` [m]: the tangent
    along whose direction ``u`` both surfaces move, ``p_a = c_a + r_a s_a ⊥u``,
    ``p_b = c_b + r_b s_b ⊥u`` and ``p_b − p_a = L u`` with ``L > 0``.

    With ``D = c_b − c_a`` and ``ρ = r_a s_a − r_b s_b``: ``D = L u + ρ ⊥u``, so
    ``L = √(|D|² − ρ²)`` and ``u = (L D − ρ ⊥D) / |D|²`` (an outer tangent for equal
    senses, ``|ρ| = |r_a − r_b|``; a crossed one for opposite senses, ``|ρ| = r_a + r_b``).
    Circles too close for that tangent (``|D| ≤ |ρ|``) give ``L = 0``."""
    D = b.c - a.c
    dd = float(D @ D)
    if dd <= 0.0:
        return a.c.copy(), b.c.copy()
    rho = a.r * a.s - b.r * b.s
    L = math.sqrt(max(dd - rho * rho, 0.0))
    u = (L * D - rho * _perp(D)) / dd
    u /= max(float(np.hypot(*u)), 1e-300)
    return a.c + a.r * a.s * _perp(u), b.c + b.r * b.s * _perp(u)


def roller_arc(c: Circle, p_in: np.ndarray, p_out: np.ndarray,
               n: int = ROLLER_ARC_POINTS) -> np.ndarray:
    """``n`` points on circle ``c`` from ``p_in`` to ``p_out`` in its direction of travel
    (clockwise for ``s = +1``): the web's wrap on it."""
    a_in = math.atan2(p_in[1] - c.z, p_in[0] - c.x)
    a_out = math.atan2(p_out[1] - c.z, p_out[0] - c.x)
    wrap = (c.s * (a_in - a_out)) % (2.0 * math.pi)
    alpha = a_in - c.s * wrap * np.linspace(0.0, 1.0, n)
    out = c.c + c.r * np.column_stack([np.cos(alpha), np.sin(alpha)])
    out[0], out[-1] = p_in, p_out
    return out


def line_path(unwind: Circle, rollers: Sequence[Circle], drum: Circle
              ) -> tuple[np.ndarray, np.ndarray]:
    """The web from the unwinding roll over ``rollers`` (in order) to the entry ``drum``:
    ``(points, meet)``, the path's points [m] (the exit point on the unwinding roll, then
    :data:`ROLLER_ARC_POINTS` per roller) and the point where it meets the drum [m]
    (the caller wraps the drum from there into the nip)."""
    circles = [unwind, *rollers, drum]
    ends = [span_tangent(a, b) for a, b in zip(circles[:-1], circles[1:], strict=True)]
    points = [ends[0][0][None, :]]
    for i, roller in enumerate(rollers):
        points.append(roller_arc(roller, ends[i][1], ends[i + 1][0]))
    return np.vstack(points), ends[-1][1]


def dancer_axis(up: Circle, dancer: Circle, down: Circle) -> np.ndarray:
    """The unit axis ``e`` in which a dancer's carriage moves when ``d`` grows: against
    the resultant of the unit pulls of its two spans (from the dancer's contact points
    towards ``up`` and ``down``), so that both spans lengthen, at the rate
    ``|pulls' sum| = 2 sin(β/2)`` per unit ``d`` (``β`` the drawn wrap; 2 for parallel
    spans). A web that runs straight past it (no resultant): the normal into the web,
    ``s ⊥u``."""
    p_up, q_in = span_tangent(up, dancer)
    q_out, p_down = span_tangent(dancer, down)
    pulls = []
    for frm, to in ((q_in, p_up), (q_out, p_down)):
        v = to - frm
        pulls.append(v / max(float(np.hypot(*v)), 1e-300))
    total = pulls[0] + pulls[1]
    size = float(np.hypot(*total))
    if size < 1e-9:
        return dancer.s * _perp(-pulls[0])
    return -total / size
