"""Checks of a scene of parts across its keys and tables (machines spec §3, §5, §8): a
roll's core, unique names, references to parts of the right kind, nips that can be
assembled, every wound roll fed by one web, every unwinding roll feeding one span, no
overlapping bodies without a nip. Each error names the file, the table and the key."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from winder._args import show
from winder._errors import SceneError
from winder.parts import PARTS, NipPart, Roles, WebPart
from winder.parts.roll import check_core
from winder.scene.parse import fail

__all__ = ["check_roll_core", "check_references", "check_overlaps", "check_names",
           "check_nip_bodies", "check_nip_assembly", "check_nip_slices", "check_nip_pair",
           "check_riders", "check_body_references", "check_webs", "check_spans",
           "check_wound_fed"]

#: The parts of each body type by its :data:`~winder.parts.PARTS` attribute.
Bodies = Mapping[str, Sequence[Any]]


def check_roll_core(source: str, table: str, roll: dict[str, Any]) -> None:
    """A roll's initial radius (>= core) and centre-of-mass offset
    (:func:`winder.parts.roll.check_core`); ``roll`` holds its parsed keys with
    initial_radius."""
    check_core(lambda t, k, m: fail(source, t, k, m), table, roll)


def _types(bodies: Bodies) -> list[tuple[Any, Sequence[Any]]]:
    """``(element class, parts)`` of each registered body type, in registration order."""
    return [(cls, bodies.get(attr, ())) for attr, cls in PARTS.items()]


def _tables_text() -> str:
    """``a [[drum]], [[roll]] or [[rider]]``: the registered body types' tables."""
    tables = [f"[[{cls.table}]]" for cls in PARTS.values()]
    return "a " + (", ".join(tables[:-1]) + " or " + tables[-1] if len(tables) > 1
                   else tables[0])


@dataclass(frozen=True)
class _Parts:
    """A scene's parts as the rules see them: every part's kind (its table, or ``nip``) by
    name, every body's :class:`~winder.parts.Roles` by name, the nips and the webs
    (``(label, web)``)."""

    kinds: Mapping[str, str]
    roles: Mapping[str, Roles]
    nips: Sequence[NipPart]
    webs: Sequence[tuple[str, WebPart]]

    @property
    def bodies(self) -> list[str]:
        """The bodies' names, in the scene's order."""
        return list(self.roles)

    def having(self, web: str) -> list[str]:
        """The bodies that carry a web as ``web`` (``winds``, ``unwinds``, ``wraps``)."""
        return [n for n, r in self.roles.items() if r.web == web]

    def entries(self) -> list[str]:
        """The nips a web may enter at: ``a`` a body the web wraps, ``b`` one it winds
        onto (machines.md §3)."""
        return [n.name for n in self.nips if self.roles[n.a].web == "wraps"
                and self.roles[n.b].web == "winds"]


def check_references(source: str, bodies: Bodies, nips: list[NipPart],
                      webs: list[tuple[str, WebPart]]) -> None:
    """Unique names, and every ``a``, ``b``, ``rides``, ``entry_nip``, ``from`` naming a
    part of the right kind; nips that can be assembled; every wound roll fed by exactly
    one web (``webs``: ``(label, web)``), one span per unwinding roll (machines spec
    §3, §8). ``bodies``: the parts of each body type (:data:`~winder.parts.PARTS`). The
    rules ask each body's declared roles (:meth:`~winder.parts.BodyElement.roles_of`),
    one function each, in this order."""
    parts = check_names(source, bodies, nips, webs)
    for i, nip in enumerate(nips):
        check_nip_bodies(source, parts, nip)
        check_nip_assembly(source, parts, nip)
        check_nip_slices(source, parts, nip)
        check_nip_pair(source, nips[:i], nip)
    check_riders(source, parts)
    check_body_references(source, bodies, parts)
    check_webs(source, parts)
    check_spans(source, parts)
    check_line(source, parts)
    check_unwind_drives(source, bodies, parts)
    check_wound_fed(source, parts)


def check_names(source: str, bodies: Bodies, nips: Sequence[NipPart],
                webs: Sequence[tuple[str, WebPart]]) -> _Parts:
    """Every part has its own name, and the scene has a body: the parts as the other
    rules see them."""
    kinds: dict[str, str] = {}
    roles: dict[str, Roles] = {}
    for cls, parts in _types(bodies):
        for i, p in enumerate(parts):
            _name(source, kinds, cls.table, i, p.name)
            roles[p.name] = cls.roles_of(p)
    for i, n in enumerate(nips):
        _name(source, kinds, "nip", i, n.name)
    if not roles:
        raise SceneError(f"{source}: a scene of parts needs at least one body: "
                         f"{_tables_text()}")
    return _Parts(kinds, roles, nips, webs)


def _name(source: str, kinds: dict[str, str], kind: str, i: int, name: str) -> None:
    """Register part ``i`` of its kind under ``name``, which no other part has."""
    if name in kinds:
        raise fail(source, f"{kind} #{i + 1}", "name",
                   f"{name!r} is already the name of {kinds[name]} {name!r}; "
                   f"every part needs its own name (taken: {', '.join(kinds)})")
    kinds[name] = kind


def check_nip_bodies(source: str, parts: _Parts, nip: NipPart) -> None:
    """A nip's ``a`` and ``b`` name two different bodies."""
    label, names, kinds = f"nip {nip.name!r}", parts.bodies, parts.kinds
    for key in ("a", "b"):
        ref = getattr(nip, key)
        if ref not in parts.roles:
            what = f"is {kinds[ref]} {ref!r}, not a body" if ref in kinds else \
                "is not a body of the scene"
            raise fail(source, label, key,
                       f"{show(ref)} {what}; a nip joins two bodies; valid names: "
                       f"{', '.join(names)}")
    if nip.a == nip.b:
        raise fail(source, label, "b",
                   f"{nip.b!r} is also a: a nip joins two different bodies; valid names: "
                   f"{', '.join(n for n in names if n != nip.a) or '(none)'}")


def check_nip_assembly(source: str, parts: _Parts, nip: NipPart) -> None:
    """A nip has a body free to move (not both centres fixed) to carry its normal
    force."""
    roles, kinds = parts.roles, parts.kinds
    if roles[nip.a].fixed and roles[nip.b].fixed:
        movable = [n for n, r in roles.items() if not r.fixed]
        raise fail(source, f"nip {nip.name!r}", "b",
                   f"{nip.b!r}: a nip between two bodies with fixed centres "
                   f"({kinds[nip.a]} {nip.a!r} and {kinds[nip.b]} {nip.b!r}) cannot be "
                   "assembled: neither can move to carry its normal force; valid "
                   "names: a roll free to move or a rider: "
                   f"{', '.join(movable) or '(none)'}")


def check_nip_slices(source: str, parts: _Parts, nip: NipPart) -> None:
    """Both flexible bodies of a nip have the same number of segments (one slice each)."""
    na, nb = parts.roles[nip.a].segments, parts.roles[nip.b].segments
    if na and nb and na != nb:
        raise fail(source, f"nip {nip.name!r}", "b",
                   f"{nip.b!r} has {nb} segments (flex) and {nip.a!r} {na}: both "
                   "flexible bodies of a nip need the same number of segments, one "
                   f"slice each; valid: segments = {na} on {nip.b!r}")


def check_nip_pair(source: str, before: Sequence[NipPart], nip: NipPart) -> None:
    """One nip per pair of bodies: none of the nips ``before`` it joins the same two."""
    pair = frozenset((nip.a, nip.b))
    other = next((n for n in before if frozenset((n.a, n.b)) == pair), None)
    if other is not None:
        raise fail(source, f"nip {nip.name!r}", "b",
                   f"{nip.b!r}: nip {other.name!r} already joins {nip.a!r} and "
                   f"{nip.b!r}; one nip per pair of bodies")


def check_riders(source: str, parts: _Parts) -> None:
    """A riding body rides a paper roll, through a nip with ``a`` = the roll and ``b`` =
    itself (machines.md §4)."""
    kinds, nips = parts.kinds, parts.nips
    papers = [n for n, r in parts.roles.items() if r.paper]
    for name, roles in parts.roles.items():
        ref = roles.rides
        if ref is None:
            continue
        label = f"{kinds[name]} {name!r}"
        if ref not in papers:
            what = f"is {kinds[ref]} {ref!r}, not a roll; a rider rides a paper roll" \
                if ref in kinds else "is not a roll of the scene"
            raise fail(source, label, "rides", f"{show(ref)} {what}; valid names: "
                                               f"{', '.join(papers) or '(none)'}")
        if not any(n.a == ref and n.b == name for n in nips):
            raise fail(source, label, "rides",
                       f"{ref!r}: no [[nip]] with a = {ref!r} and b = {name!r} (the rider "
                       "rests on its roll through a nip); declare one; nips: "
                       f"{', '.join(f'{n.name} ({n.a}, {n.b})' for n in nips) or '(none)'}")


def check_body_references(source: str, bodies: Bodies, parts: _Parts) -> None:
    """Any other reference among a body type's keys (``kind = "ref"``) names a body."""
    kinds, names = parts.kinds, parts.bodies
    for cls, group in _types(bodies):
        refs = [k.name for k in cls.KEYS if k.kind == "ref"]
        for p in group:
            for key in refs:
                ref = getattr(p, key, None)
                if ref is not None and ref not in parts.roles:
                    what = f"is {kinds[ref]} {ref!r}, not a body" if ref in kinds else \
                        "is not a body of the scene"
                    raise fail(source, f"{cls.table} {p.name!r}", key,
                               f"{show(ref)} {what}; valid names: {', '.join(names)}")


def check_webs(source: str, parts: _Parts) -> None:
    """Every web enters a body it winds onto from one it wraps (``entry_nip``), no two
    webs the same body, and every web has its own name (machines.md §3)."""
    kinds, nips, webs = parts.kinds, parts.nips, parts.webs
    wound, entries = parts.having("winds"), parts.entries()
    if not webs and wound:
        valid = ", ".join(entries) or "(none: no nip joins a drum, a, to the roll, b)"
        raise SceneError(f"{source}: [web]: missing required table: the scene has the "
                         f"wound roll {wound[0]!r}; add [web] with entry_nip = the nip "
                         f"where the web enters it; valid names: {valid}")
    fed: dict[str, str] = {}  # wound roll -> the label of the web that feeds it
    names: dict[str, str] = {}  # web name -> its label
    for label, web in webs:
        ref = web.entry_nip
        if ref not in entries:
            if kinds.get(ref) == "nip":
                nip = next(n for n in nips if n.name == ref)
                what = (f"is nip {ref!r} joining {kinds[nip.a]} {nip.a!r} (a) and "
                        f"{kinds[nip.b]} {nip.b!r} (b); the web enters a wound roll (b) "
                        "from the drum it wraps (a)")
            else:
                what = f"is {kinds[ref]} {ref!r}, not a nip" if ref in kinds else \
                    "is not a nip of the scene"
            raise fail(source, label, "entry_nip", f"{show(ref)} {what}; valid names: "
                                                    f"{', '.join(entries) or '(none)'}")
        roll = next(n.b for n in nips if n.name == ref)
        if roll in fed:
            free = [e for e in entries if next(n.b for n in nips if n.name == e) not in fed]
            raise fail(source, label, "entry_nip",
                       f"{ref!r} enters wound roll {roll!r}, which [{fed[roll]}] already "
                       "feeds: two webs into one roll; every wound roll is fed by exactly "
                       "one web; valid names: nips into the other wound rolls: "
                       f"{', '.join(free) or '(none)'}")
        fed[roll] = label
        if web.name in names:
            raise fail(source, label, "name",
                       f"{web.name!r} is already the name of [{names[web.name]}]; every "
                       "web needs its own name (default: its entry_nip); valid: a name "
                       f"not taken ({', '.join(names)})")
        if web.name != ref and web.name in kinds:
            raise fail(source, label, "name",
                       f"{web.name!r} is already the name of {kinds[web.name]} "
                       f"{web.name!r}; a web's name is its entry nip's or one no part "
                       f"has (taken: {', '.join(kinds)})")
        names[web.name] = label


def check_spans(source: str, parts: _Parts) -> None:
    """Every body that pays off a web feeds exactly one web's span, and every span starts
    at one (machines.md §5); ``kinds`` maps every part's name to its kind."""
    kinds, webs = parts.kinds, parts.webs
    unwinding = parts.having("unwinds")
    spans = [(_span_label(label, w, 0), w.span) for label, w in webs if w.span is not None]
    source_of: dict[str, str] = {}
    for label, span in spans:
        ref = span.source
        if ref not in unwinding:
            if ref in parts.roles and parts.roles[ref].web == "winds":
                what = f"is {kinds[ref]} {ref!r} of kind 'wound', not an unwinding roll"
            elif ref in kinds:
                what = f"is {kinds[ref]} {ref!r}, not an unwinding roll"
            else:
                what = "is not a roll of the scene"
            raise fail(source, label, "from",
                       f"{show(ref)} {what}; the span starts at the unwinding roll that "
                       "feeds it; valid names: "
                       f"{', '.join(unwinding) or '(none: no roll has kind = unwinding)'}")
        if ref in source_of:
            raise fail(source, label, "from",
                       f"{ref!r} already feeds the span of [{source_of[ref]}]: an "
                       "unwinding roll pays off one web; valid names: unwinding rolls "
                       "feeding no span: "
                       f"{', '.join(u for u in unwinding if u not in source_of) or '(none)'}")
        source_of[ref] = label
    for name in unwinding:
        if name not in source_of:
            first = not spans and len(webs) <= 1
            raise fail(source, f"{kinds[name]} {name!r}", "kind",
                       "'unwinding': an unwinding roll feeds a web span, and "
                       + ("the scene has no [web.span]; add [web.span] with from = "
                          f"{name!r} (and [web] entry_nip, where the web enters the wound "
                          "roll)" if first else
                          f"no [web.span] has from = {name!r}; add one to the web it "
                          "feeds, or make it kind = 'wound' with a web of its own"))


def _span_label(label: str, web: WebPart, i: int) -> str:
    """Span ``i`` of the web ``[label]`` in messages: ``web.span``, or ``web.span #2`` of
    several (``[[web.span]]``)."""
    return f"{label}.span" if len(web.spans) == 1 else f"{label}.span #{i + 1}"


def check_line(source: str, parts: _Parts) -> None:
    """A web line's spans (machines.md §11): every span but the last ends at a roller
    (``to``), the last at the entry nip's drum (no ``to``); no roller in two webs or twice
    in one; a roller has ``wrap`` exactly where a web wraps it."""
    kinds, roles = parts.kinds, parts.roles
    rollers = [n for n, r in roles.items() if r.roller]
    wrapped: dict[str, str] = {}  # roller -> the label of the span that ends at it
    for label, web in parts.webs:
        last = len(web.spans) - 1
        for i, span in enumerate(web.spans):
            slabel, ref = _span_label(label, web, i), span.to
            if i == last:
                if ref is not None:
                    raise fail(source, slabel, "to",
                               f"{show(ref)}: the last span ends at the entry nip's drum "
                               f"(entry_nip {web.entry_nip!r}), not at a roller; valid: "
                               "remove to, or add the span after it")
                continue
            if ref is None:
                raise fail(source, slabel, "to",
                           f"missing required key (span #{i + 1} of {last + 1} is not the "
                           "last: it ends at a roller); valid names: "
                           f"{', '.join(rollers) or '(none: no [[idler]])'}")
            if ref not in rollers:
                what = f"is {kinds[ref]} {ref!r}, not a roller" if ref in kinds else \
                    "is not a roller of the scene"
                raise fail(source, slabel, "to", f"{show(ref)} {what}; a span ends at an "
                                                 "idler roller; valid names: "
                                                 f"{', '.join(rollers) or '(none)'}")
            if ref in wrapped:
                raise fail(source, slabel, "to",
                           f"{ref!r}: [{wrapped[ref]}] already ends at it: a roller carries "
                           "one web, once; valid names: rollers no span ends at: "
                           f"{', '.join(r for r in rollers if r not in wrapped) or '(none)'}")
            wrapped[ref] = slabel
            _check_travel(source, parts, web, i)
    for name in rollers:
        given = roles[name].wrap is not None
        if given and name not in wrapped:
            raise fail(source, f"{kinds[name]} {name!r}", "wrap",
                       f"{roles[name].wrap!r}: no web wraps this roller (no span has to = "
                       f"{name!r}); valid: remove wrap, or end a [[web.span]] at it")
        if not given and name in wrapped:
            raise fail(source, f"{kinds[name]} {name!r}", "wrap",
                       f"missing required key ([{wrapped[name]}] ends at it: the web wraps "
                       "it); valid: 0 < wrap <= 2π [rad]")


def _check_travel(source: str, parts: _Parts, web: WebPart, i: int) -> None:
    """A dancer at the end of span ``i`` of ``web`` starts strictly inside its travel:
    ``d(0)``, its carriage's static balance at the initial tensions (machines.md §11)."""
    name = web.spans[i].to
    dancer = parts.roles[name].dancer if name is not None else None
    if dancer is None:
        return
    t_in = web.spans[0].T_in
    t_up, t_down = (t_in if s.initial_tension is None else s.initial_tension
                    for s in (web.spans[i], web.spans[i + 1]))
    d0 = dancer.position(t_up, t_down)
    lo, hi = dancer.travel
    if not lo < d0 < hi:
        raise fail(source, f"{parts.kinds[name]} {name!r}.dancer", "travel",
                   f"[{lo!r}, {hi!r}] does not hold d(0) = {d0:.6g} m strictly, the "
                   f"carriage's balance (load − T_up − T_down) / stiffness at the initial "
                   f"tensions {t_up:g} N and {t_down:g} N; valid: lo < {d0:.6g} < hi, or "
                   "a load that balances the tensions inside the travel")


def check_unwind_drives(source: str, bodies: Bodies, parts: _Parts) -> None:
    """An unwind's dancer control holds a dancer its web wraps, its tension control a span
    of its web that no paced pull roll separates from it (machines.md §11)."""
    web_of = {w.span.source: (label, w) for label, w in parts.webs if w.span is not None}
    for cls, group in _types(bodies):
        for p in group:
            drive = getattr(p, "drive", None)
            if p.name not in web_of or drive is None:
                continue
            label, web = web_of[p.name]
            dlabel = f"{cls.table} {p.name!r}.drive"
            dancer = getattr(drive, "dancer", None)
            if dancer is not None:
                dancers = [r for r in web.rollers if parts.roles[r].dancer is not None]
                if dancer not in dancers:
                    what = f"is {parts.kinds[dancer]} {dancer!r}, not a dancer on its web" \
                        if dancer in parts.kinds else "is not a part of the scene"
                    raise fail(source, dlabel, "dancer",
                               f"{show(dancer)} {what}; valid names: dancers [{label}] "
                               f"wraps: {', '.join(dancers) or '(none)'}")
            if getattr(drive, "kind", None) == "tension_control":
                _check_controlled_span(source, dlabel, parts, label, web, drive.span)


def _check_controlled_span(source: str, dlabel: str, parts: _Parts, label: str,
                           web: WebPart, span: int) -> None:
    """Span ``span`` of ``web`` lies in its unwind's tension zone: its spans up to the
    first one that ends at a paced roller (a pull roll on a speed profile) or the entry
    drum (machines.md §11); a span after the first only where no dancer lies in the
    zone."""
    zone = next((i for i, s in enumerate(web.spans)
                 if s.to is None or parts.roles[s.to].paced), len(web.spans) - 1)
    dancers = [s.to for s in web.spans[:zone] if parts.roles[s.to].dancer is not None]
    if 0 < span <= zone and dancers:
        raise fail(source, dlabel, "span",
                   f"{span!r}: the dancer {dancers[0]!r} lies in the unwind's tension zone "
                   "(the spans it strains together): its carriage, not the unwind, sets "
                   "the tension behind it and the rule has no design for it; valid: 0 (the "
                   "first span), or kind = 'dancer_control'")
    if span <= zone:
        return
    why = f"[{label}] has {len(web.spans)} span(s)" if span >= len(web.spans) else \
        (f"span {span} lies beyond the pull roll {web.spans[zone].to!r}, whose drive "
         "prescribes its speed: the unwind's torque cannot hold it")
    raise fail(source, dlabel, "span",
               f"{span!r}: {why}; valid: " + (", ".join(map(str, range(zone + 1)))
                                              + " (from the unwinding roll)"))


def check_wound_fed(source: str, parts: _Parts) -> None:
    """Every body the web winds onto is fed by a web (its paper comes from somewhere)."""
    fed = {next(n.b for n in parts.nips if n.name == w.entry_nip) for _, w in parts.webs}
    for roll in parts.having("winds"):
        if roll not in fed:
            valid = [n.name for n in parts.nips
                     if n.b == roll and parts.roles[n.a].web == "wraps"]
            raise fail(source, f"{parts.kinds[roll]} {roll!r}", "kind",
                       "'wound': no web feeds this wound roll, so its paper would come "
                       "from nowhere (every wound roll is fed by exactly one "
                       "web); add a [[web]] with entry_nip = the nip where its web enters "
                       "it; valid names: "
                       f"{', '.join(valid) or '(none: no nip joins a drum, a, to it, b)'}"
                       ", or make it kind = 'unwinding' with its own span")


def check_overlaps(source: str, bodies: Bodies, nips: list[NipPart]) -> None:
    """No two bodies whose circles overlap at the start (each type's ``initial_circle``:
    its ``centre`` and initial radius) without a nip between them (spec §8): nothing would
    carry the force between them. A type may leave its bodies out (a rider: the machine
    places it on top of the roll it rides, and the twin-drum winder of spec §10 starts its
    rider inside the drums' circles, a contact it does not model)."""
    circles: list[tuple[str, str, float, float, float]] = []  # kind, name, x, z, radius
    for cls, parts in _types(bodies):
        for p in parts:
            circle = cls.initial_circle(p)
            if circle is not None:
                (x, z), r = circle
                circles.append((cls.table, p.name, x, z, r))
    joined = {frozenset((n.a, n.b)) for n in nips}
    for i, (ka, a, xa, za, ra) in enumerate(circles):
        for kb, b, xb, zb, rb in circles[i + 1:]:
            gap = math.hypot(xb - xa, zb - za) - (ra + rb)
            if gap < -1e-9 * (ra + rb) and frozenset((a, b)) not in joined:
                raise fail(source, f"{kb} {b!r}", "centre",
                            f"{kb} {b!r} (radius {rb:.6g} m at ({xb:.6g}, {zb:.6g}) m) "
                            f"overlaps {ka} {a!r} (radius {ra:.6g} m at ({xa:.6g}, "
                            f"{za:.6g}) m) by {-gap:.4g} m at the start, and no [[nip]] "
                            "joins them, so nothing carries the force between them; valid: "
                            "centres at least the sum of the radii apart, or a [[nip]] with "
                            f"a = {a!r}, b = {b!r}")
