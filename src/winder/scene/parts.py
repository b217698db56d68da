"""Parsing a scene of parts (machines spec §8): the arrays of tables ``[[drum]]``,
``[[roll]]``, ``[[rider]]``, ``[[nip]]`` and the webs ``[web]``/``[[web]]`` with their
``[web.span]``, each against its part's declared keys, then the checks across them
(:mod:`winder.scene.checks`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from winder._args import show
from winder._errors import SceneError
from winder.parts import (
    ContactLaw,
    DrumPart,
    FrictionLaw,
    NipPart,
    RiderPart,
    RollPart,
    SpanPart,
    SpeedProfileDrive,
    TensionControl,
    TorqueDrive,
    UnwindTorqueDrive,
    WebPart,
)
from winder.parts.drum import DRIVE_KEYS as DRUM_DRIVE_KEYS
from winder.parts.drum import KEYS as DRUM_KEYS
from winder.parts.nip import CONTACT_KEYS, FRICTION_KEYS
from winder.parts.nip import KEYS as NIP_KEYS
from winder.parts.rider import KEYS as RIDER_KEYS
from winder.parts.roll import DRIVE_KEYS as UNWIND_DRIVE_KEYS
from winder.parts.roll import KEYS as ROLL_KEYS
from winder.parts.web import KEYS as WEB_KEYS
from winder.parts.web import SPAN_KEYS
from winder.scene.checks import check_overlaps, check_references, check_roll_core
from winder.scene.parse import check_drive_keys, check_part_name, fail, parse_table
from winder.scene.tables import Effects, Paper

__all__ = ["parse_parts"]


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


def _parse_roll_drive(source: str, label: str, kw: dict[str, Any], raw: Mapping[str, Any]
                      ) -> UnwindTorqueDrive | TensionControl | None:
    """The drive of a roll (spec §6): only an unwinding roll may have one."""
    if "drive" not in raw:
        return None
    if kw["kind"] != "unwinding":
        raise fail(source, label, "drive",
                    f"{show(raw['drive'])}: a drive on a {kw['kind']} roll; only unwinding "
                    "rolls (kind = 'unwinding') have a drive; a wound roll is turned by its "
                    "nips; valid: remove drive")
    dlabel = f"{label}.drive"
    d = parse_table(source, dlabel, raw["drive"], UNWIND_DRIVE_KEYS)
    check_drive_keys(source, dlabel, d, UNWIND_DRIVE_KEYS)
    if d["kind"] == "torque":
        return UnwindTorqueDrive(**d)
    if "tension" not in d:
        raise fail(source, dlabel, "tension",
                    "missing required key (kind = 'tension_control': the set-point [N])")
    return TensionControl(**d)


def _parse_roll(source: str, label: str, raw: Mapping[str, Any], paper: Paper | None
                ) -> RollPart:
    """One ``[[roll]]`` element: its keys, paper defaults, core and drive (spec §1, §8)."""
    kw = parse_table(source, label, raw, ROLL_KEYS)
    kw.setdefault("kind", "wound")
    if kw["kind"] == "unwinding":
        kw.setdefault("free", ())
        if kw["free"]:
            raise fail(source, label, "free",
                        f"{show(list(kw['free']))}: an unwinding roll's centre is fixed "
                        "(docs/model.md §1); valid: [] (or leave free out)")
    kw["drive"] = _parse_roll_drive(source, label, kw, raw)
    kw.setdefault("initial_radius", kw["core_radius"])
    for key in ("density", "caliper"):
        if key not in kw:
            if paper is None:
                raise fail(source, label, key, "missing required key (the scene has no "
                                                f"[paper] {key} to default to)")
            kw[key] = getattr(paper, key)
    check_roll_core(source, label, kw)
    return RollPart(**kw)


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
            slabel = f"{label}.span"
            sp = parse_table(source, slabel, raw["span"], SPAN_KEYS)
            kw["span"] = SpanPart(source=sp.pop("from"), **sp)
        webs.append((label, WebPart(**kw)))
    return webs


def parse_parts(source: str, data: Mapping[str, Any], effects: Effects,
                 paper: Paper | None) -> dict[str, Any]:
    """The parts of a scene (machines spec §8): each element's keys, then names and
    references."""
    drums = []
    for label, raw in _elements(source, data, "drum"):
        kw = parse_table(source, label, raw, DRUM_KEYS)
        dlabel = f"{label}.drive"
        d = parse_table(source, dlabel, raw["drive"], DRUM_DRIVE_KEYS)
        check_drive_keys(source, dlabel, d, DRUM_DRIVE_KEYS)
        if d["kind"] == "speed_profile":
            if "web_speed" not in d:
                raise fail(source, dlabel, "web_speed",
                            "missing required key (kind = 'speed_profile')")
            drive: SpeedProfileDrive | TorqueDrive = SpeedProfileDrive(**d)
        else:
            drive = TorqueDrive(**d)
        drums.append(DrumPart(**kw, drive=drive))
    rolls = [_parse_roll(source, label, raw, paper)
             for label, raw in _elements(source, data, "roll")]
    riders = [RiderPart(**parse_table(source, label, raw, RIDER_KEYS))
              for label, raw in _elements(source, data, "rider")]
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
    check_references(source, drums, rolls, riders, nips, webs)
    check_overlaps(source, drums, rolls, nips)
    return {"drums": tuple(drums), "rolls": tuple(rolls), "riders": tuple(riders),
            "nips": tuple(nips), "webs": tuple(w for _, w in webs)}
