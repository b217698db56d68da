"""The command line's surface: ``--version``, a help text for every option of every
subcommand, and unknown-key messages that list every key of the table (sub-tables too)."""

from __future__ import annotations

import argparse
import re
from importlib import metadata
from pathlib import Path

from winder.cli import _build_parser, main
from winder.scene.legacy import LEGACY_TABLES

ROOT = Path(__file__).resolve().parents[2]


def _actions(parser: argparse.ArgumentParser, path: tuple[str, ...] = ("winder",)):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _actions(sub, (*path, name))
        else:
            yield path, action


def test_version_is_the_installed_package(capsys) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"winder {metadata.version('winder')}"


def test_every_option_has_help() -> None:
    missing = [f"{' '.join(path)} {'/'.join(a.option_strings) or a.dest}"
               for path, a in _actions(_build_parser())
               if not isinstance(a, argparse._HelpAction) and not a.help]
    assert not missing, missing


def test_unknown_drum_key_lists_every_key_of_the_table(tmp_path: Path, capsys) -> None:
    """``[drum] web_speed`` (a drive key one level too high): the message lists the drum's
    keys and its sub-table ``drive``, where the key belongs."""
    text = (ROOT / "models" / "paper_winding.toml").read_text()
    scene = tmp_path / "s.toml"
    scene.write_text(text.replace("mass = 2000.0", "mass = 2000.0\nweb_speed = 20.0", 1))
    assert main(["run", str(scene), "--out", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    listed = re.search(r"valid keys: (.*)\)?$", err, re.M)
    assert listed, err
    assert {k.strip(" )") for k in listed.group(1).split(",")} == {
        *LEGACY_TABLES["drum"].names(), "drive"}
    assert not list(tmp_path.glob("r.*"))
