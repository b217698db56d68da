"""Nips against flexible bodies, sliced (issue #25): one slice per segment station.

A scene's nip between a flexible body of ``N`` segments (``NAME_s0 … NAME_s{N−1}``, each a
body element with ``segment_of = NAME``) and a rigid body becomes ``N`` nips of the machine,
``NIP_s{i}`` between segment ``i`` and the rigid body, each with the nip's law (its
stiffness and damping scaled by the slice's share ``1/N`` of the length: the contact
element reads :attr:`~winder.model.machine.Nip.count`) and its own friction state. Between
two flexible bodies of the same ``N``, slice ``i`` joins their segments ``i``. A web that
enters at a sliced nip enters at its middle slice (``i = N // 2``), which gives the entry
drum's surface speed and carries the web's forces on a rigid roll; into a flexible roll its
forces are spread over every slice (each segment its own ``ṁ_i u`` and ``T/N``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

from winder.model.roles import Segment

__all__ = ["segments_of", "assemble_nips", "entry_slice", "entry_slices"]


def segments_of(bodies: Sequence[Any]) -> dict[str, list[Segment]]:
    """The segment elements of each flexible body (their
    :attr:`~winder.parts.BodyElement.segment`), by the body's name, drive end first."""
    groups: dict[str, list[Segment]] = {}
    for b in bodies:
        seg = b.segment
        if seg is not None:
            groups.setdefault(seg.segment_of, []).append(seg)
    for segs in groups.values():
        segs.sort(key=lambda s: s.index)
    return groups


def assemble_nips(parts: Sequence[Any], body: Mapping[str, Any], bodies: Sequence[Any],
                  make: Callable[..., Any]) -> list[Any]:
    """The machine's nips of the scene's nip ``parts``: ``make(name, a, b, part, index,
    **slice)`` for each, sliced where a side is a flexible body (``whole``: the scene nip's
    name, ``count``: N, ``slice_length``: L/N [m])."""
    groups = segments_of(bodies)
    out: list[Any] = []
    for part in parts:
        sa, sb = groups.get(part.a), groups.get(part.b)
        if sa is None and sb is None:
            out.append(make(part.name, body[part.a], body[part.b], part, len(out)))
            continue
        if sa is not None and sb is not None and len(sa) != len(sb):
            raise ValueError(f"nip {part.name!r}: both flexible bodies of a nip need the same "
                             f"number of segments, got {len(sa)} and {len(sb)}")
        segs = sa if sa is not None else sb
        n = len(segs)
        h = segs[0].length / n
        for i in range(n):
            a = sa[i] if sa is not None else body[part.a]
            b = sb[i] if sb is not None else body[part.b]
            out.append(make(f"{part.name}_s{i}", a, b, part, len(out), whole=part.name,
                            count=n, slice_length=h))
    return out


def entry_slice(nips: Sequence[Any], name: str) -> Any:
    """The machine's nip a web enters at, for the scene's nip ``name``: the nip itself, or
    the middle slice of a sliced one."""
    slices = [n for n in nips if n.name == name or n.whole == name]
    return slices[0] if len(slices) == 1 else slices[len(slices) // 2]


def entry_slices(nips: Sequence[Any], name: str) -> list[Any]:
    """The machine's nips a web's forces act at, for the scene's nip ``name``: every slice
    where its roll (``b``) is flexible, else the one :func:`entry_slice`."""
    slices = [n for n in nips if n.whole == name]
    if slices and slices[0].b.segment_of is not None:
        return slices
    return [entry_slice(nips, name)]
