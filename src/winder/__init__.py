"""winder: paper winding machines as rigid bodies with mass and inertia that change in time.

Public API (everything else is private and may change):
"""

from typing import TYPE_CHECKING, Any

from ._errors import (
    ArgumentError,
    ArgumentTypeError,
    BudgetExceeded,
    ModelError,
    SceneError,
    SimulationError,
    WinderError,
)

# The rest is imported on first use (PEP 562): a command pays only for what it runs
# (``winder run`` never imports the FMU, the linearisation or scipy's optimisers).
_LAZY = {
    "build_fmu": "._fmu",
    "jacobian": "._linearise",
    "FunctionMassLaw": "._mass_law", "MassLaw": "._mass_law", "MassProperties": "._mass_law",
    "PaperRollLaw": "._mass_law",
    "Mode": "._modes", "ModeMap": "._modes", "mode_map": "._modes", "modes_at": "._modes",
    "Result": "._result", "load_result": "._result", "ResultFileError": "._result",
    "OutputError": "._files",
    "Scene": "._scene", "load_scene": "._scene", "scene_from_dict": "._scene",
    "DEFAULT_METHOD": "._simulate", "simulate": "._simulate",
    "Stepper": "._stepper",
    "CHANNELS": ".solve.system", "EXTRA_CHANNELS": ".solve.system",
    "MachineSystem": ".solve.system", "Machine": ".core.machine",
    "VariableMassModel": "._variable_mass",
    "FORCES": ".forces", "ForceElement": ".forces",
    "sweep": "._sweep", "SweepTable": "._sweep_table",  # Dask, pandas, pyarrow
}

if TYPE_CHECKING:  # for type checkers and IDEs: the same names, eagerly
    from ._files import OutputError
    from ._fmu import build_fmu
    from ._linearise import jacobian
    from ._mass_law import FunctionMassLaw, MassLaw, MassProperties, PaperRollLaw
    from ._modes import Mode, ModeMap, mode_map, modes_at
    from ._result import Result, ResultFileError, load_result
    from ._scene import Scene, load_scene, scene_from_dict
    from ._simulate import DEFAULT_METHOD, simulate
    from ._stepper import Stepper
    from ._sweep import sweep
    from ._sweep_table import SweepTable
    from ._variable_mass import VariableMassModel
    from .core.machine import Machine
    from .forces import FORCES, ForceElement
    from .solve.system import CHANNELS, EXTRA_CHANNELS, MachineSystem


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
    "jacobian",
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

