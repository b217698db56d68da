"""Exceptions raised by winder. Every message says what was wrong and where."""

from __future__ import annotations


class WinderError(Exception):
    """Base class of all winder errors."""


class SceneError(WinderError, ValueError):
    """A scene file or scene object is invalid (the message names the key and the file)."""


class ModelError(WinderError, ValueError):
    """A model, body or force argument is inconsistent with the Pinocchio model."""


class SimulationError(WinderError, RuntimeError):
    """The integration failed, diverged or exceeded its guards.

    Attributes
    ----------
    time:
        Simulation time at which the failure was detected [s].
    state:
        Mapping of state names to their last finite values.
    """

    def __init__(self, message: str, *, time: float | None = None,
                 state: dict[str, float] | None = None) -> None:
        super().__init__(message)
        self.time = time
        self.state = dict(state or {})
