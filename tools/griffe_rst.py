"""Griffe extension of the docs build (mkdocs.yml, mkdocstrings ``extensions``): every
docstring's reST markup (Sphinx roles, NumPy-style section headings) as Markdown, by
:func:`docs_site.rst_to_markdown`. Runs on griffe's static visit: winder is never
imported."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import griffe

sys.path.insert(0, str(Path(__file__).resolve().parent))
from docs_site import rst_to_markdown  # noqa: E402


class RstToMarkdown(griffe.Extension):
    """Rewrite each object's docstring once, when griffe has visited it."""

    def on_instance(self, *, obj: Any, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = rst_to_markdown(obj.docstring.value)
