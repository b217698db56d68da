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
from typing import TYPE_CHECKING

import numpy as np

from winder._args import number
from winder._errors import ArgumentError, ModelError
from winder.model.paper_roll import max_com_offset, paper_roll_mass

if TYPE_CHECKING:  # Pinocchio on first use: the scene's checks read this module without it
    import pinocchio as pin

__all__ = ["MassLaw", "MassProperties", "FunctionMassLaw", "PaperRollLaw", "paper_roll_mass",
           "skew", "max_com_offset"]


def skew(x: np.ndarray) -> np.ndarray:
    """Cross-product matrix ``[x]`` with ``[x] y = x × y``."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


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
        import pinocchio as pin

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
        """Rate inertia ``Ẏ = dY/ds · ṡ`` as a 6×6 matrix (``ṡ`` finite)."""
        s_dot = number(f"{type(self).__name__}.rate", "s_dot", s_dot)
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
    core_radius: ``r_c`` > 0 [m]; core_mass: > 0 [kg]; core_inertia: ``J_core`` > 0
    [kg·m²]; width: ``L`` > 0 [m]; density: ``ρ`` >= 0 [kg/m³]; com_offset: ``e`` [m],
    ``0 <= e < min(r_c, √(J_core/m_core))`` (:func:`max_com_offset`: the
    centre of mass inside the core, the inertia about it positive). All finite.

    The laws are defined for ``r >= r_c`` (finite): :meth:`mass`, :meth:`polar_inertia`,
    their derivatives, :meth:`properties`, :meth:`inertia` and :meth:`rate` raise
    :class:`~winder.ArgumentError` for any other ``r``. The fast path :meth:`scalars` does
    not check (an integrator's trial states may probe a little below the core, where the
    polynomials continue smoothly).
    """

    core_radius: float
    core_mass: float
    core_inertia: float
    width: float
    density: float
    com_offset: float = 0.0

    def __post_init__(self) -> None:
        where = "PaperRollLaw"
        for name, unit in (("core_radius", "m"), ("core_mass", "kg"),
                           ("core_inertia", "kg·m²"), ("width", "m")):
            object.__setattr__(self, name, number(where, name, getattr(self, name), lo=0.0,
                                                  lo_open=True, unit=unit))
        object.__setattr__(self, "density", number(where, "density", self.density, lo=0.0,
                                                   unit="kg/m³"))
        e_max = max_com_offset(self.core_radius, self.core_mass, self.core_inertia)
        e = number(where, "com_offset", self.com_offset, lo=0.0, unit="m")
        if not e < e_max:
            raise ArgumentError(f"{where}: com_offset = {e!r} m is out of range; valid: >= 0 "
                                f"and < min(core_radius, √(core_inertia/core_mass)) = "
                                f"{e_max:.6g} m (the centre of mass inside the core, the "
                                "inertia about it positive)")
        object.__setattr__(self, "com_offset", e)

    def _radius(self, where: str, r: float) -> float:
        """``r`` checked: finite and ``>= r_c``."""
        return number(f"PaperRollLaw.{where}", "r", r, lo=self.core_radius, unit="m",
                      valid=f"a finite radius r >= core_radius = {self.core_radius:g} m")

    # scalar laws (fast path used by the winder) ---------------------------------------
    def scalars(self, r: float) -> tuple[float, float, float, float]:
        """Fast path, unchecked: ``(m, J, dm/dr, dJ/dr)`` at ``r`` [kg, kg·m², kg/m,
        kg·m] (:func:`paper_roll_mass`, the law the machines use)."""
        return paper_roll_mass(r, self.core_radius, self.core_mass, self.core_inertia,
                               math.pi * self.density * self.width)

    def mass(self, r: float) -> float:
        """``m(r)`` [kg]."""
        return self.scalars(self._radius("mass", r))[0]

    def polar_inertia(self, r: float) -> float:
        """``J(r)`` about the roll axis [kg·m²]."""
        return self.scalars(self._radius("polar_inertia", r))[1]

    def mass_derivative(self, r: float) -> float:
        """``dm/dr`` [kg/m]."""
        return self.scalars(self._radius("mass_derivative", r))[2]

    def polar_inertia_derivative(self, r: float) -> float:
        """``dJ/dr`` [kg·m]."""
        return self.scalars(self._radius("polar_inertia_derivative", r))[3]

    def _about_com(self, m: float, J: float) -> tuple[float, float, float]:
        """Diagonal of the rotational inertia about the centre of mass [kg·m²] from ``m``
        and ``J`` (linear in both: the same map takes ``(dm/dr, dJ/dr)`` to its
        derivative)."""
        It = 0.5 * J + m * self.width**2 / 12.0
        me2 = m * self.com_offset**2
        return It, J - me2, It - me2

    def properties(self, r: float) -> MassProperties:
        m, J, dm, dJ = self.scalars(self._radius("properties", r))
        inertia = np.diag(self._about_com(m, J))
        dinertia = np.diag(self._about_com(dm, dJ))
        if not (np.all(np.isfinite(inertia)) and np.all(np.isfinite(dinertia))):
            raise ArgumentError(f"PaperRollLaw.properties: r = {r!r} m: the roll's inertia "
                                f"overflows (mass {m:.3g} kg); valid: a radius whose mass "
                                "properties are finite numbers")
        com = np.array([self.com_offset, 0.0, 0.0])
        return MassProperties(m, com, inertia, dm, np.zeros(3), dinertia)
