"""Part roles (issue #34): every body type declares what it is to the rest of the machine
(:class:`winder.parts.Roles`), and the scene's checks ask those roles, not table names.

Expectations come from the registry :data:`winder.parts.PARTS` and the shipped scenes: a
new body type is checked by declaring its roles, and a type that declares the roles of an
entry drum is one (a web may enter a wound roll from it) whatever its table."""

from __future__ import annotations

import copy
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

import winder
from winder.model.slices import segments_of
from winder.parts import NIP_ROLES, PARTS, WEB_ROLES, DrumBody, Roles, body_elements

MODELS = Path(__file__).resolve().parents[2] / "models"
SHIPPED = sorted(MODELS.glob("*.toml"))


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_every_part_declares_its_roles(path: Path) -> None:
    """Each part of each shipped scene, by its registered type: roles from the declared
    vocabulary, a fixed centre exactly where the type says, ``rides`` naming a paper
    roll, the segments where the type builds them; and each body element carries its
    part's roles, a segment itself as its :attr:`segment`."""
    scene = winder.load_scene(path)
    roles: dict[str, Roles] = {}
    for attr, cls in PARTS.items():
        for part in scene.bodies[attr]:
            r = cls.roles_of(part)
            assert isinstance(r, Roles)
            assert r.web is None or r.web in WEB_ROLES
            assert r.nip in NIP_ROLES
            assert cls.fixed_centre(part) == r.fixed
            assert r.segments == (len(cls.elements(part, _placed(scene, part)))
                                  if r.segments else None)
            roles[part.name] = r
    for name, r in roles.items():
        if r.rides is not None:
            assert roles[r.rides].paper, name
    wound = [n for n, r in roles.items() if r.web == "winds"]
    entries = {next(n.b for n in scene.nips if n.name == w.entry_nip) for w in scene.webs}
    assert set(wound) == entries  # every wound roll fed by one web (the checks passed)
    elements = body_elements(scene)
    for b in elements:
        whole = b.segment_of or b.name
        assert b.roles == roles[whole]
        assert (b.segment is b) == (b.segment_of is not None)
    groups = segments_of(elements)
    assert {n: len(s) for n, s in groups.items()} == \
        {n: r.segments for n, r in roles.items() if r.segments}


def _placed(scene: Any, part: Any) -> dict[str, Any]:
    """The body elements built before ``part`` (a rider needs the roll it rides)."""
    return {b.name: b for b in body_elements(scene)}


class FeedRoller(DrumBody):
    """A ``[[feed]]`` roller: a drum's keys and drive; the web wraps it, like a drum's."""

    table = "feed"

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        return Roles(web="wraps", nip="fixed")


class DeadDrum(DrumBody):
    """A ``[[dead]]`` drum that carries no web: its roles say so."""

    table = "dead"

    @classmethod
    def roles_of(cls, part: Any) -> Roles:
        return Roles(nip="fixed")


def _two_drum() -> dict[str, Any]:
    return tomllib.loads((MODELS / "two_drum_winder.toml").read_text(encoding="utf-8"))


@pytest.mark.parametrize("cls", [FeedRoller, DeadDrum])
def test_checks_ask_roles_not_tables(cls: type, monkeypatch: pytest.MonkeyPatch) -> None:
    """The rear drum moved to a new table: as a type whose roles say the web wraps it, the
    web enters the set from it; as one that carries no web, the same scene is refused
    naming the entry nip and no valid one (the checks never read a table's name)."""
    monkeypatch.setitem(PARTS, f"{cls.table}s", cls)
    data = _two_drum()
    rear = next(d for d in data["drum"] if d["name"] == "rear")
    data["drum"].remove(rear)
    data[cls.table] = [rear]
    if cls is FeedRoller:
        scene = winder.scene_from_dict(copy.deepcopy(data), source="<feed>")
        assert scene.bodies["feeds"][0].name == "rear"
        assert scene.web.entry_nip == "rear_nip"
    else:
        with pytest.raises(winder.SceneError,
                           match=r"\[web\] entry_nip: 'rear_nip' is nip 'rear_nip' joining "
                                 r"dead 'rear' \(a\) and roll 'set' \(b\).*valid names: "
                                 r"front_nip"):
            winder.scene_from_dict(copy.deepcopy(data), source="<dead>")


def test_roles_validate() -> None:
    """Roles outside the vocabulary, a ``rides`` without riding, are refused."""
    with pytest.raises(ValueError, match="web"):
        Roles(web="pulls")
    with pytest.raises(ValueError, match="nip"):
        Roles(nip="floating")
    with pytest.raises(ValueError, match="rides"):
        Roles(nip="free", rides="set")
    with pytest.raises(ValueError, match="rides"):
        Roles(nip="riding")
    assert replace(Roles(), nip="free").fixed is False
