"""winder: paper winding machines as rigid bodies with mass and inertia that change in time.

Public API (everything else is private and may change):
"""

from typing import TYPE_CHECKING, Any

from winder._errors import (
    ArgumentError,
    ArgumentTypeError,
    BudgetExceeded,
    ModelError,
    SceneError,
    SimulationError,
    WinderError,
)

# The rest is imported on first use (PEP 562): a command pays only for what it runs
# (``winder run`` never imports the FMU, the linearisation or the sweeps; checking a scene
# imports neither NumPy nor the solver).
_LAZY = {
    **dict.fromkeys(("build_fmu",), ".fmu.native"),
    **dict.fromkeys(("jacobian",), ".analysis.linearise"),
    **dict.fromkeys(("casadi_model", "CasadiModel"), ".analysis.control"),
    **dict.fromkeys(("linearise",), ".analysis.plant"),
    **dict.fromkeys(("fit", "FitResult"), ".analysis.fit"),
    **dict.fromkeys(("FitEventError",), ".analysis.fit_model"),
    **dict.fromkeys(("fit_modes",), ".analysis.fit_modes"),
    **dict.fromkeys(("FunctionMassLaw", "MassLaw", "MassProperties", "PaperRollLaw"),
                    ".model.mass_law"),
    **dict.fromkeys(("Mode", "ModeMap", "mode_map", "modes_at"), ".analysis.modes"),
    **dict.fromkeys(("Result", "load_result", "ResultFileError"), ".io.result"),
    **dict.fromkeys(("OutputError",), ".io.files"),
    **dict.fromkeys(("Scene", "load_scene", "scene_from_dict"), ".scene"),
    **dict.fromkeys(("DEFAULT_METHOD", "simulate"), ".solve.simulate"),
    **dict.fromkeys(("Stepper",), ".solve.stepper"),
    **dict.fromkeys(("CHANNELS", "EXTRA_CHANNELS"), ".scene"),
    **dict.fromkeys(("MachineSystem",), ".solve.system"),
    **dict.fromkeys(("Machine",), ".model.machine"),
    **dict.fromkeys(("VariableMassModel",), ".model.variable_body"),
    **dict.fromkeys(("FORCES", "ForceElement"), ".forces"),
    **dict.fromkeys(("sweep",), ".analysis.sweep"),
    **dict.fromkeys(("SweepTable",), ".analysis.sweep_table"),  # Dask, pandas, pyarrow
}

if TYPE_CHECKING:  # for type checkers and IDEs: the same names, eagerly
    from winder.analysis.control import CasadiModel, casadi_model
    from winder.analysis.fit import FitResult, fit
    from winder.analysis.fit_model import FitEventError
    from winder.analysis.fit_modes import fit_modes
    from winder.analysis.linearise import jacobian
    from winder.analysis.modes import Mode, ModeMap, mode_map, modes_at
    from winder.analysis.plant import linearise
    from winder.analysis.sweep import sweep
    from winder.analysis.sweep_table import SweepTable
    from winder.fmu.native import build_fmu
    from winder.forces import FORCES, ForceElement
    from winder.io.files import OutputError
    from winder.io.result import Result, ResultFileError, load_result
    from winder.model.machine import Machine
    from winder.model.mass_law import FunctionMassLaw, MassLaw, MassProperties, PaperRollLaw
    from winder.model.variable_body import VariableMassModel
    from winder.scene import CHANNELS, EXTRA_CHANNELS, Scene, load_scene, scene_from_dict
    from winder.solve.simulate import DEFAULT_METHOD, simulate
    from winder.solve.stepper import Stepper
    from winder.solve.system import MachineSystem


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'winder' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


__all__ = [
    "ArgumentError",
    "ArgumentTypeError",
    "BudgetExceeded",
    "CHANNELS",
    "DEFAULT_METHOD",
    "EXTRA_CHANNELS",
    "FORCES",
    "ForceElement",
    "Machine",
    "MachineSystem",
    "Mode",
    "ModeMap",
    "Result",
    "Scene",
    "Stepper",
    "build_fmu",
    "CasadiModel",
    "casadi_model",
    "fit",
    "FitResult",
    "FitEventError",
    "fit_modes",
    "jacobian",
    "linearise",
    "load_result",
    "load_scene",
    "mode_map",
    "modes_at",
    "scene_from_dict",
    "simulate",
    "sweep",
    "SweepTable",
    "FunctionMassLaw",
    "MassLaw",
    "MassProperties",
    "ModelError",
    "OutputError",
    "ResultFileError",
    "PaperRollLaw",
    "SceneError",
    "SimulationError",
    "VariableMassModel",
    "WinderError",
]
__version__ = "0.1.0"

