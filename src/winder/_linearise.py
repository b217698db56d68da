"""Jacobian of the winder dynamics: Pinocchio's ABA derivatives plus the chain rule.

``∂ẏ/∂y`` of :meth:`WinderSystem.rhs`. The rigid-body part (``∂q̈/∂q``, ``∂q̈/∂v`` with the
joint-frame external forces held) comes from ``pin.computeABADerivatives``; the external
forces then enter through ``q̈ += M⁻¹ Σ_j J_jᵀ δf_j``: the nip forces through the contact
law's tangent (``∂F_n/∂δ``, ``∂F_n/∂δ̇``), the slip law (``∂F_ss/∂F_n``, ``∂F_ss/∂v_s``),
the web momentum (``∂(ṁ u)``) and the rotation of the nip force into the body frames;
the variable-mass force ``−Ẏ v`` through ``∂v/∂(q, v)`` (Pinocchio's joint velocity
derivatives) and ``∂Ẏ/∂ω``. The radius column (the mass properties change with ``r``,
which Pinocchio's derivatives do not cover) is a central difference.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ._args import number, show
from ._errors import ArgumentError, ArgumentTypeError
from ._model import DRUM, ROLL, ROLL_Z
from ._system import WinderSystem

__all__ = ["jacobian"]


def jacobian(system: WinderSystem, t: float, y: np.ndarray) -> np.ndarray:
    """``∂f/∂y`` [n × n] of ``f = system.rhs`` at time ``t`` [s] and state ``y`` (finite,
    ``system.n_states`` values in the order of ``system.state_names``)."""
    if not isinstance(system, WinderSystem):
        raise ArgumentTypeError(f"jacobian: system must be a winder.WinderSystem, got "
                                f"{show(system)} ({type(system).__name__})")
    t = number("jacobian", "t", t, unit="s")
    try:
        y = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentTypeError(f"jacobian: y must be an array of {system.n_states} numbers, "
                                f"got {show(y)} ({type(y).__name__})") from None
    if y.shape != (system.n_states,) or not np.all(np.isfinite(y)):
        raise ArgumentError(f"jacobian: y must be {system.n_states} finite values "
                            f"({', '.join(system.state_names)}), got {show(y.tolist())}")
    n = len(y)
    sc = system.scene
    fx_on = sc.effects
    c, qv, a = system.evaluate(t, y)  # leaves system._fext = nip forces + (−Ẏ v)
    model, data = system.model, system.data
    q, v = qv[:3].copy(), qv[3:].copy()
    fext = pin.StdVec_Force()
    for f in system._fext:
        fext.append(pin.Force(f.vector.copy()))
    pin.computeABADerivatives(model, data, q, v, system._tau, fext)
    da_dq, da_dv = data.ddq_dq.copy(), data.ddq_dv.copy()
    Minv = np.triu(data.Minv)
    Minv = Minv + np.triu(Minv, 1).T
    pin.computeJointJacobians(model, data, q)
    Jl = {j: pin.getJointJacobian(model, data, j, pin.LOCAL) for j in (DRUM, ROLL)}
    free = system._free_drum
    # state → (q, v) maps: columns of dq/dy, dv/dy
    dq = np.zeros((3, n))
    dv = np.zeros((3, n))
    dq[1, 0] = dq[2, 1] = 1.0          # z, φ
    dv[1, 2] = dv[2, 3] = 1.0          # ż, ω
    i_om = -1
    if free:
        dq[0, 5] = dv[0, 6] = 1.0      # θ_d, Ω
        i_om = 6
    e = np.eye(n)
    R, r, w = system.drum_radius, c.r, c.omega
    h2pi = system.h_over_2pi
    # scalar force gradients
    g_fn = np.zeros(n)
    g_ft = np.zeros(n)
    g_fss = np.zeros(n)
    g_web = np.zeros(n)
    ft_row = None
    if fx_on.contact:
        law = system.contact.law
        if c.normal_force > 0.0:
            kt, ct = law.tangent(c.penetration, c.penetration_rate)
            g_fn = kt * (-e[0] + e[4]) + ct * (-e[2] + h2pi * e[3])
        g_vs = -r * e[3] - w * e[4] + (R * e[i_om] if free else 0.0)
        mu, vref = system.contact.mu, system.contact.v_ref
        th = math.tanh(c.slip_velocity / vref)
        g_fss = mu * th * g_fn + mu * c.normal_force * (1.0 - th * th) / vref * g_vs
        if fx_on.slip_relaxation:
            relax = next(eff for eff in system.effects if eff.states)
            i_ft = relax.index
            g_ft = e[i_ft].copy()
            rate = (abs(c.Omega * R) + relax.v_min) / relax.sigma
            ft_row = (i_ft, rate * (g_fss - e[i_ft]))
            if free:
                ft_row[1][i_om] += math.copysign(R, c.Omega) / relax.sigma * (
                    c.steady_friction - c.friction_force)
        else:
            g_ft = g_fss
    if fx_on.web_momentum:
        K = system.law.scalars(1.0)[2] * h2pi  # ṁ = K r ω (dm/dr at r = 1 m)
        g_mr = K * (r * e[3] + w * e[4])
        if fx_on.contact:
            g_web = c.Omega * R * g_mr + (c.mass_rate * R * e[i_om] if free else 0.0)
        else:
            g_web = w * r * g_mr + c.mass_rate * (r * e[3] + w * e[4])
    # joint-frame force derivatives [6 × n]
    s, co = math.sin(c.phi), math.cos(c.phi)
    fxr, fz = c.friction_force + c.web_force, c.normal_force
    g_fx = g_ft + g_web
    df_roll = (np.outer([co, 0, -s, 0, -r, 0], g_fx) + np.outer([s, 0, co, 0, 0, 0], g_fn)
               + np.outer([-s * fxr + co * fz, 0, -s * fz - co * fxr, 0, 0, 0], e[1])
               + np.outer([0, 0, 0, 0, -fxr, 0], e[4]))
    st, ctt = math.sin(c.theta), math.cos(c.theta)
    ft = c.friction_force
    df_drum = np.outer([-ctt, 0, -st, 0, -R, 0], g_ft) + np.outer([st, 0, -ctt, 0, 0, 0], g_fn)
    if free:
        df_drum += np.outer([st * ft + ctt * fz, 0, -ctt * ft + st * fz, 0, 0, 0], e[5])
    if fx_on.variable_mass:  # −Ẏ v_local, Ẏ = dY/dr · h ω/2π
        pin.computeForwardKinematicsDerivatives(model, data, q, v, np.zeros(3))
        dvl_dq, dvl_dv = pin.getJointVelocityDerivatives(model, data, ROLL, pin.LOCAL)
        dYdr = np.zeros((6, 6))
        system.law.rate_into(r, 1.0, dYdr)
        Yd = dYdr * c.r_dot
        vl = data.v[ROLL].vector
        df_roll += -Yd @ (dvl_dq @ dq + dvl_dv @ dv) - np.outer(dYdr @ vl * h2pi, e[3])
    gen = Minv @ (Jl[ROLL].T @ df_roll + Jl[DRUM].T @ df_drum)
    dA = da_dq @ dq + da_dv @ dv + gen
    Jac = np.zeros((n, n))
    Jac[0, 2] = Jac[1, 3] = 1.0
    Jac[4, 3] = h2pi
    Jac[2], Jac[3] = dA[ROLL_Z - 1], dA[ROLL - 1]
    if free:
        Jac[5, 6] = 1.0
        Jac[6] = dA[DRUM - 1]
    if ft_row is not None:
        Jac[ft_row[0]] = ft_row[1]
    # radius column: central difference (mass properties depend on r)
    hr = 1e-7 * max(1.0, abs(r))
    yp, ym = y.copy(), y.copy()
    yp[4] += hr
    ym[4] -= hr
    Jac[:, 4] = (system.rhs(t, yp) - system.rhs(t, ym)) / (2 * hr)
    system.evaluate(t, y)  # leave the system at the linearisation point
    return Jac
