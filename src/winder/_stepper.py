"""Step-wise simulation with inputs: the co-simulation interface (used by the FMU)."""

from __future__ import annotations

import math

import numpy as np

from . import _integrators as integ
from ._errors import SimulationError
from ._planar import PlanarSystem
from ._scene import Scene
from ._system import CHANNELS, EXTRA_CHANNELS, WinderSystem

__all__ = ["Stepper", "INPUTS", "OUTPUTS"]

#: Inputs of a :class:`Stepper`: ``drum_torque`` [N·m] (drive kind ``torque`` only).
INPUTS = ("drum_torque",)
#: Outputs: every result channel but ``t``.
OUTPUTS = CHANNELS[1:] + EXTRA_CHANNELS


class Stepper:
    """A scene advanced by fixed communication steps, with inputs set between steps.

    Inside each step the compiled DOPRI5 of :func:`winder.simulate` (adaptive, contact
    events located, drive breakpoints respected) integrates to ``rtol``; the step size of
    the integrator carries over between communication steps, so short steps cost little.

    >>> sim = Stepper(scene)                       # doctest: +SKIP
    >>> sim.set_input("drum_torque", 250.0)        # doctest: +SKIP
    >>> sim.step(1e-3)                             # doctest: +SKIP
    >>> sim.output("roll_speed")                   # doctest: +SKIP

    Parameters
    ----------
    scene: the scene (drive kind ``torque`` for a torque input).
    rtol, atol: tolerances of the internal integrator (default ``1e-8``, ``1e-10``).
    """

    def __init__(self, scene: Scene, *, rtol: float = 1e-8, atol: float = 1e-10) -> None:
        if not (rtol > 0 and atol > 0):
            raise SimulationError(f"rtol and atol must be > 0, got {rtol!r}, {atol!r}")
        self.scene = scene
        self.system = WinderSystem(scene)
        self._planar = PlanarSystem(scene, self.system)
        self.rtol, self.atol = float(rtol), float(atol)
        self.free_drum = scene.drum.drive.kind == "torque"
        self._breaks = tuple(self.system.drive.breakpoints)
        self.reset()

    def reset(self) -> None:
        """Back to ``t = 0`` and the initial state of spec §6 (inputs keep their values)."""
        self.t = 0.0
        self.y = self.system.initial_state()
        self._h = 0.0
        self._stats = np.zeros(4, dtype=np.int64)
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
        if name not in INPUTS:
            raise SimulationError(f"unknown input {name!r}; valid: {', '.join(INPUTS)}")
        v = float(value)
        if not math.isfinite(v):
            raise SimulationError(f"input {name} must be finite, got {value!r}")
        self._planar.set_drum_torque(v)
        self._outputs = None

    def step(self, dt: float) -> None:
        """Advance by ``dt`` [s]."""
        if not (math.isfinite(dt) and dt > 0):
            raise SimulationError(f"step size must be finite and > 0, got {dt!r}")
        t_end = self.t + dt
        stops = [b for b in self._breaks if self.t < b < t_end] + [t_end]
        empty_t, empty_y = np.empty(0), np.empty((len(self.y), 0))
        p = self._planar.params
        for tb in stops:
            while self.t < tb:
                status, t, h, _ = integ.dopri5(self.t, tb, self.y, p, self.rtol, self.atol,
                                               self._h, math.inf, empty_t, empty_y, 0,
                                               10_000_000, self._stats)
                if status in (integ.NON_FINITE, integ.STEP_UNDERFLOW) or \
                        not np.all(np.isfinite(self.y)):
                    where = ", ".join(f"{k}={v:.6g}" for k, v in self.state.items())
                    raise SimulationError(f"integration failed at t = {t:.6g} s (state: "
                                          f"{where}); check the inputs", time=t,
                                          state=self.state)
                self.t, self._h = (tb if status == integ.DONE else t), h
        self.t = t_end
        self._outputs = None

    def outputs(self) -> dict[str, float]:
        """All outputs (:data:`OUTPUTS`) at the current time."""
        if self._outputs is None:
            ch = self._planar.channels(np.array([self.t]), self.y[:, None])
            self._outputs = {k: float(ch[k][0]) for k in OUTPUTS}
        return self._outputs

    def output(self, name: str) -> float:
        """One output at the current time."""
        if name not in OUTPUTS:
            raise SimulationError(f"unknown output {name!r}; valid: {', '.join(OUTPUTS)}")
        return self.outputs()[name]
