"""Griffe extension of the docs build (mkdocs.yml, mkdocstrings ``extensions``): every
docstring's reST markup (Sphinx roles, NumPy-style section headings) as Markdown, by
:func:`docs_site.rst_to_markdown`, and ``#:`` comments as attribute docstrings. Runs on
griffe's static visit: winder is never imported."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import griffe

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docs_site import comment_doc, rst_to_markdown  # noqa: E402


class RstToMarkdown(griffe.Extension):
    """Rewrite each object's docstring once, when griffe has visited it; an attribute
    without one takes its ``#:`` comment (``FORCES``, ``CHANNELS``, class variables)."""

    def on_instance(self, *, obj: Any, **kwargs: Any) -> None:
        if obj.docstring is None and obj.is_attribute and obj.lineno:
            found = obj.filepath is not None and obj.filepath in obj.lines_collection
            text = comment_doc(obj.lines_collection[obj.filepath] if found else [], obj.lineno)
            if text:
                obj.docstring = griffe.Docstring(text, lineno=obj.lineno, parent=obj)
        if obj.docstring is not None:
            obj.docstring.value = rst_to_markdown(obj.docstring.value)
