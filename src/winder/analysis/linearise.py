"""Jacobian of a machine's dynamics: the exact, generated ``∂ẏ/∂y``.

``winder.jacobian(system, t, y)`` is :meth:`MachineSystem.jac` behind the argument checks
of the public API: CasADi differentiates the one symbolic expression of the dynamics
(Pinocchio's ABA on symbols, the force elements, the variable-mass ``−Ẏv``) and the
generated C evaluates it (:mod:`winder.model.codegen`). On the numeric Pinocchio path (no C
compiler) it is a central difference of ``system.rhs``.
"""

from __future__ import annotations

import numpy as np

from winder._args import number, show
from winder._errors import ArgumentError, ArgumentTypeError
from winder.solve.system import MachineSystem

__all__ = ["jacobian"]


def jacobian(system: MachineSystem, t: float, y: np.ndarray) -> np.ndarray:
    """``∂f/∂y`` [n × n] of ``f = system.rhs`` at time ``t`` [s] and state ``y`` (finite,
    ``system.n_states`` values in the order of ``system.state_names``), with the system's
    parameters (``system.params``) and locked modes (``system.modes``)."""
    if not isinstance(system, MachineSystem):
        raise ArgumentTypeError(f"jacobian: system must be a MachineSystem "
                                f"(winder.solve.system), got {show(system)} "
                                f"({type(system).__name__})")
    t = number("jacobian", "t", t, unit="s")
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentTypeError(f"jacobian: y must be an array of {system.n_states} numbers, "
                                f"got {show(y)} ({type(y).__name__})") from None
    if y.shape != (system.n_states,) or not np.all(np.isfinite(y)):
        raise ArgumentError(f"jacobian: y must be {system.n_states} finite values "
                            f"({', '.join(system.state_names)}), got {show(y.tolist())}")
    return np.array(system.jac(t, np.ascontiguousarray(y)), dtype=float)
