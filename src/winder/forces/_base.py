"""The force-element interface: what an effect adds to the machine's dynamics.

Every effect of ``[effects]`` is one :class:`ForceElement` in its own module, written over
a math namespace (:mod:`winder.model.mathns`) so that the same code builds the generated C
and runs on the numeric Pinocchio path.
"""

from __future__ import annotations

from abc import ABC
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from winder._schema import Channel, Key
    from winder.model.machine import Evaluation, Machine

__all__ = ["ForceElement"]


class ForceElement(ABC):
    """Base class of the physical effects a scene switches on (``[effects]``).

    To add an effect (nothing else is touched: not the integrators, the code generator,
    the channels or the CLI):

    1. Subclass :class:`ForceElement` in its own module under ``winder/forces/``; set
       ``name`` (the ``[effects]`` key).
    2. Declare the quantities it writes for others (``provides``) and reads from others
       (``requires``: some element must provide it; ``uses``: read where provided, else a
       default), as frozensets of names. The machine runs every provider before its
       readers (:func:`~winder.model.element_order.order_elements`; ties in registration
       order; a missing provider or a cycle is an
       :class:`~winder.model.element_order.ElementOrderError`). The quantities:
       ``"gravity"`` [m/s²] (ABA's gravity), ``"drive_torque"`` [N·m] by body (operation
       sense), ``"spatial_force"`` by body (``[f; τ]`` in its joint frame, through
       ``ev.add_spatial_force``), ``"span_rate"`` [N/s] by web, ``"com_offset"`` [m]
       (``BodyState.com_offset``), ``"steady_friction"`` [N] (``NipState``).
    3. In :meth:`declare`, register with the :class:`~winder.model.machine.Machine` what it
       needs: run-time parameters (``machine.parameter(name, value)``, values from the
       scene's parts), states (``machine.state(name, initial)``), result channels
       declared in ``CHANNELS`` (``machine.channel(declaration, owner)``), locked modes
       (``machine.mode(name, switches, ModeKind..., owner=part)``).
    4. In :meth:`apply`, read the :class:`~winder.model.machine.Evaluation`
       (``ev.mathns`` is the math namespace; ``ev.p(name)`` a parameter, ``ev.x(name)`` a
       state, ``ev.bodies``/``ev.nips`` the kinematics, ``ev.provided(quantity, key)``
       what another element provides), add forces with ``ev.add_force``, write state
       derivatives with ``ev.set_rate``, channels with ``ev.set_channel`` and what it
       provides with ``ev.provide(quantity, key, value)``. Branch on states only through
       ``ev.mathns.if_else``/``fmax`` (the generated code is branch-free).
    5. Register the class in ``winder/forces/__init__.py`` (``FORCES``, one line; one that
       a body's drive calls for, by its ``drives``, in ``DRIVES``) and add the key to
       ``[effects]`` in the scene schema.

    An effect that is off is never instantiated, so it costs nothing.
    """

    name: ClassVar[str]
    settings: ClassVar[tuple[Key, ...]] = ()  # its own keys, [effects.NAME] (scene schema)
    #: the result channels it writes, declared once (it registers each with
    #: ``machine.channel(declaration, owner)``; the reference lists them)
    CHANNELS: ClassVar[tuple[Channel, ...]] = ()

    #: quantities it writes for other elements and the machine
    provides: ClassVar[frozenset[str]] = frozenset()
    #: quantities it reads, which some element must provide
    requires: ClassVar[frozenset[str]] = frozenset()
    #: quantities it reads where some element provides them (else a default)
    uses: ClassVar[frozenset[str]] = frozenset()

    def declare(self, machine: Machine) -> None:  # noqa: B027 - optional hook
        """Register parameters, states and channels (once, when the machine is built)."""

    def apply(self, ev: Evaluation) -> None:  # noqa: B027 - optional hook
        """Per evaluation: add forces, write state derivatives and channels."""

    def static(self, ev: Evaluation) -> Any:  # noqa: B027 - optional hook
        """Like :meth:`apply` for the static balance of the initial state (default: the
        same)."""
        self.apply(ev)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
