"""The numbers of the README and the docs pages against their sources
(benchmarks/doc_numbers.py): every ``<!-- numbers: NAME -->…<!-- /numbers -->`` block says
what its source gives (docs/numbers.json, the benchmarks' JSON, the scene files, closed
forms); one changed digit in any block fails; and, slow, docs/numbers.json against a
fresh run of the demo's scenes."""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, module)
    spec.loader.exec_module(module)
    return module


dn = _load("doc_numbers")


@pytest.fixture(scope="module")
def sources():
    return dn.Sources()


def _texts() -> dict[str, str]:
    return {p.relative_to(ROOT).as_posix(): p.read_text("utf-8") for p in dn.pages()}


def test_every_page_says_what_its_sources_give(sources):
    stale = [str(s) for page, text in _texts().items()
             for s in dn.check_text(text, page, sources)]
    assert stale == [], ("stale numbers (python benchmarks/doc_numbers.py --write fills "
                         "them):\n" + "\n".join(stale))


def test_every_number_is_on_a_page_and_every_block_names_one():
    used = {n for names in dn.used().values() for n in names}
    assert sorted(set(dn.RENDER) - used) == [], "numbers no page quotes"
    assert sorted(used - set(dn.RENDER)) == [], "blocks naming no number"
    assert "README.md" in dn.used()


def _bump(text: str) -> str:
    """The block's text with its first digit changed (9 -> 0, else +1)."""
    m = re.search(r"\d", text)
    assert m, f"a block without a digit: {text!r}"
    d = m.group()
    return text[: m.start()] + ("0" if d == "9" else str(int(d) + 1)) + text[m.end():]


def test_one_changed_digit_in_any_block_fails(sources):
    """Every block of every page, one at a time: its first digit changed, the check names
    that block (page, line, name), and filling the page restores it (up to its line
    breaks)."""
    n = 0
    for page, text in _texts().items():
        for m in dn.BLOCK.finditer(text):
            changed = (text[: m.start("text")] + _bump(m.group("text"))
                       + text[m.end("text"):])
            stale = dn.check_text(changed, page, sources)
            line = text.count("\n", 0, m.start()) + 1
            assert [(s.page, s.line, s.name) for s in stale] == \
                [(page, line, m.group("name"))], (page, line)
            filled = dn.fill_text(changed, sources)
            assert dn.check_text(filled, page, sources) == []
            assert filled.split() == text.split()  # the same words; a wrap may move
            n += 1
    assert n >= 30


def test_the_blocks_syntax(sources):
    ok = "a <!-- numbers: flex.segments -->8<!-- /numbers --> b"
    assert dn.blocks(ok) == [("flex.segments", "8", 1)]
    for bad in ("a <!-- numbers: flex.segments -->8 b",                   # not closed
                "a 8<!-- /numbers --> b",                                  # not opened
                "<!-- numbers: a -->1 <!-- numbers: b -->2<!-- /numbers -->"
                "<!-- /numbers -->",                                        # nested
                "text\n<!-- numbers: flex.segments -->8<!-- /numbers --> more"):  # line start
        with pytest.raises(ValueError):
            dn.blocks(bad)
    table = "x\n\n<!-- numbers: flex.segments -->\n\n8\n\n<!-- /numbers -->\n"
    assert dn.check_text(table, "t.md", sources) == []
    with pytest.raises(KeyError, match="no such number"):
        dn.check_text("a <!-- numbers: nope -->1<!-- /numbers -->", "t.md", sources)


def test_the_closed_forms_against_the_flexible_drum_test():
    """The rotary inertia's closed form here is the one of tests/parts/test_flex_rotary.py
    (the Timoshenko equation on stiff bearings): the same drum, the same numbers."""
    spec = importlib.util.spec_from_file_location(
        "flex_rotary", ROOT / "tests" / "parts" / "test_flex_rotary.py")
    ft = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ft)
    import math
    for k in (1, 2):
        kappa = k * math.pi / ft.L
        a, c = ft.RHO_A * ft.RHO_I / ft.KGA, ft.EI * kappa ** 4
        b = ft.RHO_A + ft.RHO_I * kappa ** 2 + ft.RHO_A * ft.EI * kappa ** 2 / ft.KGA
        want = math.sqrt((b - math.sqrt(b * b - 4 * a * c)) / (2 * a)) / (2 * math.pi)
        got = dn._timoshenko(k, length=ft.L, ro=ft.RO, wall=ft.WALL, rotary=True)
        assert got == pytest.approx(want, rel=1e-12)


def test_differences_name_what_moved():
    rn = _load("readme_numbers")
    old = json.loads(dn.NUMBERS_JSON.read_text("utf-8"))
    assert rn.differences(old, old) == []
    new = json.loads(dn.NUMBERS_JSON.read_text("utf-8"))
    new["two_drum_winder"]["peak_band"]["rider_nip"] *= 1.002  # beyond 1e-3
    new["two_drum_winder"]["run"]["wall_time"] *= 3  # wall times are not compared
    new["two_drum_winder"]["run"]["events"] += 100  # within 2 %
    a, b = (x["two_drum_winder"]["peak_band"]["rider_nip"] for x in (old, new))
    assert rn.differences(old, new) == [f".two_drum_winder.peak_band.rider_nip: {a!r} against "
                                        f"{b!r}"]


@pytest.mark.slow
def test_numbers_json_against_a_fresh_run(tmp_path):
    """docs/numbers.json against the scenes run afresh (benchmarks/readme_numbers.py,
    minutes): every number within 1e-3 relative (the runs are deterministic on one
    machine; the margin is for another compiler's rounding), the event and evaluation
    counts within 2 %, the wall times not compared."""
    rn = _load("readme_numbers")
    old = json.loads(dn.NUMBERS_JSON.read_text("utf-8"))
    assert rn.differences(old, rn.pages_numbers(tmp_path)) == []


def test_unmarked_lists_the_numbers_outside_blocks_and_code():
    page = ("a <!-- numbers: flex.segments -->8.5 s<!-- /numbers --> and `2.5 s` and 4.67 1/s"
            "\n\n```text\n3.5 s\n```\nsection 2. then 71.9° at 132.9 rad/s\n")
    assert dn.unmarked(page) == [(1, "4.67"), (6, "71.9°"), (6, "132.9 rad/s")]


def test_the_dancer_designs_phase_margin_against_python_control():
    """The closed form of the dancer design's phase margin (the page's "at every radius")
    is python-control's margin of the design loop ``(3ω_c s² + 3ω_c² s + ω_c³)/s³``, at
    two bandwidths."""
    import control

    guide = _load("doc_numbers_guide")
    for wc in (2.0, 5.0):
        _, pm, _, _ = control.margin(control.tf([3 * wc, 3 * wc**2, wc**3], [1, 0, 0, 0]))
        assert guide.design_phase_margin() == pytest.approx(pm, abs=1e-6)


@pytest.mark.slow
def test_guide_numbers_json_against_a_fresh_run():
    """docs/guide_numbers.json (the web-line page's loops and modes, control.md's MPC)
    against a fresh run of benchmarks/guide_numbers.py (a few minutes): every number within
    1e-3 relative, the timings and the load not compared."""
    rn, gn = _load("readme_numbers"), _load("guide_numbers")
    old = json.loads((ROOT / "docs" / "guide_numbers.json").read_text("utf-8"))
    assert rn.differences(old, json.loads(json.dumps(gn.guide_numbers()))) == []


def test_a_dated_record_names_its_date_and_commit_and_is_left_out():
    """docs/speed.md is a dated record (its numbers of 2026-11-23, before the C
    integrators): marked with its date and commit, left out of ``--unmarked``."""
    text = (ROOT / "docs" / "speed.md").read_text("utf-8")
    m = dn.DATED.search(text)
    assert m is not None and (m["date"], m["commit"]) == ("2026-11-23", "c83a5c7")
    assert m["date"] in text.split("-->", 2)[1] and m["commit"] in text
    assert dn.DATED.search("<!-- dated record: 2026-11-23 -->") is None  # no commit
