"""The documentation site's build helpers (``make docs``; mkdocs.yml ``hooks``).

Standard library only: ``tests/test_docs.py`` imports this module without mkdocs, and the
site is built without importing winder (griffe reads ``src/`` statically).

- :func:`api_names` and :func:`api_markdown`: the API reference (``docs/api.md``) is
  generated at build time from ``winder.__all__`` as written in ``src/winder/__init__.py``
  (read with :mod:`ast`, never imported), one ``::: winder.NAME`` block per public name,
  grouped by the module that defines it. :func:`on_page_markdown` is the mkdocs hook that
  puts it in place of :data:`API_MARKER`.
- :func:`rst_to_markdown`: the docstrings are written with Sphinx roles
  (``:class:`~winder.Scene```) and NumPy-style section headings (``Parameters`` over a
  dashed line, items ``name: meaning``); mkdocstrings renders Markdown. The griffe
  extension ``tools/griffe_rst.py`` passes every docstring through this function.
"""

from __future__ import annotations

import ast
import logging
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
INIT = ROOT / "src" / "winder" / "__init__.py"
#: The line of ``docs/api.md`` that the generated reference replaces.
API_MARKER = "<!-- winder.__all__ -->"

#: Sections of the API page, in order: (title, module prefixes relative to ``winder``).
#: A name is placed in the first section one of whose prefixes starts its module; a name
#: no section claims lands in "Other" (so a new public name is never left out).
API_SECTIONS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("Scenes", (".scene",)),
    ("Simulation", (".solve",)),
    ("Results and files", (".io",)),
    ("Resonance map", (".analysis.modes",)),
    ("Sweeps", (".analysis.sweep",)),
    ("Calibration", (".analysis.fit",)),
    ("Control design", (".analysis.control", ".analysis.plant", ".analysis.linearise")),
    ("FMU", (".fmu",)),
    ("Variable-mass core and the machine", (".model",)),
    ("Effects", (".forces",)),
    ("Errors", ("._errors",)),
)


def _literal(tree: ast.Module, name: str) -> ast.expr:
    for node in tree.body:
        targets = node.targets if isinstance(node, ast.Assign) else []
        if any(isinstance(t, ast.Name) and t.id == name for t in targets):
            return node.value
    raise LookupError(f"{INIT}: no assignment to {name}")


def api_names(init: Path = INIT) -> list[str]:
    """``winder.__all__`` as written in ``init`` (read statically, in its order)."""
    tree = ast.parse(init.read_text(encoding="utf-8"))
    return list(ast.literal_eval(_literal(tree, "__all__")))


def api_modules(init: Path = INIT) -> dict[str, str]:
    """Each name ``winder/__init__.py`` binds, to the module (relative to ``winder``,
    ``.solve.simulate``) it comes from: its top-level ``from winder.X import``
    statements and the lazy table ``_LAZY`` (``dict.fromkeys(names, module)`` entries)."""
    tree = ast.parse(init.read_text(encoding="utf-8"))
    where: dict[str, str] = {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("winder."):
            for alias in node.names:
                where[alias.asname or alias.name] = node.module[len("winder"):]
    lazy = _literal(tree, "_LAZY")
    if not isinstance(lazy, ast.Dict):
        raise TypeError(f"{init}: _LAZY is no dict display")
    for value in lazy.values:
        if not (isinstance(value, ast.Call) and len(value.args) == 2):
            raise TypeError(f"{init}: _LAZY entry {ast.unparse(value)} is no "
                            "dict.fromkeys(names, module)")
        names, module = (ast.literal_eval(a) for a in value.args)
        for name in names:
            where[name] = module
    return where


def api_sections(init: Path = INIT) -> list[tuple[str, list[str]]]:
    """The API page's sections with their names (each of ``winder.__all__`` once)."""
    where = api_modules(init)
    sections: dict[str, list[str]] = {title: [] for title, _ in API_SECTIONS}
    sections["Other"] = []
    for name in api_names(init):
        module = where.get(name, "")
        title = next((t for t, prefixes in API_SECTIONS
                      if any(module == p or module.startswith((p + ".", p + "_"))
                             for p in prefixes)), "Other")
        sections[title].append(name)
    return [(title, sorted(names, key=str.lower)) for title, names in sections.items()
            if names]


def api_markdown(init: Path = INIT) -> str:
    """The generated part of ``docs/api.md``: a heading per section, a ``:::`` block per
    public name."""
    lines: list[str] = []
    for title, names in api_sections(init):
        lines += [f"## {title}", ""]
        for name in names:
            lines += [f"::: winder.{name}", ""]
    return "\n".join(lines)


_FENCE = re.compile(r"(?ms)^ {0,3}(```|~~~).*?^ {0,3}\1[^\n]*$")
_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1", re.S)
_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def relative_links(markdown: str) -> list[str]:
    """The relative link and image targets of a page (not in code; no URL scheme, no bare
    ``#anchor``), without their ``#anchor``."""
    text = _CODE.sub("", _FENCE.sub("", markdown))
    text = re.sub(r"(?m)^(?: {4}|\t).*$", "", text)       # indented code blocks
    out = []
    for target in _LINK.findall(text):
        if re.match(r"[A-Za-z][A-Za-z0-9+.-]*:", target) or target.startswith(("#", "/")):
            continue
        out.append(target.split("#", 1)[0])
    return out


def links_outside(markdown: str, page: Path, docs: Path) -> list[str]:
    """The targets of ``page`` (a file under ``docs``) that leave ``docs``: they work on a
    repository browser but break on the site (``../src/winder/x.py``, ``../README.md``)."""
    root = docs.resolve()
    return [t for t in relative_links(markdown)
            if not (page.parent / t).resolve().is_relative_to(root)]


def on_page_markdown(markdown: str, page, config, files) -> str:  # noqa: ANN001 - mkdocs
    """mkdocs hook: a link out of ``docs/`` is a warning (``--strict``: an error); the API
    page gets its reference in place of :data:`API_MARKER`."""
    docs = Path(config["docs_dir"])
    for target in links_outside(markdown, docs / page.file.src_path, docs):
        logging.getLogger("mkdocs.hooks.docs_site").warning(
            "%s links to %r, outside docs/: it would break on the site (name the file "
            "in code, or link a page under docs/)", page.file.src_path, target)
    if API_MARKER not in markdown:
        return markdown
    return markdown.replace(API_MARKER, api_markdown())


# --- reST markup of the docstrings to Markdown ------------------------------------------

_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|mod|data|exc|obj|const|term):"
                   r"`(?P<body>[^`]+)`")
_NAME = r"\*{0,2}[A-Za-z_][\w.]*(?: \[[^\]]*\])?"   # a name, its unit: 't_end [s]'
_ITEM = re.compile(rf"^(?P<names>{_NAME}(?:\s*,\s*{_NAME})*):(?:\s+(?P<text>.*))?$")
_BARE = re.compile(r"^(?P<names>\*{0,2}[A-Za-z_][\w.]*(?:\s*,\s*\*{0,2}[A-Za-z_][\w.]*)*)"
                   r"(?:\s+:\s+(?P<type>.+))?$")


def comment_doc(lines: list[str], lineno: int) -> str | None:
    """The ``#:`` comment lines right above line ``lineno`` (1-based) of ``lines``: the
    Sphinx convention for documenting an assignment, which griffe does not read."""
    found: list[str] = []
    i = lineno - 2
    while i >= 0 and lines[i].lstrip().startswith("#:"):
        found.append(lines[i].lstrip()[2:].strip())
        i -= 1
    return "\n".join(reversed(found)) or None


def _role(match: re.Match[str]) -> str:
    body = match.group("body").strip()
    shown = re.match(r"(?s)(.*?)\s*<([^>]+)>$", body)
    if shown:  # :class:`text <target>`
        return f"`{shown.group(1)}`"
    if body.startswith("~"):
        body = body[1:].rsplit(".", 1)[-1]
    return f"`{body}`"


def rst_to_markdown(text: str) -> str:
    """A docstring's reST markup as Markdown: roles as code spans (``~`` keeps the last
    component), ``Title``/``-----`` sections as bold titles with their ``name: meaning``
    items as a list, a paragraph's closing ``::`` as ``:`` (its indented block stays a
    code block)."""
    text = _ROLE.sub(_role, text)
    out: list[str] = []
    lines = text.split("\n")
    in_section = False
    i = 0
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        if (re.fullmatch(r"[A-Z][A-Za-z ]+", line) and re.fullmatch(r"-{3,}", nxt)
                and len(nxt) >= len(line.strip()) - 1):
            if out and out[-1].strip():
                out.append("")
            out += [f"**{line.strip()}**", ""]
            in_section = True
            i += 2
            continue
        if in_section and line and not line[0].isspace():
            item = _ITEM.match(line)
            if item:
                names = ", ".join(f"`{n.strip()}`" for n in item.group("names").split(","))
                rest = item.group("text") or ""
                out.append(f"- {names}: {rest}".rstrip())
                i += 1
                continue
            bare = _BARE.match(line)
            if bare and nxt[:1].isspace() and nxt.strip():  # NumPy: 'name : type' over
                names = ", ".join(f"`{n.strip()}`" for n in bare.group("names").split(","))
                kind = f" ({bare.group('type').strip()})" if bare.group("type") else ""
                out.append(f"- {names}{kind}:")            # its indented meaning
                i += 1
                continue
            if out and out[-1].startswith(("- ", "    ")):
                out.append("")  # a plain paragraph after the list
        elif in_section and not line:
            pass
        out.append(line)
        i += 1
    md = "\n".join(out)
    md = re.sub(r"(?m)^[ \t]*::[ \t]*$", "", md)           # a lone '::'
    md = re.sub(r"(?m)(\S)[ \t]*::[ \t]*$", r"\1:", md)    # 'Example::' -> 'Example:'
    return md
