"""The free coordinates of a machine's bodies (``STEM_positions.png``), at any scale.

A rigid body gets a row per free coordinate (``x``, ``z``) and, after ``z``, its bounce
(``z`` less its centred mean, :func:`winder.plots.smooth.bounce`). A flexible body gets
one set of rows whatever its number of segments: the motion of its axis (the mean of its
segments, less its value at the start), the bounce of that mean, and per free coordinate a
heat map of each segment's deflection (position along the width × time,
:func:`winder.plots.flex.deflection`). The rows are packed onto pages of at most
:data:`winder.plots.layout.MAX_HEIGHT_PX` (a body's rows on one page): a machine with more
bodies than fit gets ``STEM_positions_2.png``, ... (:func:`winder.plots.layout.pages`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from winder.io.result import Result
from winder.parts import BodyElement
from winder.plots.flex import FlexBody, deflection, flexible_bodies
from winder.plots.layout import HEADER, ROW, page_suffix, pages
from winder.plots.smooth import bounce

__all__ = ["FigureBody", "figure_bodies", "positions_figures", "BOUNCE_WINDOW"]

#: The window of the centred mean the bounce is taken from [s].
BOUNCE_WINDOW = 0.5


@dataclass(frozen=True)
class FigureBody:
    """A body as the figures draw it: a part (``name``, ``role``) and its body elements
    (one for a rigid body; a flexible body's segments, ``flex`` its layout)."""

    name: str
    role: str
    elements: tuple[BodyElement, ...]
    flex: FlexBody | None = None

    @property
    def label(self) -> str:
        """``roll set``; a flexible body says its segments (``roll set, 8 segments``)."""
        more = f", {len(self.elements)} segments" if self.flex is not None else ""
        return f"{self.role} {self.name}{more}"


def figure_bodies(scene: Any, elements: list[BodyElement]) -> list[FigureBody]:
    """The parts of ``scene`` in the order of their ``elements``: a flexible body's
    segments (:attr:`BodyElement.segment_of`) grouped into one."""
    flex = {b.name: b for b in flexible_bodies(scene)}
    out: dict[str, list[BodyElement]] = {}
    for e in elements:
        out.setdefault(getattr(e, "segment_of", None) or e.name, []).append(e)
    return [FigureBody(name, els[0].role, tuple(els), flex.get(name) if
                       getattr(els[0], "segment_of", None) else None)
            for name, els in out.items()]


@dataclass(frozen=True)
class _Row:
    """One row of the figure: ``draw(axes, colour-bar axes)``; ``heat``: it uses the
    colour-bar axes."""

    draw: Callable[[plt.Axes, plt.Axes], None]
    heat: bool = False


def _title(ax: plt.Axes, text: str) -> None:
    ax.set_title(text, fontsize=10)
    ax.grid(True, alpha=0.3)


def _bounce_row(result: Result, y: np.ndarray, label: str, what: str, unit_mm: str) -> _Row:
    t = result.t

    def draw(ax: plt.Axes, _: plt.Axes) -> None:
        tb, b, used = bounce(t, y, BOUNCE_WINDOW)
        ax.plot(tb, 1e3 * b, lw=0.4, label=label)
        ax.set_ylabel("bounce" + unit_mm)
        edge = f" (none in the first and last {used / 2:.3g} s)" if len(tb) \
            else " (the run is shorter than a window)"
        _title(ax, f"{what}: bounce, less its centred mean over {used:.3g} s{unit_mm}{edge}")
        ax.legend(fontsize=8, loc="upper left")
    return _Row(draw)


def _rigid_rows(result: Result, body: FigureBody, units: Callable[[str, str], str]
                ) -> list[_Row]:
    e = body.elements[0]
    t = result.t
    rows = []
    for c in ("x", "z"):
        channel = f"{e.name}_{c}"
        if channel not in result:
            continue
        y = result[channel]
        unit = units(channel, "")

        def draw(ax: plt.Axes, _: plt.Axes, y=y, c=c, unit=unit) -> None:
            ax.plot(t, y, lw=0.5, label=f"{e.name} {c}")
            ax.set_ylabel(c + unit)
            _title(ax, f"{e.name}: {'horizontal' if c == 'x' else 'vertical'} position "
                   f"{c}{unit}")
            ax.legend(fontsize=8, loc="upper left")
        rows.append(_Row(draw))
        if c == "z":  # the rise with the radius hides the bounce: show it apart
            rows.append(_bounce_row(result, y, f"{e.name} z − mean", e.name,
                                    units(channel, "m")))
    return rows


def _flex_rows(result: Result, body: FigureBody, units: Callable[[str, str], str]
               ) -> list[_Row]:
    fb = body.flex
    t = result.t
    coords = [c for c in ("x", "z")
              if all(f"{e.name}_{c}" in result for e in body.elements)]
    if not coords or fb is None:
        return []
    mean = {c: np.mean([result[f"{e.name}_{c}"] for e in body.elements], axis=0)
            for c in coords}
    mm = units(f"{body.elements[0].name}_{coords[0]}", "m")
    n = len(body.elements)

    def axis(ax: plt.Axes, _: plt.Axes) -> None:
        for c in coords:
            ax.plot(t, 1e3 * (mean[c] - mean[c][0]), lw=0.6, label=f"{c} − {c}(0)",
                    ls="-" if c == "x" else "--")
        ax.set_ylabel(", ".join(f"Δ{c}" for c in coords) + mm)
        _title(ax, f"{body.label}: motion of its axis (the mean of its {n} segments) "
               f"from the start{mm}")
        ax.legend(fontsize=8, loc="upper left")
    rows = [_Row(axis)]
    if "z" in coords:
        rows.append(_bounce_row(result, mean["z"], f"{body.name} mean z − its mean",
                                f"{body.name}'s axis", mm))
    ref = "from its bearings' line" if fb.support is not None else \
        "from the segments' mean (bending only)"
    for c in ("z", "x"):
        if c not in coords:
            continue
        d = 1e3 * deflection(result, fb, c)

        def heat(ax: plt.Axes, cax: plt.Axes, d=d, c=c) -> None:
            top = float(np.max(np.abs(d))) or 1e-9
            mesh = ax.pcolormesh(t, fb.stations, d.T, shading="nearest", cmap="RdBu_r",
                                 vmin=-top, vmax=top, rasterized=True)
            plt.colorbar(mesh, cax=cax, label=f"{c} deflection [mm]")
            ax.set_ylabel("along the width y [m]")
            ax.set_ylim(0.0, fb.length)
            ax.set_title(f"{body.name}: {c} deflection of each of its {n} segments {ref} "
                         f"(largest {top:.3g} mm)", fontsize=10)
        rows.append(_Row(heat, heat=True))
    return rows


def positions_figures(result: Result, scene: Any, elements: list[BodyElement], out: Path,
                      stem: str, name: str, units: Callable[[str, str], str],
                      save: Callable[[plt.Figure, Path], Path]) -> list[Path]:
    """``STEM_positions.png`` (and ``STEM_positions_2.png``, ... when the bodies' rows
    fill more than a page) of the bodies with free coordinates; ``units(channel,
    prefix)`` gives ``" [unit]"``, ``save`` writes a figure. Returns the paths (none
    when no body moves)."""
    groups = []
    for body in figure_bodies(scene, elements):
        rows = (_flex_rows if body.flex is not None else _rigid_rows)(result, body, units)
        if rows:
            groups.append(rows)
    paths = []
    for p, page in enumerate(pages([len(g) for g in groups])):
        rows = [r for i in page for r in groups[i]]
        fig = plt.figure(figsize=(9.6, HEADER + ROW * len(rows)), layout="constrained")
        grid = fig.add_gridspec(len(rows), 2, width_ratios=(60, 1))
        first = None
        for i, row in enumerate(rows):
            ax = fig.add_subplot(grid[i, 0], sharex=first)
            first = first or ax
            cax = fig.add_subplot(grid[i, 1])
            row.draw(ax, cax)
            if not row.heat:
                cax.set_visible(False)
            if i < len(rows) - 1:
                ax.tick_params(labelbottom=False)
        fig.axes[-2].set_xlabel("t" + units("t", ""))
        more = f" (page {p + 1})" if p else ""
        fig.suptitle(f"{name}: free coordinates of the bodies{more}", fontsize=11)
        paths.append(save(fig, out / f"{stem}_positions{page_suffix(p)}.png"))
    return paths
