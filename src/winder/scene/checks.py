"""Checks of a scene of parts across its keys and tables (machines spec §3, §5, §8): a
roll's core, unique names, references to parts of the right kind, nips that can be
assembled, every wound roll fed by one web, every unwinding roll feeding one span, no
overlapping bodies without a nip. Each error names the file, the table and the key."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from winder._args import show
from winder._errors import SceneError
from winder.parts import PARTS, NipPart, RollPart, WebPart
from winder.parts.roll import check_core
from winder.scene.parse import fail

__all__ = ["check_roll_core", "check_references", "check_overlaps"]

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


def _segments(types: list[tuple[Any, Sequence[Any]]], name: str) -> int | None:
    """The number of segments of the flexible body ``name`` (None: rigid)."""
    for _, parts in types:
        for p in parts:
            if p.name == name:
                flex = getattr(p, "flex", None)
                return None if flex is None else flex.segments
    return None


def _tables_text() -> str:
    """``a [[drum]], [[roll]] or [[rider]]``: the registered body types' tables."""
    tables = [f"[[{cls.table}]]" for cls in PARTS.values()]
    return "a " + (", ".join(tables[:-1]) + " or " + tables[-1] if len(tables) > 1
                   else tables[0])


def check_references(source: str, bodies: Bodies, nips: list[NipPart],
                      webs: list[tuple[str, WebPart]]) -> None:
    """Unique names, and every ``a``, ``b``, ``rides``, ``entry_nip``, ``from`` naming a
    part of the right kind; nips that can be assembled; every wound roll fed by exactly
    one web (``webs``: ``(label, web)``), one span per unwinding roll (machines spec
    §3, §8). ``bodies``: the parts of each body type (:data:`~winder.parts.PARTS`)."""
    types = _types(bodies)
    rolls: Sequence[RollPart] = bodies.get("rolls", ())
    riders: Sequence[Any] = bodies.get("riders", ())
    kinds: dict[str, str] = {}
    for kind, parts in (*((cls.table, parts) for cls, parts in types), ("nip", nips)):
        for i, p in enumerate(parts):
            if p.name in kinds:
                raise fail(source, f"{kind} #{i + 1}", "name",
                            f"{p.name!r} is already the name of {kinds[p.name]} {p.name!r}; "
                            f"every part needs its own name (taken: {', '.join(kinds)})")
            kinds[p.name] = kind
    body_names = [n for n, k in kinds.items() if k != "nip"]
    if not body_names:
        raise SceneError(f"{source}: a scene of parts needs at least one body: "
                         f"{_tables_text()}")
    fixed = {p.name for cls, parts in types for p in parts if cls.fixed_centre(p)}
    pairs: dict[frozenset[str], str] = {}
    for nip in nips:
        label = f"nip {nip.name!r}"
        for key in ("a", "b"):
            ref = getattr(nip, key)
            if ref not in body_names:
                what = f"is {kinds[ref]} {ref!r}, not a body" if ref in kinds else \
                    "is not a body of the scene"
                raise fail(source, label, key,
                           f"{show(ref)} {what}; a nip joins two bodies; valid names: "
                           f"{', '.join(body_names)}")
        if nip.a == nip.b:
            raise fail(source, label, "b",
                        f"{nip.b!r} is also a: a nip joins two different bodies; valid "
                        "names: "
                        f"{', '.join(n for n in body_names if n != nip.a) or '(none)'}")
        if nip.a in fixed and nip.b in fixed:
            raise fail(source, label, "b",
                        f"{nip.b!r}: a nip between two bodies with fixed centres "
                        f"({kinds[nip.a]} {nip.a!r} and {kinds[nip.b]} {nip.b!r}) cannot be "
                        "assembled: neither can move to carry its normal force; valid "
                        "names: a roll free to move or a rider: "
                        f"{', '.join(n for n in body_names if n not in fixed) or '(none)'}")
        na, nb = (_segments(types, getattr(nip, key)) for key in ("a", "b"))
        if na and nb and na != nb:
            raise fail(source, label, "b",
                        f"{nip.b!r} has {nb} segments (flex) and {nip.a!r} {na}: both "
                        "flexible bodies of a nip need the same number of segments, one "
                        f"slice each; valid: segments = {na} on {nip.b!r}")
        pair = frozenset((nip.a, nip.b))
        if pair in pairs:
            raise fail(source, label, "b", f"{nip.b!r}: nip {pairs[pair]!r} already joins "
                                            f"{nip.a!r} and {nip.b!r}; one nip per pair of "
                                            "bodies")
        pairs[pair] = nip.name
    roll_names = [r.name for r in rolls]
    for rider in riders:
        label = f"rider {rider.name!r}"
        if rider.rides not in roll_names:
            what = f"is {kinds[rider.rides]} {rider.rides!r}, not a roll; a rider rides a " \
                "paper roll" if rider.rides in kinds else "is not a roll of the scene"
            raise fail(source, label, "rides", f"{show(rider.rides)} {what}; valid names: "
                                                f"{', '.join(roll_names) or '(none)'}")
        if not any(n.a == rider.rides and n.b == rider.name for n in nips):
            raise fail(source, label, "rides",
                        f"{rider.rides!r}: no [[nip]] with a = {rider.rides!r} and b = "
                        f"{rider.name!r} (the rider rests on its roll through a nip); "
                        "declare one; nips: "
                        f"{', '.join(f'{n.name} ({n.a}, {n.b})' for n in nips) or '(none)'}")
    for cls, parts in types:  # any other reference of a body type's keys: to a body
        refs = [k.name for k in cls.KEYS if k.kind == "ref"]
        for p in parts:
            for key in refs:
                ref = getattr(p, key, None)
                if ref is not None and ref not in body_names:
                    what = f"is {kinds[ref]} {ref!r}, not a body" if ref in kinds else \
                        "is not a body of the scene"
                    raise fail(source, f"{cls.table} {p.name!r}", key,
                               f"{show(ref)} {what}; valid names: {', '.join(body_names)}")
    wound = [r.name for r in rolls if r.kind == "wound"]
    entries = [n.name for n in nips if kinds[n.a] == "drum" and n.b in wound]
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
    _check_span(source, kinds, rolls, webs)
    for roll in wound:
        if roll not in fed:
            valid = [n.name for n in nips if n.b == roll and kinds[n.a] == "drum"]
            raise fail(source, f"roll {roll!r}", "kind",
                        "'wound': no web feeds this wound roll, so its paper would come "
                        "from nowhere (every wound roll is fed by exactly one "
                        "web); add a [[web]] with entry_nip = the nip where its web enters "
                        "it; valid names: "
                        f"{', '.join(valid) or '(none: no nip joins a drum, a, to it, b)'}"
                        ", or make it kind = 'unwinding' with its own span")


def _check_span(source: str, kinds: Mapping[str, str], rolls: list[RollPart],
                webs: list[tuple[str, WebPart]]) -> None:
    """Every unwinding roll feeds exactly one web's span, and every span starts at an
    unwinding roll (spec §5); ``kinds`` maps every part's name to its kind."""
    unwinding = [r.name for r in rolls if r.kind == "unwinding"]
    spans = [(label, w.span) for label, w in webs if w.span is not None]
    source_of: dict[str, str] = {}
    for label, span in spans:
        ref = span.source
        if ref not in unwinding:
            if kinds.get(ref) == "roll":
                what = f"is roll {ref!r} of kind 'wound', not an unwinding roll"
            elif ref in kinds:
                what = f"is {kinds[ref]} {ref!r}, not an unwinding roll"
            else:
                what = "is not a roll of the scene"
            raise fail(source, f"{label}.span", "from",
                        f"{show(ref)} {what}; the span starts at the unwinding roll that "
                        "feeds it; valid names: "
                        f"{', '.join(unwinding) or '(none: no roll has kind = unwinding)'}")
        if ref in source_of:
            raise fail(source, f"{label}.span", "from",
                        f"{ref!r} already feeds the span of [{source_of[ref]}]: an "
                        "unwinding roll pays off one web; valid names: unwinding rolls "
                        "feeding no span: "
                        f"{', '.join(u for u in unwinding if u not in source_of) or '(none)'}")
        source_of[ref] = label
    for name in unwinding:
        if name not in source_of:
            first = not spans and len(webs) <= 1
            raise fail(source, f"roll {name!r}", "kind",
                        "'unwinding': an unwinding roll feeds a web span, and "
                        + ("the scene has no [web.span]; add [web.span] with from = "
                           f"{name!r} (and [web] entry_nip, where the web enters the wound "
                           "roll)" if first else
                           f"no [web.span] has from = {name!r}; add one to the web it "
                           "feeds, or make it kind = 'wound' with a web of its own"))


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
