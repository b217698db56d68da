"""Step-wise simulation with inputs: the co-simulation interface (used by the FMU)."""

from __future__ import annotations

import functools
import math
import os
import time
from typing import Any

import numpy as np

from winder._args import real_argument
from winder._errors import ArgumentError, SimulationError, state_text
from winder.io.result import Result
from winder.scene import naming_of
from winder.scene.load import Scene
from winder.solve import integrators as integ
from winder.solve.auto import choose_method
from winder.solve.budgets import COMPILED_MAX_RHS, budget_error, check_budgets, check_tolerances
from winder.solve.cint import ROSENBROCK
from winder.solve.simulate import _as_scene
from winder.solve.system import MachineSystem

__all__ = ["Stepper", "inputs_of", "outputs_of"]


def inputs_of(system: MachineSystem) -> dict[str, str]:
    """The inputs of a scene: input name → run-time parameter: ``DRUM_torque`` per
    torque-driven drum or unwinding roll, ``ROLL_tension_setpoint`` [N] of a
    tension-controlled unwind (as the scene names them: :meth:`Naming.inputs
    <winder.scene.Naming.inputs>`)."""
    names = system.torque_inputs() + [name for b in system.machine.bodies
                                      for name in b.setpoint_inputs]
    return naming_of(system.scene).inputs({n.replace(".", "_"): n for n in names})


def outputs_of(system: MachineSystem) -> tuple[str, ...]:
    """The outputs of a scene: its result channels but ``t``."""
    return tuple(system.outputs)
_RAISE = {"max_rhs": "Stepper(max_rhs=...) or [solver] max_rhs; it is the budget of one step",
          "max_wall": "Stepper(max_wall=...) or [solver] max_wall; it is the budget of one "
                      "step"}


class Stepper:
    """A scene advanced by fixed communication steps, with inputs set between steps.

    Inside each step the compiled DOPRI5 of :func:`winder.simulate` (adaptive, contact
    and core events located, drive breakpoints respected) integrates to ``rtol``; the
    step size of the integrator carries over between communication steps, so short steps
    cost little. Each step has a budget (``max_rhs`` evaluations, ``max_wall`` seconds):
    a step that reaches it raises :class:`~winder.BudgetExceeded` and leaves the stepper
    at the time reached (``t``), from where it may go on.

    >>> sim = Stepper(scene)                       # doctest: +SKIP
    >>> sim.set_input("drum_torque", 250.0)        # doctest: +SKIP
    >>> sim.step(1e-3)                             # doctest: +SKIP
    >>> sim.output("roll_speed")                   # doctest: +SKIP

    Parameters
    ----------
    scene: the scene, from :func:`winder.load_scene` or the path of a scene file (as
        :func:`winder.simulate` takes it); a drum of drive kind ``torque`` for a torque
        input (its drive's ``torque`` is the input until :meth:`set_input` changes it).
        Inputs: :attr:`inputs` (``drum_torque`` for a single-drum scene, ``DRUM_torque`` per
        torque-driven drum of a machine from parts); outputs: :attr:`output_names`.
    rtol, atol: tolerances of the internal integrator (default ``1e-8``, ``1e-10``): rtol
        finite in (0, 0.1], atol finite in (0, 1e-3] [state units].
    max_rhs, max_wall: budget of each :meth:`step`: evaluations and wall-clock seconds
        (default ``[solver] max_rhs``, else 50 million, and ``max_wall``).
    method: the compiled integrator inside each step: ``DOPRI5`` (default), ``DOP853C``
        (order 8: fewer evaluations at tight tolerances), or one of the Rosenbrock methods
        ``RODAS4``, ``RODAS3``, ``ROS34PW2`` (stiff machines: exact sparse Jacobian), or
        ``auto`` (:func:`winder.solve.auto.choose_method`'s probe).
    """

    def __init__(self, scene: Scene | str | os.PathLike, *, rtol: float = 1e-8,
                 atol: float = 1e-10, max_rhs: int | None = None,
                 max_wall: float | None = None, method: str = "DOPRI5") -> None:
        scene = _as_scene(scene)
        valid = ("auto", "DOPRI5", "DOP853C", *ROSENBROCK)
        if not isinstance(method, str) or method not in valid:
            raise ArgumentError(f"method = {method!r} is not a Stepper method; valid: "
                                f"{', '.join(valid)}")
        self.rtol, self.atol = check_tolerances(rtol, atol)
        self.max_rhs, self.max_wall = check_budgets(
            (scene.solver.max_rhs or COMPILED_MAX_RHS) if max_rhs is None else max_rhs,
            scene.solver.max_wall if max_wall is None else max_wall)
        self.scene = scene
        self.system = MachineSystem(scene)
        if self.system.generated is None:
            raise SimulationError("the Stepper needs the generated code: no C compiler")
        self.inputs = inputs_of(self.system)
        self.output_names = outputs_of(self.system)
        self.free_drum = bool(self.system.torque_inputs())
        self._breaks = tuple(self.system.breakpoints)
        self.reset()
        if method == "auto":
            method = choose_method(self.system, self.rtol, self.atol, 0.0, self.y,
                                   math.inf).method
        #: the integrator inside each step
        self.method = method
        k = self.system.kernels
        explicit = {"DOPRI5": k.dopri5, "DOP853C": k.dop853}
        self._run = explicit[method] if method in explicit else functools.partial(
            k.rodas, order=ROSENBROCK[method][0], reuse=ROSENBROCK[method][1])

    def reset(self) -> None:
        """Back to ``t = 0`` and the initial state of machines.md §7 (inputs keep their
        values)."""
        self.t = 0.0
        self.y = self.system.initial_state()
        self._h = 0.0
        self._stats = np.zeros(8, dtype=np.int64)
        self.system.end = None
        self._outputs: dict[str, float] | None = None

    @property
    def state(self) -> dict[str, float]:
        """The state vector by name."""
        return dict(zip(self.system.state_names, map(float, self.y), strict=True))

    @property
    def rhs_evaluations(self) -> int:
        return int(self._stats[0])

    def set_input(self, name: str, value: float) -> None:
        """Set an input (held constant over the next steps)."""
        if name not in self.inputs:
            valid = ", ".join(self.inputs) or "none (no drum of drive kind 'torque')"
            raise ArgumentError(f"unknown input {name!r}; valid: {valid}")
        if self.inputs[name] not in self.system.machine.param_names:
            raise ArgumentError(f"{name} is an input only with [drum.drive] kind = 'torque'; "
                                "this scene prescribes the drum speed")
        v = real_argument(name, value, math.isfinite,
                          "a finite number [N]" if name.endswith("setpoint") else
                          "a finite number [N·m]")
        self.system.set_input(self.inputs[name], v)
        self._outputs = None

    def step(self, dt: float) -> None:
        """Advance by ``dt`` [s]: finite, and at least the time resolution at ``t``
        (``1e-14·max(1 s, |t|)``).

        Where an unwinding roll runs out of web the step stops there (``t`` < the step's
        end; :attr:`ended` says why).

        Raises
        ------
        ArgumentError: a bad ``dt``.
        BudgetExceeded: the step reached its budget; the stepper stays at the time
            reached (``.time``) and may go on from there.
        SimulationError: the integration failed, or a nip's penetration reached its bound
            (δ >= min(r_a, r_b); the stepper stays at that time).
        """
        if self.ended is not None:
            raise SimulationError(f"the run has ended: {self.ended}", time=self.t,
                                  state=self.state)
        resolution = integ.TIME_RESOLUTION * max(1.0, abs(self.t))
        dt = real_argument("dt", dt, lambda v: math.isfinite(v) and v >= resolution,
                           f"finite and >= {resolution:.3g} s (the time resolution at t = "
                           f"{self.t:.6g} s, 1e-14·max(1 s, |t|))")
        t_start, t_end = self.t, self.t + dt
        stops = [b for b in self._breaks if self.t < b < t_end] + [t_end]
        empty_t, empty_y = np.empty(0), np.empty((len(self.y), 0))
        sy = self.system
        nfev0, steps0, stiff0 = (int(x) for x in self._stats[[0, 1, 4]])
        wall0 = time.perf_counter()
        run = self._run  # the C integrator of the machine's library
        for tb in stops:
            while self.t < tb:
                spent = int(self._stats[0]) - nfev0
                over = ("max_rhs" if spent >= self.max_rhs else
                        "max_wall" if time.perf_counter() - wall0 > self.max_wall else None)
                if over is not None:
                    raise self._over(over, t_start, t_end, spent, steps0, stiff0, wall0)
                budget = min(integ.CHUNK, self.max_rhs - spent)
                status, t, h, _ = run(sy.fns, sy.table, self.t, tb, self.y, sy.params,
                                      sy.modes, self.rtol, self.atol, self._h, math.inf,
                                      empty_t, empty_y, 0, budget, self._stats)
                if status in (integ.NON_FINITE, integ.STEP_UNDERFLOW) or \
                        not np.all(np.isfinite(self.y)):
                    where = state_text(self.state)
                    what = ("the state went non-finite" if status == integ.NON_FINITE
                            else "the step size underflowed (too stiff or discontinuous)")
                    raise SimulationError(f"integration failed at t = {t:.6g} s: {what} "
                                          f"(state: {where})", time=t, state=self.state)
                if status == integ.PENETRATED:  # a nip beyond its bound: stop there
                    self.t, self._h = t, h
                    self._outputs = None
                    raise sy.penetration_error(t, self.y, method=self.method, max_step=None,
                                               atol=self.atol)
                if status == integ.EXHAUSTED:  # the unwinding roll ran out of web
                    self.system.ended(t, self.y)
                    self.t, self._h = t, h
                    self._outputs = None
                    return
                self.t, self._h = (tb if status == integ.DONE else t), h
                self._outputs = None
        self.t = t_end
        self._outputs = None

    @property
    def ended(self) -> str | None:
        """Why the machine cannot go on (an unwinding roll ran out of web), else None:
        :meth:`step` then stops at that time, and further steps raise."""
        return self.system.end[2] if self.system.end is not None else None

    def _over(self, kind: str, t_start: float, t_end: float, nfev: int, steps0: int,
              stiff0: int, wall0: float) -> Exception:
        outputs = self.outputs()
        units = self.system.channel_units
        partial = Result({"t": np.array([self.t]),
                          **{k: np.array([v]) for k, v in outputs.items()}},
                         {"scene": self.scene.name, "partial": True},
                         units={k: units[k] for k in ("t", *outputs) if k in units})
        limit: Any = self.max_rhs if kind == "max_rhs" else self.max_wall
        return budget_error(kind, limit, meth=self.method, t=self.t, t_start=t_start,
                            t_end=t_end, step=self._h or None,
                            steps=int(self._stats[1]) - steps0,
                            stiff_steps=int(self._stats[4]) - stiff0 if self.method in
                            ("DOPRI5", "DOP853C") else None, nfev=nfev,
                            wall=time.perf_counter() - wall0, state=self.state,
                            partial=partial, how=_RAISE, alternatives="a looser rtol")

    def outputs(self) -> dict[str, float]:
        """All outputs (:attr:`output_names`) at the current time."""
        if self._outputs is None:
            ch = self.system.channels(np.array([self.t]), self.y[:, None])
            self._outputs = {k: float(ch[k][0]) for k in self.output_names}
        return self._outputs

    def output(self, name: str) -> float:
        """One output at the current time."""
        if name not in self.output_names:
            raise ArgumentError(f"unknown output {name!r}; valid: "
                                f"{', '.join(self.output_names)}")
        return self.outputs()[name]
