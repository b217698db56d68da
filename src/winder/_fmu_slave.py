"""The pythonfmu slave behind ``winder fmu`` (imported inside the FMU; see :mod:`._fmu`)."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from ._drive import SpeedProfile
from ._errors import WinderError
from ._fmu import FMU_PARAMETERS, scene_with_parameters
from ._scene import load_scene
from ._stepper import OUTPUTS, Stepper

__all__ = ["WinderSlave"]

_PINNED: list[dict[str, Any]] = []


class WinderSlave(Fmi2Slave):
    """Co-simulation slave: parameters, input ``drum_torque_command``, all channels as
    outputs."""

    author = "winder"
    description = "Paper winder: driven drum and growing paper roll on a compliant nip"

    def __init__(self, **kwargs: Any) -> None:
        # pythonfmu 0.7's binary releases a *borrowed* reference to the slave module's
        # globals each time it instantiates (PyModule_GetDict then Py_DECREF; PythonFMU
        # issue #228: the second instance fails, then the heap is corrupted). The script
        # holds one extra reference; every instance adds the one the next will take.
        module = sys.modules.get(type(self).__module__)
        if module is not None:
            _PINNED.append(vars(module))
        super().__init__(**kwargs)
        self._scene = load_scene(Path(self.resources) / "scene.toml")
        sc = self._scene
        tables = {"drum.drive": sc.drum.drive, "roll": sc.roll, "contact": sc.contact,
                  "friction": sc.friction, "paper": sc.paper}
        for name, (table, key, text) in FMU_PARAMETERS.items():
            setattr(self, name, float(getattr(tables[table], key)))
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed, description=text))
        self.speed_profile = sc.drum.drive.kind == "speed_profile"
        self.register_variable(Boolean(
            "speed_profile", causality=Fmi2Causality.parameter,
            variability=Fmi2Variability.fixed,
            description="true: drum follows the web-speed profile; false: driven by "
                        "drum_torque_command"))
        self.rtol = 1e-8
        self.register_variable(Real("rtol", causality=Fmi2Causality.parameter,
                                    variability=Fmi2Variability.fixed,
                                    description="tolerance of the internal DOPRI5 [-]"))
        self.drum_torque_command = 0.0
        self.register_variable(Real("drum_torque_command", causality=Fmi2Causality.input,
                                    variability=Fmi2Variability.continuous,
                                    description="drum drive torque [N m] (free drum)"))
        self._stepper: Stepper | None = None
        self._build()
        for name in (*OUTPUTS, "web_speed_reference"):
            self.register_variable(Real(name, causality=Fmi2Causality.output,
                                        variability=Fmi2Variability.continuous,
                                        initial=Fmi2Initial.exact))

    def _build(self) -> None:
        values = {name: getattr(self, name) for name in FMU_PARAMETERS}
        scene = scene_with_parameters(self._scene, values, speed_profile=bool(self.speed_profile))
        self._stepper = Stepper(scene, rtol=float(self.rtol))
        self._profile = SpeedProfile(scene.drum.radius, float(self.web_acceleration),
                                     float(self.profile_web_speed))
        self._publish()

    def _publish(self) -> None:
        st = self._stepper
        assert st is not None
        for name, value in st.outputs().items():
            setattr(self, name, value)
        self.web_speed_reference = float(self._profile.web_speed(st.t))

    def exit_initialization_mode(self) -> None:
        self._build()  # parameters may have been set during initialisation

    def do_step(self, current_time: float, step_size: float) -> bool:
        st = self._stepper
        assert st is not None
        try:
            if abs(current_time - st.t) > 1e-9 * max(1.0, abs(current_time)):
                raise WinderError(f"do_step at t = {current_time} but the FMU is at "
                                  f"t = {st.t} (steps must be contiguous)")
            if st.free_drum:
                tau = float(self.drum_torque_command)
                if not math.isfinite(tau):
                    raise WinderError(f"input drum_torque_command is not finite: {tau!r}")
                st.set_input("drum_torque", tau)
            st.step(step_size)
        except WinderError as exc:
            self.log(str(exc), status=Fmi2Status.error, category="logStatusError")
            return False
        self._publish()
        return True
