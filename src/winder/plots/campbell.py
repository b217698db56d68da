"""The resonance map's figure (a Campbell chart) of a :class:`winder.ModeMap`: its modes
against the wound roll's radius with the rotation harmonics and their crossings, the
simulated normal-force envelopes below (a map over an unwinding roll's radius: its web
line's modes and the parent's rotation harmonics); a map of one row (the initial state of a machine
without a wound roll, or with contact off) as markers."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.transforms import Bbox

from winder.analysis.modes import FREE_BELOW
from winder.io.result import Result
from winder.plots import figures  # (matplotlib on Agg)
from winder.plots.figures import (
    MODE_COLOURS,
    NIP_COLOURS,
    _in,
    _label,
    normal_force_envelope,
    plt,
)
from winder.plots.labels import cluster, mode_styles, place_labels, short_harmonic

__all__ = ["campbell_figure"]

_HARMONIC_STYLE = {"1x": "-", "2x": "--", "3x": ":"}


def campbell_figure(mode_map, path: str | Path, *, result: Result | None = None,
                    title: str = "", envelopes: dict[str, tuple[str, str]] | None = None,
                    colours: dict[str, str] | None = None) -> Path:
    """Resonance map (:class:`winder.ModeMap`): the bounce modes (one line per free
    coordinate; a flexible machine: :meth:`~winder.ModeMap.shown`, its bending orders 1–2
    and torsion order 1 too) and the slowest slip mode against the radius, the 1×/2×/3× roll
    rotation lines and the drums' rotation, every crossing of a harmonic with a bounce mode
    marked; with ``result``, the simulated normal-force envelopes below on the same radius
    axis (``envelopes``: label → (force channel, radius channel); default the single-drum
    ``normal_force`` against ``radius``; ``colours``: label → colour, :func:`nip_colours`
    when the labels are nip names, so that a nip has its colour of the run figures).

    With more than one mode: a colour per body and a line style and marker per mode of it
    (:func:`winder.plots.labels.mode_styles`, no two alike), the legend beside the chart,
    each crossing numbered where its number overlaps no other (crossings closer than a
    marker share one) and listed in a table below the chart."""
    mm = mode_map
    line = mm.unwinding  # a web line's modes against the parent's radius
    one = len(mm.coordinates) == 1 and not line
    drawn = mm.line_shown if line else mm.shown() if mm.flexible else mm.coordinates
    crossings = mm.crossings(drawn)
    width, height = (13.5, 6.5) if mm.flexible else (8, 4.2) if one else (11, 4.6)
    rows = _crossing_rows(crossings, mm.roll if line else "roll")
    # the table's columns: as many as fit beside the legend (its longest label, 7 pt)
    legend = _PT * 7 * max([54, *(len(f"bending mode {c} (damped)") for c in drawn)]) + 0.9
    column = _PT * 7.5 * max([len(x) for x in rows] + [1]) + 0.3
    ncol = max(1, min(math.ceil(len(rows) / 6), int((width - legend - 0.9) // column)))
    lines = min(math.ceil(len(rows) / ncol), _TABLE_LINES) if rows and not one else 0
    heights = [height] * (2 if result is not None else 1) + ([0.35 + 0.16 * lines]
                                                               if lines else [])
    fig = plt.figure(figsize=(width, sum(heights)), layout="constrained")
    grid = fig.add_gridspec(len(heights), 1, height_ratios=heights)
    ax = fig.add_subplot(grid[0])
    r = mm.radius
    single = len(r) == 1  # the initial state (or a map of one radius): markers, no lines
    if single and not np.isfinite(r[0]):  # no wound roll: no radius axis
        r = np.zeros(1)
    styles = {c: (MODE_COLOURS[i % len(MODE_COLOURS)], "-", "") for i, c in enumerate(drawn)} \
        if not mm.flexible else mode_styles(drawn, MODE_COLOURS)
    over = []  # the overdamped stretches: (mode, mask)
    for i, c in enumerate(drawn):
        f = mm.frequency(c)
        colour, ls, marker = styles[c]
        kind = "torsion" if c in mm.torsion else "bending" if ".bend." in c else \
            "line" if c in mm.line else "bounce"
        label = "bounce mode (damped)" if one else f"{kind} mode {c} " + (
            "|λ|/2π" if kind == "torsion" else "(damped)")
        if single:  # one row: markers (an x order beside its z order of the same frequency:
            # hollow), a free body (a zero eigenvalue: nothing holds it) along the bottom
            if c in mm.natural and mm.natural[c][0] < FREE_BELOW:
                ax.plot(r, [0.03 + 0.04 * i], marker="v", ms=8, ls="none", color=colour,
                        transform=ax.get_xaxis_transform(), label=f"{c} free: 0 Hz "
                        "(nothing holds it)")
                continue
            hollow = {"mfc": "none", "ms": 11, "mew": 1.5} if ".bend.x" in c else {"ms": 7}
            ax.plot(r, np.where(f > 0, f, np.nan), color=colour, ls="none",
                    marker="D" if kind == "torsion" else "o", **hollow, label=label)
            continue
        ax.plot(r, np.where(f > 0, f, np.nan), color=colour, ls=ls, marker=marker or None,
                markevery=max(1, len(r) // 8), ms=4,
                lw=2 if kind == "bounce" or c.endswith(".carriage") else 1.3, label=label)
        if np.any(f == 0):  # overdamped (real eigenvalue): a bar along the bottom
            over.append((c, f == 0))
    if line:
        pass  # the line's map: its own modes only (the winder's slip modes stay put)
    elif not single or np.all(mm.slip_frequency > 0):  # (a NaN: no slip mode)
        ax.plot(r, mm.slip_frequency, "C2" if one else "C7", lw=1.0,
                **({"marker": "s", "ls": "none"} if single else {}),
                label="slip/torsion mode |λ|/2π (slowest)")
    harmonics = mm.harmonics()
    for name, h in harmonics.items():
        if line and name not in _HARMONIC_STYLE:
            continue  # the drums' rotation: not an excitation of the line's map
        if name in _HARMONIC_STYLE:
            if single and not np.all(np.isfinite(h)):
                continue  # no wound roll: no roll rotation
            which = f"rotation of {mm.roll} (unwinding)" if line else "roll rotation"
            ax.plot(r, h, *(("x",) if single else (_HARMONIC_STYLE[name],)), color="k",
                    lw=1, label=f"{name[:-1]}× {which} at {mm.web_speed:g} m/s")
        elif single:  # a drum's rotation: the same at every radius
            ax.axhline(float(h[0]), ls="-.", color="0.45", lw=1, label=f"{name} rotation")
        else:
            ax.plot(r, h, "-.", color="0.45", lw=1, label=f"{name} rotation")
    shown = [mm.frequency(c) for c in drawn]
    if line:
        harmonics = {k: h for k, h in harmonics.items() if k in _HARMONIC_STYLE}
    values = np.concatenate([f[np.isfinite(f) & (f > 0)]
                             for f in (*shown, *harmonics.values())])
    log = values.size > 0 and values.max() / values.min() > 30
    if log:
        ax.set_yscale("log")
        ax.set_ylim(values.min() * 0.7 if line else max(values.min() * 0.7, 0.1),
                    values.max() * 1.5)
    elif single or line or not np.any(np.isfinite(mm.bounce_frequency)):
        top = max(float(values.max()) if values.size else 0.0,
                  float(np.nanmax(mm.slip_frequency, initial=0.0)))
        ax.set_ylim(0, top * 1.15 if top > 0 else 1.0)
    else:
        ax.set_ylim(0, float(np.nanmax(mm.bounce_frequency)) * 1.1)
    if len(r) > 1:  # the map's radii (--radius-min/max), the envelope too where it is longer
        span = float(r.max() - r.min())
        ax.set_xlim(float(r.min()) - 0.02 * span, float(r.max()) + 0.02 * span)
    for k, (c, mask) in enumerate(over):
        colour = styles[c][0]
        level = 0.02 + 0.03 * k
        ax.plot(r, np.where(mask, level, np.nan), color=colour, lw=4, solid_capstyle="butt",
                transform=ax.get_xaxis_transform(),
                label=("bounce mode overdamped here (real eigenvalue: no oscillation)"
                       if one else "_"))
    if over and not one:
        ax.plot([], [], color="0.6", lw=4, label="bar: the mode named at its end is "
                "overdamped there (no oscillation)")
    points = []
    for c, h, rc in crossings:
        f = float(np.interp(rc, r, mm.frequency(c)))
        ax.plot([rc], [f], "o", color="C3", ms=5, mfc="none", mew=1.2)
        points.append((rc, f))
        if one:
            ax.axvline(rc, color="C3", lw=0.8, alpha=0.7)
            ax.annotate(f"{h[:-1]}×: r = {rc:.3f} m", (rc, ax.get_ylim()[1] * 0.02 + 1),
                        rotation=90, fontsize=8, color="C3", va="bottom")
    if crossings and not one:
        ax.plot([], [], "o", color="C3", mfc="none", label="crossing (critical radius): "
                "numbered, listed below")
    ax.set_ylabel("frequency [Hz]")
    if one:
        ax.legend(fontsize=8, loc="upper right")
    else:  # many lines: the legend beside the chart (the layout makes room for it)
        fig.legend(*ax.get_legend_handles_labels(), fontsize=7 if mm.flexible else 7.5,
                   loc="outside right upper")
    ax.grid(alpha=0.3, which="both" if log else "major")
    ax.set_title(_label(title, 120) or "Resonance map (Campbell chart)")
    axes = [ax]
    if result is not None:
        b = fig.add_subplot(grid[1], sharex=ax)
        axes.append(b)
        pairs = envelopes or {"": ("normal_force", "radius")}
        for i, (label, (force, radius)) in enumerate(pairs.items()):
            rr, lo, hi, _ = normal_force_envelope(result, force=force, radius=radius)
            colour = (colours or {}).get(label, NIP_COLOURS[i % len(NIP_COLOURS)])
            b.fill_between(rr, lo / 1e3, hi / 1e3, color=colour, alpha=0.5, lw=0,
                           label=label or None)
            b.plot(rr, hi / 1e3, color=colour, lw=0.6)
        for _, _, rc in crossings:
            b.axvline(rc, color="C3", lw=0.8, alpha=0.5)
        if len(pairs) > 1:
            b.legend(fontsize=8, loc="upper right")
        b.set_ylabel("normal force envelope"
                     + _in(result, next(iter(pairs.values()))[0], "k"))
        b.grid(alpha=0.3)
        b.set_title("simulated nip normal force (min-max over 0.5 s)", fontsize=10)
        if len(r) > 1:
            b.set_xlim(*ax.get_xlim())
    if mm.initial_state and not np.isfinite(mm.radius[0]):
        ax.set_xlim(-1.0, 1.0)
        ax.set_xticks([])
        axes[-1].set_xlabel(f"the initial state ({mm.initial_reason})")
    elif mm.initial_state:
        axes[-1].set_xlabel(f"roll radius r [m]: the initial state ({mm.initial_reason})")
    elif line:
        axes[-1].set_xlabel(f"radius of the unwinding roll {mm.roll} r [m] (core: empty, "
                            "right: full)")
    else:
        axes[-1].set_xlabel("roll radius r [m]")
    if lines:
        _crossing_labels(fig, ax, grid[-1], rows, points, over, ncol, lines, r)
    return figures._save(fig, Path(path))  # (looked up: the tests capture it)


#: The crossings' table lists at most this many lines per column (the rest: a count).
_TABLE_LINES = 30
#: Width of a monospace character per point of font size [in] (DejaVu Sans Mono: 0.6 em).
_PT = 0.6 / 72


def _crossing_rows(crossings: list[tuple[str, str, float]], roll: str = "roll") -> list[str]:
    """The table's lines: number, harmonic (of ``roll``'s rotation), mode, radius, in
    aligned columns."""
    if not crossings:
        return []
    short = {h: short_harmonic(h).replace("× roll", f"× {roll}") for _, h, _ in crossings}
    wide = max(len(x) for x in short.values())
    mode = max(len(c) for c, _, _ in crossings)
    return [f"{i + 1:>2}  {short[h]:<{wide}}  {c:<{mode}}  r = {rc:.4f} m"
            for i, (c, h, rc) in enumerate(crossings)]


def _crossing_labels(fig: plt.Figure, ax: plt.Axes, cell, rows: list[str], points: list,
                     over: list, ncol: int, lines: int, radius: np.ndarray) -> None:
    """Number the crossings (``points``, data coordinates; ``rows`` their table lines)
    of the resonance map ``ax`` (those closer than a marker
    share one label: ``3,7``) where no label overlaps another, name the overdamped bars
    (``over``) at their right ends, and list the numbers in a table in ``cell``. The
    layout is fixed first (the labels are placed in display coordinates)."""
    table = fig.add_subplot(cell)
    table.axis("off")
    table.set_title("crossings (critical radii): where a harmonic of the rotation meets a "
                    "mode", fontsize=8, loc="left")
    fig.canvas.draw()  # the constrained layout, once
    fig.set_layout_engine("none")
    renderer = fig.canvas.get_renderer()
    avoid = []
    for k, (c, mask) in enumerate(over):  # name each bar at its right end
        last = float(radius[np.flatnonzero(mask)[-1]])
        art = ax.text(last, 0.02 + 0.03 * k, f" {c}", transform=ax.get_xaxis_transform(),
                      fontsize=6.5, va="center", color="0.25")
        avoid.append(art.get_window_extent(renderer))
    xy = ax.transData.transform(np.array(points)) if points else np.zeros((0, 2))
    avoid += [Bbox.from_extents(x - 4, y - 4, x + 4, y + 4) for x, y in xy]  # the markers
    groups = cluster(xy, 9.0)
    place_labels(ax, [points[g[0]] for g in groups],
                 [",".join(str(i + 1) for i in g) for g in groups], avoid=avoid)
    shown = rows[:ncol * lines]
    if len(rows) > len(shown):
        shown[-1] = f"… and {len(rows) - len(shown) + 1} more (winder modes prints them all)"
    for i, text in enumerate(shown):
        col, line = divmod(i, lines)
        table.text(col / ncol, 1.0 - (line + 0.5) / lines, text, fontsize=7.5,
                   family="monospace", va="center", transform=table.transAxes)
