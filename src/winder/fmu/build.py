"""FMI 2.0 co-simulation export (pythonfmu): the winder as an FMU for controller work.

The FMU runs *inside the host's Python*: pythonfmu's binary loads the Python interpreter
of the importing process and imports :mod:`winder` (with Pinocchio) from it.
A host that loads the FMU must therefore be a Python process (FMPy, or any tool that
embeds that Python) whose environment has winder installed; the scene travels inside the
FMU (``resources/scene.toml``).

Interface of a single-drum scene (the old format)
-------------------------------------------------
- parameters (:data:`FMU_PARAMETERS`): web speed and acceleration, imbalance, nip
  stiffness and damping, friction, caliper, density, width, and ``speed_profile``: true
  drives the drum along the built-in web-speed profile (``drum_torque`` is then an
  output), false frees the drum, started at the profile's initial speed, and drives it
  by the input ``drum_torque_command``.
- input ``drum_torque_command`` [N·m] (named apart from the output channel
  ``drum_torque``, which reports the torque acting in either mode).
- outputs: every result channel (the scene's naming's columns but ``t``) and
  ``web_speed_reference`` = ``min(a_w t, v_w)`` [m/s], the profile a speed controller
  follows.

Interface of a machine from parts
---------------------------------
- parameters (:func:`fmu_parameters`): every part's keys declared as FMU parameters
  (:attr:`Key.fmu <winder._schema.Key.fmu>`, in the part's ``KEYS``; a drive's only for
  the drive kind that takes them), named by part, in the parts' order: per drum
  ``DRUM_web_speed`` (and ``DRUM_web_acceleration`` for a speed profile), per roll
  ``ROLL_width``, ``ROLL_com_offset``, ``ROLL_density``, ``ROLL_caliper`` (and
  ``ROLL_bandwidth`` for a tension-controlled unwinding roll), per nip
  ``NIP_contact_stiffness``, ``NIP_contact_damping``, ``NIP_mu``,
  ``NIP_slip_reference_velocity``, ``NIP_relaxation_length``, and ``web_tension``; the
  drives are the scene's.
  A winder line (``[web.span]``, machines.md §5) has ``span_length``, ``span_EA`` and
  ``span_T_in`` instead of ``web_tension`` (the tension is the span's state).
- inputs: the :class:`~winder.Stepper`'s, ``DRUM_torque`` [N·m] per torque-driven drum
  or unwinding roll (``parent_torque``), ``ROLL_tension_setpoint`` [N] of a
  tension-controlled unwind (none when every drum follows a speed profile); units and
  descriptions from their declarations (:data:`winder.model.channels.INPUTS`).
- outputs: the Stepper's outputs (machines.md §9 channels) but the ``DRUM_torque``
  channel of a torque-driven drum, which is its input (same name, same value); with an
  unwinding roll also ``t`` [s], the time of the outputs.
- run-out: when an unwinding roll reaches its core (:attr:`winder.Stepper.ended`),
  ``fmi2DoStep`` stops there, publishes the outputs at that time, logs why and fails
  (``do_step`` returns false); every later step fails the same way.
- ``rtol``: tolerance of the internal DOPRI5 (both kinds).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Any

from winder._errors import WinderError
from winder._schema import Key
from winder.scene import naming_of
from winder.scene.keys import find_key
from winder.scene.load import Scene, load_scene
from winder.scene.schema import ARRAYS, TABLES

__all__ = ["build_fmu", "FMU_PARAMETERS", "fmu_parameters", "parameter_units",
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

# pythonfmu's binary finds the class by the pattern ``class X(Fmi2Slave):`` in this file,
# hence the alias.
_SLAVE_SCRIPT = '''"""winder FMU: the scene in resources/scene.toml (needs a Python with winder)."""
from winder.fmu.slave import WinderSlave as Fmi2Slave

_pinned_globals = [globals()]  # see winder.fmu.slave.WinderSlave.__init__


class Winder(Fmi2Slave):
    """The winder co-simulation slave."""
'''


class FmuError(WinderError):
    """The FMU could not be built or does not run in this Python."""


#: A parameter's place in the scene: the table, the element name for an array of tables
#: (None for a single table) and the key path below it.
ParameterPath = tuple[str, "str | None", tuple[str, ...]]


def _elements(scene: Scene, table: str) -> Any:
    """The parts of the scene's array of tables ``table`` (:data:`~winder.scene.schema.ARRAYS`:
    the scene's field ``TABLEs``)."""
    return getattr(scene, f"{table}s")


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
    if web is not None:
        sub = ("span",) if web.span is not None else ()
        for path, k, unit in _flagged(".".join(("web", *sub)),
                                      web.span if sub else web):
            who = " ".join(("web", *sub)) + ": " if sub else ""
            out[k.fmu] = (("web", None, (*sub, *path)), f"{who}{k.doc} [{unit}]", unit)
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
    for key in path:
        obj = getattr(obj, key)
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


def build_fmu(scene_path: str | Path, out: str | Path) -> Path:
    """Build ``out`` (an ``.fmu``) from a scene file, atomically: the complete FMU or
    nothing at ``out``, and no build folder left in the temporary directory, on an error
    or a signal. Raises :class:`FmuError` when pythonfmu is missing or the build fails."""
    # imported here, not at the top: FMU hosts import this module (the slave, FMPy hosts),
    # and with more modules loaded there pythonfmu 0.7's heap corruption (see
    # winder.fmu.slave) showed again: 1-3 of the 7 FMU host tests aborted per run
    from winder.io.files import atomic_write, scratch_dir

    try:
        from pythonfmu import FmuBuilder
    except ImportError as exc:
        raise FmuError("building an FMU needs pythonfmu: pip install 'winder[fmu]'") from exc
    scene_path = Path(scene_path)
    scene = load_scene(scene_path)  # validate before packing
    if len(scene.webs) > 1:
        raise FmuError(f"{scene_path}: [[web]]: {len(scene.webs)} webs "
                       f"({', '.join(w.name for w in scene.webs)}); the FMU takes a scene "
                       "with one web (one winding station); valid: one [web] table (run "
                       "several stations with winder run)")
    out = Path(out)
    if out.suffix != ".fmu":
        raise FmuError(f"output file must end in .fmu, got {str(out)!r}")
    with scratch_dir("winder_fmu_") as d:
        script = d / "winder_fmu.py"
        script.write_text(_SLAVE_SCRIPT, encoding="utf-8")
        scene_copy = d / "scene.toml"
        shutil.copyfile(scene_path, scene_copy)
        staged = d / "build" / "winder.fmu"
        # pythonfmu's own scratch folder goes inside ours (removed with it, even on a signal)
        saved, tempfile.tempdir = tempfile.tempdir, str(d)
        try:
            FmuBuilder.build_FMU(script, dest=staged, project_files=[scene_copy],
                                 needsExecutionTool="true")
        except Exception as exc:  # pythonfmu raises bare exceptions
            raise FmuError(f"pythonfmu could not build the FMU from {scene_path}: {exc}") \
                from exc
        finally:
            tempfile.tempdir = saved
        atomic_write(out, lambda tmp_out: shutil.copyfile(staged, tmp_out))
    return out
