"""The pythonfmu slave behind ``winder fmu`` (imported inside the FMU; its interface:
:mod:`winder.fmu.build`)."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

# scipy (its libgfortran) loaded with this module, not lazily inside the first
# instantiate (the static balance of a body free in x and z calls scipy.optimize.root):
# loaded there, the host process aborted at exit in libgfortran's finaliser ("corrupted
# double-linked list") in 2-6 of 12-16 runs of a two-drum FMU; loaded here, 0 of 48.
import scipy.optimize  # noqa: F401
from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from winder._errors import WinderError
from winder.fmu.build import (
    fmu_parameters,
    parameter_units,
    parameter_value,
    scene_with_parameters,
)
from winder.fmu.units import UnitReal, with_unit_definitions
from winder.model.channels import input_of
from winder.model.units import DIMENSIONS
from winder.parts import body_elements
from winder.scene.load import load_scene
from winder.solve.stepper import Stepper

__all__ = ["WinderSlave"]

_PINNED: list[dict[str, Any]] = []


class WinderSlave(Fmi2Slave):
    """Co-simulation slave: parameters, torque inputs, all channels as outputs (the
    interface of :mod:`winder.fmu.build`: single-drum scenes keep their own)."""

    author = "winder"
    description = "Paper winding machine from winder (scene in resources/scene.toml)"

    def __init__(self, **kwargs: Any) -> None:
        # pythonfmu 0.7's binary releases a *borrowed* reference to the slave module's
        # globals each time it instantiates (PyModule_GetDict then Py_DECREF; PythonFMU
        # issue #228: the second instance fails, then the heap is corrupted). The script
        # holds one extra reference; every instance adds the one the next will take.
        module = sys.modules.get(type(self).__module__)
        if module is not None:
            _PINNED.append(vars(module))
        super().__init__(**kwargs)
        self._scene = sc = load_scene(Path(self.resources) / "scene.toml")
        self._own = own = sc.naming.fmu  # the scene's own interface (single-drum), or None
        self._places = fmu_parameters(sc)
        units = parameter_units(sc)
        for name, (place, text) in self._places.items():
            setattr(self, name, parameter_value(sc, place))
            # the scene key's unit (none where it has no fixed dimension: N/m^p)
            unit = units[name] if units[name] in DIMENSIONS else None
            self.register_variable(UnitReal(name, causality=Fmi2Causality.parameter,
                                            variability=Fmi2Variability.fixed,
                                            description=text, unit=unit))
        if own is not None:  # its drum on the speed profile, or freed on the torque input
            setattr(self, own.profile_switch, any(b.prescribed for b in body_elements(sc)))
            self.register_variable(Boolean(
                own.profile_switch, causality=Fmi2Causality.parameter,
                variability=Fmi2Variability.fixed,
                description=f"{own.switch_doc} {', '.join(own.inputs)}"))
        self.rtol = 1e-8
        self.register_variable(Real("rtol", causality=Fmi2Causality.parameter,
                                    variability=Fmi2Variability.fixed,
                                    description="tolerance of the internal DOPRI5 [-]"))
        self._stepper: Stepper | None = None
        self._built: tuple[Any, ...] | None = None
        self._inputs: dict[str, str] = {}  # FMU input name → Stepper input name
        self._build()
        st = self._stepper
        assert st is not None
        self._inputs = (dict(own.inputs) if own is not None
                        else {name: name for name in st.inputs})
        for name, stepper_name in self._inputs.items():
            # start value: the scene's drive torque (own interface: 0, the freed drum's)
            start = 0.0 if own is not None else float(
                st.system.params[st.system.machine.param_index(st.inputs[stepper_name])])
            setattr(self, name, start)
            decl = input_of(st.inputs[stepper_name])  # its declaration, with its unit
            self.register_variable(UnitReal(name, causality=Fmi2Causality.input,
                                            variability=Fmi2Variability.continuous,
                                            description=f"{decl.doc} [{decl.unit}]",
                                            unit=decl.unit))
        # the profile min(a_w t, v_w), in the unit of its web speed parameter
        reference = {} if own is None else {own.profile_reference: units[own.speed]}
        self._outputs = (*(k for k in st.output_names if k not in self._inputs), *reference)
        units = {**st.system.channel_units, **reference}
        for name in self._outputs:
            self.register_variable(UnitReal(name, causality=Fmi2Causality.output,
                                            variability=Fmi2Variability.continuous,
                                            initial=Fmi2Initial.exact, unit=units[name]))
        # a run that can end inside a step (an unwinding roll) tells the time it reached
        self._clock = st.system.machine.unwind is not None
        if self._clock:
            self.t = 0.0
            self.register_variable(UnitReal(
                "t", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                initial=Fmi2Initial.exact, unit="s",
                description="time of the outputs [s]: the end of the last step, or where "
                            "the run ended inside it"))

    def to_xml(self, model_options: dict[str, str] | None = None) -> Any:
        """pythonfmu's model description with the units of the outputs (``unit``
        attributes and ``<UnitDefinitions>``)."""
        root = super().to_xml(model_options or {})
        return with_unit_definitions(root, self.vars.values())

    def _build(self) -> None:
        """A Stepper of the scene with the parameters' values (again only when they
        changed since the last build)."""
        values = {name: float(getattr(self, name)) for name in self._places}
        own = self._own
        profile = None if own is None else bool(getattr(self, own.profile_switch))
        key = (tuple(values.values()), profile, float(self.rtol))
        if key != self._built:
            scene = scene_with_parameters(self._scene, values, speed_profile=profile)
            self._stepper = Stepper(scene, rtol=float(self.rtol))
            self._built = key
        else:
            assert self._stepper is not None
            self._stepper.reset()
        self._publish()

    def _publish(self) -> None:
        st = self._stepper
        assert st is not None
        for name, value in st.outputs().items():
            if name not in self._inputs:  # a parts scene's DRUM_torque is the input
                setattr(self, name, value)
        if getattr(self, "_clock", False):
            self.t = st.t
        own = self._own
        if own is not None:  # the profile min(a_w t, v_w) [m/s] (a_w = 0: v_w from t = 0)
            a, v = float(getattr(self, own.acceleration)), float(getattr(self, own.speed))
            setattr(self, own.profile_reference, min(a * st.t, v) if a > 0 else v)

    def exit_initialization_mode(self) -> None:
        self._build()  # parameters may have been set during initialisation

    def do_step(self, current_time: float, step_size: float) -> bool:
        st = self._stepper
        assert st is not None
        try:
            if st.ended is not None:  # before the time check: the step before stopped early
                raise WinderError(f"the run has ended: {st.ended}")
            if abs(current_time - st.t) > 1e-9 * max(1.0, abs(current_time)):
                raise WinderError(f"do_step at t = {current_time} but the FMU is at "
                                  f"t = {st.t} (steps must be contiguous)")
            for name, stepper_name in self._inputs.items():
                if st.inputs[stepper_name] not in st.system.machine.param_names:
                    continue  # an input without its parameter: a single-drum scene on its
                    # speed profile (a line's tension set-point is an input with no
                    # torque-driven body, and a parameter)
                tau = float(getattr(self, name))
                if not math.isfinite(tau):
                    raise WinderError(f"input {name} is not finite: {tau!r}")
                st.set_input(stepper_name, tau)
            st.step(step_size)
        except WinderError as exc:
            self.log(str(exc), status=Fmi2Status.error, category="logStatusError")
            return False
        self._publish()
        if st.ended is not None:  # stopped inside the step: outputs at that time
            self.log(f"{st.ended}; the step from t = {current_time:.9g} s by "
                     f"{step_size:.6g} s stopped at t = {st.t:.9g} s (the outputs are "
                     "those of that time); no further steps", status=Fmi2Status.discard,
                     category="logStatusDiscard")
            return False
        return True
