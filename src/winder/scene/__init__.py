"""Scenes (spec section 7; machines spec §8): each key declared once
(:mod:`winder._schema`, the parts' ``KEYS``, :mod:`winder.scene.schema`), read and
checked into a frozen :class:`Scene`.

Modules, one job each: ``schema`` (the tables of keys that are no part's), ``tables``
(``[scene]``, ``[effects]``, ``[paper]``, ``[solver]`` dataclasses), ``parse`` (one table
against its keys), ``parts`` (a scene of parts), ``checks`` (references, overlaps, cores),
``naming`` (how a scene names channels, keys and FMU variables), ``legacy`` (the
single-drum format, translated into parts, with its names), ``validate`` (a whole scene),
``scene`` (:class:`Scene`), ``load`` (files), ``keys`` (units and meanings), ``paths``
(dotted key paths), ``reference`` (``docs/scene-reference.md``).
"""

from winder.scene.keys import key_doc, key_unit
from winder.scene.legacy import (
    CHANNELS,
    EXTRA_CHANNELS,
    SINGLE_DRUM,
    LegacyContact,
    LegacyFriction,
)
from winder.scene.load import load_scene
from winder.scene.naming import Naming, naming_of
from winder.scene.scene import Scene, scene_from_dict
from winder.scene.schema import BACKENDS, DRIVE_KINDS, EFFECT_NAMES, MAX_SAMPLES, METHODS
from winder.scene.tables import Effects, Paper, SceneInfo, Solver

__all__ = ["Scene", "SceneInfo", "Effects", "Paper", "Solver", "LegacyContact",
           "LegacyFriction", "Naming", "naming_of", "SINGLE_DRUM", "CHANNELS",
           "EXTRA_CHANNELS", "load_scene", "scene_from_dict", "key_unit", "key_doc",
           "EFFECT_NAMES", "DRIVE_KINDS", "METHODS", "BACKENDS", "MAX_SAMPLES"]
