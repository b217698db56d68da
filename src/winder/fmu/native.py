"""A native FMI 2.0 co-simulation FMU of a scene: the compiled machine, no Python inside
(issue #24, phase 1).

The archive holds ``binaries/linux64/MODEL.so``, built with the system C compiler from
the machine's generated C (:func:`winder.model.codegen.write_source`: the same functions
:func:`winder.simulate` calls), winder's C integrators (``solve/c/``: the same DOPRI5 and
RK4 with located events and switched modes) and the wrapper ``fmu/c/fmi2.c``;
``sources/`` with all of them, the machine's data (``winder_model.h``) and the FMI 2.0
headers of FMPy's ``c-code/`` (BSD-2, their license beside them), listed in
``<SourceFiles>`` so that ``fmpy compile`` rebuilds it for another platform; and
``modelDescription.xml``.

Interface (every name from the machine's and the scene's names):

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
- locals: the states and their derivatives (``der(...)``), for
  ``fmi2GetDirectionalDerivative`` (exact Jacobian for derivatives w.r.t. states; central
  differences otherwise).

The initial state is the static balance (:meth:`MachineSystem.initial_state
<winder.solve.system.MachineSystem.initial_state>`) of the scene's parameter values,
computed here at build time; where the host sets parameters, ``fmi2ExitInitializationMode``
solves the balance again in C (Newton on the generated force residual and its exact
Jacobian, from the built balance and in its active set: :mod:`winder.fmu.balance`). The
rest of the initial state (speeds, radii) stays the scene's.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import uuid
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

import numpy as np

from winder._errors import WinderError
from winder.fmu.balance import Balance, balance_of, write_balance_source
from winder.fmu.parameters import (
    FmuError,
    fmu_parameters,
    parameter_units,
    parameter_value,
    scene_with_parameters,
)
from winder.model.channels import input_of
from winder.model.codegen import CFLAGS, SANITIZE_CFLAGS, run_compiler, write_source
from winder.model.locked_modes import ModeKind
from winder.model.machine import Machine
from winder.model.units import BASE_UNITS, DIMENSIONS, dimensions, fmi_name
from winder.parts import body_elements
from winder.scene.load import Scene, load_scene
from winder.solve.stepper import inputs_of
from winder.solve.system import MachineSystem

__all__ = ["build_fmu", "NativeInterface", "native_interface", "SOLVER_PARAMETERS"]

_C = Path(__file__).resolve().parent / "c"
_SOLVE_C = Path(__file__).resolve().parents[1] / "solve" / "c"
#: the integrators' sources copied into the FMU (ros2.c is not used)
_INTEGRATORS = ("dopri5.c", "rk4.c", "machine.c")
_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
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


# ---- files ---------------------------------------------------------------------------------

def _c_array(ctype: str, name: str, values: Any, fmt: Any = str) -> str:
    """A static C array (a trailing 0 so that none is empty)."""
    items = [fmt(v) for v in values] + ["0"]
    return f"static const {ctype} {name}[] = {{{', '.join(items)}}};\n"


def _model_header(iface: NativeInterface, symbol: str, guid: str, balance: Balance) -> str:
    """``winder_model.h``: the machine's sizes, data and generated functions."""
    sy, m = iface.system, iface.system.machine
    owners = [f'"{mode.owner}"' for mode in m.modes] + ["0"]
    lines = [
        "/* The machine of one scene for fmi2.c (written by winder.fmu.native). */",
        "#ifndef WINDER_MODEL_H", "#define WINDER_MODEL_H", "#include <stdint.h>",
        f'#define W_GUID "{guid}"',
        f"#define W_N {sy.n_states}", f"#define W_NP {len(m.param_names)}",
        f"#define W_NSLOTS {len(sy.table)}", f"#define W_NSW {len(m.switch_names)}",
        f"#define W_NCH {len(m.channel_names)}", f"#define W_NOUT {len(iface.outputs)}",
        f"#define W_NIN {len(iface.inputs)}", f"#define W_NPAR {len(iface.parameters)}",
        f"#define W_NRAMP {len(iface.ramps)}", f"#define W_NZ {len(indicators(sy))}",
    ]
    lines += [f"#define W_NU {len(balance.unknowns)}",
              f"int {symbol}_balance_flat(const double* t, const double* x, const double* p, "
              "const double* m, double* out);", f"#define W_BAL_FN {symbol}_balance_flat"]
    for k in ("rhs", "jac", "out", "sw"):
        lines.append(f"int {symbol}_{k}_flat(const double* t, const double* x, "
                     "const double* p, const double* m, double* out);")
        lines.append(f"#define W_{k.upper()}_FN {symbol}_{k}_flat")
    text = "\n".join(lines) + "\n"
    text += _c_array("double", "W_X0", iface.x0, float.hex)
    text += _c_array("double", "W_P0", sy.params, float.hex)
    text += _c_array("int64_t", "W_TABLE", sy.table.ravel())
    text += _c_array("int", "W_OUT_CH", iface.out_channels)
    text += _c_array("int", "W_IN_P", iface.input_params)
    text += _c_array("int", "W_PAR_P", iface.parameter_params)
    text += _c_array("int", "W_RAMP", [i for r in iface.ramps for i in r])
    text += _c_array("int", "W_Z", indicators(sy))
    text += _c_array("int", "W_Z_ZERO", [side for _, side in _indicators(sy)])
    text += _c_array("int", "W_U", balance.unknowns)
    text += _c_array("double", "W_MB", balance.modes, float.hex)
    own = iface.own or ("", False, -1, -1, 0.0, 0.0)
    text += (f"#define W_OWN {int(iface.own is not None)}\n"
             f"#define W_PROFILE {int(own[1])}\n#define W_REF_AP {own[2]}\n"
             f"#define W_REF_VP {own[3]}\n#define W_REF_A {float.hex(own[4])}\n"
             f"#define W_REF_V {float.hex(own[5])}\n")
    text += f"static const char* const W_SLOT_OWNER[] = {{{', '.join(owners)}}};\n"
    return text + "#endif\n"


def indicators(system: MachineSystem) -> list[int]:
    """The event indicators of model exchange: the switching functions (indices into
    ``machine.switch_names``) the mode table switches on, in the table's order: a
    contact's ``g1``, a core's ``g1`` and ``g2``, an unwinding roll's end ``g1``."""
    return [g for g, _ in _indicators(system)]


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
            out.setdefault(int(g), side)
    return list(out.items())


def _dependencies(iface: NativeInterface, pattern: dict[str, np.ndarray]
                  ) -> list[str]:
    """Per state derivative, the ModelVariables indices (1-based) of the states and inputs
    it depends on: the structural sparsity of the generated Jacobians."""
    n = len(iface.states)
    deps: list[set[int]] = [set() for _ in range(n)]
    for row, col in pattern["x"].tolist():
        deps[row].add(iface.states[col].vr + 1)
    by_param = {p: v for p, v in zip(iface.input_params, iface.inputs, strict=True)}
    for row, col in pattern["p"].tolist():
        if col in by_param:
            deps[row].add(by_param[col].vr + 1)
    return [" ".join(map(str, sorted(d))) for d in deps]


def _scalar(parent: ET.Element, v: Variable) -> None:
    attrs = {"name": v.name, "valueReference": str(v.vr), "causality": v.causality,
             "variability": v.variability}
    if v.description:
        attrs["description"] = v.description
    if v.initial is not None:
        attrs["initial"] = v.initial
    sv = ET.SubElement(parent, "ScalarVariable", attrs)
    real: dict[str, str] = {}
    if v.start is not None:
        real["start"] = repr(float(v.start))
    if v.unit is not None:
        real["unit"] = v.unit
    if v.derivative is not None:
        real["derivative"] = str(v.derivative + 1)  # an index into ModelVariables (1-based)
    ET.SubElement(sv, "Real", real)


def _model_description(iface: NativeInterface, model: str, guid: str, scene: Scene,
                       sources: list[str], pattern: dict[str, np.ndarray]) -> bytes:
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": scene.name or model, "guid": guid,
        "description": f"winder machine of scene {scene.name!r} (native: no Python)",
        "generationTool": "winder", "variableNamingConvention": "flat",
        "numberOfEventIndicators": str(len(indicators(iface.system)))})
    me = ET.SubElement(root, "ModelExchange", {
        "modelIdentifier": model, "needsExecutionTool": "false",
        "completedIntegratorStepNotNeeded": "true",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions":
        "true", "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
        "providesDirectionalDerivative": "true"})
    files = ET.SubElement(me, "SourceFiles")
    for f in sources:
        ET.SubElement(files, "File", {"name": f})
    cs = ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": model, "needsExecutionTool": "false",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions":
        "true", "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
        "providesDirectionalDerivative": "true"})
    files = ET.SubElement(cs, "SourceFiles")
    for f in sources:
        ET.SubElement(files, "File", {"name": f})
    real_vars = [*iface.outputs, *iface.inputs, *iface.parameters, *iface.solver,
                 *iface.states, *iface.derivatives]
    used = sorted({v.unit for v in real_vars if v.unit is not None})
    if used:
        defs = ET.SubElement(root, "UnitDefinitions")
        by_fmi = {fmi_name(u): u for u in DIMENSIONS}
        for name in used:
            exps = dimensions(by_fmi[name])
            unit = ET.SubElement(defs, "Unit", {"name": name})
            ET.SubElement(unit, "BaseUnit", {b: str(exps[b]) for b in BASE_UNITS
                                             if exps.get(b)})
    cats = ET.SubElement(root, "LogCategories")
    for c in ("logStatusError", "logStatusDiscard"):
        ET.SubElement(cats, "Category", {"name": c})
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0.0",
                                              "stopTime": repr(float(scene.scene.duration)),
                                              "tolerance": "1e-08"})
    mv = ET.SubElement(root, "ModelVariables")
    # the index of each variable in ModelVariables is its position (1-based): Reals in
    # value-reference order, then the Boolean rk4
    for v in real_vars:
        _scalar(mv, v)
    sv = ET.SubElement(mv, "ScalarVariable", {
        "name": "rk4", "valueReference": "0", "causality": "parameter",
        "variability": "fixed", "initial": "exact",
        "description": "true: fixed-step RK4 of step rk4_step (real-time targets); false: "
                       "DOPRI5 to rtol and atol with located events"})
    ET.SubElement(sv, "Boolean", {"start": "false"})
    if iface.own is not None:  # the single-drum interface's switch (built in one mode)
        name, profile = iface.own[0], iface.own[1]
        own = scene.naming.fmu
        assert own is not None
        sv = ET.SubElement(mv, "ScalarVariable", {
            "name": name, "valueReference": "1", "causality": "parameter",
            "variability": "fixed", "initial": "exact",
            "description": f"{own.switch_doc} {', '.join(own.inputs)} (this FMU was built "
                          f"with {name} = {str(profile).lower()}: the other value is "
                          f"refused; winder fmu --{name.replace('_', '-')}/"
                          f"--no-{name.replace('_', '-')} builds either)"})
        ET.SubElement(sv, "Boolean", {"start": str(profile).lower()})
    ms = ET.SubElement(root, "ModelStructure")
    outs = ET.SubElement(ms, "Outputs")
    for v in iface.outputs:
        ET.SubElement(outs, "Unknown", {"index": str(v.vr + 1)})
    ders = ET.SubElement(ms, "Derivatives")
    for v, dep in zip(iface.derivatives, _dependencies(iface, pattern), strict=True):
        ET.SubElement(ders, "Unknown", {"index": str(v.vr + 1), "dependencies": dep})
    init = ET.SubElement(ms, "InitialUnknowns")
    for v in iface.derivatives:
        ET.SubElement(init, "Unknown", {"index": str(v.vr + 1)})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _compile(sources: Path, model: str, out: Path, symbol: str,
             sanitize: bool) -> None:
    base = [f for f in CFLAGS if f != "-shared"] + ["-fvisibility=hidden"]
    if sanitize:
        base = ["-O1" if f == "-O3" else f for f in base] + list(SANITIZE_CFLAGS)
    strict = [*base, "-ffp-contract=off", "-std=c99"]  # as solve/cint.py compiles them
    objs = []
    for src in (f"{symbol}.c", f"{symbol}_balance.c", *_INTEGRATORS, "fmi2.c"):
        flags = base if src.startswith(symbol) else strict
        obj = sources.parent.parent / (Path(src).stem + ".o")
        run_compiler([*flags, "-I", str(sources), "-c", str(sources / src), "-o", str(obj)],
                     src)
        objs.append(str(obj))
    link = ["-shared", *(SANITIZE_CFLAGS if sanitize else ["-Wl,--no-undefined"])]
    run_compiler([*link, *objs, "-o", str(out), "-lm"], f"{model}.so")


def _headers_dir() -> Path:
    try:
        import fmpy
    except ImportError as exc:
        raise FmuError("the FMI 2.0 headers come from FMPy's c-code/: pip install "
                       "'winder[fmu]'") from exc
    return Path(fmpy.__file__).resolve().parent / "c-code"


def _license_text() -> str:
    import importlib.metadata

    dist = importlib.metadata.distribution("fmpy")
    for f in dist.files or ():
        if "LICENSE" in f.name.upper():
            return f.read_text()
    raise FmuError("FMPy's license text is not found in its distribution")


def model_identifier(scene: Scene) -> str:
    """The FMU's model identifier: ``winder_`` and the scene's name as a C identifier."""
    return "winder_" + (re.sub(r"\W", "_", scene.name or "") or "machine")


def build_fmu(scene_path: str | Path, out: str | Path, *,
              sanitize: bool = False, speed_profile: bool | None = None) -> Path:
    """Build the native FMU of a scene file at ``out`` (an ``.fmu``), atomically.
    ``sanitize``: compile with AddressSanitizer and UBSan (for tests; the host must then
    load libasan). ``speed_profile`` (single-drum scenes only): the drum on its speed
    profile (true) or freed on the input ``drum_torque_command`` (false), fixed at build
    time (the two are different machines); None: the scene's drive. Raises
    :class:`FmuError`."""
    from winder.io.files import atomic_write, scratch_dir

    scene_path, out = Path(scene_path), Path(out)
    scene = load_scene(scene_path)
    profile = None
    if scene.naming.fmu is not None:
        profile = (float(scene.drum.drive.web_acceleration),
                   float(scene.drum.drive.web_speed))
        if speed_profile is None:
            speed_profile = any(b.prescribed for b in body_elements(scene))
        scene = scene_with_parameters(scene, {}, speed_profile=speed_profile)
    elif speed_profile is not None:
        raise FmuError("speed_profile is a parameter of single-drum scenes only")
    if out.suffix != ".fmu":
        raise FmuError(f"output file must end in .fmu, got {str(out)!r}")
    if len(scene.webs) > 1:
        raise FmuError(f"{scene_path}: [[web]]: {len(scene.webs)} webs "
                       f"({', '.join(w.name for w in scene.webs)}); the FMU takes a scene "
                       "with one web (one winding station); valid: one [web] table (run "
                       "several stations with winder run)")
    iface = native_interface(scene, profile)
    model = model_identifier(scene)
    headers = _headers_dir()
    with scratch_dir("winder_native_fmu_") as d:
        stage, src = d / "fmu", d / "fmu" / "sources"
        (stage / "binaries" / "linux64").mkdir(parents=True)
        src.mkdir()
        _, symbol, pattern = write_source(iface.system.machine, src)
        balance = balance_of(iface.system.machine, iface.x0, iface.system.params)
        write_balance_source(iface.system.machine, balance, f"{symbol}_balance", src)
        for f in (*_INTEGRATORS, "events.h"):
            shutil.copyfile(_SOLVE_C / f, src / f)
        shutil.copyfile(_C / "fmi2.c", src / "fmi2.c")
        for h in _HEADERS:
            shutil.copyfile(headers / h, src / h)
        (src / "LICENSE-FMI-headers.txt").write_text(
            "The FMI 2.0 headers fmi2*.h in this folder come from FMPy's c-code/ "
            "(https://github.com/CATIA-Systems/FMPy):\n\n" + _license_text(),
            encoding="utf-8")
        digest = hashlib.sha256()
        for f in sorted(src.iterdir()):
            digest.update(f.name.encode() + f.read_bytes())
        guid = "{" + str(uuid.UUID(digest.hexdigest()[:32])) + "}"
        (src / "winder_model.h").write_text(_model_header(iface, symbol, guid, balance),
                                            encoding="utf-8")
        _compile(src, model, stage / "binaries" / "linux64" / f"{model}.so", symbol,
                 sanitize)
        sources = [f"{symbol}.c", f"{symbol}_balance.c", *_INTEGRATORS, "fmi2.c"]
        (stage / "modelDescription.xml").write_bytes(
            _model_description(iface, model, guid, scene, sources, pattern))
        staged = d / "out.fmu"
        with zipfile.ZipFile(staged, "w", zipfile.ZIP_DEFLATED) as zf:
            for f in sorted(stage.rglob("*")):
                if f.is_file():
                    zf.write(f, f.relative_to(stage).as_posix())
        atomic_write(out, lambda tmp: shutil.copyfile(staged, tmp))
    return out
