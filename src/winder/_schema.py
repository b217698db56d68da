"""Scene keys, declared once: the :class:`Key` and the :class:`Table` of keys.

Each key of a scene file is one :class:`Key` (its type, unit, bounds, default or
required, choices and a one-line meaning), declared beside what reads it: a part's keys
in its module under ``winder/parts/`` (``KEYS``), an effect's settings on its
:class:`~winder.forces.ForceElement` (``settings``), the other tables in
:mod:`winder.scene.schema` (and the old single-drum format's in
:mod:`winder.scene.legacy`). Everything else reads these declarations:

- the parser and its error messages (:func:`winder.scene.parse.parse_table`);
- units and meanings (:func:`winder.scene.key_unit`, :func:`winder.scene.key_doc`);
- the generated ``docs/scene-reference.md`` (:mod:`winder.scene.reference`);
- the FMU's parameter units and descriptions (:mod:`winder.fmu.parameters`).

Each result channel is one :class:`Channel` (its name pattern, unit and meaning),
declared by what writes it: the generic body, nip and web channels in
:mod:`winder.model.channels`, a part's own on its body element (``CHANNELS``), an effect's
on its :class:`~winder.forces.ForceElement` (``CHANNELS``). The machine registers its
channels with their units from these (:meth:`winder.model.machine.Machine.channel`), the
reference lists them, the single-drum format names its columns through them.

This module imports nothing of winder but the error types, so every layer may read it.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from typing import Any

__all__ = ["Key", "Table", "Channel", "KINDS", "NO_DEFAULT", "format_number", "WHOLE_RULES"]

#: Kinds of key value: ``num`` a finite number; ``bool`` true or false; ``str`` a string
#: (one of ``choices`` where given); ``name`` a part's name; ``ref`` the name of another
#: part; ``pair`` two numbers ``[x, z]``; ``sense`` +1 or −1; ``axes`` a set of
#: ``"x"``, ``"z"``; ``load`` a rider's load schedule; ``table`` a sub-table (parsed on
#: its own, by its own :class:`Table`).
KINDS = ("num", "bool", "str", "name", "ref", "pair", "sense", "axes", "load", "table")


class _NoDefault:
    def __repr__(self) -> str:
        return "NO_DEFAULT"


#: :attr:`Key.default` of a key whose default is not declared on the key: a part's key
#: takes its dataclass field's default, a required key has none.
NO_DEFAULT: Any = _NoDefault()


@dataclass(frozen=True, kw_only=True)
class Key:
    """One key of a scene table.

    name:
        The TOML key.
    kind:
        One of :data:`KINDS`.
    doc:
        Its meaning, one line (the reference's "meaning" column).
    unit:
        The unit of a number (``"m"``, ``"kg·m²"``; ``"-"`` dimensionless; ``""`` none in
        common, and every key that is not a number).
    lo, lo_open, hi:
        Bounds of a number: ``[lo, hi]`` (``(lo, hi]`` when ``lo_open``); ``lo`` None
        with ``hi`` bounds ``|value| <= hi``; ``hi`` None: no upper bound (or one set by
        another key, as ``output_step <= duration``).
    choices:
        The valid strings of a ``str`` key (empty: any).
    required:
        Whether the key must be given.
    default:
        The value an absent key takes, where the key itself declares it (an effect's
        settings); :data:`NO_DEFAULT` where it comes from elsewhere: a part's key takes
        its dataclass field's default.
    default_text:
        The reference's "default" column where it is not a plain value
        (``"core_radius"``, ``"[paper] density"``); None: the value.
    doc_unit:
        The reference's "unit" column where it says more than :attr:`unit` can, which
        labels plot axes (a stiffness in ``N/m (N/m^p)``); None: :attr:`unit`.
    items:
        The two numbers of a ``pair`` (``x``, ``z``) or of each point of a ``load``
        (``radius``, ``line_load``), each a number :class:`Key` with its unit and bounds.
    valid:
        The reference's "range" column for a key whose validity is not a range of numbers
        (``1–200 printable characters``); None: from the bounds or the items.
    fmu:
        The FMU parameter this number is, by its name after its part's (``contact_stiffness``
        of a nip ``front`` is the FMU parameter ``front_contact_stiffness``; a key of a
        single table, ``web_tension``, is named as given); ``""``: not an FMU parameter.
        :mod:`winder.fmu.parameters` collects these from every part's keys.
    law_units:
        Units of the number that depend on a sibling key ``law``: ``(("hunt_crossley",
        "N/m^p"),)`` is the unit under that law (a Hunt–Crossley stiffness); the unit is
        :attr:`unit` under any other.
    """

    name: str
    kind: str = "num"
    doc: str
    unit: str = ""
    lo: float | None = None
    lo_open: bool = False
    hi: float | None = None
    choices: tuple[str, ...] = ()
    required: bool = False
    default: Any = NO_DEFAULT
    default_text: str | None = None
    doc_unit: str | None = None
    items: tuple[Key, ...] = ()
    valid: str | None = None
    fmu: str = ""
    law_units: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise TypeError(f"Key: name must be a non-empty string, got {self.name!r}")
        if self.kind not in KINDS:
            raise ValueError(f"Key {self.name!r}: kind {self.kind!r} is not one of "
                             f"{', '.join(KINDS)}")
        if not isinstance(self.doc, str) or not self.doc:
            raise ValueError(f"Key {self.name!r}: doc must say what the key means")
        if self.kind != "num" and (self.lo is not None or self.hi is not None):
            raise ValueError(f"Key {self.name!r}: only a number (kind 'num') has bounds")
        if self.choices and self.kind != "str":
            raise ValueError(f"Key {self.name!r}: only a string (kind 'str') has choices")
        if self.lo is not None and self.hi is not None and not self.lo <= self.hi:
            raise ValueError(f"Key {self.name!r}: lo {self.lo!r} > hi {self.hi!r}")
        if (len(self.items) == 2) != (self.kind in ("pair", "load")) or \
                any(i.kind != "num" for i in self.items):
            raise ValueError(f"Key {self.name!r}: a pair or a load (and only they) has two "
                             "number items")
        if self.required and self.default is not NO_DEFAULT:
            raise ValueError(f"Key {self.name!r}: a required key has no default")

    @property
    def shown_unit(self) -> str:
        """The unit the reference shows: :attr:`doc_unit`, else :attr:`unit`, else ``-``
        for a key that is not a number."""
        if self.doc_unit is not None:
            return self.doc_unit
        return self.unit if self.kind == "num" else "-"

    def range_text(self) -> str:
        """The range of a number as the reference writes it: ``(0, 10]``, ``[0, ∞)``,
        ``\\|x\\| ≤ 1e8``, ``any finite``; for a pair or load its items' ranges; ``""``
        where there is none."""
        if self.valid is not None:
            return self.valid
        if self.items:
            first, second = (i.range_text() for i in self.items)
            if first == second and first.startswith("\\|x\\|"):
                return "each \\|·\\|" + first[len("\\|x\\|"):]
            return ", ".join(f"{i.name.replace('_', ' ')} {i.range_text()}"
                             for i in self.items)
        if self.kind == "name":
            return "1–40 letters, digits, _ or -, first a letter or _"
        if self.kind != "num":
            return ""
        if self.lo is None:
            return f"\\|x\\| ≤ {format_number(self.hi)}" if self.hi is not None \
                else "any finite"
        left = f"({format_number(self.lo)}" if self.lo_open else f"[{format_number(self.lo)}"
        return f"{left}, {format_number(self.hi)}]" if self.hi is not None else f"{left}, ∞)"


def format_number(x: float) -> str:
    """``x`` as in a scene file: 1e6, not 1e+06."""
    return re.sub(r"e([+-])0*(\d)", lambda m: "e" + m.group(1).replace("+", "") + m.group(2),
                  f"{x:g}")


@dataclass(frozen=True)
class Table:
    """The keys of one scene table, in the order messages and the reference list them.

    ``kinds`` maps a kind of the table (a drive's ``kind``) to the keys that kind takes
    (empty: every key for every kind)."""

    keys: tuple[Key, ...]
    kinds: dict[str, tuple[str, ...]] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        names = [k.name for k in self.keys]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"Table: keys declared twice: {', '.join(twice)}")
        for kind, keys in self.kinds.items():
            unknown = [k for k in keys if k not in names]
            if unknown:
                raise ValueError(f"Table: kind {kind!r} names keys not in the table: "
                                 f"{', '.join(unknown)}")

    def __iter__(self) -> Iterator[Key]:
        return iter(self.keys)

    def __len__(self) -> int:
        return len(self.keys)

    def __contains__(self, name: object) -> bool:
        return any(k.name == name for k in self.keys)

    def __getitem__(self, name: str) -> Key:
        for k in self.keys:
            if k.name == name:
                return k
        raise KeyError(name)

    def names(self) -> tuple[str, ...]:
        """The keys' names, in order."""
        return tuple(k.name for k in self.keys)

    def select(self, *names: str, **changes: Any) -> tuple[Key, ...]:
        """The keys ``names`` (in that order), each with ``changes`` applied
        (``required=True``): the same declaration read by another table."""
        return tuple(replace(self[n], **changes) if changes else self[n] for n in names)


#: Placeholders of a :class:`Channel` name: ``BODY`` any drum, roll or rider, ``ROLL`` a
#: paper roll, ``RIDER`` a rider, ``NIP`` a nip (each the part's name in a channel).
PLACEHOLDERS = ("BODY", "ROLL", "RIDER", "NIP")

#: How a flexible body's channel is formed from its segments' (:attr:`Channel.whole`), and
#: what the reference says of it: the body keeps every body-level channel of its rigid
#: self, with the same meaning.
WHOLE_RULES = {
    "drive": "the drive end's (segment 0) of a driven body, else the segments' mean",
    "drive_sum": "the drive end's (segment 0) of a driven body, else the segments' sum",
    "mean": "the segments' mean",
    "sum": "the segments' sum",
    "shared": "the segments' one value (segment 0's)",
}


@dataclass(frozen=True, kw_only=True)
class Channel:
    """One result channel, declared once by what writes it.

    name:
        Its name pattern: ``PLACEHOLDER_suffix`` for a part's channel (``BODY_speed``,
        ``ROLL_radius``, ``NIP_normal_force``; :data:`PLACEHOLDERS`), else the channel's
        own name (``t``, ``web_speed``; a web's channel takes the prefix ``WEB_`` in a
        scene of several webs).
    unit:
        Its SI unit (``rad/s``, ``N·m``; ``-`` a pure number), non-empty.
    doc:
        Its meaning, one line (the reference's "meaning" column).
    whole:
        A body's channel: how a flexible body (its segments ``BODY_s{i}``) forms it from
        its segments' values, one of :data:`WHOLE_RULES` (``drive``, ``drive_sum``,
        ``mean``, ``sum``, ``shared``), so the flexible body keeps the channel of its
        rigid self with the same meaning (:mod:`winder.model.whole_body`); ``""``: none.
    """

    name: str
    unit: str
    doc: str
    whole: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*",
                                                               self.name):
            raise ValueError(f"Channel: name must be an identifier, got {self.name!r}")
        if not isinstance(self.unit, str) or not self.unit:
            raise TypeError(f"channel {self.name!r}: unit must be a non-empty string such "
                            f"as 'm' or '-', got {self.unit!r}")
        if not isinstance(self.doc, str) or not self.doc:
            raise ValueError(f"Channel {self.name!r}: doc must say what the channel means")
        if self.whole and self.whole not in WHOLE_RULES:
            raise ValueError(f"Channel {self.name!r}: whole must be one of "
                             f"{', '.join(WHOLE_RULES)} or empty, got {self.whole!r}")

    @property
    def placeholder(self) -> str:
        """The part placeholder of the name (``BODY`` of ``BODY_speed``), or ``""``."""
        head = self.name.split("_", 1)[0]
        return head if head in PLACEHOLDERS and "_" in self.name else ""

    @property
    def suffix(self) -> str:
        """The name after its placeholder (``speed`` of ``BODY_speed``), or the name."""
        return self.name[len(self.placeholder) + 1:] if self.placeholder else self.name

    def of(self, owner: str = "") -> str:
        """The channel's name for ``owner``: the part's name for a placeholder
        (``front_speed``), else a prefix (``""``, or ``WEB_`` of a web among several)."""
        if self.placeholder:
            if not owner:
                raise ValueError(f"channel {self.name!r}: a part's channel needs its name")
            return f"{owner}_{self.suffix}"
        return f"{owner}{self.name}"
