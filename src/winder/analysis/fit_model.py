"""The simulated channels of a scene and their exact sensitivities to scene keys, for
:func:`winder.fit`.

A fit parameter is a scene key path (``contact.stiffness``, ``nip.front_nip.contact.
stiffness``; :mod:`winder.scene.paths`, as ``winder sweep`` names them). Its value enters
the machine through the run-time parameters ``p`` and the initial state ``x0`` of the
scene built with it (:class:`~winder.model.machine.Machine`, about 1 ms): ``∂p/∂θ`` and
the scene part of ``∂x0/∂θ`` are taken from that map by central differences with
Richardson extrapolation (exact for the usual identity map, ~1e-12 otherwise); a key that
changes the machine's structure (its generated code) cannot be fitted.

The states follow ``ẋ = f(x, p, t)`` (the machine's one symbolic definition, contact
closed: :func:`winder.analysis.control._symbolic`), integrated by CVODES (CasADi) from the
static balance with the forward sensitivity equations ``Ṡ = f_x S + f_p ∂p/∂θ``
(CasADi's forward mode on the integrator: CVODES's staggered sensitivities with error
control). The balance's own sensitivity is the implicit function theorem on its force
residual: ``∂x_u/∂θ = −r_u⁻¹ (r_x ∂x/∂θ + r_p ∂p/∂θ)``. The channels ``y = h(x, p, t)``
and ``∂y/∂θ = h_x S + h_p ∂p/∂θ``.

Events: the model holds every nip in contact and every roll winding. Along the samples
the switching functions are checked; where a nip lifts off or a roll reaches its core
the evaluation stops with :class:`FitEventError` naming the event, its time and the
window to fit instead.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from winder._errors import ArgumentError, SceneError, SimulationError
from winder.analysis.control import _symbolic, contact_closed_modes
from winder.model.locked_modes import AT_CORE, CORE_AUTO, IN_CONTACT, WINDING, ModeKind
from winder.model.machine import Machine
from winder.scene.load import Scene, scene_from_dict
from winder.scene.paths import get_path, resolve, set_path
from winder.solve.equilibrium import static_state
from winder.solve.system import MachineSystem

__all__ = ["FitEventError", "Evaluation", "ForwardModel", "scene_with", "key_value"]


class FitEventError(SimulationError):
    """An event (a nip lifting off, a roll reaching its core) inside the fitted window: the
    sensitivities of the contact-closed model do not hold across it. The message names
    the event, its time and a window without it."""


def key_value(scene: Scene, key: str, where: str = "params") -> float:
    """The scene's value of the key path ``key`` [the key's unit] (an ``ArgumentError``
    naming ``where`` and the key when it does not exist or is not a number)."""
    data = scene.to_dict()
    try:
        resolve(data, key)
        value = get_path(data, key)
    except ArgumentError as exc:
        raise ArgumentError(f"{where}: {exc}") from None
    except KeyError:
        raise ArgumentError(f"{where}: key {key!r} is not in the scene (give it a value "
                            "in the scene file to fit it)") from None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ArgumentError(f"{where}: key {key!r} is {value!r}, not a number; only "
                            "numbers can be fitted")
    return float(value)


def scene_with(scene: Scene, values: dict[str, float], where: str = "params") -> Scene:
    """``scene`` with the key paths set to ``values``, validated like a file."""
    data = copy.deepcopy(scene.to_dict())
    for key, v in values.items():
        set_path(data, key, float(v))
    try:
        return scene_from_dict(data, source=scene.source)
    except SceneError as exc:
        raise ArgumentError(f"{where}: {', '.join(f'{k}={v:.6g}' for k, v in values.items())}"
                            f": {exc}") from None


@dataclass(frozen=True)
class Evaluation:
    """The channels at the samples and their sensitivities: ``y`` (channels × samples)
    [channel units], ``S`` (channels × samples × parameters) [channel unit / key unit]."""

    y: np.ndarray
    S: np.ndarray


class ForwardModel:
    """The channels ``channels`` (result names) of ``scene`` at the times ``t`` [s] (> 0
    increasing, or 0 first) as functions of the key paths ``keys``, with their exact
    sensitivities (module docstring). ``rtol``: CVODES's relative tolerance (``atol`` is
    ``rtol`` times each state's scale)."""

    def __init__(self, scene: Scene, keys: Sequence[str], channels: Sequence[str],
                 t: np.ndarray, *, rtol: float = 1e-8) -> None:
        import casadi as ca

        self.scene, self.keys, self.channels = scene, tuple(keys), tuple(channels)
        self.t = np.asarray(t, dtype=float)
        self.rtol = float(rtol)
        self.theta0 = np.array([key_value(scene, k) for k in self.keys])
        self.system = system = MachineSystem(scene)
        machine = system.machine
        self._structure = machine.structure_key()
        outs = system.outputs
        missing = [c for c in self.channels if c not in outs]
        if missing:
            raise ArgumentError(f"channels: {missing[0]!r} is not a channel of this scene; "
                                f"valid: {', '.join(outs)}")
        self.units = {c: outs[c][1] for c in self.channels}
        # the rolls that start at their core turning backwards hold there (AT_CORE) until
        # they turn forwards at τ_i, then wind: the locked core mode as a function of t
        self._cores = [i for i, mode in enumerate(machine.modes) if mode.kind is ModeKind.CORE]
        tau = ca.SX.sym("tau", len(self._cores))
        fixed = contact_closed_modes(system)

        def modes(t: Any) -> Any:
            out = [ca.SX(float(v)) for v in fixed]
            for j, i in enumerate(self._cores):
                out[i] = ca.if_else(t < tau[j], float(AT_CORE), float(WINDING))
            return ca.vertcat(*out)

        x, u, p, xdot, y, pnames = _symbolic(system, [], [outs[c][0] for c in self.channels],
                                             modes=modes)
        self._pnames = list(pnames[:-1])
        self._porder = [machine.param_names.index(n) for n in self._pnames]
        n_th, n_x, n_p = len(self.keys), machine.n_states, len(self._pnames)
        # p(θ) about the current point: p = pc + D δ, x0 = xc + X δ; sensitivities at δ = 0
        # (τ held: the core mode's two sides have the same rates where the roll turns)
        delta = ca.SX.sym("delta", n_th)
        pc = ca.SX.sym("pc", n_p)
        D = ca.SX.sym("D", n_p, n_th)
        tt = ca.SX.sym("t")
        pfull = ca.vertcat(pc + ca.mtimes(D, delta), tt)
        ode = ca.substitute(xdot, p, pfull)
        self.scales = self._state_scales(system)
        t_out = self.t[self.t > 0.0]
        self._at_zero = len(self.t) - len(t_out)
        if self._at_zero > 1 or len(t_out) == 0 or np.any(np.diff(t_out) <= 0):
            raise ArgumentError("t: the sample times must be increasing and > 0 (or 0 "
                                "first)")
        opts = {"reltol": self.rtol, "abstol": self.rtol * float(np.min(self.scales)),
                "max_num_steps": 10**8, "fsens_err_con": True}
        dae = {"x": x, "p": ca.vertcat(delta, pc, ca.vec(D), tau), "t": tt, "ode": ode}
        integ = ca.integrator("fit_states", "cvodes", dae, 0.0, t_out, opts)
        # the probe: the states on a fine grid, for the times the rolls turn forwards
        step = min(1e-3, float(self.t[-1]) / 2000)
        self._probe_t = np.arange(1, int(math.ceil(float(self.t[-1]) / step)) + 1) * step
        self._probe = ca.integrator("fit_probe", "cvodes", dae, 0.0, self._probe_t,
                                    {k: v for k, v in opts.items() if k != "fsens_err_con"})
        xc = ca.MX.sym("xc", n_x)
        X0 = ca.MX.sym("X0", n_x, n_th)
        dm = ca.MX.sym("delta", n_th)
        pcm = ca.MX.sym("pc", n_p)
        Dm = ca.MX.sym("D", n_p, n_th)
        taum = ca.MX.sym("tau", len(self._cores))
        xs0 = xc + ca.mtimes(X0, dm)
        X = integ(x0=xs0, p=ca.vertcat(dm, pcm, ca.vec(Dm), taum))["xf"]
        if self._at_zero:
            X = ca.horzcat(xs0, X)
        h = ca.Function("h", [x, p, tau], [y])
        times = ca.DM(self.t).T
        pm = ca.repmat(pcm + ca.mtimes(Dm, dm), 1, len(self.t))
        Y = h.map(len(self.t))(X, ca.vertcat(pm, times), ca.repmat(taum, 1, len(self.t)))
        ins = [dm, xc, X0, pcm, Dm, taum]
        self._fun = ca.Function("channels", ins, [Y, X])
        self._jac = ca.Function("sensitivities", ins, [Y, ca.jacobian(ca.vec(Y), dm), X])
        self._balance = self._balance_function(machine)
        self.evaluations = 0

    # ---- the parameters' map ---------------------------------------------------------------
    @staticmethod
    def _state_scales(system: MachineSystem) -> np.ndarray:
        """A magnitude of each state for CVODES's absolute tolerance: 1e-3 of a length
        state's unit, 1 of the rest, scaled like the scene's own ``atol`` / ``rtol``."""
        return np.array([1e-4 if n.rpartition(".")[2] in ("x", "z", "radius") else 1.0
                         for n in system.state_names])

    def machine_at(self, theta: np.ndarray) -> Machine:
        """The machine of the scene with the keys at ``theta``; its structure must be the
        scene's (a key that changes the generated code is refused)."""
        scene = scene_with(self.scene, dict(zip(self.keys, map(float, theta), strict=True)))
        m = Machine(scene)
        if m.structure_key() != self._structure:
            raise ArgumentError(f"params: {', '.join(self.keys)}: a value changes the "
                                "machine's structure (its generated code), not only its "
                                "parameters; such a key cannot be fitted")
        return m

    def _map(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        m = self.machine_at(theta)
        return np.asarray(m.parameters(), dtype=float)[self._porder], \
            np.asarray(m.state_initial, dtype=float)

    def parameter_map(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                        np.ndarray, Machine]:
        """``(p, ∂p/∂θ, x_initial, ∂x_initial/∂θ, machine)`` at ``theta``: central
        differences of the key → parameter map with steps ``h`` and ``h/2`` combined by
        Richardson extrapolation (exact for a linear map). A key whose two differences
        agree to 1e-10 (a linear map: the usual identity) keeps its column: its map is
        not differenced again."""
        theta = np.asarray(theta, dtype=float)
        m = self.machine_at(theta)
        p = np.asarray(m.parameters(), dtype=float)[self._porder]
        xi = np.asarray(m.state_initial, dtype=float)
        D = np.zeros((len(p), len(theta)))
        E = np.zeros((len(xi), len(theta)))
        linear = self.__dict__.setdefault("_linear", {})
        for j in range(len(theta)):
            if j in linear:
                D[:, j], E[:, j] = linear[j]
                continue
            h = 1e-4 * max(abs(theta[j]), 1e-300) if theta[j] != 0 else 1e-6

            def diff(step: float, j: int = j) -> tuple[np.ndarray, np.ndarray]:
                a, b = theta.copy(), theta.copy()
                a[j] += step
                b[j] -= step
                (pa, xa), (pb, xb) = self._map(a), self._map(b)
                return (pa - pb) / (2 * step), (xa - xb) / (2 * step)

            d1, e1 = diff(h)
            d2, e2 = diff(h / 2)
            D[:, j] = (4 * d2 - d1) / 3
            E[:, j] = (4 * e2 - e1) / 3
            size = max(float(np.max(np.abs(D[:, j]), initial=0.0)),
                       float(np.max(np.abs(E[:, j]), initial=0.0)), 1e-300)
            if max(float(np.max(np.abs(d1 - d2), initial=0.0)),
                   float(np.max(np.abs(e1 - e2), initial=0.0))) <= 1e-10 * size:
                linear[j] = (D[:, j].copy(), E[:, j].copy())
        # round-off of the differences: entries below 1e-9 of the column's largest are 0
        D[np.abs(D) < 1e-9 * np.max(np.abs(D), axis=0, initial=0.0)] = 0.0
        return p, D, xi, E, m

    # ---- the balance -------------------------------------------------------------------------
    def _balance_function(self, machine: Machine) -> Any:
        """``(r, r_x, r_p)``: the static balance's force residual of the free coordinates
        (:func:`winder.solve.equilibrium.static_state`: every nip in contact) and its
        exact Jacobians, from the one symbolic definition."""
        import casadi as ca

        from winder.model.backends import SymbolicBackend, default_route

        self._unknowns = []
        if machine.scene.effects.contact:
            for b in machine.bodies:
                fixed = b.fixed_at_rest()
                self._unknowns += [(b.name, c, machine.index(f"{b.name}.{c}"))
                                   for c in b.free if c not in fixed]
        if not self._unknowns:
            return None
        xs = ca.SX.sym("x", machine.n_states)
        ps = ca.SX.sym("p", len(machine.param_names))
        modes = np.full(len(machine.mode_names), float(CORE_AUTO))
        modes[machine.mode_slots(ModeKind.CONTACT)] = IN_CONTACT
        ev = machine.evaluate(SymbolicBackend(machine.model, default_route()), 0.0, xs, ps,
                              ca.DM(modes), static=True)
        r = ca.vertcat(*[ev.bodies[b].fx if c == "x" else ev.bodies[b].fz
                         for b, c, _ in self._unknowns])
        return ca.Function("balance", [xs, ps], [r, ca.jacobian(r, xs), ca.jacobian(r, ps)])

    def initial_state(self, machine: Machine, p: np.ndarray, D: np.ndarray,
                      E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(x0, ∂x0/∂θ)``: the static balance (one Newton step polishes it) and its
        sensitivity by the implicit function theorem."""
        pm = np.asarray(machine.parameters(), dtype=float)
        x0 = static_state(machine, pm).state.copy()
        X0 = E.copy()
        if self._balance is None:
            return x0, X0
        idx = [i for _, _, i in self._unknowns]
        Dfull = np.zeros((len(pm), D.shape[1]))
        Dfull[self._porder] = D
        for _ in range(2):
            r, rx, _ = (np.array(v) for v in self._balance(x0, pm))
            x0[idx] -= np.linalg.solve(rx[:, idx], r.ravel())
        r, rx, rp = (np.array(v) for v in self._balance(x0, pm))
        X0[idx] = 0.0
        X0[idx] = -np.linalg.solve(rx[:, idx], rx @ X0 + rp @ Dfull)
        return x0, X0

    # ---- evaluation ------------------------------------------------------------------------
    def turning_times(self, x0: np.ndarray, p: np.ndarray, machine: Machine) -> np.ndarray:
        """``τ`` [s] of each wound roll: 0 for a roll that winds from the start, else (a
        roll at its core turning backwards, held there) the time its speed turns forwards
        (the switching function ``ROLL.forward`` crossing zero on the probe's 1 ms grid,
        interpolated linearly: the states' error goes as the square of τ's), ``inf``
        where it never does."""
        system = self.system
        system.params = np.asarray(machine.parameters(), dtype=float)
        system.modes = contact_closed_modes(system)
        names = machine.switch_names
        tau = np.zeros(len(self._cores))
        held = []
        for j, i in enumerate(self._cores):
            mode = machine.modes[i]
            g = system.switches(0.0, x0)
            if g[names.index(mode.switches[0])] >= 0.0 and \
                    g[names.index(mode.switches[1])] <= 0.0:
                held.append(j)
        if not held:
            return tau
        tau[held] = np.inf
        D0 = np.zeros((len(p), len(self.keys)))
        X = np.array(self._probe(x0=x0, p=np.concatenate([np.zeros(len(self.keys)), p,
                                                           D0.ravel(order="F"), tau]))["xf"])
        t = np.concatenate([[0.0], self._probe_t])
        X = np.hstack([x0[:, None], X])
        for j in held:
            mode = machine.modes[self._cores[j]]
            k = names.index(mode.switches[1])
            prev = 0.0
            for n, tn in enumerate(t):
                g = float(system.switches(float(tn), X[:, n])[k])
                if n > 0 and g > 0.0:
                    tau[j] = t[n - 1] + (t[n] - t[n - 1]) * (-prev) / (g - prev)
                    break
                prev = g
        return tau

    def evaluate(self, theta: np.ndarray, *, sensitivities: bool = True,
                 check: bool = True) -> Evaluation:
        """The channels at ``theta`` (and their sensitivities); with ``check``, stop with
        :class:`FitEventError` at an event within the samples."""
        p, D, _, E, machine = self.parameter_map(theta)
        x0, X0 = self.initial_state(machine, p, D, E)
        self.tau = tau = self.turning_times(x0, p, machine)
        args = (np.zeros(len(self.keys)), x0, X0, p, D, tau)
        self.evaluations += 1
        try:
            if sensitivities:
                Y, J, X = self._jac(*args)
            else:
                Y, X = self._fun(*args)
                J = None
        except RuntimeError as exc:
            raise SimulationError(f"fit: the integration failed at "
                                  f"{dict(zip(self.keys, map(float, theta), strict=True))}:"
                                  f" {str(exc).splitlines()[-1][:300]}") from None
        Y = np.array(Y)
        if not np.all(np.isfinite(Y)):
            raise SimulationError("fit: the simulated channels are not finite at "
                                  f"{dict(zip(self.keys, map(float, theta), strict=True))}")
        if check:
            self.check_events(np.array(X), machine)
        n_c, n_t = Y.shape
        S = np.zeros((n_c, n_t, len(self.keys))) if J is None else \
            np.array(J).reshape(n_t, n_c, len(self.keys)).transpose(1, 0, 2)
        return Evaluation(Y, S)

    def check_events(self, X: np.ndarray, machine: Machine) -> None:
        """Stop at the first sample where a nip has lifted off (``NIP.contact`` < 0) or a
        roll's radius is below its core (``ROLL.unwound`` > 0): the contact-closed model
        (and its sensitivities) no longer hold there."""
        system = self.system
        system.params = np.asarray(machine.parameters(), dtype=float)
        system.modes = contact_closed_modes(system)
        names = machine.switch_names
        first: tuple[float, str] | None = None
        for k, tk in enumerate(self.t):
            g = system.switches(float(tk), X[:, k])
            for mode in machine.modes:
                v = float(g[names.index(mode.switches[0])])
                if mode.kind is ModeKind.CONTACT and v < 0.0:
                    first = (float(tk), f"nip {mode.owner!r} lifts off (contact ends)")
                elif mode.kind is not ModeKind.CONTACT and \
                        v > 1e-9 * float(X[machine.index(mode.state), k]):
                    first = (float(tk), f"roll {mode.owner!r} reaches its core")
                if first:
                    break
            if first:
                break
        if first is None:
            return
        tk, what = first
        k = int(np.searchsorted(self.t, tk))
        before = float(self.t[k - 1]) if k > 0 else 0.0
        hint = (f"fit a window that ends before it (t_end < {before:.6g} s, --t-end)"
                if before > self.t[0] else "choose a window without it (t_start, t_end)")
        raise FitEventError(f"fit: an event inside the fitted window: {what} between "
                            f"t = {before:.6g} s and {tk:.6g} s; the contact-closed model's "
                            f"sensitivities do not hold across it: {hint}", time=tk)

