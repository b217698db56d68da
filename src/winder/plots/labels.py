"""Labels that do not collide and styles that stay apart on a chart of many lines: the
resonance map's mode styles (a colour per body, a line style and marker per mode of it) and
its crossings' numbers, placed beside their markers where they overlap no other label, with
the table that says what each number is."""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.text import Text
from matplotlib.transforms import Bbox

__all__ = ["mode_styles", "place_labels", "overlaps", "cluster", "short_harmonic",
           "MODE_DASHES"]

#: ``(linestyle, marker)`` of a body's modes, in the order its modes come: bending in x
#: (orders 1, 2), in z (orders 1, 2), torsion, then any further.
MODE_DASHES = (("-", ""), ("--", ""), ("-", "^"), ("--", "^"), (":", ""), ("-.", ""),
               (":", "s"), ("-.", "s"), ("-", "o"), ("--", "o"))


def mode_styles(modes: list[str], colours: tuple[str, ...]
                ) -> dict[str, tuple[str, str, str]]:
    """``(colour, linestyle, marker)`` of each mode (``BODY.rest``: ``set.bend.z1``,
    ``set.z``, ``front.torsion1``): a colour per body, a line style and marker per mode of
    that body (:data:`MODE_DASHES`); no two modes alike. With more bodies than ``colours``
    or more modes of a body than :data:`MODE_DASHES`, the colours cycle and the
    combinations are numbered through instead (still no two alike)."""
    bodies = list(dict.fromkeys(m.split(".")[0] for m in modes))
    kinds = {b: [m for m in modes if m.split(".")[0] == b] for b in bodies}
    if len(bodies) <= len(colours) and all(len(k) <= len(MODE_DASHES) for k in kinds.values()):
        return {m: (colours[bodies.index(b)], *MODE_DASHES[k.index(m)])
                for b, k in kinds.items() for m in k}
    combos = [(c, ls, mk) for ls, mk in MODE_DASHES for c in colours]
    if len(modes) > len(combos):  # more modes than named combinations: numbered markers
        return {m: (colours[i % len(colours)], "-", f"${i}$") for i, m in enumerate(modes)}
    return dict(zip(modes, combos, strict=False))


def cluster(points: np.ndarray, within: float) -> list[list[int]]:
    """Groups of the indices of ``points`` (display coordinates [px], ``n × 2``) that
    lie within ``within`` [px] of another of their group (single linkage)."""
    n = len(points)
    group = list(range(n))

    def root(i: int) -> int:
        while group[i] != i:
            group[i] = group[group[i]]
            i = group[i]
        return i
    for i in range(n):
        for j in range(i + 1, n):
            if np.hypot(*(points[i] - points[j])) <= within:
                group[root(i)] = root(j)
    out: dict[int, list[int]] = {}
    for i in range(n):
        out.setdefault(root(i), []).append(i)
    return list(out.values())


def overlaps(boxes: list[Bbox]) -> list[tuple[int, int]]:
    """The pairs of ``boxes`` that overlap (touching edges do not)."""
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes[i].overlaps(boxes[j])]


#: The labels' background: the lines beneath show through faintly.
_BOX = {"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75}

#: The line from a label placed away from its marker to the marker.
_LEADER = {"arrowstyle": "-", "color": "C3", "lw": 0.5, "shrinkA": 0, "shrinkB": 3}

#: Offsets [pt] tried for a label, nearest first: right, above, left, below, diagonals.
_OFFSETS = [(dx * s, dy * s) for s in (4, 10, 18, 28, 40)
            for dx, dy in ((1, 0.6), (1, -1.6), (-1, 0.6), (-1, -1.6), (0, 1.4), (0, -2.6),
                           (1.6, 1.6), (-1.6, -2.6))]


def place_labels(ax: plt.Axes, xy: list[tuple[float, float]], texts: list[str], *,
                 fontsize: float = 7.0, color: str = "C3", avoid: list[Bbox] | None = None
                 ) -> list[Text]:
    """Write ``texts[i]`` near the data point ``xy[i]`` of ``ax``, each at the nearest of
    a set of offsets where it overlaps no label placed before it (nor a box of ``avoid``,
    display coordinates) and stays inside the axes (the nearest one when none is free).
    The figure's layout must be final (drawn once, its layout engine off): the placement
    is in display coordinates."""
    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    placed: list[Bbox] = list(avoid or [])
    out = []
    for (x, y), text in zip(xy, texts, strict=True):
        best = None
        for dx, dy in _OFFSETS:
            art = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                              fontsize=fontsize, color=color, ha="left" if dx >= 0 else
                              "right", va="bottom", bbox=_BOX,
                              arrowprops=_LEADER if np.hypot(dx, dy) > 15 else None)
            box = art.get_window_extent(renderer).expanded(1.08, 1.15)
            inside = frame.containsx(box.x0) and frame.containsx(box.x1) and \
                frame.containsy(box.y0) and frame.containsy(box.y1)
            if inside and not any(box.overlaps(b) for b in placed):
                best = (art, box)
                break
            art.remove()
        if best is None:  # nowhere free: the first offset, where it is least in the way
            dx, dy = _OFFSETS[0]
            art = ax.annotate(text, (x, y), xytext=(dx, dy), textcoords="offset points",
                              fontsize=fontsize, color=color, va="bottom", bbox=_BOX)
            best = (art, art.get_window_extent(renderer))
        placed.append(best[1])
        out.append(best[0])
    return out


def short_harmonic(name: str) -> str:
    """A harmonic's name in a table: ``1x`` → ``1× roll``; a drum's rotation keeps its
    name (``drum front/rear``)."""
    return re.sub(r"^(\d)x$", r"\1× roll", name)
