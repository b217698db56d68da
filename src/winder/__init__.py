"""winder: paper winding machines as rigid bodies with mass and inertia that change in time.

Public API (everything else is private and may change):
"""

from ._errors import (
    ArgumentError,
    ArgumentTypeError,
    BudgetExceeded,
    ModelError,
    SceneError,
    SimulationError,
    WinderError,
)
from ._fmu import build_fmu
from ._linearise import jacobian
from ._mass_law import FunctionMassLaw, MassLaw, MassProperties, PaperRollLaw
from ._modes import Mode, ModeMap, mode_map, modes_at
from ._result import Result, load_result
from ._scene import Scene, load_scene, scene_from_dict
from ._simulate import DEFAULT_METHOD, simulate
from ._stepper import Stepper
from ._system import CHANNELS, EXTRA_CHANNELS, WinderSystem
from ._variable_mass import VariableMassModel
from .effects import EFFECTS, Effect

__all__ = [
    "ArgumentError",
    "ArgumentTypeError",
    "BudgetExceeded",
    "CHANNELS",
    "DEFAULT_METHOD",
    "EFFECTS",
    "EXTRA_CHANNELS",
    "Effect",
    "Mode",
    "ModeMap",
    "Result",
    "Scene",
    "Stepper",
    "WinderSystem",
    "build_fmu",
    "jacobian",
    "load_result",
    "load_scene",
    "mode_map",
    "modes_at",
    "scene_from_dict",
    "simulate",
    "FunctionMassLaw",
    "MassLaw",
    "MassProperties",
    "ModelError",
    "PaperRollLaw",
    "SceneError",
    "SimulationError",
    "VariableMassModel",
    "WinderError",
]
__version__ = "0.1.0"
