"""Rigid-body dynamics with time-varying mass on top of Pinocchio.

For every body with spatial inertia ``Y(t)`` and spatial velocity ``v`` (joint frame)

    d/dt (Y v) + v ×* (Y v) = f_ext      ⇔      Y a + v ×* Y v = f_ext − Ẏ v,

so the variable-mass effect is the spatial force ``−Ẏ v`` added to the body's external
forces before Pinocchio's ABA/RNEA run. Mass that joins a body brings no momentum;
momentum carried by arriving or leaving mass is added with :meth:`momentum_flux`.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from winder._args import number, show
from winder._errors import ArgumentError, ArgumentTypeError

__all__ = ["VariableMassModel"]


def _as_rate_matrix(rate: pin.Inertia | np.ndarray) -> np.ndarray:
    where = "VariableMassModel.set_body"
    if isinstance(rate, pin.Inertia):
        arr = np.array(rate.matrix(), dtype=float)
    else:
        try:
            arr = np.array(rate, dtype=float)
        except (TypeError, ValueError):
            raise ArgumentTypeError(f"{where}: rate must be a pin.Inertia or a symmetric 6x6 "
                                    f"array of numbers, got {show(rate)} "
                                    f"({type(rate).__name__})") from None
    if arr.shape != (6, 6):
        raise ArgumentError(f"{where}: rate must be a pin.Inertia or a symmetric 6x6 array, "
                            f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ArgumentError(f"{where}: rate has non-finite entries at "
                            f"{np.argwhere(~np.isfinite(arr)).tolist()[:4]}; valid: finite "
                            "numbers")
    asym = np.abs(arr - arr.T).max()
    if not asym <= 1e-12 * max(1.0, np.abs(arr).max()):
        raise ArgumentError(f"{where}: rate must be symmetric (it is the time derivative of a "
                            f"spatial inertia matrix), got |rate - rate.T| up to {asym:.3g}")
    return arr


class VariableMassModel:
    """A :class:`pinocchio.Model` whose bodies may carry time-varying mass properties.

    The model is wrapped, not copied: :meth:`set_body` writes ``model.inertias[j]`` of
    the caller's model. Joints without a rate behave exactly as plain Pinocchio.

    Parameters
    ----------
    model:
        Any Pinocchio model (revolute, prismatic, free-flyer joints, chains, trees).
    """

    def __init__(self, model: pin.Model) -> None:
        if not isinstance(model, pin.Model):
            raise ArgumentTypeError(f"VariableMassModel: model must be a pinocchio.Model, got "
                                    f"{show(model)} ({type(model).__name__})")
        self.model = model
        self.data = model.createData()
        self._rates: dict[int, np.ndarray] = {}
        self._zero = pin.StdVec_Force()
        for _ in range(model.njoints):
            self._zero.append(pin.Force.Zero())
        self._work = pin.StdVec_Force()
        for _ in range(model.njoints):
            self._work.append(pin.Force.Zero())

    # bodies ----------------------------------------------------------------------------
    def _check_joint(self, joint_id: int) -> int:
        names = ", ".join(f"{i}={self.model.names[i]}" for i in range(1, self.model.njoints))
        if isinstance(joint_id, bool) or not isinstance(joint_id, numbers.Integral):
            raise ArgumentTypeError(f"joint_id must be an integer joint index, got "
                                    f"{show(joint_id)} ({type(joint_id).__name__}); valid: "
                                    f"{names}")
        j = int(joint_id)
        if not 1 <= j < self.model.njoints:
            raise ArgumentError(f"joint_id {joint_id!r} is not a moving joint of the model; "
                                f"valid: {names or 'none (the model has no moving joint)'}")
        return j

    def set_body(self, joint_id: int, *, inertia: pin.Inertia | None = None,
                 rate: pin.Inertia | np.ndarray | None = None) -> None:
        """Set the body of joint ``joint_id``: its inertia ``Y`` and its rate ``Ẏ``.

        Parameters
        ----------
        joint_id:
            Index of the joint in ``model`` (1 … njoints-1).
        inertia:
            Spatial inertia ``Y`` of the body in the joint frame; ``None`` keeps the
            model's.
        rate:
            ``Ẏ = dY/dt``: a :class:`pinocchio.Inertia` or a symmetric 6×6 array [SI per
            second]. It may be indefinite (build it from attributes or as a matrix).
            ``None`` means ``Ẏ = 0``.
        """
        j = self._check_joint(joint_id)
        if inertia is not None:
            if not isinstance(inertia, pin.Inertia):
                raise ArgumentTypeError(f"VariableMassModel.set_body: inertia must be a "
                                        f"pin.Inertia, got {show(inertia)} "
                                        f"({type(inertia).__name__})")
            self.model.inertias[j] = inertia
        if rate is None:
            self._rates.pop(j, None)
        else:
            mat = _as_rate_matrix(rate)
            if np.any(mat):
                self._rates[j] = mat
            else:
                self._rates.pop(j, None)

    def bind_rate(self, joint_id: int) -> np.ndarray:
        """Fast path: a writable 6×6 array that *is* the body's rate ``Ẏ`` from now on.

        Fill it in place before each :meth:`aba_into` (no validation, no allocation).
        ``set_body(joint_id, rate=None)`` unbinds it."""
        j = self._check_joint(joint_id)
        buf = np.zeros((6, 6))
        self._rates[j] = buf
        return buf

    def rate(self, joint_id: int) -> np.ndarray:
        """``Ẏ`` of a joint's body as a 6×6 matrix (zeros if none is set)."""
        j = self._check_joint(joint_id)
        return self._rates.get(j, np.zeros((6, 6))).copy()

    # forces ----------------------------------------------------------------------------
    def _check_fext(self, fext: Sequence[pin.Force] | None) -> Sequence[pin.Force]:
        if fext is None:
            return self._zero
        n = self.model.njoints
        try:
            count = len(fext)
        except TypeError:
            raise ArgumentTypeError(f"fext must be a list of pin.Force, one per joint, got "
                                    f"{show(fext)} ({type(fext).__name__})") from None
        if count != n:
            raise ArgumentError(f"fext has {count} forces but the model has {n} joints "
                                f"(one pin.Force per joint, the universe included)")
        for i, f in enumerate(fext):
            if not isinstance(f, pin.Force):
                raise ArgumentTypeError(f"fext[{i}] is a {type(f).__name__}, expected "
                                        "pin.Force")
        return fext

    def _check_vector(self, name: str, value: np.ndarray, size: int) -> np.ndarray:
        try:
            arr = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise ArgumentTypeError(f"{name} must be an array of {size} numbers, got "
                                    f"{show(value)} ({type(value).__name__})") from None
        if arr.shape != (size,):
            raise ArgumentError(f"{name} must have shape ({size},) for this model, got shape "
                                f"{arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ArgumentError(f"{name} has non-finite entries {show(arr.tolist())}; valid: "
                                "finite numbers")
        return arr
    def variable_mass_forces(self, q: np.ndarray, v: np.ndarray,
                             fext: Sequence[pin.Force] | None = None) -> pin.StdVec_Force:
        """``fext`` plus ``−Ẏ v`` on every variable body (joint frames), as a new list."""
        base = self._check_fext(fext)
        q = self._check_vector("q", q, self.model.nq)
        v = self._check_vector("v", v, self.model.nv)
        out = pin.StdVec_Force()
        for f in base:
            out.append(pin.Force(f))
        self._add_rate_forces(q, v, out)
        return out

    def _add_rate_forces(self, q: np.ndarray, v: np.ndarray, fext: pin.StdVec_Force) -> None:
        """Add ``−Ẏ v`` in place to the force of every variable body (joint frames)."""
        if self._rates:
            pin.forwardKinematics(self.model, self.data, q, v)
            for j, Yd in self._rates.items():
                fext[j] = pin.Force(fext[j].vector - Yd @ self.data.v[j].vector)

    def momentum_flux(self, q: np.ndarray, joint_id: int, *, mass_rate: float,
                      velocity: np.ndarray, point: np.ndarray) -> pin.Force:
        """Force of a mass flux on a body, in the joint frame, to add to ``fext``.

        Mass arrives at rate ``mass_rate`` ``ṁ`` [kg/s] with world velocity ``velocity``
        ``u`` [m/s] at the world point ``point`` [m]; it brings the momentum flux
        ``ṁ u`` acting at that point. For ejection (``ṁ < 0``) ``u`` is the world velocity
        of the leaving mass (a rocket: body velocity minus the exhaust speed).
        """
        j = self._check_joint(joint_id)
        q = self._check_vector("q", q, self.model.nq)
        mass_rate = number("VariableMassModel.momentum_flux", "mass_rate", mass_rate,
                           unit="kg/s")
        velocity = self._check_vector("velocity", velocity, 3)
        point = self._check_vector("point", point, 3)
        pin.forwardKinematics(self.model, self.data, q)
        lin = mass_rate * velocity
        f_world = pin.Force(lin, np.cross(point, lin))
        return self.data.oMi[j].actInv(f_world)

    # dynamics --------------------------------------------------------------------------
    def aba(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
            fext: Sequence[pin.Force] | None = None) -> np.ndarray:
        """Forward dynamics ``a`` with the ``−Ẏ v`` terms; ``fext`` in joint frames."""
        tau = self._check_vector("tau", tau, self.model.nv)
        forces = self.variable_mass_forces(q, v, fext)
        return pin.aba(self.model, self.data, q, v, tau, forces).copy()

    def rnea(self, q: np.ndarray, v: np.ndarray, a: np.ndarray,
             fext: Sequence[pin.Force] | None = None) -> np.ndarray:
        """Inverse dynamics ``τ`` consistent with :meth:`aba`; ``fext`` in joint frames."""
        a = self._check_vector("a", a, self.model.nv)
        forces = self.variable_mass_forces(q, v, fext)
        return pin.rnea(self.model, self.data, q, v, a, forces).copy()

    def aba_into(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                 fext: pin.StdVec_Force) -> np.ndarray:
        """Fast path of :meth:`aba`: adds ``−Ẏ v`` *in place* to a caller-owned ``fext``
        of the right length (not re-checked) and runs ABA. Returns ``data.ddq``."""
        self._add_rate_forces(q, v, fext)
        return pin.aba(self.model, self.data, q, v, tau, fext)

    def rnea_into(self, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                  fext: pin.StdVec_Force) -> np.ndarray:
        """Fast path of :meth:`rnea`, like :meth:`aba_into` (``fext`` modified in place)."""
        self._add_rate_forces(q, v, fext)
        return pin.rnea(self.model, self.data, q, v, a, fext)
