"""The spans of a web (machines.md §5, §11): one span from the unwinding roll to the entry
drum, or several over idler rollers (``[[web.span]]``), each a tension state of its own."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["Span", "line_spans", "span_tag"]


@dataclass
class Span:
    """One span of a web (machines.md §5, §11): its part, its place ``index`` from the
    unwinding roll, the prefixes of its states and parameters (``key``: ``span.`` for a
    web's only span, ``span{i}.`` among several, after the web's ``span_key``) and of its
    channels (``channel``: ``span_``, ``span{i}_``), the body at its upstream end (the
    unwinding roll or a roller) and at its downstream end (a roller, or None: the entry
    nip's drum)."""

    part: Any
    index: int
    key: str
    channel: str
    upstream: Any
    downstream: Any = None


def span_tag(index: int, count: int) -> str:
    """How span ``index`` of a web of ``count`` spans is named in its states, parameters,
    channels and FMU parameters: ``span`` for a web's only span, else ``span{index}``."""
    return "span" if count == 1 else f"span{index}"


def line_spans(web: Any, unwind: Any, bodies: Mapping[str, Any], key: str,
               channel: str) -> list[Span]:
    """The :class:`Span` s of the web part ``web`` (its ``spans``, else its one ``span``)
    from the unwinding roll ``unwind``, each ending at the body its ``to`` names in
    ``bodies`` (None: the entry drum); ``key``, ``channel`` the web's span prefixes."""
    parts = tuple(getattr(web, "spans", ()) or (web.span,))
    out: list[Span] = []
    up = unwind
    for i, sp in enumerate(parts):
        tag = span_tag(i, len(parts))
        down = bodies[sp.to] if getattr(sp, "to", None) else None
        out.append(Span(sp, i, f"{key}{tag}.", f"{channel}{tag}_", up, down))
        up = down
    return out
