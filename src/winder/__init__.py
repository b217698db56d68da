"""winder: paper winding machines as rigid bodies with mass and inertia that change in time.

Public API (everything else is private and may change):
"""

from ._errors import ModelError, SceneError, SimulationError, WinderError
from ._mass_law import FunctionMassLaw, MassLaw, MassProperties, PaperRollLaw
from ._variable_mass import VariableMassModel

__all__ = [
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
