"""FMI 2.0 co-simulation export (pythonfmu): the winder as an FMU for controller work.

The FMU runs *inside the host's Python*: pythonfmu's binary loads the Python interpreter
of the importing process and imports :mod:`winder` (with Pinocchio and numba) from it.
A host that loads the FMU must therefore be a Python process (FMPy, or any tool that
embeds that Python) whose environment has winder installed; the scene travels inside the
FMU (``resources/scene.toml``).

Interface
---------
- parameters (:data:`FMU_PARAMETERS`): web speed and acceleration, imbalance, nip
  stiffness and damping, friction, caliper, density, width, and ``speed_profile``: true
  drives the drum along the built-in web-speed profile (``drum_torque`` is then an
  output), false frees the drum, started at the profile's initial speed, and drives it
  by the input ``drum_torque_command``.
- input ``drum_torque_command`` [N·m] (named apart from the output channel
  ``drum_torque``, which reports the torque acting in either mode).
- outputs: every result channel (:data:`winder._stepper.OUTPUTS`) and
  ``web_speed_reference`` = ``min(a_w t, v_w)`` [m/s], the profile a speed controller
  follows.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Any

from ._errors import WinderError
from ._scene import Scene, load_scene

__all__ = ["build_fmu", "FMU_PARAMETERS", "scene_with_parameters", "FmuError"]

#: FMU parameter name → (scene table, key, description with unit).
FMU_PARAMETERS: dict[str, tuple[str, str, str]] = {
    "profile_web_speed": ("drum.drive", "web_speed", "final web speed of the profile [m/s]"),
    "web_acceleration": ("drum.drive", "web_acceleration", "web acceleration [m/s2]"),
    "com_offset": ("roll", "com_offset", "centre of mass offset e [m]"),
    "contact_stiffness": ("contact", "stiffness", "nip stiffness k [N/m]"),
    "contact_damping": ("contact", "damping", "nip damping c [N s/m]"),
    "mu": ("friction", "mu", "friction coefficient [-]"),
    "slip_reference_velocity": ("friction", "slip_velocity",
                                "slip regularisation v_ref [m/s]"),
    "relaxation_length": ("friction", "relaxation_length", "relaxation length [m]"),
    "caliper": ("paper", "caliper", "paper thickness h [m]"),
    "density": ("paper", "density", "paper density [kg/m3]"),
    "width": ("roll", "width", "roll width L [m]"),
}

# pythonfmu's binary finds the class by the pattern ``class X(Fmi2Slave):`` in this file,
# hence the alias.
_SLAVE_SCRIPT = '''"""winder FMU: the scene in resources/scene.toml (needs a Python with winder)."""
from winder._fmu_slave import WinderSlave as Fmi2Slave

_pinned_globals = [globals()]  # see winder._fmu_slave.WinderSlave.__init__


class Winder(Fmi2Slave):
    """The winder co-simulation slave."""
'''


class FmuError(WinderError):
    """The FMU could not be built or does not run in this Python."""


def scene_with_parameters(scene: Scene, values: dict[str, float], *,
                          speed_profile: bool) -> Scene:
    """The scene with FMU parameter values applied (validated like a file)."""
    changes: dict[str, dict[str, Any]] = {}
    drive: dict[str, Any] = {}
    for name, value in values.items():
        if name not in FMU_PARAMETERS:
            raise FmuError(f"unknown FMU parameter {name!r}; valid: {', '.join(FMU_PARAMETERS)}")
        table, key, _ = FMU_PARAMETERS[name]
        if table == "drum.drive":
            drive[key] = float(value)
        else:
            changes.setdefault(table, {})[key] = float(value)
    d = scene.drum.drive
    a = drive.get("web_acceleration", d.web_acceleration)
    v = drive.get("web_speed", d.web_speed)
    if speed_profile:
        drive.update(kind="speed_profile", web_acceleration=a, web_speed=v)
    else:  # free drum, started at the profile's initial speed
        drive.update(kind="torque", web_acceleration=a, web_speed=0.0 if a > 0 else v,
                     torque=0.0)
    changes["drum"] = {"drive": drive}
    return scene.replace(**changes)


def build_fmu(scene_path: str | Path, out: str | Path) -> Path:
    """Build ``out`` (an ``.fmu``) from a scene file, atomically: the complete FMU or
    nothing at ``out``, and no build folder left in the temporary directory, on an error
    or a signal. Raises :class:`FmuError` when pythonfmu is missing or the build fails."""
    # imported here, not at the top: FMU hosts import this module (the slave, FMPy hosts),
    # and with more modules loaded there pythonfmu 0.7's heap corruption (see
    # winder._fmu_slave) showed again: 1-3 of the 7 FMU host tests aborted per run
    from ._files import atomic_write, scratch_dir

    try:
        from pythonfmu import FmuBuilder
    except ImportError as exc:
        raise FmuError("building an FMU needs pythonfmu: pip install 'winder[fmu]'") from exc
    scene_path = Path(scene_path)
    load_scene(scene_path)  # validate before packing
    out = Path(out)
    if out.suffix != ".fmu":
        raise FmuError(f"output file must end in .fmu, got {str(out)!r}")
    with scratch_dir("winder_fmu_") as d:
        script = d / "winder_fmu.py"
        script.write_text(_SLAVE_SCRIPT, encoding="utf-8")
        scene_copy = d / "scene.toml"
        shutil.copyfile(scene_path, scene_copy)
        staged = d / "build" / "winder.fmu"
        # pythonfmu's own scratch folder goes inside ours (removed with it, even on a signal)
        saved, tempfile.tempdir = tempfile.tempdir, str(d)
        try:
            FmuBuilder.build_FMU(script, dest=staged, project_files=[scene_copy],
                                 needsExecutionTool="true")
        except Exception as exc:  # pythonfmu raises bare exceptions
            raise FmuError(f"pythonfmu could not build the FMU from {scene_path}: {exc}") \
                from exc
        finally:
            tempfile.tempdir = saved
        atomic_write(out, lambda tmp_out: shutil.copyfile(staged, tmp_out))
    return out
