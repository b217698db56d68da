"""A channel declared once (:class:`winder._schema.Channel`) and a scene's naming
(:mod:`winder.scene.naming`): the single-drum format's names come from its one module,
translated from the machine's, and everything else asks the scene's naming."""

from __future__ import annotations

from pathlib import Path

import pytest

import winder
from winder._schema import Channel
from winder.scene import Naming, naming_of
from winder.scene.legacy import COLUMNS, SINGLE_DRUM
from winder.solve.system import MachineSystem

ROOT = Path(__file__).resolve().parents[2]


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
    # a result without its scene: the naming that reads one, and the bodies it draws
    assert naming_of(None) == SINGLE_DRUM and not Naming.bodies_without_scene
    assert dict(naming_of(None).bodies_without_scene) == {
        "drum": ("angle", "speed"), "roll": ("z", "angle", "speed", "radius")}
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


#: Modules outside ``winder/scene`` allowed to name the single-drum format's names, each
#: with the names it may use: none (an entry that no longer violates fails the test).
STILL_NAMING: dict[str, set[str]] = {}
#: The package's public names of the single-drum columns (``winder.CHANNELS``, lazily from
#: :mod:`winder.scene`): the one place outside the scene package that names them.
PUBLIC = {"src/winder/__init__.py": {"CHANNELS", "EXTRA_CHANNELS"}}


def test_only_the_scene_package_knows_the_single_drum_format():
    """Outside ``winder/scene`` no module reads ``scene.legacy``, imports
    :mod:`winder.scene.legacy` or names a ``LEGACY_`` table, nor names the single-drum
    format's naming, columns or keys (``SINGLE_DRUM``, ``CHANNELS``, ``EXTRA_CHANNELS``,
    ``by_parts``, ``initial_height``): they ask the scene's naming (a docstring may point
    to the module; an element's own ``CHANNELS`` declarations are no legacy names)."""
    import re

    files = [p for p in (ROOT / "src" / "winder").rglob("*.py") if "scene" not in p.parts]
    files += sorted((ROOT / "viewer").glob("*.py"))
    pattern = re.compile(r"\.legacy\b(?!`)|\blegacy\s+import|\bLEGACY|_legacy\b")
    hits = [f"{p.relative_to(ROOT)}:{i}" for p in files
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if pattern.search(line)]
    assert not hits
    names = {
        "SINGLE_DRUM": re.compile(r"\bSINGLE_DRUM\b"),
        "EXTRA_CHANNELS": re.compile(r"\bEXTRA_CHANNELS\b"),
        # the legacy tuple, not an element's ``CHANNELS`` (``self.CHANNELS``, a class body's
        # ``CHANNELS = (...)``, ````CHANNELS```` in a docstring)
        "CHANNELS": re.compile(r"(?<![\w.`])CHANNELS\b|\bwinder\.CHANNELS\b"),
        "by_parts": re.compile(r"\bby_parts\b"),
        "initial_height": re.compile(r"\binitial_height\b"),
    }
    declaration = re.compile(r"^\s+CHANNELS\s*(:[^=]*)?=")
    assert names["CHANNELS"].search("from winder.scene import CHANNELS")
    assert names["CHANNELS"].search("out = winder.CHANNELS[1:]")
    assert not names["CHANNELS"].search("for ch in b.CHANNELS:")
    assert declaration.match("    CHANNELS = (Channel(name=...),)")
    found: dict[str, set[str]] = {}
    for p in files:
        for line in p.read_text(encoding="utf-8").splitlines():
            for name, pat in names.items():
                if pat.search(line) and not (name == "CHANNELS" and declaration.match(line)):
                    found.setdefault(str(p.relative_to(ROOT)), set()).add(name)
    for path, allowed in {**STILL_NAMING, **PUBLIC}.items():
        assert found.get(path, set()) == allowed, \
            f"{path}: names {sorted(found.get(path, set()))}, allow-list {sorted(allowed)}"
    assert {p: n for p, n in found.items() if p not in {**STILL_NAMING, **PUBLIC}} == {}
