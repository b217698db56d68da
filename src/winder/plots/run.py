"""The figures of a run: the paper's figures of a single-drum scene
(:func:`winder.plots.figures.paper_figures`), the machine's of a scene of parts
(:func:`winder.plots.machine.machine_figures`)."""

from __future__ import annotations

from pathlib import Path

from winder.io.result import Result
from winder.plots.figures import paper_figures
from winder.plots.machine import machine_figures
from winder.scene.load import Scene

__all__ = ["run_figures"]


def run_figures(result: Result, out_dir: str | Path, *, scene: Scene | None = None,
                closeup: Result | None = None) -> list[Path]:
    """Write the figures of ``result`` into ``out_dir`` (``closeup``: a single-drum scene's
    finely sampled first lift-off); returns the paths."""
    if "normal_force" not in result:  # a scene of parts: its channels are the parts'
        return machine_figures(result, out_dir, scene=scene)
    return paper_figures(result, out_dir, scene=scene, closeup=closeup)
