"""The :class:`Scene`: a complete winder scene, its parts and tables (spec section 7;
machines spec §8), as frozen dataclasses; built by :func:`winder.scene.load_scene` or
:func:`scene_from_dict`, which validate every key (:mod:`winder.scene.validate`)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from winder._args import show
from winder._errors import ArgumentError, ArgumentTypeError
from winder.parts import PARTS, DrumPart, NipPart, RiderPart, RollPart, WebPart
from winder.scene.legacy import (
    OWN_TABLES,
    SINGLE_DRUM,
    Drum,
    LegacyContact,
    LegacyFriction,
    Roll,
    legacy_parts,
)
from winder.scene.naming import BY_PARTS, Naming
from winder.scene.tables import Effects, Paper, SceneInfo, Solver
from winder.scene.validate import scene_kwargs

__all__ = ["Scene", "scene_from_dict"]


@dataclass(frozen=True)
class Scene:
    """A complete winder scene. Build one with :func:`load_scene` or :func:`scene_from_dict`.

    The parts describe every scene: ``bodies``, the parts of each registered body type by
    its :data:`winder.parts.PARTS` attribute (``{"drums": (...), "rolls": (...), ...}``,
    each also an attribute: ``scene.drums``, ``scene.rolls``, ``scene.riders``, and
    ``scene.discs`` for a type registered as ``"discs"``), ``nips`` and ``webs``; ``web``
    is the first (or only) web, or None.
    A scene in the single-drum format (``legacy``) also has ``drum``, ``roll``,
    ``contact`` and ``friction``, and its parts are derived from them (machines spec §8):
    drum "drum" at the origin, sense +1; roll "roll" free in ``z`` at ``(0, R + r0)``,
    sense −1; nip "nip" (a = drum, b = roll); web entering at "nip" with tension 0. In a
    scene of parts those four are None, and ``paper`` is None unless ``[paper]`` is given.
    Every wound roll is fed by exactly one web (``webs``, one per wound roll, machines spec
    §3); a winder line has an unwinding roll (``rolls``, kind ``"unwinding"``) feeding the
    span of a web (``web.span``, machines spec §5).
    """

    scene: SceneInfo
    effects: Effects
    drum: Drum | None
    roll: Roll | None
    paper: Paper | None
    contact: LegacyContact | None
    friction: LegacyFriction | None
    solver: Solver
    source: str = "<scene>"
    bodies: Mapping[str, tuple[Any, ...]] = field(default_factory=dict, hash=False)
    nips: tuple[NipPart, ...] = ()
    web: WebPart | None = None
    webs: tuple[WebPart, ...] = ()
    legacy: bool = field(init=False)

    def __post_init__(self) -> None:
        legacy = self.drum is not None
        object.__setattr__(self, "legacy", legacy)
        if legacy:  # the parts always follow the single-drum tables
            assert self.roll is not None and self.paper is not None
            assert self.contact is not None and self.friction is not None
            parts = legacy_parts(self.drum, self.roll, self.paper, self.contact, self.friction)
            bodies = {n: v for n, v in parts.items() if n in PARTS}
            for name, value in parts.items():
                if name not in bodies:
                    object.__setattr__(self, name, value)
        else:
            bodies = dict(self.bodies)
        unknown = [a for a in bodies if a not in PARTS]
        if unknown:
            raise ArgumentError(f"Scene: bodies {', '.join(map(repr, unknown))}: not a body "
                                f"type; valid: {', '.join(PARTS)} (winder.parts.PARTS)")
        # every registered type, in registration order (the machine builds them so)
        object.__setattr__(self, "bodies", {a: tuple(bodies.get(a, ())) for a in PARTS})
        # ``webs`` is every web; ``web`` the first (or only) one, kept for code that reads a
        # single web; given only ``web``, ``webs`` is that one
        webs = tuple(self.webs) or ((self.web,) if self.web is not None else ())
        object.__setattr__(self, "webs", webs)
        object.__setattr__(self, "web", webs[0] if webs else None)

    @property
    def drums(self) -> tuple[DrumPart, ...]:
        """The ``[[drum]]`` parts."""
        return self.bodies.get("drums", ())

    @property
    def rolls(self) -> tuple[RollPart, ...]:
        """The ``[[roll]]`` parts."""
        return self.bodies.get("rolls", ())

    @property
    def riders(self) -> tuple[RiderPart, ...]:
        """The ``[[rider]]`` parts."""
        return self.bodies.get("riders", ())

    def __getattr__(self, name: str) -> tuple[Any, ...]:
        """``scene.ATTRIBUTE``: the parts of a body type registered as ``ATTRIBUTE``."""
        bodies = self.__dict__.get("bodies", {})
        if name in bodies or (name in PARTS and not name.startswith("_")):
            return tuple(bodies.get(name, ()))
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def name(self) -> str:
        return self.scene.name

    @property
    def naming(self) -> Naming:
        """How the scene names its result channels, its keys in messages and its FMU
        variables: by its parts, or the single-drum format's names
        (:mod:`winder.scene.naming`)."""
        return SINGLE_DRUM if self.legacy else BY_PARTS

    def replace(self, **changes: Mapping[str, Any]) -> Scene:
        """A copy with some tables' keys changed: ``scene.replace(roll={"com_offset": 0})``.

        Each keyword is a table (``drum={"drive": {...}}`` reaches ``[drum.drive]``) and
        its value a mapping of that table's keys to new values; sub-tables merge the same
        way. For an array of tables (a scene of parts) the mapping selects elements by
        name: ``nip={"front": {"contact": {"stiffness": 1e8}}}``. The result is validated
        like a file (:class:`SceneError` naming the key).

        Raises
        ------
        ArgumentError: a keyword that is not a table of the scene, or an element name
            that is not in the array.
        ArgumentTypeError: a table given as something other than a mapping of keys.
        """
        data = self.to_dict()
        for table, values in changes.items():
            if table not in data:
                raise ArgumentError(f"Scene.replace: {table} is not a table of the scene; "
                                    f"valid tables: {', '.join(data)}")
            _merge(data[table], values, table, ())
        return scene_from_dict(data, source=self.source)

    def to_dict(self) -> dict[str, Any]:
        """The scene as nested dictionaries (TOML tables; arrays of tables as lists of
        dictionaries with their ``name``). A roll's density or caliper equal to
        ``[paper]``'s is left to ``[paper]``, a tension controller's ``span`` of 0 (the
        default) is left out; tuples become lists."""
        out: dict[str, Any] = {"scene": _table_dict(self.scene),
                               "effects": self.effects.to_dict()}
        if self.legacy:
            return {**out, **{n: _table_dict(getattr(self, n)) for n in OWN_TABLES},
                    "solver": _table_dict(self.solver)}
        if self.paper is not None:
            out["paper"] = _table_dict(self.paper)
        for key, parts in (*((cls.table, self.bodies.get(attr, ()))
                             for attr, cls in PARTS.items()), ("nip", self.nips)):
            if parts:
                out[key] = [_table_dict(p) for p in parts]
        for roll in out.get("roll", ()):
            for key in ("density", "caliper"):
                if self.paper is not None and roll[key] == getattr(self.paper, key):
                    del roll[key]
            if (roll.get("drive") or {}).get("span") == 0:  # the default: the first span
                del roll["drive"]["span"]
        if len(self.webs) == 1:
            out["web"] = _web_dict(self.webs[0])
        elif self.webs:  # [[web]], one table per wound roll
            out["web"] = [_web_dict(w, named=True) for w in self.webs]
        out["solver"] = _table_dict(self.solver)
        return out

    def elements(self) -> tuple[list[Any], list[Any]]:
        """What :class:`~winder.model.machine.Machine` assembles: the body elements of the
        parts (:func:`winder.parts.body_elements`) and the force elements of the effects
        and drives (:func:`winder.forces.force_elements`)."""
        from winder.forces import force_elements
        from winder.parts import body_elements

        bodies = body_elements(self)
        return bodies, force_elements(self.effects, bodies)


def _web_dict(web: WebPart, *, named: bool = False) -> dict[str, Any]:
    """``[web]`` as a TOML table: with a span, ``[web.span]`` (its roll under the key
    ``from``) and no ``tension`` (the span's state); its name only if ``named`` or not the
    default (its entry nip's)."""
    out = _table_dict(web)
    if not named and web.name == web.entry_nip:
        del out["name"]
    spans = out.pop("spans", [])
    if web.mu == WebPart.mu:
        del out["mu"]
    if web.span is not None:
        del out["tension"]
        tables = [{**({"from": s.pop("source")} if "source" in s else {}), **s}
                  for s in spans]
        for later in tables[1:]:  # only the first span has T_in (machines.md §11)
            later.pop("T_in", None)
        out["span"] = tables[0] if len(tables) == 1 else tables
    return out


def _table_dict(obj: Any) -> dict[str, Any]:
    """A dataclass as a TOML table: None values left out, tuples as lists."""
    def plain(v: Any) -> Any:
        if isinstance(v, tuple | list):
            return [plain(x) for x in v]
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items() if x is not None}
        return v
    return plain(obj if isinstance(obj, dict) else dataclasses.asdict(obj))


def _merge(node: Any, values: Any, table: str, path: tuple[str, ...]) -> None:
    """Merge ``values`` into ``node`` (a table or an array of named tables) in place, for
    :meth:`Scene.replace`; ``table`` and ``path`` place it in messages."""
    where = table + "".join(f"[{p!r}]" for p in path)
    dotted = ".".join((table, *path))
    if not isinstance(values, Mapping):
        inner = (f"{next(iter(node))!r}: ..." if isinstance(node, dict) and node else "...")
        if isinstance(node, list):
            names = [str(e.get("name")) for e in node]
            inner = f"{names[0]!r}: {{...}}" if names else "..."
        example = "{" + inner + "}"
        for p in reversed(path):
            example = f"{{{p!r}: {example}}}"
        what = (f"[[{dotted}]] names to mappings of keys" if isinstance(node, list)
                else f"[{dotted}] keys")
        raise ArgumentTypeError(
            f"Scene.replace: {where} must be a mapping of {what} to values, e.g. "
            f"{table}={example}; got {show(values)} ({type(values).__name__})")
    if isinstance(node, list):  # unnamed elements (a line's spans) by their index
        names = [str(e.get("name", i)) for i, e in enumerate(node)]
        for name, sub in values.items():
            name = str(name)
            if name not in names:
                raise ArgumentError(f"Scene.replace: {where} has no element named "
                                    f"{show(name)}; valid names: {', '.join(names)}")
            _merge(node[names.index(name)], sub, table, (*path, name))
        return
    for key, value in values.items():
        old = node.get(key)
        tables = isinstance(old, dict) or (
            isinstance(old, list) and bool(old) and all(isinstance(e, dict) for e in old))
        if tables:  # a sub-table or an array of named tables: merge into it
            _merge(node[key], value, table, (*path, key))
        else:  # a value, or a list of values (a rider's load schedule): replace it
            node[key] = value



def scene_from_dict(data: dict[str, Any], *, source: str = "<scene>") -> Scene:
    """Validate nested dictionaries (as read from TOML) and build a :class:`Scene`: the
    single-drum format or a scene of parts (machines spec §8). Every error is a
    :class:`~winder.SceneError` naming the file, the table, the key and the value."""
    return Scene(**scene_kwargs(data, source=source))
