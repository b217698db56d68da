"""Exceptions raised by winder. Every message says what was wrong and where."""

from __future__ import annotations


class WinderError(Exception):
    """Base class of all winder errors."""


class SceneError(WinderError, ValueError):
    """A scene file or scene object is invalid (the message names the key and the file)."""


class ModelError(WinderError, ValueError):
    """A model, body or force argument is inconsistent with the Pinocchio model."""


class ArgumentError(WinderError, ValueError):
    """A bad argument to a winder function or command: the message names the argument, the
    value given and what is valid. (A wrong *type* raises :class:`ArgumentTypeError`.)"""


class ArgumentTypeError(WinderError, TypeError):
    """An argument of the wrong type: the message names the argument and the types accepted."""


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


def state_text(state: dict[str, float]) -> str:
    """``z=0.575, roll_angle=0, …``: a state for an error message (6 significant digits)."""
    return ", ".join(f"{name}={value:.6g}" for name, value in state.items())


class BudgetExceeded(SimulationError):
    """A run hit its evaluation or wall-clock budget (``max_rhs``, ``max_wall``).

    The run ended cleanly: the message names the budget, the time reached, the last step
    size and the state; :attr:`partial` holds the result up to :attr:`time` (or ``None``
    where no sample was reached), and :attr:`step` the last step size [s]."""

    def __init__(self, message: str, *, time: float | None = None,
                 state: dict[str, float] | None = None, step: float | None = None,
                 partial: object | None = None) -> None:
        super().__init__(message, time=time, state=state)
        self.step = step
        self.partial = partial
