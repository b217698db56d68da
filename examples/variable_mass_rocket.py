"""Purpose: a rocket on a slider ejecting mass through the flux helper vs Tsiolkovsky."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from scipy.integrate import solve_ivp

import winder

m0, burn, ue, T = 10.0, 1.5, 300.0, 4.0
model = pin.Model()
j = model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "slider")
model.appendBodyToJoint(j, pin.Inertia(m0, np.zeros(3), np.eye(3)), pin.SE3.Identity())
model.gravity = pin.Motion.Zero()
vm = winder.VariableMassModel(model)
law = winder.FunctionMassLaw(lambda t: (m0 - burn * t, -burn),
                             lambda t: (np.zeros(3), np.zeros(3)),
                             lambda t: ((m0 - burn * t) * np.eye(3) * 0.1, -burn * 0.1 * np.eye(3)))


def rhs(t: float, y: np.ndarray) -> np.ndarray:
    vm.set_body(1, inertia=law.inertia(t), rate=law.rate(t, 1.0))
    q, v = y[:1], y[1:]
    thrust = vm.momentum_flux(q, 1, mass_rate=-burn, velocity=np.array([v[0] - ue, 0, 0]),
                              point=np.array([q[0], 0, 0]))
    return np.array([v[0], vm.aba(q, v, np.zeros(1), [pin.Force.Zero(), thrust])[0]])


sol = solve_ivp(rhs, (0, T), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12)
exact = ue * math.log(m0 / (m0 - burn * T))
print(f"Δv simulated {sol.y[1, -1]:.12f} m/s, Tsiolkovsky {exact:.12f} m/s, "
      f"relative error {abs(sol.y[1, -1] - exact) / exact:.1e}")
