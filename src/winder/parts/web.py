"""The webs (machines spec §3, §5, §8 ``[web]``/``[[web]]``, ``[web.span]``): where the
paper enters each wound roll, and under which tension: a constant one, or the state of an
elastic span from an unwinding roll. Every wound roll is fed by exactly one web."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["WebPart", "SpanPart"]


@dataclass(frozen=True)
class SpanPart:
    """``[web.span]``: the elastic span from an unwinding roll to the winder's entry drum
    (spec §5). source (TOML key ``from``): the unwinding roll's name; length ``L_s``
    (0, 1e3] [m]; EA (0, 1e12] [N] (axial stiffness); T_in [0, 1e7] [N] (wound-in tension
    of the unwinding roll); initial_tension [0, 1e7] [N] (None: ``T_in``, the
    equilibrium at equal speeds)."""

    source: str
    length: float
    EA: float
    T_in: float = 0.0
    initial_tension: float | None = None


@dataclass(frozen=True)
class WebPart:
    """``[web]`` (or one ``[[web]]`` element): entry_nip (the name of the nip where the web
    enters its wound roll: ``a`` a drum, ``b`` a wound roll), tension [0, 1e7] [N]
    (constant; 0 and unused with a span), span (:class:`SpanPart` or None), name (None:
    the entry nip's name; it prefixes the web's channels in a scene of several webs)."""

    entry_nip: str
    tension: float = 0.0
    span: SpanPart | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        if self.name is None:
            object.__setattr__(self, "name", self.entry_nip)
