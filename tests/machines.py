"""Scene builders for the machine tests: plain parts objects (``SimpleNamespace``) with the
attributes :class:`winder.model.machine.Machine` reads, until the parts loader lands.

Every builder returns a fresh object (nothing is shared between parts, so overriding one
nip's law does not touch another) and takes keyword overrides. :func:`override` sets any
value by a dotted path (``"set.caliper"``, ``"front.drive.torque"``,
``"rear_nip.contact.damping"``, ``"scene.gravity"``, ``"web.tension"``); :func:`effects`
switches effects on and off.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from types import SimpleNamespace as NS
from typing import Any

import numpy as np

from winder.forces import FORCES, force_elements
from winder.parts import body_elements

__all__ = ["EFFECTS", "effects", "contact", "friction", "speed_profile", "torque_drive",
           "drum", "wound_roll", "rider", "nip", "machine_scene", "override", "two_drum",
           "single_drum", "free_roll", "state_matrix"]

#: The ``[effects]`` keys, in the order of the scene schema: the registry's.
EFFECTS = tuple(FORCES)


def effects(**flags: bool) -> NS:
    """``[effects]``: every effect on unless ``flags`` says otherwise
    (``effects(gravity=False)``); ``enabled()`` lists those on; ``setting(effect, key)``
    is the declared default of an effect's setting."""
    from winder.scene.schema import effect_settings

    unknown = set(flags) - set(EFFECTS)
    if unknown:
        raise KeyError(f"unknown effects {sorted(unknown)}")
    d = {n: bool(flags.get(n, True)) for n in EFFECTS}
    e = NS(**d)
    e.enabled = lambda: tuple(n for n in EFFECTS if getattr(e, n))
    e.setting = lambda effect, key: effect_settings(effect)[key].default
    return e


def contact(law: str = "linear", **kw: float) -> NS:
    """``[nip.contact]``: stiffness [N/m^p], damping [N·s/m], exponent, hc_damping [s/m]."""
    c = NS(law=law, stiffness=2.5e7, damping=1.5e4, exponent=1.5, hc_damping=0.0)
    if law == "hunt_crossley":
        c.stiffness, c.hc_damping = 5e9, 0.3
    return _set(c, kw)


def friction(**kw: float) -> NS:
    """``[nip.friction]``: mu, slip_velocity [m/s], relaxation_length [m], min_speed [m/s]."""
    return _set(NS(mu=0.35, slip_velocity=0.05, relaxation_length=0.01, min_speed=0.1), kw)


def speed_profile(**kw: float) -> NS:
    """A drum speed profile: web_acceleration [m/s²], web_speed [m/s], ratio."""
    return _set(NS(kind="speed_profile", web_acceleration=0.7, web_speed=41.7, ratio=1.0,
                   torque=0.0), kw)


def torque_drive(**kw: float) -> NS:
    """A torque drive: torque [N·m] input, web_speed [m/s] the initial surface speed."""
    return _set(NS(kind="torque", web_acceleration=0.0, web_speed=5.0, ratio=1.0,
                   torque=120.0), kw)


def drum(name: str, centre: tuple[float, float], drive: NS | None = None, **kw: Any) -> NS:
    """A drum: radius [m], inertia [kg·m²], mass [kg], fixed centre [m], sense ±1."""
    return _set(NS(name=name, radius=0.5, inertia=600.0, mass=3000.0, centre=tuple(centre),
                   sense=1, drive=drive if drive is not None else speed_profile()), kw)


def wound_roll(name: str, centre: tuple[float, float], free: Iterable[str] = ("z",),
               **kw: Any) -> NS:
    """A wound paper roll (winder-model §2): free coordinates, core, paper, initial state."""
    return _set(NS(name=name, kind="wound", centre=tuple(centre), free=tuple(free), sense=-1,
                   core_radius=0.05, core_mass=40.0, core_inertia=0.1, width=5.0,
                   initial_radius=0.05, initial_speed=0.0, com_offset=0.0005, density=650.0,
                   caliper=70e-6, held_z=None), kw)


def rider(name: str, rides: str, **kw: Any) -> NS:
    """A rider roll on top of ``rides`` (machines.md §4): line-load schedule ``load``
    ``((radius [m], q [N/m]), ...)``."""
    return _set(NS(name=name, rides=rides, radius=0.15, mass=1500.0, inertia=25.0, x=0.0,
                   load=((0.05, 3000.0), (0.3, 300.0))), kw)


def nip(name: str, a: str, b: str, law: str = "linear", **kw: Any) -> NS:
    """A nip between bodies ``a`` and ``b`` with its own contact and friction objects."""
    return _set(NS(name=name, a=a, b=b, contact=contact(law), friction=friction()), kw)


def machine_scene(name: str, *, drums: Iterable[NS] = (), rolls: Iterable[NS] = (),
                  riders: Iterable[NS] = (), nips: Iterable[NS] = (),
                  web: NS | None = None, effect_flags: NS | None = None,
                  gravity: float = 9.81) -> NS:
    """A scene object with parts (what ``Machine(scene)`` reads; ``elements()`` as a
    :class:`winder.Scene`'s)."""
    sc = NS(name=name, scene=NS(name=name, gravity=gravity, duration=10.0, output_step=0.01),
            effects=effect_flags if effect_flags is not None else effects(),
            drums=tuple(drums), rolls=tuple(rolls), riders=tuple(riders), nips=tuple(nips),
            web=web)
    sc.elements = lambda: elements(sc)
    return sc


def elements(scene: Any) -> tuple[list[Any], list[Any]]:
    """The body and force elements of ``scene`` (as :meth:`winder.Scene.elements`)."""
    bodies = body_elements(scene)
    return bodies, force_elements(scene.effects, bodies)


def override(scene: NS, values: dict[str, Any]) -> NS:
    """Set values by dotted path: the first component names a part (drum, roll, rider,
    nip) or ``scene``/``web``/``effects``; returns ``scene`` (changed in place)."""
    parts = {p.name: p for group in (scene.drums, scene.rolls, scene.riders, scene.nips)
             for p in group}
    parts.update(scene=scene.scene, web=scene.web, effects=scene.effects)
    for path, value in values.items():
        head, *rest = path.split(".")
        obj = parts[head]
        for k in rest[:-1]:
            obj = getattr(obj, k)
        if not hasattr(obj, rest[-1]):
            raise KeyError(f"{path}: no such attribute")
        setattr(obj, rest[-1], value)
    return scene


def _set(obj: NS, kw: dict[str, Any]) -> NS:
    for k, v in kw.items():
        if not hasattr(obj, k):
            raise KeyError(f"{k!r}: not an attribute of {obj}")
        setattr(obj, k, v)
    return obj


# ---- whole machines -------------------------------------------------------------------------
def two_drum(*, drive: str = "speed_profile", law: str = "linear", rider_roll: bool = True,
             free: Iterable[str] = ("x", "z"), values: dict[str, Any] | None = None,
             **flags: bool) -> NS:
    """The two-drum winder of machines.md §10: drums ``front``/``rear`` at ``x = ∓0.525``,
    the set ``set`` in the valley (free ``x``, ``z``), a rider ``rider`` on top, nips
    ``front_nip``, ``rear_nip`` (the web's entry) and ``rider_nip``. ``drive``:
    ``speed_profile`` or ``torque`` (both drums); ``law`` of every nip; ``flags`` switch
    effects; ``values`` are :func:`override` paths."""
    mk = speed_profile if drive == "speed_profile" else torque_drive
    z0 = math.sqrt(0.55 ** 2 - 0.525 ** 2)
    drums = (drum("front", (-0.525, 0.0), mk()), drum("rear", (0.525, 0.0), mk()))
    rolls = (wound_roll("set", (0.0, z0), free),)
    nips = [nip("front_nip", "front", "set", law), nip("rear_nip", "rear", "set", law)]
    riders = ()
    if rider_roll:
        riders = (rider("rider", "set"),)
        nips.append(nip("rider_nip", "set", "rider", law))
    sc = machine_scene("two_drum", drums=drums, rolls=rolls, riders=riders, nips=nips,
                       web=NS(entry_nip="rear_nip", tension=1000.0),
                       effect_flags=effects(**flags))
    return override(sc, values or {})


def single_drum(*, drive: str = "speed_profile", law: str = "linear",
                free: Iterable[str] = ("z",), values: dict[str, Any] | None = None,
                **flags: bool) -> NS:
    """The single-drum machine of winder-model (the legacy format): drum ``drum`` at the
    origin, roll ``roll`` on top (free in ``free``), nip ``nip`` (the web's entry)."""
    mk = speed_profile if drive == "speed_profile" else torque_drive
    d = drum("drum", (0.0, 0.0), mk())
    r = wound_roll("roll", (0.0, 0.55), free)
    sc = machine_scene("single_drum", drums=(d,), rolls=(r,),
                       nips=(nip("nip", "drum", "roll", law),),
                       web=NS(entry_nip="nip", tension=200.0), effect_flags=effects(**flags))
    return override(sc, values or {})


def free_roll(*, free: Iterable[str] = ("x", "z"), values: dict[str, Any] | None = None,
              **flags: bool) -> NS:
    """One wound roll ``roll`` alone (no drum, no nip, no web): a free-flying body."""
    sc = machine_scene("free_roll", rolls=(wound_roll("roll", (0.0, 1.0), free),),
                       effect_flags=effects(**flags))
    return override(sc, values or {})


def state_matrix(system: Any, names: list[str], *, h: float) -> np.ndarray:
    """``∂ẏ/∂y`` of a :class:`~winder.solve.system.MachineSystem` over the states ``names``
    at its initial state, by central differences of step ``h`` [state units]."""
    idx = [system.index(k) for k in names]
    y0 = system.initial_state()
    A = np.empty((len(idx), len(idx)))
    for k, c in enumerate(idx):
        a, b = y0.copy(), y0.copy()
        a[c] += h
        b[c] -= h
        A[:, k] = (system.rhs(0.0, a)[idx] - system.rhs(0.0, b)[idx]) / (2 * h)
    return A
