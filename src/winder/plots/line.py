"""The figure of a web line's run (machines.md §11, issue #34): ``STEM_line.png`` (or
``STEM_WEB_line.png`` among several webs), one per web that runs over rollers:

- every span's tension [N] (``span{i}_tension``, its length in the legend);
- each dancer's carriage position [mm] with its travel ends drawn as limits
  (``NAME_position``), then its speed [mm/s] (``NAME_position_dot``);
- each roller's load cell [N] (``NAME_load_cell``);
- each roller's traction [-], its share of the capstan limit ``exp(μ β) − 1``
  (``NAME_traction``), with the limit 1 drawn: at 1 the web would slip on that roller.

Every legend beside its panel; rows of a page at most
:data:`winder.plots.layout.MAX_HEIGHT_PX` tall (the spans, each dancer's two rows, the
rollers' two rows: a line with many dancers continues on ``STEM_line_2.png``)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from winder.io.result import Result
from winder.parts import BodyElement, WebPart
from winder.plots.layout import MAX_HEIGHT, line_styles, page_suffix

__all__ = ["line_figures"]

#: Height of a row [in], of the title and time axis [in], the figure's width [in].
_ROW, _HEADER, _WIDTH = 2.2, 1.4, 11.0


def line_figures(result: Result, webs: list[WebPart], bodies: list[BodyElement], out: Path,
                 stem: str, name: str, unit: Callable[[str, str], str],
                 save: Callable[[plt.Figure, Path], Path]) -> list[Path]:
    """The line figures of ``webs`` (those with rollers and their channels in ``result``)
    into ``out``; ``unit(channel, prefix)`` the `` [unit]`` of a channel, ``save`` the
    figures' writer."""
    body = {b.name: b for b in bodies}
    paths: list[Path] = []
    for w in webs:
        rollers = [s.to for s in w.spans if getattr(s, "to", None)]
        if not rollers or f"{rollers[0]}_load_cell" not in result:
            continue
        pre = f"{w.name}_" if len(webs) > 1 else ""
        rows = [("spans", None)] + [(kind, n) for n in rollers
                                    if body[n].roles.dancer is not None
                                    for kind in ("position", "speed")]
        rows += [("load_cell", None), ("traction", None)]
        per_page = max(3, int((MAX_HEIGHT - _HEADER) // _ROW))
        chunks = [rows[i:i + per_page] for i in range(0, len(rows), per_page)]
        for page, chunk in enumerate(chunks):
            fig, axes = plt.subplots(len(chunk), 1, sharex=True, squeeze=False,
                                     figsize=(_WIDTH, _HEADER + _ROW * len(chunk)))
            ax = axes[:, 0]
            for a, (kind, n) in zip(ax, chunk, strict=True):
                _ROWS[kind](a, result, w, pre, rollers, body.get(n), unit)
                a.grid(True, alpha=0.3)
                a.legend(fontsize=7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
            ax[0].set_title(f"{name}: the web line" + (f" {w.name}" if pre else "")
                            + (f" (page {page + 1})" if len(chunks) > 1 else "")
                            + "\n" + ax[0].get_title(), fontsize=10)
            ax[-1].set_xlabel("t" + unit("t", ""))
            paths.append(save(fig, out / f"{stem}_{pre}line{page_suffix(page)}.png"))
    return paths


def _spans(ax: plt.Axes, result: Result, web: WebPart, pre: str, rollers: list[str],
           _: BodyElement | None, unit: Callable[[str, str], str]) -> None:
    names = [f"{pre}span{i}_tension" for i in range(len(web.spans))]
    u = unit(names[0], "")
    for (colour, ls, marker), i, s in zip(line_styles(len(names)), range(len(names)),
                                          web.spans, strict=True):
        ends = f"{getattr(s, 'source', None) or rollers[i - 1]} → " \
               f"{s.to if getattr(s, 'to', None) else 'entry drum'}"
        ax.plot(result.t, result[names[i]], color=colour, ls=ls, marker=marker or None,
                markevery=0.1 if marker else None, ms=4, lw=0.8,
                label=f"span {i}: {ends} (L = {s.length:g} m)")
    ax.set_ylabel("tension T" + u)
    ax.set_title("span tensions" + u, fontsize=10)


def _position(ax: plt.Axes, result: Result, web: WebPart, pre: str, rollers: list[str],
              b: BodyElement, unit: Callable[[str, str], str]) -> None:
    lo, hi = b.roles.dancer.travel
    ax.plot(result.t, 1e3 * result[f"{b.name}_position"], lw=0.9, color="C0",
            label=f"{b.name} position d")
    for end, value, ls in (("lower", lo, "--"), ("upper", hi, ":")):
        ax.axhline(1e3 * value, color="C3", ls=ls, lw=1.2,
                   label=f"{end} end of travel ({1e3 * value:g} mm): the run ends there")
    ax.axhline(0.0, color="k", lw=0.5)
    span = hi - lo
    ax.set_ylim(1e3 * (lo - 0.08 * span), 1e3 * (hi + 0.08 * span))
    ax.set_ylabel("position d [mm]")
    ax.set_title(f"{b.name} (dancer): carriage position within its travel [mm] (0: centre; "
                 "both spans lengthen with d)", fontsize=10)


def _speed(ax: plt.Axes, result: Result, web: WebPart, pre: str, rollers: list[str],
           b: BodyElement, unit: Callable[[str, str], str]) -> None:
    ax.plot(result.t, 1e3 * result[f"{b.name}_position_dot"], lw=0.7, color="C1",
            label=f"{b.name} carriage speed ḋ")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel("speed ḋ [mm/s]")
    ax.set_title(f"{b.name} (dancer): carriage speed [mm/s]", fontsize=10)


def _load_cell(ax: plt.Axes, result: Result, web: WebPart, pre: str, rollers: list[str],
               _: BodyElement | None, unit: Callable[[str, str], str]) -> None:
    u = unit(f"{rollers[0]}_load_cell", "")
    for (colour, ls, marker), n in zip(line_styles(len(rollers)), rollers, strict=True):
        ax.plot(result.t, result[f"{n}_load_cell"], color=colour, ls=ls,
                marker=marker or None, markevery=0.1 if marker else None, ms=4, lw=0.8,
                label=f"roller {n}")
    ax.set_ylabel("load cell" + u)
    ax.set_title("rollers' load cells: bearing force of the two tensions over the wrap" + u,
                 fontsize=10)


def _traction(ax: plt.Axes, result: Result, web: WebPart, pre: str, rollers: list[str],
              _: BodyElement | None, unit: Callable[[str, str], str]) -> None:
    top = 1.0
    for (colour, ls, marker), n in zip(line_styles(len(rollers)), rollers, strict=True):
        y = result[f"{n}_traction"]
        ax.plot(result.t, y, color=colour, ls=ls, marker=marker or None,
                markevery=0.1 if marker else None, ms=4, lw=0.8, label=f"roller {n}")
        top = max(top, float(np.nanmax(y, initial=0.0)))
    ax.axhline(1.0, color="k", ls="--", lw=1.5, label="limit 1: the web slips on the roller")
    ax.set_ylim(0.0, 1.1 * top)
    ax.set_ylabel("traction [-]")
    ax.set_title("rollers' traction: share of the capstan limit exp(μ β) − 1 used",
                 fontsize=10)


_ROWS = {"spans": _spans, "position": _position, "speed": _speed, "load_cell": _load_cell,
         "traction": _traction}
