"""What a scene's native FMU exposes (:mod:`winder.fmu.native`): its variables with value
references in the wrappers' layout (``fmu/c/layout.h``: outputs, inputs, parameters,
solver settings, states, derivatives), the machine data the wrappers need, and the event
indicators of model exchange.

- inputs: the :class:`~winder.Stepper`'s (``DRUM_torque`` [N·m] per torque-driven drum
  or unwinding roll, ``ROLL_tension_setpoint`` [N]), units and descriptions from their
  declarations (:func:`winder.model.channels.input_of`);
- parameters (``fixed``): the scene's FMU parameters (:func:`winder.fmu.parameters.fmu_parameters`,
  named by part, units and descriptions from the scene schema) that are run-time
  parameters of the machine (found by changing each and comparing the machine's
  parameter vectors: changing one compiles nothing); a drum's ramp time ``v_w / a_w`` is
  recomputed from its speed and acceleration; ``rtol``, ``atol`` (DOPRI5), ``rk4``
  (Boolean: fixed-step RK4 for real-time targets) and ``rk4_step`` [s];
- outputs: every channel (:attr:`MachineSystem.outputs <winder.solve.system.MachineSystem.outputs>`)
  with its unit, but the channel of a torque input (same name); with an unwinding roll
  also ``t`` [s], the time of the outputs;
- locals: the states and their derivatives (``der(...)``), for directional derivatives
  (exact Jacobian for derivatives w.r.t. states; central differences otherwise).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from winder._errors import WinderError
from winder.fmu.parameters import (
    FmuError,
    fmu_parameters,
    parameter_units,
    parameter_value,
    scene_with_parameters,
)
from winder.model.channels import input_of
from winder.model.locked_modes import ModeKind
from winder.model.machine import Machine
from winder.model.units import DIMENSIONS, fmi_name
from winder.parts import body_elements
from winder.scene.load import Scene
from winder.solve.stepper import inputs_of
from winder.solve.system import MachineSystem

__all__ = ["Variable", "NativeInterface", "native_interface", "indicators", "zero_sides",
           "SOLVER_PARAMETERS"]

#: name → (start, description with unit) of the solver settings (Reals, then ``rk4``)
SOLVER_PARAMETERS: dict[str, tuple[float, str]] = {
    "rtol": (1e-8, "relative tolerance of the internal DOPRI5 [-]"),
    "atol": (1e-10, "absolute tolerance of the internal DOPRI5 [state units]"),
    "rk4_step": (1e-3, "largest step of the fixed-step RK4 (rk4 = true): each "
                       "communication step is divided evenly into steps of at most this [s]"),
}



@dataclass(frozen=True)
class Variable:
    """One scalar variable of the model description."""

    name: str
    vr: int
    causality: str
    variability: str
    start: float | None
    unit: str | None = None
    description: str = ""
    initial: str | None = None
    derivative: int | None = None


@dataclass(frozen=True)
class NativeInterface:
    """What the native FMU of a scene exposes and the machine data its wrapper needs."""

    system: MachineSystem
    outputs: tuple[Variable, ...]
    out_channels: tuple[int, ...]      # channel index per output; -1 zero, -2 time
    inputs: tuple[Variable, ...]
    input_params: tuple[int, ...]
    parameters: tuple[Variable, ...]
    parameter_params: tuple[int, ...]
    skipped: tuple[str, ...]           # scene FMU parameters that are no run-time parameter
    solver: tuple[Variable, ...]
    states: tuple[Variable, ...]
    derivatives: tuple[Variable, ...]
    ramps: tuple[tuple[int, int, int], ...]  # (a_w, v_w, ramp time) parameter indices
    x0: np.ndarray
    #: a single-drum scene's own interface (:attr:`Naming.fmu
    #: <winder.scene.naming.Naming.fmu>`): its profile switch's name and built value, and
    #: its profile ``min(a_w t, v_w)``: the machine parameter indices of ``a_w``, ``v_w``
    #: (-1: none, the constants then) and the constants ``a_w``, ``v_w``; else None
    own: tuple[str, bool, int, int, float, float] | None = None


def _unit(unit: str | None) -> str | None:
    """A winder unit text as the FMU names it, or None where it has no fixed dimension."""
    return fmi_name(unit) if unit is not None and unit in DIMENSIONS else None


def _runtime_parameters(scene: Scene, machine: Machine
                        ) -> tuple[dict[str, int], list[str]]:
    """FMU parameter name → machine parameter index, for the scene's FMU parameters that
    are one run-time parameter (changing the scene value changes that parameter to the
    same value, and at most a drum's ramp time besides); and the names of the others."""
    own = scene.naming.fmu
    profile = None if own is None else any(b.prescribed for b in body_elements(scene))
    base, key = machine.parameters(), machine.structure_key()
    names = machine.param_names
    found: dict[str, int] = {}
    skipped: list[str] = []
    for name, (place, _) in fmu_parameters(scene).items():
        value = parameter_value(scene, place)
        new = value * 1.001 if value != 0.0 else 1e-6
        try:
            other = Machine(scene_with_parameters(scene, {name: new}, speed_profile=profile))
        except WinderError:
            skipped.append(name)
            continue
        p = other.parameters()
        changed = {int(i) for i in np.nonzero(p != base)[0]}
        same = [i for i in changed if p[i] == new and base[i] == value]
        rest = changed - set(same)
        if other.structure_key() != key or len(same) != 1 or \
                any(not names[i].endswith(".ramp_time") for i in rest):
            skipped.append(name)
            continue
        found[name] = same[0]
    return found, skipped


def native_interface(scene: Scene, profile: tuple[float, float] | None = None
                     ) -> NativeInterface:
    """The variables of ``scene``'s native FMU, with value references in the wrapper's
    layout (``fmu/c/fmi2.c``): outputs, inputs, parameters, solver settings, states,
    derivatives. ``profile``: a single-drum scene's speed profile ``(a_w, v_w)`` as the
    scene file gives it (its drum freed, ``scene`` starts it at the initial speed); None:
    ``scene``'s."""
    system = MachineSystem(scene)
    if system.generated is None:
        raise FmuError("a native FMU needs the generated code: no C compiler")
    m = system.machine
    names = m.param_names
    ramps = []
    for i, name in enumerate(names):
        if name.endswith(".ramp_time"):
            stem = name[: -len(".ramp_time")]
            ramps.append((m.param_index(f"{stem}.web_acceleration"),
                          m.param_index(f"{stem}.web_speed"), i))
    times = sorted({float(system.params[t]) for a, _, t in ramps if system.params[a] > 0})
    if sorted(system.breakpoints) != times:
        raise FmuError(f"breakpoints {system.breakpoints} are not the drums' ramp times "
                       f"{times}: the native FMU cannot move them with the parameters")
    x0 = system.initial_state()
    inputs = {n: names.index(p) for n, p in inputs_of(system).items() if p in names}
    own = scene.naming.fmu
    if own is not None:  # the single-drum interface: its own input names
        inputs = {fmu: inputs[st] for fmu, st in own.inputs.items() if st in inputs}
    outputs = {n: c for n, (c, _) in system.outputs.items() if n not in inputs}
    units = system.channel_units
    ch0 = system.channels(np.array([0.0]), x0[:, None])
    vr = 0
    outs, out_ch = [], []
    for name, channel in outputs.items():
        outs.append(Variable(name, vr, "output", "continuous", float(ch0[name][0]),
                             _unit(units[name]), initial="exact"))
        out_ch.append(m.channel_names.index(channel) if channel in m.channel_names else -1)
        vr += 1
    own_data = None
    if own is not None:  # the profile a speed controller follows, min(a_w t, v_w)
        drive = scene.drum.drive
        a_w, v_w = profile or (float(drive.web_acceleration), float(drive.web_speed))
        profile = any(b.prescribed for b in body_elements(scene))
        ia = names.index("drum.web_acceleration") if profile else -1
        iv = names.index("drum.web_speed") if profile else -1
        ref0 = v_w if a_w <= 0 else 0.0
        outs.append(Variable(own.profile_reference, vr, "output", "continuous", ref0,
                             _unit(parameter_units(scene)[own.speed]), initial="exact"))
        out_ch.append(-3)
        vr += 1
        own_data = (own.profile_switch, profile, ia, iv, a_w, v_w)
    if m.unwind is not None:
        outs.append(Variable("t", vr, "output", "continuous", 0.0, "s",
                             "time of the outputs [s]: the end of the last step, or where "
                             "the run ended inside it", initial="exact"))
        out_ch.append(-2)
        vr += 1
    ins = []
    for name, i in inputs.items():
        decl = input_of(names[i])
        ins.append(Variable(name, vr, "input", "continuous",
                            0.0 if own is not None else float(system.params[i]),
                            _unit(decl.unit), f"{decl.doc} [{decl.unit}]"))
        vr += 1
    found, skipped = _runtime_parameters(scene, m)
    texts = fmu_parameters(scene)
    punits = parameter_units(scene)
    pars = []
    for name, i in found.items():
        pars.append(Variable(name, vr, "parameter", "fixed", float(system.params[i]),
                             _unit(punits[name]), texts[name][1], initial="exact"))
        vr += 1
    solver = []
    for name, (start, text) in SOLVER_PARAMETERS.items():
        solver.append(Variable(name, vr, "parameter", "fixed", start,
                               "s" if name == "rk4_step" else None, text, initial="exact"))
        vr += 1
    states, ders = [], []
    n = system.n_states
    for k, name in enumerate(system.state_names):
        states.append(Variable(name, vr + k, "local", "continuous", float(x0[k]),
                               description=f"state {name}", initial="exact"))
    for k, name in enumerate(system.state_names):
        ders.append(Variable(f"der({name})", vr + n + k, "local", "continuous", None,
                             description=f"time derivative of {name}",
                             initial="calculated", derivative=vr + k))
    return NativeInterface(system, tuple(outs), tuple(out_ch), tuple(ins),
                           tuple(inputs.values()), tuple(pars), tuple(found.values()),
                           tuple(skipped), tuple(solver), tuple(states), tuple(ders),
                           tuple(ramps), x0, own_data)


def indicators(system: MachineSystem) -> list[int]:
    """The event indicators of model exchange: the switching functions (indices into
    ``machine.switch_names``) the mode table switches on, in the table's order: a
    contact's ``g1``, a core's ``g1`` and ``g2``, an unwinding roll's end ``g1``."""
    return [g for g, _ in _indicators(system)]


def zero_sides(system: MachineSystem) -> list[int]:
    """Per event indicator (:func:`indicators`), the side (+1 or -1) the mode rule puts
    it on at exactly zero (see :func:`_indicators`)."""
    return [side for _, side in _indicators(system)]


def _indicators(system: MachineSystem) -> list[tuple[int, int]]:
    """:func:`indicators` with the side (+1 or -1) the mode rule puts an indicator at
    exactly zero on (``modes_of`` in ``solve/c/events.h``): a core's ``r_c − r`` and an
    end's at zero are at the core (+1); a contact at zero is open, a roll at rest at its
    core is not winding (-1). The FMU reports a zero indicator as ±1e-300 on that side:
    a host that starts on a boundary (a roll at rest on its core) then sees a sign change
    when the state leaves it."""
    out: dict[int, int] = {}
    for kind, g1, g2, _, _ in system.table.tolist():
        pairs = ((g1, 1), (g2, -1)) if kind == ModeKind.CORE else \
            ((g1, 1 if kind == ModeKind.END else -1),)
        for g, side in pairs:
            if out.setdefault(int(g), side) != side:
                raise FmuError(f"switching function {system.machine.switch_names[g]!r} "
                               "is a contact's and a core's: its zero has no one side")
    return list(out.items())
