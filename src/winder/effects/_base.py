"""The effect interface: what states an effect adds and what forces it applies."""

from __future__ import annotations

from abc import ABC
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from .._scene import Scene

if TYPE_CHECKING:
    from .._system import WinderSystem

__all__ = ["Effect", "Context"]


class Context:
    """Everything one evaluation of the winder knows, shared by the effects.

    The system fills the kinematic inputs, zeroes the force accumulators, calls each
    active effect's :meth:`Effect.apply` in order, then assembles the forces.

    Inputs [SI]: ``t``; roll ``z, z_dot, phi, omega``; radius ``r``, ``r_dot``; drum
    ``theta, Omega, Omega_dot`` (``Omega_dot`` is ``nan`` for a free drum); roll ``mass,
    inertia`` (about the axis), ``mass_rate, inertia_rate``; ``drum_radius``; state vector
    ``y`` and its derivative ``dy`` (effects write their own entries).

    Accumulators: ``normal_force`` (on the roll, up) [N], ``friction_force`` (on the roll
    at the nip, +x) [N], ``web_force`` (momentum flux on the roll at the nip, +x) [N];
    diagnostics ``penetration, penetration_rate, slip_velocity, steady_friction``.
    """

    __slots__ = ("t", "z", "z_dot", "phi", "omega", "r", "r_dot", "theta", "Omega",
                 "Omega_dot", "mass", "inertia", "mass_rate", "inertia_rate", "drum_radius",
                 "y", "dy", "normal_force", "friction_force", "web_force", "penetration",
                 "penetration_rate", "slip_velocity", "steady_friction")

    def __init__(self) -> None:
        for name in self.__slots__:
            setattr(self, name, 0.0)
        self.y = self.dy = np.zeros(0)

    def reset_forces(self) -> None:
        self.normal_force = self.friction_force = self.web_force = 0.0
        self.penetration = self.penetration_rate = self.steady_friction = 0.0


class Effect(ABC):
    """Base class of the physical effects a scene switches on (``[effects]``).

    To add an effect (the integrator is never touched):

    1. Subclass :class:`Effect` in its own module under ``winder/effects/``; set ``name``
       (the ``[effects]`` key) and ``order`` (lower runs first; an effect that reads what
       another wrote runs after it).
    2. Take what it needs from the :class:`~winder.Scene` in ``__init__``.
    3. If it adds states, list their names in ``states`` and return their initial values
       from :meth:`initial_state`; the system sets ``self.index``, the position of the
       first one in the state vector.
    4. One-time set-up that changes the model or other parts goes in :meth:`configure`
       (e.g. gravity sets the model's gravity; variable mass binds the roll's rate).
    5. Per evaluation, :meth:`apply` reads the :class:`Context`, adds to its force
       accumulators and writes ``ctx.dy[self.index + k]`` for its states. It must not
       allocate Pinocchio objects (it runs millions of times).
    6. Register the class in ``winder/effects/__init__.py`` (``EFFECTS``) and add the key
       to the scene schema.

    An effect that is off is never instantiated, so it costs nothing.
    """

    name: ClassVar[str]
    order: ClassVar[int] = 50
    states: ClassVar[tuple[str, ...]] = ()
    index: int = -1

    def __init__(self, scene: Scene) -> None:
        self.scene = scene

    def initial_state(self, system: WinderSystem, ctx: Context) -> list[float]:
        """Initial values of :attr:`states` (``ctx`` holds the initial kinematics)."""
        return []

    def configure(self, system: WinderSystem) -> None:  # noqa: B027 - optional hook
        """One-time hook, after all effects are constructed."""

    def apply(self, ctx: Context) -> None:  # noqa: B027 - optional hook
        """Per evaluation: add forces, write state derivatives."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
