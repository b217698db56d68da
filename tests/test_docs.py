"""The documentation site, checked without building it (no mkdocs needed): every page in
``nav``, the API page covering exactly ``winder.__all__``, every example in the gallery,
no link leaving ``docs/``, and the docstring markup converter (``tools/docs_site.py``)."""

from __future__ import annotations

import ast
import importlib.util
import re
import sys
from pathlib import Path

import pytest
import yaml

import winder

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _docs_site():
    spec = importlib.util.spec_from_file_location("docs_site", ROOT / "tools" / "docs_site.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("docs_site", module)
    spec.loader.exec_module(module)
    return module


site = _docs_site()


def _config() -> dict:
    return yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))


def _nav_pages(nav) -> list[str]:
    if isinstance(nav, str):
        return [nav]
    if isinstance(nav, list):
        return [p for item in nav for p in _nav_pages(item)]
    if isinstance(nav, dict):
        return [p for value in nav.values() for p in _nav_pages(value)]
    raise TypeError(f"unexpected nav entry {nav!r}")


def _pages() -> list[str]:
    return sorted(p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md"))


def test_config_points_at_the_tools():
    config = _config()
    assert config["docs_dir"] == "docs" and config["site_dir"] == "site"
    assert config["strict"] is True
    assert config["validation"]["omitted_files"] == "warn"  # an orphan fails --strict
    assert "tools/docs_site.py" in config["hooks"]
    (mkdocstrings,) = [p["mkdocstrings"] for p in config["plugins"]
                       if isinstance(p, dict) and "mkdocstrings" in p]
    options = mkdocstrings["handlers"]["python"]["options"]
    assert options["allow_inspection"] is False  # griffe reads src/, never imports winder
    for ext in options["extensions"]:
        assert (ROOT / ext.split(":")[0]).is_file()


def test_nav_lists_every_page_once():
    nav = _nav_pages(_config()["nav"])
    assert len(nav) == len(set(nav)), sorted(p for p in nav if nav.count(p) > 1)
    pages = _pages()
    assert sorted(set(pages) - set(nav)) == [], "pages under docs/ missing from mkdocs.yml nav"
    assert sorted(set(nav) - set(pages)) == [], "nav entries with no page under docs/"


def test_api_page_covers_exactly_winder_all():
    assert site.api_names() == list(winder.__all__)  # the static read is the real list
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    assert text.count(site.API_MARKER) == 1
    assert not re.search(r"(?m)^:::", text), "api.md is generated: no ::: blocks by hand"
    generated = re.findall(r"(?m)^::: winder\.(\w+)$", site.api_markdown())
    assert sorted(generated) == sorted(winder.__all__)
    assert len(generated) == len(set(generated))
    sections = site.api_sections()  # every name in one section ("Other": none claims it)
    assert sorted(n for _, names in sections for n in names) == sorted(winder.__all__)
    assert dict(sections)["Errors"] == sorted(["ArgumentError", "ArgumentTypeError",
                                               "BudgetExceeded", "ModelError", "SceneError",
                                               "SimulationError", "WinderError"], key=str.lower)


def test_every_public_name_is_defined_where_init_says():
    """griffe resolves ``winder.NAME`` through the module ``__init__`` names for it: each
    must bind NAME at its top level (a definition, an assignment or an import)."""
    where = site.api_modules()
    for name in winder.__all__:
        module = where[name]
        path = ROOT / "src" / "winder" / Path(*module.lstrip(".").split("."))
        path = path / "__init__.py" if path.is_dir() else path.with_suffix(".py")
        tree = ast.parse(path.read_text(encoding="utf-8"))
        bound = set()
        for node in tree.body:
            if isinstance(node, ast.ClassDef | ast.FunctionDef):
                bound.add(node.name)
            elif isinstance(node, ast.Assign | ast.AnnAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                bound |= {t.id for t in targets if isinstance(t, ast.Name)}
            elif isinstance(node, ast.ImportFrom):
                bound |= {a.asname or a.name for a in node.names}
        assert name in bound, f"winder.{name}: not bound at the top of {path}"


def test_every_example_is_in_the_gallery():
    gallery = (DOCS / "examples.md").read_text(encoding="utf-8")
    listed = re.findall(r"(?m)^### `(\w+\.py)`$", gallery)
    shipped = sorted(p.name for p in (ROOT / "examples").glob("*.py"))
    assert sorted(listed) == shipped
    for example in shipped:  # each says what it is for, as the gallery does
        doc = ast.get_docstring(ast.parse((ROOT / "examples" / example).read_text("utf-8")))
        assert doc and doc.startswith("Purpose: "), example
    for image in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", gallery):
        assert (DOCS / image).is_file(), image


def test_no_page_links_outside_docs_and_every_target_exists():
    for page in DOCS.rglob("*.md"):
        text = page.read_text(encoding="utf-8")
        assert site.links_outside(text, page, DOCS) == [], page
        for target in site.relative_links(text):
            assert (page.parent / target).exists(), (page, target)


def test_links_outside_finds_what_breaks_on_the_site():
    md = ("[a](../src/winder/x.py) [b](model.md#frames) ![c](examples/f.png) "
          "`[d](../in_code.md)` [e](https://example.org) [f](#anchor) [g](../README.md)\n"
          "```\n[h](../fenced.md)\n```\n")
    assert site.relative_links(md) == ["../src/winder/x.py", "model.md", "examples/f.png",
                                       "../README.md"]
    assert site.links_outside(md, DOCS / "index.md", DOCS) == ["../src/winder/x.py",
                                                               "../README.md"]
    guide = "[up](../model.md) [out](../../README.md) [deep](../../docs/model.md)"
    assert site.links_outside(guide, DOCS / "guide" / "page.md", DOCS) == ["../../README.md"]


@pytest.mark.parametrize(("rst", "markdown"), [
    (":class:`~winder.ArgumentError` and :func:`winder.load_scene`",
     "`ArgumentError` and `winder.load_scene`"),
    (":meth:`the step <winder.Stepper.step>`", "`the step`"),
    ("Parameters\n----------\nscene: the scene.\nrtol, atol: tolerances,\n    in (0, 0.1].",
     "**Parameters**\n\n- `scene`: the scene.\n- `rtol`, `atol`: tolerances,\n"
     "    in (0, 0.1]."),
    ("Text.\n\nRaises\n------\nSceneError\n    If bad.\n",
     "Text.\n\n**Raises**\n\n- `SceneError`:\n    If bad.\n"),
    ("t_end [s], rtol [-]: per run.", "t_end [s], rtol [-]: per run."),  # no section
    ("Attributes\n----------\nt_end [s], rtol [-]: per run.",
     "**Attributes**\n\n- `t_end [s]`, `rtol [-]`: per run."),
    ("Example::\n\n    code()\n", "Example:\n\n    code()\n"),
])
def test_rst_to_markdown(rst, markdown):
    assert site.rst_to_markdown(rst) == markdown


def test_the_docs_build_needs_no_winder_dependency():
    """The `docs` extra is the docs toolchain alone (`make docs` installs only it)."""
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"]
    docs = project["optional-dependencies"]["docs"]
    names = {re.split(r"[<>=\[ ]", d, maxsplit=1)[0].lower() for d in docs}
    assert {"mkdocs", "mkdocs-material", "mkdocstrings", "mkdocstrings-python"} <= names
    runtime = {re.split(r"[<>=\[ ]", d, maxsplit=1)[0].lower() for d in project["dependencies"]}
    assert not names & runtime
    assert all(re.search(r">=\d", d) for d in docs), "pinned minimum versions"


def test_comment_doc_reads_the_sphinx_attribute_comment():
    lines = ["x = 1", "#: first line", "#: second line", "FORCES = {}", "", "y = 2"]
    assert site.comment_doc(lines, 4) == "first line\nsecond line"
    assert site.comment_doc(lines, 6) is None
    assert site.comment_doc(lines, 1) is None


def _blocks(lang: str | None = None):
    """(page, info string, body) of every fenced block under docs/ and of the README
    (``lang``: that one)."""
    for page in [ROOT / "README.md", *sorted(DOCS.rglob("*.md"))]:
        text = page.read_text(encoding="utf-8")
        for info, body in re.findall(r"(?ms)^```(\w*)[^\n]*\n(.*?)^```", text):
            if lang is None or info == lang:
                yield page.relative_to(ROOT), info, body


def test_code_blocks_are_valid_python_and_toml():
    import tomllib

    from winder.scene import scene_from_dict

    pythons = tomls = 0
    for page, _, body in _blocks("python"):
        compile(body, f"{page} (python block)", "exec")
        pythons += 1
    for page, _, body in _blocks("toml"):
        data = tomllib.loads(body)
        if "scene" in data:  # a whole scene: it must load
            scene_from_dict(data, source=str(page))
        tomls += 1
    assert pythons >= 8 and tomls >= 3


def test_command_lines_in_the_docs_parse_with_the_real_cli():
    """Every ``winder ...`` line of a code block (not a synopsis with ``[options]``)
    parses with winder's own argument parser, and every ``models/*.toml`` it names
    exists."""
    import shlex

    from winder.cli import _build_parser

    parser = _build_parser()
    checked = 0
    for page, _, body in _blocks():
        for line in re.sub(r"\\\n\s*", " ", body).splitlines():
            if not re.match(r"\s*(\S*/)?winder\s", line) or " [" in line:
                continue
            words = shlex.split(line, comments=True)
            try:
                parser.parse_args(words[1:])
            except SystemExit as exc:
                raise AssertionError(f"{page}: {line.strip()!r} does not parse") from exc
            for word in words:
                if word.startswith("models/"):
                    assert (ROOT / word).is_file(), f"{page}: {word}"
            checked += 1
    assert checked >= 20


def test_readme_starts_and_stays_short():
    """The README: at most 300 lines, the two commands first, a quick start for one's own
    machine (a whole scene, ``winder run``, ``winder view``) within its first 60 lines,
    and every shipped scene in its table."""
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 300, len(lines)
    commands = [i for i, line in enumerate(lines) if line.strip().startswith("make ")]
    assert [lines[i].split()[1] for i in commands[:2]] == ["demo", "test"]
    head = "\n".join(lines[:60])
    assert "```toml" in head and "winder run " in head and "winder view " in head
    tables = {m for m in re.findall(r"^\| `([\w.]+\.toml)` \|", "\n".join(lines), re.M)}
    assert tables == {p.name for p in (ROOT / "models").glob("*.toml")}
