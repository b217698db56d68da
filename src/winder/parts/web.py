"""The webs (machines spec §3, §5, §8, §11 ``[web]``/``[[web]]``, ``[web.span]``,
``[[web.span]]``): where the paper enters each wound roll, and under which tension: a
constant one, or the states of elastic spans from an unwinding roll, over idler rollers,
to the entry drum. Every wound roll is fed by exactly one web."""

from __future__ import annotations

from dataclasses import dataclass

from winder._schema import Key, Table

__all__ = ["WebPart", "SpanPart", "KEYS", "SPAN_KEYS"]

#: The keys of ``[web]`` (or of each ``[[web]]``).
KEYS = Table((
    Key(name="name", kind="name", default_text="its entry_nip",
        doc="the web's name, in its channels and messages where a scene has several webs "
            "([[web]], one per wound roll)"),
    Key(name="entry_nip", kind="ref", required=True,
        doc="the nip where the web enters the wound roll (a: the drum it wraps, b: the "
            "roll)"),
    Key(name="tension", unit="N", lo=0.0, hi=1e7, fmu="web_tension",
        doc="constant web tension (not with [web.span])"),
    Key(name="span", kind="table", default_text="none",
        doc="an elastic span from an unwinding roll, a sub-table: keys below; several "
            "spans over idler rollers: [[web.span]], one table per span in order"),
    Key(name="mu", unit="-", lo=0.0, lo_open=True, hi=10.0, default=0.3, fmu="web_mu",
        doc="friction coefficient of the web on the idler rollers (their traction)"),
))

#: The keys of ``[web.span]`` (``from`` is the field ``source``).
SPAN_KEYS = Table((
    Key(name="from", kind="ref", default_text="required on the first span",
        doc="the unwinding roll that feeds the span (the first span only)"),
    Key(name="to", kind="ref", default_text="none: the entry nip's drum",
        doc="the idler roller where the span ends (every span of [[web.span]] but the "
            "last)"),
    Key(name="length", required=True, unit="m", lo=0.0, lo_open=True, hi=1e3,
        fmu="span_length",
        doc="span length L_s"),
    Key(name="EA", required=True, unit="N", lo=0.0, lo_open=True, hi=1e12, fmu="span_EA",
        doc="axial stiffness EA of the web"),
    Key(name="T_in", unit="N", lo=0.0, hi=1e7, fmu="span_T_in",
        doc="tension wound into the unwinding roll (the first span only)"),
    Key(name="initial_tension", unit="N", lo=0.0, hi=1e7, default_text="T_in",
        doc="span tension at t = 0"),
))


@dataclass(frozen=True)
class SpanPart:
    """``[web.span]``: the elastic span from an unwinding roll to the winder's entry drum
    (spec §5), or one span of ``[[web.span]]`` (spec §11). source (TOML key ``from``): the
    unwinding roll's name (None on a span after the first); length ``L_s`` [m]; EA [N]
    (axial stiffness); T_in [N] (wound-in tension of the unwinding roll, first span);
    initial_tension [N] (None: ``T_in``, the equilibrium at equal speeds); to: the idler
    roller where it ends (None: the entry nip's drum); bounds: :data:`SPAN_KEYS`."""

    source: str | None
    length: float
    EA: float
    T_in: float = 0.0
    initial_tension: float | None = None
    to: str | None = None


@dataclass(frozen=True)
class WebPart:
    """``[web]`` (or one ``[[web]]`` element): entry_nip (the name of the nip where the web
    enters its wound roll: ``a`` a drum, ``b`` a wound roll), tension [N] (constant; 0
    and unused with a span), span (:class:`SpanPart` or None: its first span), name
    (None: the entry nip's name; it prefixes the web's channels in a scene of several
    webs), spans (every span in order from the unwinding roll, spec §11; given only
    ``span``: that one), mu (its friction on idler rollers); bounds: :data:`KEYS`."""

    entry_nip: str
    tension: float = 0.0
    span: SpanPart | None = None
    name: str | None = None
    spans: tuple[SpanPart, ...] = ()
    mu: float = 0.3

    def __post_init__(self) -> None:
        if self.name is None:
            object.__setattr__(self, "name", self.entry_nip)
        if not self.spans and self.span is not None:
            object.__setattr__(self, "spans", (self.span,))
        object.__setattr__(self, "spans", tuple(self.spans))
        if self.spans and self.span is None:
            object.__setattr__(self, "span", self.spans[0])
        if self.spans and self.span is not self.spans[0]:
            raise ValueError(f"web {self.name!r}: span is not spans[0]; valid: the first "
                             "span, or give only one of them")

    @property
    def rollers(self) -> tuple[str, ...]:
        """The idler rollers the web wraps, in order (every span's ``to``)."""
        return tuple(s.to for s in self.spans if s.to is not None)
