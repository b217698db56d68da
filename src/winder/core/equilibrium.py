"""The initial state of machines.md §7: free translational coordinates in static balance.

Angles 0, translational velocities 0, speeds from the scene; each free ``x``/``z`` solves
the force balance of its body (gravity, rider load, the nips' normal forces at ``δ̇ = 0``
and friction at ``F_t(0)``, the web forces at ``T(0)``). The scene's centre is the initial
guess. The largest force residual is reported with the result; above
:data:`RESIDUAL_LIMIT` of the largest force in the balance the start is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .backends import NumericBackend
from .machine import AUTO, CORE_AUTO, FREE, IN_CONTACT, Machine

__all__ = ["static_state", "Equilibrium", "EquilibriumError", "RESIDUAL_LIMIT"]

#: Largest accepted residual of the static balance, relative to the largest force in it.
RESIDUAL_LIMIT = 1e-6


class EquilibriumError(ValueError):
    """No static balance for a body: names the body and the residual."""


@dataclass(frozen=True)
class Equilibrium:
    """The initial state and its static balance: ``residual`` [N] (largest), ``scale``
    [N] (largest force in the balance)."""

    state: np.ndarray
    residual: float
    scale: float


def _forces(machine: Machine, be: NumericBackend, x: np.ndarray, p: np.ndarray,
            modes: np.ndarray, unknowns: list[tuple[str, str, int]]) -> tuple[np.ndarray, float]:
    ev = machine.evaluate(be, 0.0, x, p, modes, static=True)
    res = np.array([ev.bodies[b].fx if c == "x" else ev.bodies[b].fz for b, c, _ in unknowns])
    scale = max([abs(ns.normal_force) for ns in ev.nips.values()]
                + [abs(bs.mass * p[machine.param_index("gravity")])
                   for bs in ev.bodies.values()] if "gravity" in machine.param_names else
                [abs(ns.normal_force) for ns in ev.nips.values()] + [0.0])
    return res, scale


def static_state(machine: Machine, p: np.ndarray | None = None) -> Equilibrium:
    """The initial state of ``machine`` (spec §7) for parameters ``p`` (default: the
    scene's)."""
    from scipy.optimize import root

    p = machine.parameters() if p is None else p
    x = np.array(machine.state_initial, dtype=float)
    # every nip touching, its law extended smoothly to δ < 0 (so the balance is smooth);
    # a nip that would pull is opened and the balance solved again (an active set)
    contact = [i for i, n in enumerate(machine.mode_names) if n.endswith(".contact")]
    modes = np.full(len(machine.mode_names), float(CORE_AUTO))
    modes[contact] = IN_CONTACT
    unknowns = []
    resting = bool(machine.scene.effects.contact)  # without contact, free bodies start
    for b in machine.bodies:  # at their centres (§7)
        fixed_z = b.kind == "roll" and getattr(b.part, "initial_height", None) is not None
        for c in b.free:
            if c == "z" and fixed_z:
                x[machine.index(f"{b.name}.z")] = b.part.initial_height
            elif resting:
                unknowns.append((b.name, c, machine.index(f"{b.name}.{c}")))
    be = NumericBackend(machine.model)
    if not unknowns:
        return Equilibrium(x, 0.0, 0.0)
    idx = [i for _, _, i in unknowns]

    def residual(u: np.ndarray) -> np.ndarray:
        x[idx] = u
        return _forces(machine, be, x, p, modes, unknowns)[0]

    u0 = x[idx].copy()
    for _ in range(len(contact) + 1):
        sol = root(residual, u0, method="hybr", options={"xtol": 1e-15})
        x[idx] = sol.x
        ev = machine.evaluate(be, 0.0, x, p, modes, static=True)
        pulling = [i for i in contact if modes[i] == IN_CONTACT
                   and ev.nips[machine.mode_names[i][:-len(".contact")]].normal_force < 0.0]
        if not pulling:
            break
        modes[pulling] = FREE
    modes[contact] = AUTO
    res, scale = _forces(machine, be, x, p, modes, unknowns)
    worst = int(np.argmax(np.abs(res)))
    if not np.all(np.isfinite(res)) or abs(res[worst]) > RESIDUAL_LIMIT * max(scale, 1e-300):
        b, c, _ = unknowns[worst]
        raise EquilibriumError(
            f"no static balance for body {b!r} along {c}: force residual {res[worst]:.3g} N "
            f"(largest force {scale:.3g} N, limit {RESIDUAL_LIMIT:g} of it); check its "
            "centre, its nips and the loads on it")
    return Equilibrium(x, float(np.max(np.abs(res))), scale)
