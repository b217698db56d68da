"""A flexible body as a whole (issue 32, item 4): the body-level channels of its rigid self,
formed from its segments'.

A flexible body ``NAME`` is the segment bodies ``NAME_s0 … NAME_s{N−1}`` (``segment_of =
NAME``, segment 0 at the drive end); each has every channel of a body (``NAME_s{i}_speed``,
...). The body keeps every body-level channel its rigid self has, with the same name, unit
and meaning: each channel a segment registers whose declaration says how the whole forms it
(:attr:`~winder._schema.Channel.whole`, :data:`~winder._schema.WHOLE_RULES`) is registered
for the body too, and written from its segments' values in every evaluation:

- ``drive``: a driven body's (segment 0 prescribed, or a drive torque on it) drive-end
  value, else the segments' mean: ``NAME_speed``, ``NAME_angle``, ``NAME_accel``;
- ``drive_sum``: a driven body's drive-end value, else the sum: ``NAME_torque`` (the drive
  torque; of an undriven body the torque of the nip friction and web forces about its
  axis, summed over its segments);
- ``mean``: ``NAME_x``, ``NAME_z`` and their rates and accelerations, for the axes its
  rigid self is free along (:attr:`~winder.parts.BodyElement.whole_free`: a drum none, a
  rider ``z``, a roll its ``free``);
- ``sum``: a roll's ``NAME_mass``, ``NAME_inertia`` and their rates, a rider's
  ``NAME_load``; ``shared``: a roll's ``NAME_radius`` (one state).

Nothing here knows a kind of part: a new flexible part type, or a new channel declared with
its ``whole``, is covered as it is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from winder._schema import Channel
from winder.model.channels import COORD_CHANNELS
from winder.model.slices import segments_of

# (the machine and its evaluation are :class:`winder.model.machine.Machine` and
# ``Evaluation``: typed Any here, since machine.py imports this module)

__all__ = ["Whole", "declare_wholes", "write_wholes", "combine"]


@dataclass(frozen=True)
class Whole:
    """A flexible body ``name``: its ``segments`` (drive end first) and its channels, each
    ``(declaration, channel name, the segments' channel names)``."""

    name: str
    segments: tuple[Any, ...]
    channels: tuple[tuple[Channel, str, tuple[str, ...]], ...]


def declare_wholes(machine: Any) -> list[Whole]:
    """Register the body-level channels of every flexible body of ``machine`` (after every
    body and force element has registered its own: :attr:`Machine.channel_owners
    <winder.model.machine.Machine.channel_owners>`); return them."""
    wholes = []
    for body, segs in segments_of(machine.bodies).items():
        first = segs[0]
        free = first.free if first.whole_free is None else first.whole_free
        unheld = {ch for c in COORD_CHANNELS if c not in free for ch in COORD_CHANNELS[c]}
        channels = []
        for decl, owner in list(machine.channel_owners.values()):
            if owner == first.name and decl.whole and decl not in unheld:
                channels.append((decl, machine.channel(decl, body),
                                 tuple(decl.of(s.name) for s in segs)))
        wholes.append(Whole(body, tuple(segs), tuple(channels)))
    return wholes


def combine(rule: str, values: list[Any], driven: bool) -> Any:
    """The whole body's value by ``rule`` (:data:`~winder._schema.WHOLE_RULES`) from its
    segments' ``values`` (drive end first); ``driven``: the body has a drive at segment 0."""
    if rule == "shared" or (driven and rule in ("drive", "drive_sum")):
        return values[0]
    total = sum(values[1:], values[0])
    return total if rule in ("sum", "drive_sum") else total / len(values)


def write_wholes(ev: Any, wholes: list[Whole]) -> None:
    """Write the channels of ``wholes`` from their segments' in ``ev`` (after those)."""
    for w in wholes:
        first = w.segments[0]
        driven = first.prescribed or ev.provided("drive_torque", first.name) is not None
        for decl, name, parts in w.channels:
            ev.channels[name] = combine(decl.whole, [ev.channels[p] for p in parts], driven)
