"""A scene's machine as one ODE system: generated code (or Pinocchio on numbers), its
parameters, locked modes, initial state and result channels.

``MachineSystem(scene)`` builds the :class:`~winder.model.machine.Machine`, compiles its
generated functions (cached; see :mod:`winder.model.codegen`) and serves the integrators:
``rhs``/``jac`` for scipy's methods, the function addresses ``fns``, the mode ``table``
and the parameter vector ``params`` for the compiled ones, ``channels`` for the result.
``backend="pinocchio"`` evaluates the same dynamics through ``pin.aba``/``pin.rnea`` on
numbers (the cross-check, and the fallback where no C compiler exists, with a warning).
"""

from __future__ import annotations

import ctypes
import math
import warnings
from typing import Any

import numpy as np

from winder._errors import ArgumentError, SimulationError, state_text
from winder.model.backends import NumericBackend
from winder.model.channels import TIME
from winder.model.codegen import CompilerMissing, Generated, generate
from winder.model.locked_modes import AT_CORE, AUTO, CORE_AUTO, WINDING, ModeKind
from winder.model.machine import Machine
from winder.scene import naming_of
from winder.solve import integrators as integ
from winder.solve.cint import Kernels, link
from winder.solve.equilibrium import Equilibrium, cached_static_state

__all__ = ["MachineSystem", "NoCompilerWarning"]

class NoCompilerWarning(UserWarning):
    """The generated path is unavailable (no C compiler): the numeric Pinocchio path runs."""


class MachineSystem:
    """Right-hand side, Jacobian and outputs of a scene's machine. Build once, evaluate
    many times.

    Parameters
    ----------
    scene: a validated :class:`~winder.Scene`.
    backend: ``compiled`` (generated C) or ``pinocchio`` (``pin.aba`` on numbers).
    """

    def __init__(self, scene: Any, *, backend: str = "compiled") -> None:
        self.scene = scene
        self.machine = m = Machine(scene)
        self.state_names = tuple(m.state_names)
        self.params = m.parameters()
        self.backend = backend
        self.generated: Generated | None = None
        if backend == "compiled":
            try:
                self.generated = generate(m, link=link())
            except CompilerMissing as exc:
                warnings.warn(f"{exc}: the generated code cannot be built; running the "
                              "numeric Pinocchio path (much slower)", NoCompilerWarning,
                              stacklevel=2)
                self.backend = "pinocchio"
        self._numeric = NumericBackend(m.model) if self.generated is None else None
        self.fns = self.generated.addresses if self.generated is not None else None
        #: the C integrators of the machine's library (None on the numeric path)
        self.kernels = Kernels(self.generated) if self.generated is not None else None
        self._flat: dict[int, Any] = {}  # ctypes callers of the generated functions
        rows = [mode.table_row(m) for mode in m.modes]
        self.table = np.array(rows, dtype=np.int64).reshape(len(rows), 5)
        self.modes = np.array([mode.kind.automatic for mode in m.modes], dtype=float)
        #: ``(state index, least value [m])`` of every radius an event stops at its core
        #: (and every dancer's lower end); ``ceilings`` the greatest values (its upper end)
        stops = [(m.index(mode.state), m.param_values[m.param_index(mode.param)], mode)
                 for mode in m.modes if mode.state is not None]
        self.radii = [(i, v) for i, v, mode in stops if not mode.name.endswith("travel_hi")]
        self.ceilings = [(i, v) for i, v, mode in stops if mode.name.endswith("travel_hi")]
        self.breakpoints = sorted({t for b in m.bodies for t in b.breakpoints()})
        self.nfev = 0
        self._tb = np.empty(1)
        self._bufs: dict[int, tuple[np.ndarray, int]] = {}
        self._held: tuple[np.ndarray, np.ndarray] | None = None
        self._eq: Equilibrium | None = None
        #: ``(t, state, message)`` where an unwinding roll ran out of web, else None
        self.end: tuple[float, np.ndarray, str] | None = None

    # ---- state --------------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def equilibrium(self) -> Equilibrium:
        """The static balance of the initial state (machines.md §7; kept on disk for the
        same scene and parameters: :func:`~winder.solve.equilibrium.cached_static_state`)."""
        if self._eq is None:
            self._eq = cached_static_state(self.machine, self.params)
        return self._eq

    def initial_state(self) -> np.ndarray:
        """The initial state of machines.md §7."""
        return self.equilibrium.state.copy()

    def index(self, name: str) -> int:
        """Position of state ``name``."""
        return self.machine.index(name)

    def set_input(self, name: str, value: float) -> None:
        """Set a run-time parameter, e.g. ``DRUM.torque`` [N·m] of a torque-driven drum."""
        self.params[self.machine.param_index(name)] = value

    def torque_inputs(self) -> list[str]:
        """Names of the torque inputs (``BODY.torque``, one per torque-driven drum or
        unwinding roll)."""
        return [name for b in self.machine.bodies for name in b.torque_inputs]

    def set_core_mode(self, core: int) -> None:
        """Lock the core mode of every wound roll (``CORE_AUTO``, ``WINDING``,
        ``AT_CORE``) for :meth:`rhs`."""
        if core not in (CORE_AUTO, WINDING, AT_CORE):
            raise ArgumentError(f"core mode must be one of {CORE_AUTO}, {WINDING}, {AT_CORE}, "
                                f"got {core!r}")
        self.modes[self.table[:, 0] == integ.K_CORE] = core

    def ended(self, t: float, y: np.ndarray) -> None:
        """Record that the run ends at ``t`` [s] in state ``y``: the state of an END mode
        (:attr:`~winder.model.locked_modes.ModeKind.END`: an unwinding roll's radius)
        reached its parameter (the core radius, machines.md §1)."""
        m = self.machine
        ends = [mode for mode in m.modes if mode.kind is ModeKind.END]
        hit = [mode for mode in ends if _reached(mode, y[m.index(mode.state)],
                                                 self.params[m.param_index(mode.param)])]
        mode = hit[0] if hit else (ends[0] if ends else None)
        if mode is not None and mode.name.endswith(("travel_lo", "travel_hi")):
            end = "lower" if mode.name.endswith("lo") else "upper"
            text = (f"the dancer {mode.owner!r} reached the {end} end of its travel (d = "
                    f"{self.params[m.param_index(mode.param)]:.6g} m) at t = {t:.6g} s: the "
                    "run ends there")
        else:
            roll = mode.owner if mode is not None else "?"
            text = (f"the unwinding roll {roll!r} ran out of web (its radius reached the "
                    f"core) at t = {t:.6g} s: the run ends there")
        self.end = (float(t), np.array(y, dtype=float), text)

    def clamp_radii(self, Y: np.ndarray) -> None:
        """Samples interpolated between a step's start and its core event may dip below
        ``r_c`` by round-off; the state never does."""
        for i, rc in self.radii:
            np.maximum(Y[i], rc, out=Y[i])
        for i, hi in self.ceilings:
            np.minimum(Y[i], hi, out=Y[i])

    # ---- evaluation -----------------------------------------------------------------------
    def evaluate_numeric(self, t: float, y: np.ndarray, modes: np.ndarray | None = None,
                         *, outputs: bool = True) -> Any:
        """The dynamics on the numeric Pinocchio path (an :class:`Evaluation`)."""
        be = self._numeric or NumericBackend(self.machine.model)
        self._numeric = be
        return self.machine.evaluate(be, t, y, self.params,
                                     self.modes if modes is None else modes, outputs=outputs)

    def _call(self, which: int, t: float, y: np.ndarray, size: int) -> np.ndarray:
        """One generated function at ``(t, y)``, called through ctypes with the addresses
        of persistent buffers (about 3 µs from Python: ``ndarray.ctypes`` costs more than
        the call, so ``y`` is copied into a buffer whose address is kept)."""
        held = self._held
        if held is None or held[0] is not self.params or held[1] is not self.modes:
            self._bufs.clear()  # first call, or params/modes replaced: new addresses
            self._held = (self.params, self.modes)
            self._ybuf = np.empty(self.n_states)
            self._addrs = [a.ctypes.data for a in (self._tb, self._ybuf, self.params,
                                                    self.modes)]
        fn = self._flat.get(which)
        if fn is None:  # the Jacobian's library is built on first use
            address = (self.generated.jacobian() if which == integ.F_JAC
                       else int(self.generated.addresses[which]))
            fn = self._flat[which] = ctypes.CFUNCTYPE(ctypes.c_int,
                                                      *[ctypes.c_void_p] * 5)(address)
        buf = self._bufs.get(which)
        if buf is None:
            out = np.empty(size)
            buf = self._bufs[which] = (out, out.ctypes.data)
        self._tb[0] = t
        self._ybuf[:] = y
        fn(*self._addrs, buf[1])
        return buf[0].copy()

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """``dy/dt`` (clamped nip laws; core modes as locked)."""
        self.nfev += 1
        if self.generated is not None:
            dy = self._call(integ.F_RHS, t, y, self.n_states)
        else:
            ev = self.evaluate_numeric(t, y, outputs=False)
            dy = np.array([float(ev.rates[n]) for n in self.state_names])
        if not np.all(np.isfinite(dy)):
            raise self.blowup_error(t, y, dy)
        return dy

    def jac(self, t: float, y: np.ndarray) -> np.ndarray:
        """The exact Jacobian ``∂(dy/dt)/∂y`` (generated: its library built on the first
        call, :meth:`~winder.model.codegen.Generated.jacobian`), or central differences on
        the numeric path."""
        if self.generated is not None:
            n = self.n_states
            return self._call(integ.F_JAC, t, y, n * n).reshape(n, n, order="F")
        n = len(y)
        J = np.empty((n, n))
        for k in range(n):
            h = 1e-7 * max(1.0, abs(y[k]))
            a, b = np.array(y, float), np.array(y, float)
            a[k] += h
            b[k] -= h
            J[:, k] = (self.rhs(t, a) - self.rhs(t, b)) / (2 * h)
        return J

    def switches(self, t: float, y: np.ndarray) -> np.ndarray:
        """The switching functions (``machine.switch_names``)."""
        if self.generated is not None:
            return self._call(integ.F_SW, t, y, len(self.machine.switch_names))
        ev = self.evaluate_numeric(t, y, outputs=False)
        return np.array([float(ev.switches[n]) for n in self.machine.switch_names])

    def blowup_error(self, t: float, y: np.ndarray, dy: np.ndarray) -> SimulationError:
        """The error for a non-finite derivative: which states, which effects, the state."""
        bad = [n for n, v, d in zip(self.state_names, y, dy, strict=False)
               if not (math.isfinite(v) and math.isfinite(d))]
        effects = ", ".join(f.name for f in self.machine.forces) or "none"
        state = dict(zip(self.state_names, map(float, y), strict=True))
        return SimulationError(
            f"non-finite state or derivative at t = {t:.6g} s in {bad or 'accelerations'} "
            f"(active effects: {effects}); the state was " + state_text(state)
            + ". Try a stiff method (method='Radau' or 'BDF') or a tighter rtol.",
            time=t, state=state)

    def beyond_bound(self, t: float, y: np.ndarray) -> list[tuple[str, float, float]]:
        """The nips whose penetration is beyond its bound at ``(t, y)``: ``(nip, δ [m],
        min(r_a, r_b) [m])`` each, from the guard functions ``NIP.overlap`` (> 0, or not
        a number) of the generated switching functions."""
        g = self.switches(t, y)
        m, out = self.machine, []
        for nip in m.nips:
            name = f"{nip.name}.overlap"
            if name not in m.switch_names:  # contact off: no nip force, no bound
                continue
            over = float(g[m.switch_names.index(name)])
            if not over <= 0.0:
                radii = [b.radius_of(y, m) for b in (nip.a, nip.b)]
                out.append((nip.name, over + min(radii), min(radii)))
        return out

    def penetration_error(self, t: float, y: np.ndarray, *, method: str,
                          max_step: float | None, atol: float) -> SimulationError:
        """The error for a run stopped where a nip's penetration reached its bound
        (``δ >= min(r_a, r_b)``: one body's axis inside the other): the time, the nip, and
        what to change (the method, ``max_step``, ``atol``)."""
        state = dict(zip(self.state_names, map(float, y), strict=True))
        bad = self.beyond_bound(t, y)
        nips = "; ".join(f"nip {name!r} ({self.machine.nip[name].b.name!r} on "
                         f"{self.machine.nip[name].a.name!r}): penetration {delta:.6g} m "
                         f"reached the smaller radius, {bound:.6g} m" for name, delta, bound in bad)
        if method == "RK4":
            how = f"method 'RK4' with its fixed step {max_step or 1e-3:g} s"
            fix = ("method 'DOPRI5' (error control), or 'ROS2' for a stiff nip; or a smaller "
                   "max_step (--max-step)")
        else:
            how = (f"method {method!r} with atol {atol:g}"
                   + ("" if max_step is None else f" and max_step {max_step:g} s"))
            fix = ("method 'ROS2' or 'Radau' (stiff nips); a smaller atol (the shipped "
                   "scenes use 1e-8); or a max_step (--max-step) below the nip's period")
        return SimulationError(
            f"the run stopped at t = {t:.6g} s: {nips or 'a nip crossed its bound'} (one "
            f"body's axis inside the other): {how} lost the contact, and nothing after "
            f"this time would be right. Change the method, max_step or atol: try {fix}. "
            "The state was " + state_text(state) + ".", time=t, state=state)

    # ---- outputs ----------------------------------------------------------------------------
    @property
    def outputs(self) -> dict[str, tuple[str, str]]:
        """The result's channels after ``t``: name → (the machine's channel, unit), as the
        scene names them (:attr:`winder.scene.Scene.naming`: machines.md §9, or the
        single-drum format's names of winder-model §8)."""
        return naming_of(self.scene).outputs(self.machine.channel_units)

    @property
    def channel_units(self) -> dict[str, str]:
        """The unit of every channel :meth:`channels` returns, in its order: ``t`` [s],
        then each channel's declared unit (:attr:`outputs`)."""
        return {TIME.name: TIME.unit, **{n: u for n, (_, u) in self.outputs.items()}}

    def channels(self, t: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
        """All result channels at times ``t`` for states ``Y`` (``(n_states, len(t))``):
        machines.md §9 names, or winder-model §8 names for a single-drum scene."""
        t = np.ascontiguousarray(t, dtype=float)
        Y = np.ascontiguousarray(Y, dtype=float)
        names = self.machine.channel_names
        if self.kernels is not None:
            out = self.kernels.channels(self.fns, self.table, t, Y, self.params)
        else:
            out = np.empty((len(names), len(t)))
            modes = self.modes.copy()
            for i, ti in enumerate(t):
                g = self.switches(float(ti), Y[:, i])
                for s, row in enumerate(self.table):
                    modes[s] = AUTO if row[0] == integ.K_CONTACT else 0.0 \
                        if row[0] == integ.K_END else (
                            AT_CORE if g[row[1]] >= 0.0 and g[row[2]] <= 0.0 else WINDING)
                ev = self.evaluate_numeric(float(ti), Y[:, i], modes)
                out[:, i] = [float(ev.channels.get(n, 0.0)) for n in names]
        ch = dict(zip(names, out, strict=True))
        # a channel the machine lacks (an effect off) is zeros
        return {"t": t.copy(), **{name: ch[c] if c in ch else np.zeros(len(t))
                                  for name, (c, _) in self.outputs.items()}}


def _reached(mode: Any, value: float, end: float) -> bool:
    """Whether the state ``value`` of the END ``mode`` has reached its ``end``: an
    unwinding roll's radius its core, a dancer's position an end of its travel (its
    upper end from below)."""
    tol = 1e-9 * max(abs(end), 1e-3)
    return value >= end - tol if mode.name.endswith("travel_hi") else value <= end + tol
