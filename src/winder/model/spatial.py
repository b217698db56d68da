"""Pinocchio's articulated-body algorithm and RNEA over a ``pin.Model``, on CasADi symbols.

This is the note's route "py": the algorithms of Pinocchio (LOCAL convention: motions and
forces ``[linear; angular]`` in each joint's frame, ``fext`` per joint in its frame),
written over the structure of a :class:`pinocchio.Model` (parents, joint placements, joint
axes) with the inertias, external forces and gravity as symbolic inputs. It supports the
1-DoF joints of planar machines (revolute and prismatic, any axis); every result is tested
against ``pin.aba``/``pin.rnea`` to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from winder._errors import ModelError

__all__ = ["JointInfo", "joint_infos", "SpatialFunctions", "python_route"]


@dataclass(frozen=True)
class JointInfo:
    """Joint ``i`` of the model: parent, placement in the parent joint frame, axis, kind."""

    parent: int
    rotation: np.ndarray  # 3×3 of the placement
    translation: np.ndarray  # [m]
    axis: np.ndarray  # unit vector in the joint frame
    revolute: bool


def joint_infos(model: pin.Model) -> list[JointInfo]:
    """The structure of every joint after the universe (1-DoF joints only)."""
    out = []
    for i in range(1, model.njoints):
        jm = model.joints[i]
        if jm.nq != 1 or jm.nv != 1:
            raise ModelError(f"joint {model.names[i]!r} ({jm.shortname()}): only 1-DoF "
                             "revolute and prismatic joints are supported")
        jd = jm.createData()
        jm.calc(jd, np.zeros(model.nq))
        S = np.asarray(jd.S).reshape(6)
        lin, ang = S[:3], S[3:]
        revolute = bool(np.linalg.norm(ang) > 0.5)
        axis = ang if revolute else lin
        M = model.jointPlacements[i]
        out.append(JointInfo(int(model.parents[i]), np.array(M.rotation),
                             np.array(M.translation), np.array(axis), revolute))
    return out


def _skew(ca: Any, v: Any) -> Any:
    return ca.vertcat(ca.horzcat(0, -v[2], v[1]), ca.horzcat(v[2], 0, -v[0]),
                      ca.horzcat(-v[1], v[0], 0))


def _rotation(ca: Any, axis: np.ndarray, angle: Any) -> Any:
    """Rodrigues: rotation by ``angle`` about the unit ``axis``."""
    K = _skew(ca, ca.DM(axis))
    return ca.DM.eye(3) + ca.sin(angle) * K + (1 - ca.cos(angle)) * (K @ K)


def _act_inv_matrix(ca: Any, R: Any, p: Any) -> Any:
    """6×6 matrix of ``M.actInv`` on motions ``[v; ω]`` for ``M = (R, p)``."""
    Rt = R.T
    return ca.vertcat(ca.horzcat(Rt, -Rt @ _skew(ca, p)), ca.horzcat(ca.SX.zeros(3, 3), Rt))


def _motion_cross(ca: Any, v: Any, w: Any) -> Any:
    lv, av = v[:3], v[3:]
    return ca.vertcat(ca.cross(av, w[:3]) + ca.cross(lv, w[3:]), ca.cross(av, w[3:]))


def _force_cross(ca: Any, v: Any, f: Any) -> Any:
    lv, av = v[:3], v[3:]
    return ca.vertcat(ca.cross(av, f[:3]), ca.cross(av, f[3:]) + ca.cross(lv, f[:3]))


def inertia_matrix(ca: Any, dyn: Any) -> Any:
    """6×6 spatial inertia from the 10 dynamic parameters of
    ``pin.Inertia.toDynamicParameters()``: ``m, m c, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz``
    (rotational inertia about the joint origin)."""
    m, mc = dyn[0], dyn[1:4]
    Io = ca.vertcat(ca.horzcat(dyn[4], dyn[5], dyn[7]), ca.horzcat(dyn[5], dyn[6], dyn[8]),
                    ca.horzcat(dyn[7], dyn[8], dyn[9]))
    S = _skew(ca, mc)
    return ca.vertcat(ca.horzcat(m * ca.SX.eye(3), -S), ca.horzcat(S, Io))


class SpatialFunctions:
    """``vel``, ``aba`` and ``rnea`` of a model on CasADi ``SX`` inputs (see module doc).

    Arguments are column vectors: ``q, v`` [nq], ``tau``/``a`` [nv], ``dyn`` [10 per joint],
    ``fext`` [6 per joint, LOCAL], ``g`` [3] (the gravity vector, e.g. ``(0, 0, −9.81)``).
    """

    def __init__(self, model: pin.Model) -> None:
        self.joints = joint_infos(model)
        self.nv = model.nv
        self._last: tuple[Any, Any, tuple[list[Any], list[Any], list[Any]]] | None = None
        self._last_bodies: tuple[Any, Any, Any, tuple[list[Any], ...]] | None = None

    def _kinematics(self, q: Any, v: Any) -> tuple[list[Any], list[Any], list[Any]]:
        """Each joint's placement (motion transform from its parent), spatial velocity and
        motion subspace; those of the last call again when ``q`` and ``v`` are the same
        symbols (the velocities, ABA and RNEA of one evaluation share them: built once)."""
        import casadi as ca

        last = self._last
        if last is not None and ca.is_equal(last[0], q, 0) and ca.is_equal(last[1], v, 0):
            return last[2]
        X, V, S = [], [], []
        for i, j in enumerate(self.joints):
            axis = ca.DM(j.axis)
            if j.revolute:
                R = ca.DM(j.rotation) @ _rotation(ca, j.axis, q[i])
                p = ca.DM(j.translation)
                s = ca.vertcat(ca.DM.zeros(3), axis)
            else:
                R = ca.DM(j.rotation)
                p = ca.DM(j.translation) + R @ axis * q[i]
                s = ca.vertcat(axis, ca.DM.zeros(3))
            A = _act_inv_matrix(ca, R, p)  # parent motion -> joint frame
            vp = V[j.parent - 1] if j.parent > 0 else ca.SX.zeros(6)
            V.append(A @ vp + s * v[i])
            X.append(A)
            S.append(s)
        self._last = (q, v, (X, V, S))
        return X, V, S

    def _bodies(self, q: Any, v: Any, dyn: Any) -> tuple[list[Any], ...]:
        """:meth:`_kinematics` and, per joint, the velocity-product acceleration ``C = v ×
        S q̇``, the spatial inertia ``Y`` and the bias force ``v ×* Y v``; those of the last
        call again for the same symbols (ABA and RNEA of one evaluation share them)."""
        import casadi as ca

        last = self._last_bodies
        if last is not None and all(ca.is_equal(a, b, 0) for a, b in zip(last[:3], (q, v, dyn),
                                                                          strict=True)):
            return last[3]
        X, V, S = self._kinematics(q, v)
        C, Y, B = [], [], []
        for i in range(len(self.joints)):
            C.append(_motion_cross(ca, V[i], S[i] * v[i]))
            Y.append(inertia_matrix(ca, dyn[10 * i:10 * i + 10]))
            B.append(_force_cross(ca, V[i], Y[i] @ V[i]))
        out = (X, V, S, C, Y, B)
        self._last_bodies = (q, v, dyn, out)
        return out

    def vel(self, q: Any, v: Any) -> list[Any]:
        """Spatial velocity of every joint in its frame (``data.v[1:]``)."""
        return self._kinematics(q, v)[1]

    def aba(self, q: Any, v: Any, tau: Any, dyn: Any, fext: Any, g: Any) -> Any:
        """Joint accelerations ``q̈`` (``pin.aba(model, data, q, v, tau, fext)``)."""
        import casadi as ca

        X, V, S, C, Y, B = self._bodies(q, v, dyn)
        n = len(self.joints)
        Ia = list(Y)
        pA = [B[i] - fext[6 * i:6 * i + 6] for i in range(n)]
        U, D, u = [None] * n, [None] * n, [None] * n
        for i in reversed(range(n)):
            U[i] = Ia[i] @ S[i]
            D[i] = S[i].T @ U[i]
            u[i] = tau[i] - S[i].T @ pA[i]
            par = self.joints[i].parent
            if par > 0:
                Iaa = Ia[i] - U[i] @ U[i].T / D[i]
                pa = pA[i] + Iaa @ C[i] + U[i] * u[i] / D[i]
                Ia[par - 1] = Ia[par - 1] + X[i].T @ Iaa @ X[i]
                pA[par - 1] = pA[par - 1] + X[i].T @ pa
        a0 = ca.vertcat(-g, ca.DM.zeros(3))
        A: list[Any] = [None] * n
        ddq = []
        for i in range(n):
            par = self.joints[i].parent
            ap = X[i] @ (A[par - 1] if par > 0 else a0) + C[i]
            qdd = (u[i] - U[i].T @ ap) / D[i]
            A[i] = ap + S[i] * qdd
            ddq.append(qdd)
        return ca.vertcat(*ddq)

    def rnea(self, q: Any, v: Any, a: Any, dyn: Any, fext: Any, g: Any) -> Any:
        """Joint torques ``τ`` (``pin.rnea(model, data, q, v, a, fext)``)."""
        import casadi as ca

        X, V, S, C, Y, B = self._bodies(q, v, dyn)
        n = len(self.joints)
        a0 = ca.vertcat(-g, ca.DM.zeros(3))
        A: list[Any] = [None] * n
        F = []
        for i in range(n):
            par = self.joints[i].parent
            A[i] = X[i] @ (A[par - 1] if par > 0 else a0) + S[i] * a[i] + C[i]
            F.append(Y[i] @ A[i] + B[i] - fext[6 * i:6 * i + 6])
        tau: list[Any] = [None] * n
        for i in reversed(range(n)):
            tau[i] = S[i].T @ F[i]
            par = self.joints[i].parent
            if par > 0:
                F[par - 1] = F[par - 1] + X[i].T @ F[i]
        return ca.vertcat(*tau)


def python_route(model: pin.Model) -> SpatialFunctions:
    """The route-"py" functions of ``model``."""
    return SpatialFunctions(model)
