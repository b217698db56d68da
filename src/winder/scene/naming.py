"""How a scene names what it shows: its result channels, its keys in messages and its FMU
variables (:attr:`winder.scene.Scene.naming`).

A scene of parts names everything by its parts (:class:`Naming`, the default): channels
``BODY_speed``, keys ``[[drum]] 'front' drive``. The single-drum format names them its
own way (:class:`winder.scene.legacy.SingleDrumNaming`: ``drum_speed``, ``radius``,
``[drum.drive]``), translated there, the only module that knows that format. Every layer
above the scene asks the scene's naming instead of asking which format it was read from.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

__all__ = ["Naming", "FmuNames", "BY_PARTS", "naming_of"]


@dataclass(frozen=True, kw_only=True)
class FmuNames:
    """A scene's own FMU interface, where it has one (the single-drum format's), instead
    of the one the FMU builds from the parts.

    parameters:
        FMU parameter name → (scene table, key) (``profile_web_speed`` →
        ``("drum.drive", "web_speed")``).
    profile_switch:
        The boolean parameter that drives the drum along its speed profile (true) or frees
        it on a torque input (false).
    inputs:
        FMU input name → :class:`~winder.Stepper` input name (start value 0).
    profile_reference:
        The output that reports the speed profile ``min(a_w t, v_w)`` [m/s] (from the
        parameters :attr:`acceleration` and :attr:`speed`).
    acceleration, speed:
        The FMU parameters of the profile's acceleration [m/s²] and web speed [m/s].
    switch_doc:
        The description of :attr:`profile_switch` (the inputs it frees the drum on
        follow it).
    """

    parameters: Mapping[str, tuple[str, str]]
    profile_switch: str
    inputs: Mapping[str, str]
    profile_reference: str
    acceleration: str
    speed: str
    switch_doc: str = "true: follows the speed profile; false: driven by"


@dataclass(frozen=True)
class Naming:
    """The names of a scene of parts (machines.md §9): each result channel under its
    machine name, each key under its part (``[[nip]] 'front' friction mu``), the FMU
    interface built from the parts."""

    #: whether the analyses add what a machine from parts shows beyond a fixed interface:
    #: the mode map's columns per bounce coordinate and per drum, the Campbell diagram's
    #: normal-force envelopes
    by_parts: ClassVar[bool] = True
    #: the scene's own FMU interface (None: built from the parts)
    fmu: ClassVar[FmuNames | None] = None
    #: result channels an older result may lack (the viewer then draws that body still)
    optional: ClassVar[frozenset[str]] = frozenset()

    def outputs(self, units: Mapping[str, str]) -> dict[str, tuple[str, str]]:
        """The result's channels after ``t``, in order: output name → (the machine's
        channel, unit), from the machine's channels and units ``units``
        (:attr:`~winder.model.machine.Machine.channel_units`)."""
        return {name: (name, unit) for name, unit in units.items()}

    def output_name(self, channel: str) -> str:
        """The result's name of the machine's channel ``channel``."""
        return channel

    def inputs(self, inputs: Mapping[str, str]) -> dict[str, str]:
        """The :class:`~winder.Stepper`'s inputs as the scene names them: input name →
        run-time parameter, from the machine's ``inputs`` (``DRUM_torque`` →
        ``DRUM.torque`` per torque-driven body, ``ROLL_tension_setpoint``)."""
        return dict(inputs)

    def drive_changes(self, scene: Any, changes: dict[str, Any], speed_profile: bool) -> None:
        """Add to ``changes`` (:meth:`Scene.replace <winder.scene.Scene.replace>`'s, by
        table) the drive's for the FMU's :attr:`FmuNames.profile_switch`
        ``speed_profile``: nothing without an own FMU interface (a scene of parts keeps
        its drives)."""

    def key(self, table: str, part: str, *path: str) -> str:
        """The message path of a part's key: ``key("nip", "front", "friction", "mu")`` is
        ``[[nip]] 'front' friction mu``; ``key("drum", "front", "drive")`` names the
        drive's table."""
        return " ".join((f"[[{table}]] {part!r}", *path))

    #: a naming that reads a result written without its scene (an older result file):
    #: body name → the roles (``x``, ``z``, ``angle``, ``speed``, ``radius``) the viewer
    #: draws it by, as :meth:`output_name` of ``BODY_ROLE``; empty: the result needs its
    #: scene (:func:`naming_of` ``(None)`` is the naming that has them)
    bodies_without_scene: ClassVar[Mapping[str, tuple[str, ...]]] = {}

    def mode_map_columns(self, columns: Mapping[str, Any]) -> dict[str, Any]:
        """The resonance map's table (:meth:`winder.ModeMap.as_columns`) from all its
        ``columns``: every one."""
        return dict(columns)

    def result_meta(self, scene: Any) -> dict[str, Any]:
        """What a result of ``scene`` carries in its ``meta`` for the figures of this
        naming (none for a scene of parts)."""
        return {}


#: The naming of every scene of parts.
BY_PARTS = Naming()


def naming_of(scene: object) -> Naming:
    """``scene``'s :attr:`~winder.scene.Scene.naming`; by its parts for an object that has
    none (the plain scene objects the machine tests build); for ``None`` (a result
    without its scene) the naming that reads one (:attr:`Naming.bodies_without_scene`,
    the single-drum format's), else by parts."""
    if scene is None:
        return next((cls() for cls in Naming.__subclasses__() if cls.bodies_without_scene),
                    BY_PARTS)
    naming = getattr(scene, "naming", None)
    return naming if isinstance(naming, Naming) else BY_PARTS
