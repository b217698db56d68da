"""Mass properties of one body as functions of a scalar growth state.

A :class:`MassLaw` gives, for a growth state ``s`` (a radius, a burnt mass, time ...),
the mass ``m(s)``, the centre of mass ``c(s)`` in the joint frame, the rotational inertia
about the centre of mass ``I_c(s)`` and their derivatives with respect to ``s``. From this
single parametrisation it builds the spatial inertia ``Y(s)`` and its derivative
``dY/ds``; the rate inertia entering the dynamics is ``Ẏ = dY/ds · ṡ``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ._errors import ModelError

__all__ = ["MassLaw", "MassProperties", "FunctionMassLaw", "PaperRollLaw", "skew",
           "spatial_inertia_matrix"]


def skew(x: np.ndarray) -> np.ndarray:
    """Cross-product matrix ``[x]`` with ``[x] y = x × y``."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def spatial_inertia_matrix(mass: float, com: np.ndarray, inertia_c: np.ndarray) -> np.ndarray:
    """6×6 spatial inertia (Pinocchio order: linear, angular) about the frame origin."""
    C = skew(com)
    Y = np.empty((6, 6))
    Y[:3, :3] = mass * np.eye(3)
    Y[:3, 3:] = -mass * C
    Y[3:, :3] = mass * C
    Y[3:, 3:] = inertia_c - mass * C @ C
    return Y


@dataclass(frozen=True)
class MassProperties:
    """Mass properties and their derivatives with respect to the growth state ``s``.

    Attributes
    ----------
    mass, dmass:
        ``m`` [kg] and ``dm/ds``.
    com, dcom:
        Centre of mass in the joint frame ``c`` [m] and ``dc/ds``.
    inertia, dinertia:
        Rotational inertia about the centre of mass ``I_c`` [kg·m²] and ``dI_c/ds``.
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray
    dmass: float
    dcom: np.ndarray
    dinertia: np.ndarray

    def spatial(self) -> pin.Inertia:
        """``Y(s)`` as a :class:`pinocchio.Inertia`."""
        return pin.Inertia(self.mass, np.asarray(self.com, float),
                           np.asarray(self.inertia, float))

    def spatial_derivative(self) -> np.ndarray:
        """``dY/ds`` as a 6×6 matrix (may be indefinite)."""
        C, dC = skew(self.com), skew(self.dcom)
        dh = self.dmass * np.asarray(self.com) + self.mass * np.asarray(self.dcom)
        dH = skew(dh)
        dY = np.empty((6, 6))
        dY[:3, :3] = self.dmass * np.eye(3)
        dY[:3, 3:] = -dH
        dY[3:, :3] = dH
        dY[3:, 3:] = (self.dinertia - self.dmass * C @ C
                      - self.mass * (dC @ C + C @ dC))
        return dY


class MassLaw(ABC):
    """Mass, centre of mass and inertia of a body as smooth functions of a state ``s``.

    To write a law:

    1. Subclass :class:`MassLaw` and implement :meth:`properties`, returning the values
       *and* the ``s``-derivatives at ``s`` (one parametrisation, so they cannot drift
       apart).
    2. Keep ``m > 0`` and ``I_c`` positive definite on the admissible range of ``s``;
       raise :class:`~winder.ModelError` outside it.
    3. Use :meth:`inertia` and :meth:`rate` to feed
       :meth:`winder.VariableMassModel.set_body`; ``rate`` needs ``ṡ``.
    """

    @abstractmethod
    def properties(self, s: float) -> MassProperties:
        """Mass properties and their ``s``-derivatives at growth state ``s``."""

    def inertia(self, s: float) -> pin.Inertia:
        """Spatial inertia ``Y(s)`` in the joint frame."""
        return self.properties(s).spatial()

    def rate(self, s: float, s_dot: float) -> np.ndarray:
        """Rate inertia ``Ẏ = dY/ds · ṡ`` as a 6×6 matrix."""
        return self.properties(s).spatial_derivative() * s_dot


class FunctionMassLaw(MassLaw):
    """A mass law from callables: each of ``mass``, ``com``, ``inertia`` maps ``s`` to
    ``(value, d value/ds)``. Useful for time-varying bodies (``s = t``)."""

    def __init__(self, mass: Callable[[float], tuple[float, float]],
                 com: Callable[[float], tuple[np.ndarray, np.ndarray]],
                 inertia: Callable[[float], tuple[np.ndarray, np.ndarray]]) -> None:
        self._mass, self._com, self._inertia = mass, com, inertia

    def properties(self, s: float) -> MassProperties:
        m, dm = self._mass(s)
        c, dc = self._com(s)
        ic, dic = self._inertia(s)
        if not m > 0.0:
            raise ModelError(f"mass law gives non-positive mass {m!r} at s = {s!r}")
        return MassProperties(float(m), np.asarray(c, float), np.asarray(ic, float),
                              float(dm), np.asarray(dc, float), np.asarray(dic, float))


@dataclass(frozen=True)
class PaperRollLaw(MassLaw):
    """A paper roll on a core; growth state ``s = r``, the outer radius [m].

    ``m(r) = m_core + ρπL(r² − r_c²)``, ``J(r) = J_core + ½ρπL(r⁴ − r_c⁴)`` about the roll
    axis (joint ``y``), centre of mass at ``(e, 0, 0)`` in the roll frame. Transverse
    inertias: core and paper as hollow cylinders of width ``L``.

    Parameters
    ----------
    core_radius: ``r_c`` [m]; core_mass: [kg]; core_inertia: ``J_core`` [kg·m²];
    width: ``L`` [m]; density: ``ρ`` [kg/m³]; com_offset: ``e`` [m].
    """

    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    density: float
    com_offset: float = 0.0

    def __post_init__(self) -> None:
        for name in ("core_radius", "core_mass", "core_inertia", "width"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ModelError(f"PaperRollLaw.{name} must be finite and > 0, got {value!r}")
        if not (math.isfinite(self.density) and self.density >= 0.0):
            raise ModelError(f"PaperRollLaw.density must be finite and >= 0, got {self.density!r}")
        if not math.isfinite(self.com_offset):
            raise ModelError(f"PaperRollLaw.com_offset must be finite, got {self.com_offset!r}")

    # scalar laws (fast path used by the winder) ---------------------------------------
    def mass(self, r: float) -> float:
        """``m(r)`` [kg]."""
        return self.core_mass + self.density * math.pi * self.width * (r * r - self.core_radius**2)

    def polar_inertia(self, r: float) -> float:
        """``J(r)`` about the roll axis [kg·m²]."""
        k = 0.5 * self.density * math.pi * self.width
        return self.core_inertia + k * (r**4 - self.core_radius**4)

    def mass_derivative(self, r: float) -> float:
        """``dm/dr`` [kg/m]."""
        return 2.0 * math.pi * self.density * self.width * r

    def polar_inertia_derivative(self, r: float) -> float:
        """``dJ/dr`` [kg·m]."""
        return 2.0 * math.pi * self.density * self.width * r**3

    def write_inertia(self, r: float, Y: pin.Inertia) -> None:
        """Fast path: overwrite mass and rotational inertia of ``Y`` (lever ``(e,0,0)``
        must already be set) with ``Y(r)``."""
        m, J = self.mass(r), self.polar_inertia(r)
        It = 0.5 * J + m * self.width**2 / 12.0
        me2 = m * self.com_offset**2
        Y.mass = m
        Y.inertia = np.diag((It, J - me2, It - me2))

    def rate_into(self, r: float, r_dot: float, out: np.ndarray) -> None:
        """Fast path: write ``Ẏ = dY/dr · ṙ`` into the 6×6 array ``out`` (only the
        structurally non-zero entries are written; the others must be zero)."""
        dm = self.mass_derivative(r) * r_dot
        dJ = self.polar_inertia_derivative(r) * r_dot
        dIt = 0.5 * dJ + dm * self.width**2 / 12.0
        dme = dm * self.com_offset
        out[0, 0] = out[1, 1] = out[2, 2] = dm
        out[1, 5] = out[5, 1] = dme
        out[2, 4] = out[4, 2] = -dme
        out[3, 3] = out[5, 5] = dIt
        out[4, 4] = dJ

    def properties(self, r: float) -> MassProperties:
        m, dm = self.mass(r), self.mass_derivative(r)
        J, dJ = self.polar_inertia(r), self.polar_inertia_derivative(r)
        if not m > 0.0:
            raise ModelError(f"paper roll mass {m!r} kg is not positive at r = {r!r} m")
        e = self.com_offset
        L2 = self.width**2 / 12.0
        It, dIt = 0.5 * J + m * L2, 0.5 * dJ + dm * L2
        me2, dme2 = m * e * e, dm * e * e
        inertia = np.diag([It, J - me2, It - me2])
        dinertia = np.diag([dIt, dJ - dme2, dIt - dme2])
        com = np.array([e, 0.0, 0.0])
        return MassProperties(m, com, inertia, dm, np.zeros(3), dinertia)
