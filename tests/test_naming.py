"""A channel declared once (:class:`winder._schema.Channel`) and a scene's naming
(:mod:`winder.scene.naming`): the single-drum format's names come from its one module,
translated from the machine's, and everything else asks the scene's naming."""

from __future__ import annotations

from pathlib import Path

import pytest

import winder
from winder._schema import Channel
from winder.scene import SINGLE_DRUM, Naming, naming_of
from winder.scene.legacy import COLUMNS
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[1]


def test_channel_declaration_names_its_channels():
    speed = Channel(name="BODY_speed", unit="rad/s", doc="speed")
    assert (speed.placeholder, speed.suffix, speed.of("front")) == ("BODY", "speed",
                                                                   "front_speed")
    web = Channel(name="web_speed", unit="m/s", doc="web speed")
    assert (web.placeholder, web.of(), web.of("a_")) == ("", "web_speed", "a_web_speed")
    with pytest.raises(ValueError, match="needs its name"):
        speed.of()
    with pytest.raises(TypeError, match="unit must be a non-empty string"):
        Channel(name="x", unit="", doc="x")
    with pytest.raises(ValueError, match="doc must say"):
        Channel(name="x", unit="m", doc="")


def test_machine_registers_declarations_only():
    """``Machine.channel`` takes a declaration (its unit with it), not a unit literal."""
    system = MachineSystem(winder.load_scene(ROOT / "models" / "two_drum_winder.toml"),
                           backend="pinocchio")
    with pytest.raises(TypeError, match="a Channel declaration"):
        system.machine.channel("front_speed", "rad/s")  # type: ignore[arg-type]
    extra = Channel(name="BODY_extra", unit="N", doc="an extra channel")
    assert system.machine.channel(extra, "front") == "front_extra"
    assert system.machine.channel_units["front_extra"] == "N"


def test_keys_in_messages_by_format():
    """The message path of a part's key: by part in a scene of parts, the single-drum
    format's tables for its scene (each pair by hand)."""
    parts = Naming()
    assert parts.key("drum", "front", "drive") == "[[drum]] 'front' drive"
    assert parts.key("nip", "n", "friction", "mu") == "[[nip]] 'n' friction mu"
    assert parts.key("roll", "r", "centre") == "[[roll]] 'r' centre"
    assert SINGLE_DRUM.key("drum", "drum", "drive") == "[drum.drive]"
    assert SINGLE_DRUM.key("nip", "nip", "friction", "mu") == "[friction] mu"
    assert SINGLE_DRUM.key("nip", "nip", "contact", "stiffness") == "[contact] stiffness"
    assert SINGLE_DRUM.key("roll", "roll", "core_radius") == "[roll] core_radius"
    assert SINGLE_DRUM.key("roll", "roll", "centre") == "[roll] initial_radius"
    assert SINGLE_DRUM.key("drum", "drum", "centre") == "[drum] radius"


def test_scene_naming_and_single_drum_columns():
    """A single-drum scene names its columns by winder-model §8 (each the machine's
    channel of drum, roll or nip, renamed), in the declared unit even where the machine
    lacks the channel (``web_force`` with ``web_momentum`` off); a scene of parts keeps the
    machine's names."""
    paper = winder.load_scene(ROOT / "models" / "paper_winding.toml")
    parts = winder.load_scene(ROOT / "models" / "two_drum_winder.toml")
    assert paper.naming is SINGLE_DRUM and not paper.naming.by_parts
    assert type(parts.naming) is Naming and parts.naming.by_parts
    assert naming_of(object()).by_parts  # a plain scene object: by parts
    assert (*winder.CHANNELS, *winder.EXTRA_CHANNELS) == ("t", *COLUMNS)
    assert SINGLE_DRUM.output_name("roll_radius") == "radius"
    assert SINGLE_DRUM.output_name("nip_normal_force") == "normal_force"
    assert SINGLE_DRUM.output_name("drum_speed") == "drum_speed"
    off = paper.replace(effects={"web_momentum": False})
    system = MachineSystem(off, backend="pinocchio")
    assert "web_force" not in system.machine.channel_units
    assert system.channel_units["web_force"] == "N"
    assert system.channel_units["radius"] == "m" and system.channel_units["z"] == "m"
    assert tuple(system.channel_units) == (*winder.CHANNELS, *winder.EXTRA_CHANNELS)
    system = MachineSystem(parts, backend="pinocchio")
    assert list(system.channel_units)[1:] == system.machine.channel_names


def test_only_the_scene_package_knows_the_single_drum_format():
    """Outside ``winder/scene`` no module reads ``scene.legacy``, imports
    :mod:`winder.scene.legacy` or names a ``LEGACY_`` table: they ask the scene's naming
    (a docstring may point to the module)."""
    import re

    files = [p for p in (ROOT / "src" / "winder").rglob("*.py") if "scene" not in p.parts]
    files += sorted((ROOT / "viewer").glob("*.py"))
    pattern = re.compile(r"\.legacy\b(?!`)|\blegacy\s+import|\bLEGACY|_legacy\b")
    hits = [f"{p.relative_to(ROOT)}:{i}" for p in files
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if pattern.search(line)]
    assert not hits
