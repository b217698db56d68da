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

    To add an effect, write its module and register it: nothing else is touched (not the
    scene schema, the scene's tables, the reference generator, the integrators, the code
    generator, the channels or the CLI). Its ``[effects]`` key, meaning, default and
    settings are read from the class (:class:`winder.scene.schema.EffectsTable`):

    1. Subclass :class:`ForceElement` in its own module under ``winder/forces/``; set
       ``name`` (the ``[effects]`` key), ``doc`` (its meaning, one line, for the scene
       reference and messages; default: the first line of the class docstring) and, for
       an effect off unless a scene switches it on, ``default = False``.
    2. Declare its own keys, if any, in ``settings`` (:class:`~winder._schema.Key`s, with
       units and bounds; a scene sets them in ``[effects.NAME]``, read with
       ``machine.scene.effects.setting(name, key)``: the declared default where not
       given).
    3. Declare the quantities it writes for others (``provides``) and reads from others
       (``requires``: some element must provide it; ``uses``: read where provided, else a
       default), as frozensets of names. The machine runs every provider before its
       readers (:func:`~winder.model.element_order.order_elements`; ties in the order of
       :func:`~winder.forces.force_elements`; a missing provider or a cycle is an
       :class:`~winder.model.element_order.ElementOrderError`). The quantities:
       ``"gravity"`` [m/s²] (ABA's gravity), ``"drive_torque"`` [N·m] by body (operation
       sense), ``"spatial_force"`` by body (``[f; τ]`` in its joint frame, through
       ``ev.add_spatial_force``), ``"span_rate"`` [N/s] by web, ``"com_offset"`` [m]
       (``BodyState.com_offset``), ``"steady_friction"`` [N] (``NipState``).
    4. In :meth:`declare`, register with the :class:`~winder.model.machine.Machine` what it
       needs: run-time parameters (``machine.parameter(name, value)``, values from the
       scene's parts and its settings), states (``machine.state(name, initial)``), result
       channels declared in ``CHANNELS`` (``machine.channel(declaration, owner)``), locked modes
       (``machine.mode(name, switches, ModeKind..., owner=part)``).
    5. In :meth:`apply`, read the :class:`~winder.model.machine.Evaluation`
       (``ev.mathns`` is the math namespace; ``ev.p(name)`` a parameter, ``ev.x(name)`` a
       state, ``ev.bodies``/``ev.nips`` the kinematics, ``ev.provided(quantity, key)``
       what another element provides), add forces with ``ev.add_force``, write state
       derivatives with ``ev.set_rate``, channels with ``ev.set_channel`` and what it
       provides with ``ev.provide(quantity, key, value)``. Branch on states only through
       ``ev.mathns.if_else``/``fmax`` (the generated code is branch-free).
    6. Register the class: one line in ``FORCES`` of ``winder/forces/__init__.py`` (its
       place there is its place in ``[effects]``, the reference and messages; where its
       declarations leave it open, it runs after the built-in effects, ``RUN_ORDER``).
       One that a body's drive calls for (by its ``drives``) goes in ``DRIVES`` instead
       and is no ``[effects]`` key.

    An effect that is off is never instantiated, so it costs nothing.

    Example: a viscous drag ``τ = −c ω`` [N·m] in the bearings of every body, with the
    coefficient ``c`` [N·m·s/rad] its own setting (``tests/test_effect_registry.py``
    defines it and checks ``ω(t) = ω0 exp(−c t / J)`` of a drum spinning down)::

        class BearingDrag(ForceElement):
            '''Viscous drag in every body's bearings.'''

            name = "bearing_drag"
            doc = "a viscous torque −c ω in every body's bearings"
            default = False  # off unless a scene switches it on
            settings = (Key(name="c", unit="N·m·s/rad", lo=0.0, hi=1e6, default=0.0,
                            doc="drag coefficient c"),)
            provides = frozenset({"spatial_force"})

            def declare(self, machine):
                machine.parameter("bearing_drag.c",
                                  machine.scene.effects.setting(self.name, "c"))

            def apply(self, ev):
                c = ev.p("bearing_drag.c")
                for name, bs in ev.bodies.items():  # [f; τ] in the joint frame, τ_y
                    ev.add_spatial_force(name, [0.0, 0.0, 0.0, 0.0, -c * bs.omega, 0.0])

        FORCES["bearing_drag"] = BearingDrag   # in FORCES of winder/forces/__init__.py

    and a scene switches it on with ``[effects.bearing_drag]`` ``c = 0.5`` (or
    ``bearing_drag = true`` for its defaults).
    """

    name: ClassVar[str]
    #: its meaning, one line (the scene reference; default: the docstring's first line)
    doc: ClassVar[str] = ""
    #: on (True) or off where a scene does not say
    default: ClassVar[bool] = True
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

    def structure_tag(self, machine: Machine) -> str:
        """Everything about it in ``machine`` that changes the generated code beyond its
        name and the names it registers (default: nothing)."""
        return ""

    @classmethod
    def summary(cls) -> str:
        """Its meaning in one line: :attr:`doc`, else the first line of its docstring."""
        if cls.doc:
            return cls.doc
        lines = (cls.__doc__ or "").strip().splitlines()
        return lines[0].strip() if lines else cls.name

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
