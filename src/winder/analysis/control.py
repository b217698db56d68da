"""The plant for control design: a machine's nonlinear dynamics as CasADi Functions
(:func:`casadi_model`), for MPC and estimators, from the one symbolic definition the
generated C is built from (:meth:`Machine.evaluate <winder.model.machine.Machine.evaluate>`
on CasADi symbols, as :mod:`winder.model.codegen`): no physics derived twice.

``f(x, u, p) → ẋ`` and ``h(x, u, p) → y`` hold the machine in its **contact-closed mode**:
every nip in contact (:data:`~winder.model.locked_modes.IN_CONTACT`, its unclamped law),
every wound roll winding (:data:`~winder.model.locked_modes.WINDING`). ``x``: the states
(``machine.state_names``); ``u``: the inputs (:data:`INPUT_KINDS`: the drive torques and
tension set-points of :func:`winder.solve.stepper.inputs_of`, and a perturbation of each
speed-profile drum's web speed); ``p``: every other run-time parameter of the machine, then
the time ``t`` [s] (the drums' speed profiles are functions of it; past a drum's ramp it
drops out); ``y``: the chosen result channels, as the scene names them.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from winder._args import show
from winder._errors import ArgumentError, ArgumentTypeError
from winder.model.locked_modes import IN_CONTACT, WINDING, ModeKind
from winder.scene.load import Scene
from winder.solve.simulate import _as_scene
from winder.solve.stepper import inputs_of
from winder.solve.system import MachineSystem

__all__ = ["CasadiModel", "casadi_model", "INPUT_KINDS", "STATE_UNITS", "state_unit",
           "plant_inputs", "contact_closed_modes"]

#: The kinds of input, by the run-time parameter's name after the body's: its unit and
#: what it is.
INPUT_KINDS = {
    "torque": ("N·m", "drive torque of a torque-driven drum or unwinding roll"),
    "tension_setpoint": ("N", "tension set-point of a tension-controlled unwind"),
    "web_speed": ("m/s", "web speed of a speed-profile drum (its profile's plateau: a "
                         "perturbation of the drum's speed past its ramp)"),
}
#: The unit of a state, by its name after the body's (``set.z_dot`` → ``z_dot``).
STATE_UNITS = {"x": "m", "z": "m", "theta": "rad", "x_dot": "m/s", "z_dot": "m/s",
               "theta_dot": "rad/s", "radius": "m", "friction": "N", "tension": "N",
               "tension_integral": "N·s", "tilt_x": "rad", "tilt_z": "rad",
               "tilt_rate_x": "rad/s", "tilt_rate_z": "rad/s"}
#: The time, the last parameter of ``p``.
TIME_PARAMETER = "t"


def state_unit(name: str) -> str:
    """The unit of state ``name`` (``set.z_dot`` [m/s]); ``""`` for an unknown kind."""
    return STATE_UNITS.get(name.rpartition(".")[2], "")


def plant_inputs(system: MachineSystem) -> dict[str, str]:
    """The inputs of a system's plant: input name → run-time parameter. The scene's inputs
    (:func:`~winder.solve.stepper.inputs_of`: ``DRUM_torque``, ``ROLL_tension_setpoint``;
    a single-drum scene's ``drum_torque``) that are parameters of its machine, then
    ``DRUM_web_speed`` per speed-profile drum."""
    names = system.machine.param_names
    out = {n: p for n, p in inputs_of(system).items() if p in names}
    for b in system.machine.bodies:
        if b.prescribed and f"{b.name}.web_speed" in names:
            out[f"{b.name}_web_speed"] = f"{b.name}.web_speed"
    return out


def contact_closed_modes(system: MachineSystem) -> np.ndarray:
    """The locked modes of the contact-closed mode: every nip ``IN_CONTACT``, every wound
    roll ``WINDING``, the rest as a run starts."""
    return np.array([IN_CONTACT if mode.kind is ModeKind.CONTACT else
                     WINDING if mode.kind is ModeKind.CORE else mode.kind.automatic
                     for mode in system.machine.modes], dtype=float)


def _names(where: str, what: str, given: Any, valid: Sequence[str]) -> list[str]:
    """``given`` (None: all of ``valid``) as a list of names from ``valid``, each once."""
    if given is None:
        return list(valid)
    if isinstance(given, str) or not isinstance(given, Sequence):
        raise ArgumentTypeError(f"{where}: {what} must be a list of names, got "
                                f"{show(given)} ({type(given).__name__})")
    out: list[str] = []
    for g in given:
        if not isinstance(g, str) or g not in valid:
            raise ArgumentError(f"{where}: {what}: {show(g)} is not one of this scene's "
                                f"{what}; valid: {', '.join(valid) or 'none'}")
        if g in out:
            raise ArgumentError(f"{where}: {what}: {g!r} is given twice")
        out.append(g)
    if not out:
        raise ArgumentError(f"{where}: {what} is empty; valid: some of {', '.join(valid)}")
    return out


@dataclass(frozen=True, eq=False)
class CasadiModel:
    """A machine's dynamics as CasADi Functions, in the contact-closed mode.

    ``f(x, u, p) → ẋ`` and ``h(x, u, p) → y`` (inputs named ``x``, ``u``, ``p``; outputs
    ``xdot``, ``y``). ``x0``: the initial state (the static balance, as a run starts);
    ``u0``, ``p0``: the scene's input and parameter values (``p0[-1]``, the time, 0).
    Unpacks as ``f, h = casadi_model(scene)``.
    """

    f: Any
    h: Any
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    input_names: tuple[str, ...]
    input_units: tuple[str, ...]
    #: the machine's run-time parameter of each input (``parent.torque``)
    input_parameters: tuple[str, ...]
    param_names: tuple[str, ...]
    output_names: tuple[str, ...]
    output_units: tuple[str, ...]
    x0: np.ndarray
    u0: np.ndarray
    p0: np.ndarray
    #: the locked mode values the Functions hold (:func:`contact_closed_modes`)
    modes: np.ndarray

    def __post_init__(self) -> None:
        pairs = (("state_names", self.state_names, "x0", self.x0),
                 ("input_names", self.input_names, "u0", self.u0),
                 ("param_names", self.param_names, "p0", self.p0))
        for a, names, b, values in pairs:
            if len(names) != len(values):
                raise ArgumentError(f"CasadiModel: {a} has {len(names)} names but {b} "
                                    f"{len(values)} values")
        for a, names, b, units in (("state_names", self.state_names, "state_units",
                                    self.state_units),
                                   ("input_names", self.input_names, "input_units",
                                    self.input_units),
                                   ("output_names", self.output_names, "output_units",
                                    self.output_units)):
            if len(names) != len(units):
                raise ArgumentError(f"CasadiModel: {a} and {b} differ in length")
        if self.f.size1_in(0) != len(self.state_names) or \
                self.h.size1_out(0) != len(self.output_names):
            raise ArgumentError("CasadiModel: f and h do not match the names")

    def __iter__(self) -> Iterator[Any]:
        return iter((self.f, self.h))

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    def parameters(self, t: float = 0.0, **values: float) -> np.ndarray:
        """``p``: the scene's values, the time ``t`` [s] and ``values`` by parameter name
        (``parameters(t=3.0, **{"span.EA": 1.5e6})``)."""
        p = self.p0.copy()
        p[-1] = t
        for name, v in values.items():
            if name not in self.param_names[:-1]:
                raise ArgumentError(f"CasadiModel.parameters: {name!r} is no parameter; "
                                    f"valid: {', '.join(self.param_names[:-1])}")
            p[self.param_names.index(name)] = v
        return p


def _symbolic(system: MachineSystem, input_params: Sequence[str],
              channels: Sequence[str], *, route: str | None = None,
              modes: Any = None) -> tuple[Any, Any, Any, Any, Any, list[str]]:
    """``(x, u, p, ẋ, y, parameter names)`` as CasADi SX: the machine's dynamics on
    symbols as :func:`winder.model.codegen` builds them, with the contact-closed modes
    substituted (or ``modes(t)``: a function of the time symbol ``p[-1]`` giving the
    locked modes as an SX, e.g. a roll held at its core until a time) and the parameters
    split into inputs ``u`` and the rest ``p`` (time last)."""
    import casadi as ca

    from winder.model.backends import SymbolicBackend, default_route

    machine = system.machine
    route = default_route() if route is None else route
    names = list(machine.param_names)
    rest = [n for n in names if n not in input_params]
    x = ca.SX.sym("x", machine.n_states)
    u = ca.SX.sym("u", len(input_params))
    p = ca.SX.sym("p", len(rest) + 1)
    full = [u[input_params.index(n)] if n in input_params else p[rest.index(n)]
            for n in names]
    pf = ca.vertcat(*full) if full else ca.SX(0, 1)
    t = p[len(rest)]
    m = ca.SX.sym("m", len(machine.mode_names))
    ev = machine.evaluate(SymbolicBackend(machine.model, route), t, x, pf, m)
    xdot = ca.vertcat(*[ev.rates[n] for n in machine.state_names])
    # a channel the machine lacks (an effect off) is zero, as in the result
    y = ca.vertcat(*[ev.channels[c] if c in ev.channels else ca.SX(0.0) for c in channels])
    modes = ca.DM(contact_closed_modes(system)) if modes is None else modes(t)
    xdot, y = ca.substitute([xdot, y], [m], [modes])
    return x, u, p, xdot, y, [*rest, TIME_PARAMETER]


def model_of(system: MachineSystem, *, inputs: Sequence[str] | None = None,
             outputs: Sequence[str] | None = None, where: str = "casadi_model",
             x0: np.ndarray | None = None) -> CasadiModel:
    """:func:`casadi_model` of a built :class:`MachineSystem` (its parameter values;
    ``x0``: the state to carry as :attr:`CasadiModel.x0`, default the initial state)."""
    import casadi as ca

    available = plant_inputs(system)
    chosen = _names(where, "inputs", inputs, list(available)) if available or inputs \
        else []
    outs = system.outputs
    out_names = _names(where, "outputs", outputs, list(outs))
    params = [available[n] for n in chosen]
    x, u, p, xdot, y, pnames = _symbolic(system, params, [outs[n][0] for n in out_names])
    f = ca.Function("f", [x, u, p], [xdot], ["x", "u", "p"], ["xdot"])
    h = ca.Function("h", [x, u, p], [y], ["x", "u", "p"], ["y"])
    machine = system.machine
    values = dict(zip(machine.param_names, system.params, strict=True))
    p0 = np.array([values[n] for n in pnames[:-1]] + [0.0])
    u0 = np.array([values[n] for n in params])
    x0 = system.initial_state() if x0 is None else np.array(x0, dtype=float)
    return CasadiModel(
        f, h, tuple(system.state_names), tuple(state_unit(n) for n in system.state_names),
        tuple(chosen), tuple(INPUT_KINDS[q.rpartition(".")[2]][0] for q in params),
        tuple(params), tuple(pnames), tuple(out_names),
        tuple(system.channel_units[n] for n in out_names), x0, u0, p0,
        contact_closed_modes(system))


def casadi_model(scene: Scene | str | os.PathLike, *, inputs: Sequence[str] | None = None,
                 outputs: Sequence[str] | None = None) -> CasadiModel:
    """The machine of ``scene`` as CasADi Functions ``f(x, u, p) → ẋ`` and ``h(x, u, p) →
    y`` in the contact-closed mode (module docstring), with named states, inputs,
    parameters and outputs and their units.

    ``inputs``: names among the scene's plant inputs (:func:`plant_inputs`; default all);
    ``outputs``: result channels as the scene names them
    (:attr:`MachineSystem.outputs <winder.solve.system.MachineSystem.outputs>`; default
    all). The numbers of ``f`` equal :meth:`MachineSystem.rhs
    <winder.solve.system.MachineSystem.rhs>` (with the same locked modes) to round-off.

    >>> f, h = winder.casadi_model("models/winder_line.toml")  # doctest: +SKIP

    Raises
    ------
    ArgumentError: an input or output that the scene does not have.
    """
    scene = _as_scene(scene, "casadi_model")
    return model_of(MachineSystem(scene), inputs=inputs, outputs=outputs)
