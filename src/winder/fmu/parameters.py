"""The parameters of a scene's FMU (:mod:`winder.fmu.native`): which scene keys a host may
set, under which names and units, and the scene with the host's values applied.

- A scene with its own FMU interface (:attr:`Naming.fmu <winder.scene.naming.Naming.fmu>`,
  the single-drum format's): its parameters (:data:`FMU_PARAMETERS`): web speed and
  acceleration, imbalance, nip stiffness and damping, friction, caliper, density, width.
- A machine from parts: every part's keys declared as FMU parameters
  (:attr:`Key.fmu <winder._schema.Key.fmu>`, in the part's ``KEYS``; a drive's only for
  the drive kind that takes them), named by part, in the parts' order: per drum
  ``DRUM_web_speed`` (and ``DRUM_web_acceleration`` for a speed profile), per roll
  ``ROLL_width``, ``ROLL_com_offset``, ``ROLL_density``, ``ROLL_caliper`` (and
  ``ROLL_bandwidth`` for a tension-controlled unwinding roll), per nip
  ``NIP_contact_stiffness``, ``NIP_contact_damping``, ``NIP_mu``,
  ``NIP_slip_reference_velocity``, ``NIP_relaxation_length``, and ``web_tension``.
  A winder line (``[web.span]``, machines.md §5) has ``span_length``, ``span_EA`` and
  ``span_T_in`` instead of ``web_tension`` (the tension is the span's state); a web line
  of several spans (``[[web.span]]``, §11) has them per span, named as its channels
  (``span0_length``, ``span1_EA``, …; ``T_in`` the first span's only), and the web's
  ``web_mu``; its idlers their bearings' ``IDLER_bearing_viscous``,
  ``IDLER_bearing_coulomb``, their ``IDLER_wrap`` and a dancer's ``IDLER_dancer_damping``
  (its stiffness and load move the carriage's initial balance, which only the scene
  solves).

Descriptions and units are the scene keys' declarations: a key newly declared with
``fmu=...`` is a parameter at once.
"""

from __future__ import annotations

from typing import Any

from winder._errors import WinderError
from winder._schema import Key
from winder.model.spans import span_tag
from winder.parts import PARTS
from winder.scene import naming_of
from winder.scene.keys import find_key
from winder.scene.load import Scene
from winder.scene.schema import ARRAYS, TABLES

__all__ = ["FMU_PARAMETERS", "fmu_parameters", "parameter_units",
           "parameter_value", "scene_with_parameters", "FmuError"]

def _text(table: str, key: str, unit: str | None = None) -> str:
    """A parameter's description: its scene key's meaning and unit (``unit`` where given,
    else the declared one; :func:`winder.scene.keys.find_key`)."""
    k = find_key(table, key)
    return f"{k.doc} [{k.unit if unit is None else unit}]"


#: FMU parameter name → (scene table, key, description with unit) of a scene with its own
#: FMU interface (:attr:`winder.scene.naming.Naming.fmu`: the single-drum format's, the
#: naming a result without its scene is read with); the description and unit are the
#: key's declaration.
FMU_PARAMETERS: dict[str, tuple[str, str, str]] = {
    name: (table, key, _text(table, key))
    for name, (table, key) in naming_of(None).fmu.parameters.items()}  # type: ignore[union-attr]

class FmuError(WinderError):
    """The FMU could not be built, or a parameter value is not one of its parameters."""


#: A parameter's place in the scene: the table, the element name for an array of tables
#: (None for a single table) and the key path below it.
ParameterPath = tuple[str, "str | None", tuple[str, ...]]


def _elements(scene: Scene, table: str) -> Any:
    """The parts of the scene's array of tables ``table`` (:data:`~winder.scene.schema.ARRAYS`:
    a body type's, listed in ``scene.bodies`` under its :data:`~winder.parts.PARTS`
    attribute, or ``nip``)."""
    if table == "nip":
        return scene.nips
    attr = next(a for a, cls in PARTS.items() if cls.table == table)
    return scene.bodies.get(attr, ())


def _flagged(schema: str, obj: Any) -> list[tuple[tuple[str, ...], Key, str]]:
    """``(key path, declaration, unit)`` of every FMU parameter of the schema table
    ``schema`` (``roll[]``, ``nip[].contact``) whose values are ``obj``: its numbers
    declared with :attr:`Key.fmu <winder._schema.Key.fmu>` that its ``kind`` takes (a
    drive's), then those of its sub-tables that ``obj`` has, recursively. The unit is the
    key's, or its unit under ``obj``'s ``law`` (:attr:`~winder._schema.Key.law_units`)."""
    table = TABLES[schema]
    takes = table.kinds.get(getattr(obj, "kind", None)) if table.kinds else None
    out: list[tuple[tuple[str, ...], Key, str]] = []
    for k in table:
        if takes is not None and k.name not in takes:
            continue
        if k.fmu:
            out.append(((k.name,), k, dict(k.law_units).get(getattr(obj, "law", None),
                                                           k.unit)))
        elif k.kind == "table" and f"{schema}.{k.name}" in TABLES and \
                getattr(obj, k.name, None) is not None:
            out += [((k.name, *path), key, unit) for path, key, unit in
                    _flagged(f"{schema}.{k.name}", getattr(obj, k.name))]
    return out


def _parameters(scene: Scene) -> dict[str, tuple[ParameterPath, str, str]]:
    """FMU name → (place in the scene, description with unit, unit): the scene's own
    interface's (:attr:`Naming.fmu <winder.scene.naming.Naming.fmu>`), else every part's
    keys declared as FMU parameters (:attr:`Key.fmu <winder._schema.Key.fmu>`), named
    ``PART_NAME`` (``front_nip_mu``), and the web's (the FMU's one web: its span's,
    which hold the tension as a state, or else its own)."""
    out: dict[str, tuple[ParameterPath, str, str]] = {}
    own = scene.naming.fmu
    if own is not None:  # the scene's own interface (the single-drum format's)
        data = scene.to_dict()
        for name, (table, key) in own.parameters.items():
            top, *sub = table.split(".")
            place: ParameterPath = (top, None, (*sub, key))
            k = find_key(table, key)
            unit = dict(k.law_units).get(data.get(top, {}).get("law"), k.unit) \
                if not sub else k.unit
            out[name] = (place, f"{k.doc} [{unit}]", unit)
        return out
    for table in ARRAYS:
        for part in _elements(scene, table):
            for path, k, unit in _flagged(f"{table}[]", part):
                out[f"{part.name}_{k.fmu}"] = ((table, part.name, path),
                                               f"{table} {part.name}: {k.doc} [{unit}]", unit)
    web = scene.web
    if web is not None and len(web.spans) <= 1:
        sub = ("span",) if web.span is not None else ()
        for path, k, unit in _flagged(".".join(("web", *sub)),
                                      web.span if sub else web):
            if k.name == "mu":  # the capstan limit's: only a line's rollers use it
                continue
            who = " ".join(("web", *sub)) + ": " if sub else ""
            out[k.fmu] = (("web", None, (*sub, *path)), f"{who}{k.doc} [{unit}]", unit)
    elif web is not None:  # a web line (machines.md §11): each span's, named as its channels
        for i, span in enumerate(web.spans):
            tag = span_tag(i, len(web.spans))
            for path, k, unit in _flagged("web.span", span):
                if k.name == "T_in" and i > 0:  # the first span's only
                    continue
                out[f"{tag}_{k.fmu.removeprefix('span_')}"] = (
                    ("web", None, ("span", str(i), *path)),
                    f"web span {i}: {k.doc} [{unit}]", unit)
        for path, k, unit in _flagged("web", web):
            if len(path) == 1 and k.name != "tension":  # its own; the spans hold T
                out[k.fmu] = (("web", None, path), f"web: {k.doc} [{unit}]", unit)
    return out


def fmu_parameters(scene: Scene) -> dict[str, tuple[ParameterPath, str]]:
    """The FMU parameters of ``scene`` (besides ``rtol`` and, with the scene's own
    interface, its profile switch ``speed_profile``): FMU name → (place in the scene,
    description with unit, from the scene key's declaration)."""
    return {name: (place, text) for name, (place, text, _) in _parameters(scene).items()}


def parameter_units(scene: Scene) -> dict[str, str]:
    """The unit of each FMU parameter of ``scene`` (:func:`fmu_parameters`): its scene
    key's as declared (its unit under the nip's law where it has one: ``N/m^p`` for a
    Hunt–Crossley stiffness; ``"-"``: dimensionless)."""
    return {name: unit for name, (_, _, unit) in _parameters(scene).items()}


def parameter_value(scene: Scene, place: ParameterPath) -> float:
    """The scene's value at a parameter's place (:func:`fmu_parameters`)."""
    table, element, path = place
    if element is None:
        obj: Any = getattr(scene, table)
    else:
        obj = next(p for p in _elements(scene, table) if p.name == element)
    prev = None
    for key in path:  # a web line's span by its index (machines.md §11)
        obj, prev = (prev.spans[int(key)] if key.isdigit() else getattr(obj, key)), obj
    return float(obj)


def scene_with_parameters(scene: Scene, values: dict[str, float], *,
                          speed_profile: bool | None = None) -> Scene:
    """The scene with FMU parameter values applied (validated like a file).
    ``speed_profile`` (single-drum scenes only, where it is required): true drives the
    drum along its profile, false frees it at the profile's initial speed."""
    places = fmu_parameters(scene)
    own = scene.naming.fmu
    if (own is not None) != (speed_profile is not None):
        raise FmuError("speed_profile is a parameter of single-drum scenes only")
    changes: dict[str, dict[str, Any]] = {}
    for name, value in values.items():
        if name not in places:
            raise FmuError(f"unknown FMU parameter {name!r}; valid: {', '.join(places)}")
        table, element, path = places[name][0]
        node = changes.setdefault(table, {})
        if element is not None:
            node = node.setdefault(element, {})
        for key in path[:-1]:
            node = node.setdefault(key, {})
        node[path[-1]] = float(value)
    if own is not None:
        scene.naming.drive_changes(scene, changes, bool(speed_profile))
    return scene.replace(**changes)
