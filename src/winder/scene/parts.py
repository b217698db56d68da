"""Parsing a scene of parts (machines spec §8): the arrays of tables of the registered body
types (``[[drum]]``, ``[[roll]]``, ``[[rider]]``, ...: :data:`winder.parts.PARTS`, each
parsed by its element class's ``parse``), ``[[nip]]`` and the webs ``[web]``/``[[web]]``
with their ``[web.span]``, each against its part's declared keys, then the checks across
them (:mod:`winder.scene.checks`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from winder._args import show
from winder._errors import SceneError
from winder._schema import Table
from winder.parts import PARTS, ContactLaw, FrictionLaw, NipPart, SpanPart, WebPart
from winder.parts.nip import CONTACT_KEYS, FRICTION_KEYS
from winder.parts.nip import KEYS as NIP_KEYS
from winder.parts.web import KEYS as WEB_KEYS
from winder.parts.web import SPAN_KEYS
from winder.scene.checks import check_overlaps, check_references
from winder.scene.parse import check_drive_keys, check_part_name, fail, parse_table
from winder.scene.tables import Effects, Paper

__all__ = ["parse_parts", "Reader"]


@dataclass(frozen=True)
class Reader:
    """What a body type's ``parse`` reads its table with
    (:class:`winder.parts.TableReader`): the scene's file, ``[paper]`` and ``[effects]``,
    and the parser of :mod:`winder.scene.parse`."""

    source: str
    paper: Paper | None
    effects: Effects

    def keys(self, label: str, raw: Any, table: Table) -> dict[str, Any]:
        return parse_table(self.source, label, raw, table)

    def kinds(self, label: str, parsed: Mapping[str, Any], table: Table) -> None:
        check_drive_keys(self.source, label, parsed, table)

    def fail(self, label: str, key: str, message: str) -> SceneError:
        return fail(self.source, label, key, message)


def _elements(source: str, data: Mapping[str, Any], array: str, *, named: bool = True
              ) -> list[tuple[str, dict[str, Any]]]:
    """``(label, raw table)`` of each element of ``[[array]]``; the label names it in
    messages (``drum 'front'``, or ``drum #2`` while its name is not valid, or absent
    where ``named`` is false: the name is optional)."""
    raw = data.get(array, [])
    if not isinstance(raw, list):
        raise SceneError(f"{source}: [{array}] must be an array of tables ([[{array}]], one "
                         f"per {array}, each with a name), got {show(raw)} "
                         f"({type(raw).__name__})")
    out = []
    for i, element in enumerate(raw):
        label = f"{array} #{i + 1}"
        if not isinstance(element, dict):
            raise SceneError(f"{source}: [{label}] must be a table of keys, got "
                             f"{show(element)} ({type(element).__name__})")
        if "name" not in element:
            if not named:
                out.append((label, element))
                continue
            raise fail(source, label, "name", "missing required key")
        name = check_part_name(source, label, element["name"])
        out.append((f"{array} {name!r}", element))
    return out


def _parse_webs(source: str, data: Mapping[str, Any]) -> list[tuple[str, WebPart]]:
    """``[web]`` (one table) or ``[[web]]`` (an array of tables, one per wound roll), each
    with its optional ``[web.span]`` (spec §3, §5, §8): ``(label, web)`` pairs, the label
    naming the table in messages (``web``; ``web 'name'`` or ``web #2`` in an array)."""
    web_raw = data.get("web")
    if web_raw is None:
        return []
    if isinstance(web_raw, list):
        if not web_raw:
            raise SceneError(f"{source}: [[web]]: an empty array of webs; give one [[web]] "
                             "table per wound roll, each with entry_nip, or leave web out "
                             "(a scene without wound rolls)")
        elements = _elements(source, data, "web", named=False)
    else:
        elements = [("web", web_raw)]
    webs = []
    for label, raw in elements:
        kw = parse_table(source, label, raw, WEB_KEYS)
        if "span" in raw:
            if "tension" in raw:
                raise fail(source, label, "tension",
                            f"{show(raw['tension'])}: with [web.span] the tension is the "
                            "span's state, docs/model.md §6; valid: remove tension (the span's "
                            "initial_tension sets where it starts)")
            kw["spans"] = _parse_spans(source, label, raw["span"])
        webs.append((label, WebPart(**kw)))
    return webs


def _parse_spans(source: str, label: str, raw: Any) -> tuple[SpanPart, ...]:
    """``[web.span]`` (one span from the unwinding roll to the entry drum) or
    ``[[web.span]]`` (several, in order, machines.md §11): the first names ``from``, every
    one but the last ``to`` (checked with the rollers, :mod:`winder.scene.checks`)."""
    several = isinstance(raw, list)
    if several and not raw:
        raise fail(source, label, "span", "[]: an empty array of spans; valid: one "
                                          "[[web.span]] table per span, in order")
    spans = []
    for i, element in enumerate(raw if several else [raw]):
        slabel = f"{label}.span #{i + 1}" if several else f"{label}.span"
        sp = parse_table(source, slabel, element, SPAN_KEYS)
        if i == 0 and "from" not in sp:
            raise fail(source, slabel, "from", "missing required key (the unwinding roll "
                                               "that feeds the web)")
        if i > 0:
            for key in ("from", "T_in"):
                if key in sp:
                    raise fail(source, slabel, key,
                               f"{show(sp[key])}: only the first span has {key} (span "
                               f"#{i + 1} starts at the roller span #{i} names in to); "
                               f"valid: remove {key}")
        spans.append(SpanPart(source=sp.pop("from", None), **sp))
    return tuple(spans)


def parse_parts(source: str, data: Mapping[str, Any], effects: Effects,
                 paper: Paper | None) -> dict[str, Any]:
    """The parts of a scene (machines spec §8): each element's keys, then names and
    references; the keyword arguments ``bodies`` (by :data:`~winder.parts.PARTS`
    attribute), ``nips`` and ``webs`` of :class:`~winder.scene.scene.Scene`."""
    reader = Reader(source, paper, effects)
    bodies = {attr: tuple(cls.parse(reader, label, raw)
                          for label, raw in _elements(source, data, cls.table))
              for attr, cls in PARTS.items()}
    nips = []
    for label, raw in _elements(source, data, "nip"):
        kw = parse_table(source, label, raw, NIP_KEYS)
        if effects.contact and "contact" not in raw:
            raise fail(source, label, "contact",
                        "missing required table (effects.contact is on)")
        for key, law, keys in (("contact", ContactLaw, CONTACT_KEYS),
                               ("friction", FrictionLaw, FRICTION_KEYS)):
            kw[key] = law(**parse_table(source, f"{label}.{key}", raw.get(key, {}), keys))
        nips.append(NipPart(**kw))
    webs = _parse_webs(source, data)
    check_references(source, bodies, nips, webs)
    check_overlaps(source, bodies, nips)
    return {"bodies": bodies, "nips": tuple(nips), "webs": tuple(w for _, w in webs)}
