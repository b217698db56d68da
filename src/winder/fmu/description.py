"""``modelDescription.xml`` of a scene's native FMU (:mod:`winder.fmu.native`), FMI 2.0 or
3.0, from its :class:`~winder.fmu.interface.NativeInterface`; and the FMI 3.0
``sources/buildDescription.xml``. Both versions list the same variables under the same
value references (``fmu/c/layout.h``); FMI 3.0 adds the independent ``time``, the event
indicators as variables and numbers its two Booleans after them.
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

import numpy as np

from winder.fmu.interface import NativeInterface, Variable, indicators
from winder.model.units import BASE_UNITS, DIMENSIONS, dimensions, fmi_name
from winder.scene.load import Scene

__all__ = ["model_description", "build_description"]


def model_description(iface: NativeInterface, model: str, guid: str, scene: Scene,
                      sources: list[str], pattern: dict[str, np.ndarray], *,
                      fmi_version: int) -> bytes:
    """``modelDescription.xml`` of FMI ``fmi_version`` (2 or 3): ``model`` the model
    identifier, ``guid`` the GUID (FMI 3.0: the instantiation token), ``sources`` the C
    files (FMI 2.0 lists them), ``pattern`` the structural sparsity of the generated
    Jacobian (:func:`winder.model.codegen.write_source`)."""
    if fmi_version == 3:
        return _description3(iface, model, guid, scene, pattern)
    return _description2(iface, model, guid, scene, sources, pattern)


def build_description(model: str, sources: list[str]) -> bytes:
    """FMI 3.0 ``sources/buildDescription.xml``: the C files to compile (C99) and libm.
    It carries no compiler options: a rebuild (``fmpy compile``) uses its tool's flags, so
    its numbers may differ from winder's build (``-ffp-contract=off``) by round-off."""
    root = ET.Element("fmiBuildDescription", {"fmiVersion": "3.0"})
    conf = ET.SubElement(root, "BuildConfiguration", {"modelIdentifier": model})
    files = ET.SubElement(conf, "SourceFileSet", {"language": "C99"})
    for f in sources:
        ET.SubElement(files, "SourceFile", {"name": f})
    ET.SubElement(conf, "Library", {"name": "m", "external": "true",
                                    "description": "the C math library"})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _unit_definitions(root: ET.Element, variables: list[Variable]) -> None:
    used = sorted({v.unit for v in variables if v.unit is not None})
    if used:
        defs = ET.SubElement(root, "UnitDefinitions")
        by_fmi = {fmi_name(u): u for u in DIMENSIONS}
        for name in used:
            exps = dimensions(by_fmi[name])
            unit = ET.SubElement(defs, "Unit", {"name": name})
            ET.SubElement(unit, "BaseUnit", {b: str(exps[b]) for b in BASE_UNITS
                                             if exps.get(b)})


def _header(root: ET.Element, scene: Scene) -> None:
    cats = ET.SubElement(root, "LogCategories")
    for c in ("logStatusError", "logStatusDiscard"):
        ET.SubElement(cats, "Category", {"name": c})
    ET.SubElement(root, "DefaultExperiment", {"startTime": "0.0",
                                              "stopTime": repr(float(scene.scene.duration)),
                                              "tolerance": "1e-08"})


_RK4_TEXT = ("true: fixed-step RK4 of step rk4_step (real-time targets); false: DOPRI5 to "
             "rtol and atol with located events")


def _switch_text(iface: NativeInterface, scene: Scene) -> tuple[str, bool, str]:
    """A single-drum scene's profile switch: name, built value, description."""
    assert iface.own is not None and scene.naming.fmu is not None
    name, profile, own = iface.own[0], iface.own[1], scene.naming.fmu
    opt = name.replace("_", "-")
    return name, profile, (f"{own.switch_doc} {', '.join(own.inputs)} (this FMU was built "
                           f"with {name} = {str(profile).lower()}: the other value is "
                           f"refused; winder fmu --{opt}/--no-{opt} builds either)")


def _dependencies(iface: NativeInterface, pattern: dict[str, np.ndarray], offset: int = 1
                  ) -> list[str]:
    """Per state derivative, the states and inputs it depends on (the structural sparsity
    of the generated Jacobians), as ``vr + offset``: FMI 2.0's ModelVariables indices
    (1-based: its Reals are in value-reference order), FMI 3.0's value references (0)."""
    n = len(iface.states)
    deps: list[set[int]] = [set() for _ in range(n)]
    for row, col in pattern["x"].tolist():
        deps[row].add(iface.states[col].vr + offset)
    by_param = {p: v for p, v in zip(iface.input_params, iface.inputs, strict=True)}
    for row, col in pattern["p"].tolist():
        if col in by_param:
            deps[row].add(by_param[col].vr + offset)
    return [" ".join(map(str, sorted(d))) for d in deps]


def _attributes(v: Variable, offset: int) -> tuple[dict[str, str], dict[str, str]]:
    """A Real variable's attributes: the variable's own (name, value reference,
    causality, variability, description, initial) and its type's (start, unit,
    derivative: ``vr + offset`` of its state, FMI 2.0's 1-based ModelVariables index with
    ``offset`` 1, FMI 3.0's value reference with 0)."""
    own = {"name": v.name, "valueReference": str(v.vr), "causality": v.causality,
           "variability": v.variability}
    if v.description:
        own["description"] = v.description
    if v.initial is not None:
        own["initial"] = v.initial
    typed: dict[str, str] = {}
    if v.start is not None:
        typed["start"] = repr(float(v.start))
    if v.unit is not None:
        typed["unit"] = v.unit
    if v.derivative is not None:
        typed["derivative"] = str(v.derivative + offset)
    return own, typed


def _scalar(parent: ET.Element, v: Variable) -> None:
    """FMI 2.0: a ScalarVariable with its Real (Reals are in value-reference order, so a
    state's index in ModelVariables is its value reference + 1)."""
    own, typed = _attributes(v, 1)
    ET.SubElement(ET.SubElement(parent, "ScalarVariable", own), "Real", typed)


def _description2(iface: NativeInterface, model: str, guid: str, scene: Scene,
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
    _unit_definitions(root, real_vars)
    _header(root, scene)
    mv = ET.SubElement(root, "ModelVariables")
    # the index of each variable in ModelVariables is its position (1-based): Reals in
    # value-reference order, then the Boolean rk4
    for v in real_vars:
        _scalar(mv, v)
    sv = ET.SubElement(mv, "ScalarVariable", {
        "name": "rk4", "valueReference": "0", "causality": "parameter",
        "variability": "fixed", "initial": "exact", "description": _RK4_TEXT})
    ET.SubElement(sv, "Boolean", {"start": "false"})
    if iface.own is not None:  # the single-drum interface's switch (built in one mode)
        name, profile, text = _switch_text(iface, scene)
        sv = ET.SubElement(mv, "ScalarVariable", {
            "name": name, "valueReference": "1", "causality": "parameter",
            "variability": "fixed", "initial": "exact", "description": text})
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


def _description3(iface: NativeInterface, model: str, token: str, scene: Scene,
                  pattern: dict[str, np.ndarray]) -> bytes:
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": scene.name or model, "instantiationToken": token,
        "description": f"winder machine of scene {scene.name!r} (native: no Python)",
        "generationTool": "winder", "variableNamingConvention": "flat"})
    common = {"modelIdentifier": model, "canGetAndSetFMUState": "true",
              "canSerializeFMUState": "true", "providesDirectionalDerivatives": "true"}
    ET.SubElement(root, "ModelExchange", {**common, "needsCompletedIntegratorStep": "false"})
    ET.SubElement(root, "CoSimulation", {
        **common, "canHandleVariableCommunicationStepSize": "true",
        "maxOutputDerivativeOrder": "0", "hasEventMode": "false"})
    real_vars = [*iface.outputs, *iface.inputs, *iface.parameters, *iface.solver,
                 *iface.states, *iface.derivatives]
    _unit_definitions(root, real_vars)
    _header(root, scene)
    mv = ET.SubElement(root, "ModelVariables")
    end = len(real_vars)  # layout.h: VR_TIME, the indicators, the Booleans
    ET.SubElement(mv, "Float64", {"name": "time", "valueReference": str(end),
                                  "causality": "independent", "variability": "continuous",
                                  "unit": "s", "description": "simulation time [s]"})
    for v in real_vars:
        own, typed = _attributes(v, 0)
        ET.SubElement(mv, "Float64", {**own, **typed})
    names = iface.system.machine.switch_names
    zs = indicators(iface.system)
    for k, g in enumerate(zs):
        ET.SubElement(mv, "Float64", {
            "name": f"indicator({names[g]})", "valueReference": str(end + 1 + k),
            "causality": "local", "variability": "continuous",
            "description": f"event indicator: the switching function {names[g]}"})
    b = end + 1 + len(zs)
    ET.SubElement(mv, "Boolean", {"name": "rk4", "valueReference": str(b),
                                  "causality": "parameter", "variability": "fixed",
                                  "initial": "exact", "start": "false",
                                  "description": _RK4_TEXT})
    if iface.own is not None:
        name, profile, text = _switch_text(iface, scene)
        ET.SubElement(mv, "Boolean", {"name": name, "valueReference": str(b + 1),
                                      "causality": "parameter", "variability": "fixed",
                                      "initial": "exact", "start": str(profile).lower(),
                                      "description": text})
    ms = ET.SubElement(root, "ModelStructure")
    for v in iface.outputs:
        ET.SubElement(ms, "Output", {"valueReference": str(v.vr)})
    for v, dep in zip(iface.derivatives, _dependencies(iface, pattern, 0), strict=True):
        ET.SubElement(ms, "ContinuousStateDerivative",
                      {"valueReference": str(v.vr), "dependencies": dep})
    for v in iface.derivatives:
        ET.SubElement(ms, "InitialUnknown", {"valueReference": str(v.vr)})
    for k in range(len(zs)):
        ET.SubElement(ms, "EventIndicator", {"valueReference": str(end + 1 + k)})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)
