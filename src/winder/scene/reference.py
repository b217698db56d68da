"""The scene reference (``docs/scene-reference.md``), generated from the scene schema.

Every table and key of both scene formats with its type, unit, range, default and
meaning, read from each key's one declaration (:class:`~winder._schema.Key`: the parts'
``KEYS``, the effects' ``settings``, :mod:`winder.scene.schema`,
:mod:`winder.scene.legacy`) and, for a default the key does not declare, the dataclass
field's; then the result channels, read from each channel's one declaration
(:class:`~winder._schema.Channel`: :mod:`winder.model.channels`, the parts' and the
force elements' ``CHANNELS``). Regenerate with ``make scene-reference`` or::

    python -m winder.scene.reference [--out docs/scene-reference.md] [--check]

``--check`` writes nothing and exits 1 when the file differs from what the schema gives.
"""

from __future__ import annotations

import argparse
import dataclasses
import re
import sys
from collections.abc import Iterable
from pathlib import Path

from winder._schema import NO_DEFAULT, WHOLE_RULES, Channel, Key, Table
from winder._schema import format_number as _num
from winder.forces import DRIVES, FORCES
from winder.model.channels import GENERIC_CHANNELS, TIME
from winder.parts import PARTS, ContactLaw, FrictionLaw, NipPart, SpanPart, WebPart
from winder.scene.keys import ALL_TABLES
from winder.scene.legacy import COLUMNS, Drive, Drum, Roll
from winder.scene.schema import effect_names, effect_settings
from winder.scene.tables import Effects, Paper, SceneInfo, Solver

__all__ = ["reference", "main", "CHANNEL_DECLARATIONS", "channel_declarations",
           "channel_pattern"]

#: The dataclasses whose defaults a schema table's keys take (the first that has the
#: field; ``from`` of ``[web.span]`` is the field ``source``); the body types' from
#: :data:`PARTS` (:func:`_defaults_from`).
_DEFAULTS_FROM: dict[str, tuple[type, ...]] = {
    "scene": (SceneInfo,), "effects": (Effects,), "drum": (Drum,),
    "drum.drive": (Drive,), "roll": (Roll,), "paper": (Paper,),
    "contact": (ContactLaw,), "friction": (FrictionLaw,), "solver": (Solver,),
    "nip[]": (NipPart,), "nip[].contact": (ContactLaw,),
    "nip[].friction": (FrictionLaw,), "web": (WebPart,), "web.span": (SpanPart,),
}


def _defaults_from(table: str) -> tuple[type, ...]:
    for cls in PARTS.values():
        if table == f"{cls.table}[]":
            return (cls.part_cls,)
        for key, sub in cls.SUB_TABLES.items():
            if table == f"{cls.table}[].{key}":
                return sub.defaults
    return _DEFAULTS_FROM.get(table, ())


def _declarations() -> tuple[Channel, ...]:
    """Every result channel's declaration now registered: the machine's generic ones
    (:mod:`winder.model.channels`), then each body's (:data:`PARTS`), each force
    element's (:data:`FORCES`, :data:`DRIVES`), in that order."""
    return (*GENERIC_CHANNELS, *(c for cls in PARTS.values() for c in cls.CHANNELS),
            *(c for cls in (*FORCES.values(), *DRIVES.values()) for c in cls.CHANNELS))


#: Every result channel's declaration (:class:`~winder._schema.Channel`) of the built-in
#: parts and effects (:func:`_declarations` at import).
CHANNEL_DECLARATIONS: tuple[Channel, ...] = _declarations()


def _placeholder_kinds(placeholder: str) -> tuple[str, ...]:
    """The kinds of part a placeholder of a channel's name stands for (``BODY``: every
    registered body type's table)."""
    if placeholder == "BODY":
        return tuple(cls.table for cls in PARTS.values())
    return {"ROLL": ("roll",), "RIDER": ("rider",), "NIP": ("nip",)}[placeholder]


def _kind_text(key: Key) -> str:
    if key.choices:
        return "string: " + ", ".join(f"`{c}`" for c in key.choices)
    return {"num": "number", "bool": "boolean", "str": "string", "name": "name",
            "ref": "name of a part", "pair": "[x, z]", "sense": "+1 or −1",
            "axes": 'list of "x", "z"', "load": "list of [radius, line_load]",
            "table": "sub-table"}[key.kind]


def _value_text(v: object) -> str:
    if v is None:
        return "none"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, tuple):
        return "[" + ", ".join(f'"{x}"' if isinstance(x, str) else _num(x) for x in v) + "]"
    assert isinstance(v, int | float)
    return _num(v)


def _default_text(table: str, key: Key) -> str:
    if key.default_text is not None:
        return key.default_text
    if key.required:
        return "required"
    if key.default is not NO_DEFAULT:
        return _value_text(key.default)
    field = "source" if key.name == "from" else key.name
    for cls in _defaults_from(table):
        for f in dataclasses.fields(cls):
            if f.name == field and f.default is not dataclasses.MISSING:
                return _value_text(f.default)
            if f.name == field and f.default_factory is not dataclasses.MISSING:
                return "see its keys"
    return "—"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _table(table: str, keys: Table) -> list[str]:
    lines = ["| key | type | unit | range | default | meaning |", "|---|---|---|---|---|---|"]
    for key in keys:
        lines.append(f"| `{key.name}` | {_cell(_kind_text(key))} | {_cell(key.shown_unit)} | "
                     f"{key.range_text()} | {_cell(_default_text(table, key))} | "
                     f"{_cell(key.doc)} |")
    return lines


#: Headings of the schema tables (TOML spelling); the body types' from :data:`PARTS`
#: (:func:`_heading`).
_HEADINGS = {
    "scene": "[scene]", "effects": "[effects]", "solver": "[solver]", "paper": "[paper]",
    "drum": "[drum]", "drum.drive": "[drum.drive]", "roll": "[roll]",
    "contact": "[contact]", "friction": "[friction]",
    "nip[]": "[[nip]]", "nip[].contact": "[[nip]] contact",
    "nip[].friction": "[[nip]] friction", "web": "[web] or [[web]] (one per wound roll)",
    "web.span": "[web.span]",
}
_NOTES = {
    "paper": "The default paper of every roll: optional in a scene of parts (each "
             "`[[roll]]` may give its own `density` and `caliper`), required in the "
             "single-drum format. Where the table is given, both keys are required.",
    "drum.drive": "Keys by kind: " + "; ".join(
        f"`{k}`: {', '.join(v)}" for k, v in reversed(ALL_TABLES["drum.drive"].kinds.items()))
    + ".",
}


def _heading(table: str) -> str:
    for cls in PARTS.values():
        if table == f"{cls.table}[]":
            return f"[[{cls.table}]]"
        for key, sub in cls.SUB_TABLES.items():
            if table == f"{cls.table}[].{key}":
                return f"[[{cls.table}]] {sub.heading or key}"
    return _HEADINGS[table]


def _note(table: str) -> str | None:
    """The note under a heading: a table's own, else its keys by kind (a drive)."""
    if table in _NOTES:
        return _NOTES[table]
    kinds = ALL_TABLES[table].kinds
    return "Keys by kind: " + "; ".join(
        f"`{k}`: {', '.join(v)}" for k, v in kinds.items()) + "." if kinds else None


def _body_sections() -> tuple[str, ...]:
    """Each registered body type's table, then its sub-tables."""
    return tuple(t for cls in PARTS.values()
                 for t in (f"{cls.table}[]", *(f"{cls.table}[].{k}" for k in cls.SUB_TABLES)))


def _section(table: str) -> list[str]:
    out = [f"### `{_heading(table)}`", ""]
    note = _note(table)
    if note is not None:
        out += [note, ""]
    return out + _table(table, ALL_TABLES[table]) + [""]


def _effect_sections() -> list[str]:
    """A section ``[effects.NAME]`` per effect with settings of its own."""
    out = []
    for name in effect_names():
        keys = effect_settings(name)
        if len(keys) == 1:  # only "enabled"
            continue
        out += [f"### `[effects.{name}]`", "",
                f"The effect `{name}` with its settings: `[effects] {name} = true` (or "
                "false) takes their defaults; this table sets them.", ""]
        out += _table(f"effects.{name}", keys) + [""]
    return out


def reference() -> str:
    """The text of ``docs/scene-reference.md`` (Markdown)."""
    arrays = ", ".join(f"`[[{cls.table}]]`" for cls in PARTS.values()) + ", `[[nip]]`"
    tables = [cls.table for cls in PARTS.values()]
    bodies = ", ".join(tables[:-1]) + " or " + tables[-1] if len(tables) > 1 else tables[0]
    lines = [
        "# Scene reference",
        "",
        "<!-- Generated by `python -m winder.scene.reference` (make scene-reference) from "
        "the declarations of the scene keys (src/winder/parts/*.py KEYS, src/winder/scene/"
        "schema.py, the effects' settings); do not edit by hand. -->",
        "",
        "Scene files are TOML. There are two formats: **scenes of parts** (arrays of "
        f"tables {arrays} and a `[web]` table) and "
        "the **single-drum format** (single tables `[drum]`, `[roll]`, `[contact]`, "
        "`[friction]`: one drum, one roll, one nip). `[scene]`, `[effects]` and `[solver]` "
        "are common to both. Units are SI; the physics behind each key (frames, senses, "
        "the nip and mass laws) is in [model.md](model.md).",
        "",
        "An unknown table or key, a missing required key, a wrong type, a non-finite value "
        "or one outside its range stops the run with exit status 2 and a message naming "
        "the file, the table (an element of an array by its name) and the key. Inline "
        "tables (`drive = { kind = \"torque\" }`) and sub-tables written after their array "
        "element (`[[drum]]` then `[drum.drive]`) are the same TOML. Ranges: `(a, b]` "
        "excludes a, `[a, b]` includes it; `|x| ≤ b` bounds the magnitude.",
        "",
        "## Tables of both formats",
        "",
    ]
    for t in ("scene", "effects"):
        lines += _section(t)
    lines += _effect_sections()
    lines += _section("solver")
    lines += ["## Scenes of parts", "",
              "A part's name names its result channels and its sweep key paths "
              "(`nip.rear_nip.contact.stiffness`). References (`a`, `b`, `rides`, "
              "`entry_nip`, `from`) must name an existing part of the right kind. Every "
              "wound roll needs a web entering it at a nip whose `a` is a drum.", ""]
    for t in ("paper", *_body_sections(), "nip[]", "nip[].contact", "nip[].friction", "web",
              "web.span"):
        lines += _section(t)
    lines += ["## Single-drum format", "",
              "Means: drum \"drum\" at the origin (sense +1), roll \"roll\" free along z "
              "above it (sense −1), nip \"nip\" (a = drum, b = roll), web entering at "
              "\"nip\" with tension 0. `[scene]`, `[drum]`, `[drum.drive]`, `[roll]` and "
              "`[paper]` are required, `[contact]` while `effects.contact` is on.", ""]
    for t in ("drum", "drum.drive", "roll", "paper", "contact", "friction"):
        lines += _section(t)
    lines += ["## Result channels", "",
              "One column each, SI units, first column `t` (CSV and NPZ alike). Each "
              "channel is declared once, by what writes it (the machine, a part, an "
              "effect); this list is generated from those declarations.", "",
              "### Single-drum format", "",
              "The first 16 are the standard set; the others are winder's extras. Each is "
              "a channel of the machine the format means (drum `drum`, roll `roll`, nip "
              "`nip`), renamed.", "",
              "| channel | unit | machine channel | meaning |", "|---|---|---|---|",
              f"| `{TIME.name}` | {TIME.unit} | `{TIME.name}` | {_cell(TIME.doc)} |"]
    for column, (decl, owner) in COLUMNS.items():
        lines.append(f"| `{column}` | {decl.unit} | `{decl.of(owner)}` | {_cell(decl.doc)} |")
    lines += ["", "### Scenes of parts", "",
              f"`BODY` is the name of any {bodies}, `ROLL` of a paper roll, "
              "`RIDER` of a rider, `NIP` of a nip; `web_speed` and `web_force` exist with a "
              "web, `span_tension` with `[web.span]`, `tension_error` with an unwind of kind "
              "`tension_control`. With several webs, `web_speed` and `web_force` are "
              "`WEB_web_speed` and `WEB_web_force` (`WEB` the web's name); with several "
              "spans, `span_tension` and `tension_error` are `WEB_span_tension` and "
              "`WEB_tension_error`. A web line (`[[web.span]]`, several spans over idler "
              "rollers) has `span{i}_tension` for its spans `i = 0, 1, …` from the "
              "unwinding roll (`WEB_span{i}_tension` among several webs spanned); "
              "`BODY_load_cell` and `BODY_traction` are an idler's.", "",
              "A flexible body `NAME` (`flex`) has every channel of a body for each of its "
              "segments `NAME_s{i}` (0 at the drive end) and keeps the body-level channels "
              "of its rigid self, with the same names, units and meanings, formed from its "
              "segments' as the column *flexible body* says (a driven body: one with a "
              "drive on segment 0; its `x`, `z` only where the rigid body is free).", "",
              "| channel | unit | meaning | flexible body |", "|---|---|---|---|"]
    for decl in _declarations():
        whole = WHOLE_RULES[decl.whole] if decl.whole else ""
        lines.append(f"| `{decl.name}` | {decl.unit} | {_cell(decl.doc)} | {whole} |")
    return "\n".join(lines) + "\n"


def channel_declarations(name: str, parts: dict[str, str], webs: Iterable[str] = ()
                         ) -> list[Channel]:
    """The declarations (:func:`_declarations`) the channel ``name`` of a scene of
    parts matches: a placeholder's with the name of a part of its kind, a web's alone or
    after the name of one of ``webs`` (``WEB_web_speed``); ``parts`` maps every part name
    to its kind (``drum``, ``roll``, ``rider``, ``nip``)."""
    out = []
    name = re.sub(r"(^|_)span\d+_tension$", r"\1span_tension", name)  # a line's spans
    for decl in _declarations():
        if decl.placeholder:
            owners = [p for p, k in parts.items() if k in _placeholder_kinds(decl.placeholder)]
            if any(name == decl.of(p) for p in owners):
                out.append(decl)
        elif name == decl.name or any(name == decl.of(f"{w}_") for w in webs):
            out.append(decl)
    return out


def channel_pattern(name: str, parts: dict[str, str]) -> str | None:
    """The declared name pattern (``BODY_speed``) of the channel ``name`` of a scene of
    parts (:func:`channel_declarations`; the first where several match), or None."""
    found = channel_declarations(name, parts)
    return found[0].name if found else None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("docs/scene-reference.md"),
                    help="file to write (default docs/scene-reference.md)")
    ap.add_argument("--check", action="store_true",
                    help="write nothing; exit 1 if the file is not up to date")
    args = ap.parse_args(argv)
    text = reference()
    if args.check:
        old = args.out.read_text(encoding="utf-8") if args.out.is_file() else ""
        if old != text:
            print(f"{args.out} is stale: run make scene-reference", file=sys.stderr)
            return 1
        return 0
    from winder.io.files import atomic_write

    atomic_write(args.out, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    rows = len(re.findall(r"^\| `", text, re.M))
    print(f"wrote {args.out} ({rows} keys and channels)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
