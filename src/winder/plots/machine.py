"""The figures of a run of a scene of parts (machines.md §9): drums, rolls, nip forces,
free coordinates (:mod:`winder.plots.positions`), slip, web spans and flexible parts
(:mod:`winder.plots.flex`). Figures whose rows grow with the machine (a row per drum, per
nip) are packed onto pages of at most :data:`winder.plots.layout.MAX_HEIGHT_PX`
(``STEM_slip.png``, ``STEM_slip_2.png``, ...); a flexible body is drawn as one body (its
own channels, else its segments' mean), never as a line per segment.

Written through :mod:`winder.plots.figures` (its ``_save``: atomic, or collected)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from winder.io.files import safe_stem
from winder.io.result import Result
from winder.parts import BodyElement, WebPart, body_elements
from winder.plots import figures as _f
from winder.plots.flex import flex_figures
from winder.plots.layout import LEGEND_INSIDE, MAX_HEIGHT, line_styles, page_suffix
from winder.plots.line import line_figures
from winder.plots.positions import FigureBody, figure_bodies, positions_figures
from winder.plots.smooth import centred_mean
from winder.scene.load import Scene

__all__ = ["machine_figures"]

#: Line styles and markers of lines that share a colour (the k-th of a colour).
_DASHES, _MARKS = ("-", "--", "-.", ":"), ("", "o", "s", "^")
#: Height of a row of the drums', nips' and slip figures [in].
_ROW = 2.3


def _per_page(header: float, extra: int = 0) -> int:
    """How many items (a row each, ``extra`` rows more per page) fit on a page."""
    return max(1, int((MAX_HEIGHT - header) // _ROW) - extra)


def _chunks(items: list, size: int) -> list[list]:
    return [items[i:i + size] for i in range(0, len(items), size)] or [[]]


def _parts_scene(result: Result, scene: Scene | None) -> Scene:
    """The scene of ``result``: ``scene`` or the one stored in its meta."""
    if scene is not None:
        return scene
    from winder.scene.load import scene_from_dict

    return scene_from_dict(result.meta["scene_dict"])


def _panel(ax: plt.Axes, t: np.ndarray, lines: list[tuple[str, np.ndarray]], ylabel: str,
           title: str, *, lw: float = 0.8, colors: list[str] | None = None,
           outside: bool = False) -> None:
    """One axes: a line per ``(label, values)``, legend naming the parts (beside the
    panel with more than :data:`LEGEND_INSIDE` lines, or ``outside``)."""
    many = len(lines) > LEGEND_INSIDE  # distinct styles, the legend beside the panel
    if colors is not None:  # given colours (a nip's): a repeated one gets another style
        seen = [colors[:i].count(c) for i, c in enumerate(colors)]
        styles = [(c, _DASHES[k % 4], _MARKS[k // 4 % 4]) for c, k in zip(colors, seen,
                                                                        strict=True)]
    else:
        styles = line_styles(len(lines)) if many else [(None, "-", "")] * len(lines)
    for i, (label, y) in enumerate(lines):
        colour, ls, marker = styles[i]
        ax.plot(t, y, lw=lw, label=label, color=colour, ls=ls, marker=marker or None,
                markevery=0.1 if marker else None, ms=4)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if many or outside:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    elif lines:
        ax.legend(fontsize=8, loc="best")


def _first_open(t: np.ndarray, force: np.ndarray) -> float | None:
    """First time [s] a nip carries no force (open), or None."""
    idx = np.flatnonzero(force <= 0.0)
    return float(t[idx[0]]) if len(idx) else None


def _rows(n: int, height: float = 2.3) -> tuple[plt.Figure, np.ndarray]:
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.6 + height * n), sharex=True, squeeze=False)
    return fig, axes[:, 0]


def machine_figures(result: Result, out_dir: str | Path, *, scene: Scene | None = None
                    ) -> list[Path]:
    """Figures of a run of a scene of parts (channels of machines.md §9) into ``out_dir``.

    ``STEM_drums.png``: the speed of every drum, then a row per drum with its torque and
    its mean over 0.5 s;
    ``STEM_rolls.png``: speed and radius of every paper roll (and the rider speeds);
    ``STEM_nip_forces.png``: a row per nip with its normal force and its mean over 0.5 s,
    then a close-up of the first opening of a nip; ``STEM_positions.png``: the free
    coordinates of every body (:func:`winder.plots.positions.positions_figures`: rows per
    body, its bounce without edge artefacts, a flexible body's segments as heat maps);
    ``STEM_slip.png``: a row per nip with its slip
    velocity; with a web span, ``STEM_span.png``: the span tension, the controller's
    tension error, the unwind torque and the radii; a web line over rollers,
    ``STEM_line.png`` (:mod:`winder.plots.line`): every span's tension, each dancer's
    position within its travel and its speed, each roller's load cell and traction;
    flexible parts:
    :func:`winder.plots.flex.flex_figures`. ``STEM`` is the scene name made
    file-safe; part names appear only in titles and legends. A nip keeps its colour in
    every figure. A figure whose rows would pass :data:`~winder.plots.layout.MAX_HEIGHT_PX`
    goes on pages (``STEM_drums_2.png``, ...). Returns the paths.
    """
    scene = _parts_scene(result, scene)
    out = Path(out_dir)
    name = _f._label(result.meta.get("scene", scene.name))
    stem = safe_stem(result.meta.get("scene", scene.name))
    t = result.t
    paths: list[Path] = []
    color = _f.nip_colours(scene)
    nip_label = {n.name: f"nip {n.name} ({n.a}–{n.b})" for n in scene.nips}
    bodies = body_elements(scene)  # in the machine's order
    drums = [b for b in bodies if _drive(b)]
    driven = {b.segment_of or b.name for b in drums}  # a flexible drum's other segments
    turning = [p for p in figure_bodies(scene, bodies) if p.name not in driven]  # rolls, ...
    wound = [p for p in turning if p.elements[0].radius_state]  # their radius is a channel

    # drums: speeds, then one torque row per drum (pages of at most MAX_HEIGHT)
    for page, chunk in enumerate(_chunks(drums, _per_page(1.6, 1))):
        fig, ax = _rows(1 + len(chunk))
        unit = _f._in(result, f"{chunk[0].name}_speed")
        _panel(ax[0], t, [(_body_label(d), result[f"{d.name}_speed"]) for d in chunk],
               "speed Ω" + unit, f"{name}: drum speeds{unit}")
        for a, d in zip(ax[1:], chunk, strict=True):
            unit = _f._in(result, f"{d.name}_torque", "k")
            _panel(a, t, [(_body_label(d), result[f"{d.name}_torque"] / 1e3)],
                   "torque" + unit, f"{_body_label(d)}: drive torque{unit}", lw=0.4)
            tm, mean, used = centred_mean(t, result[f"{d.name}_torque"] / 1e3, 0.5)
            a.plot(tm, mean, color="k", lw=0.8, label=f"centred mean over {used:.3g} s")
            a.legend(fontsize=8, loc="lower right")
            a.axhline(0.0, color="k", lw=0.5)
        ax[-1].set_xlabel("t" + _f._in(result, "t"))
        paths.append(_f._save(fig, out / f"{stem}_drums{page_suffix(page)}.png"))

    # rolls: speed and radius
    fig, ax = _rows(2, 3.0)
    speed = _f._in(result, f"{wound[0].elements[0].name}_speed") if wound else ""
    radius = _f._in(result, f"{wound[0].elements[0].name}_radius") if wound else ""
    _panel(ax[0], t, [(b.label, _of_body(result, b, "speed")) for b in turning],
           "speed ω" + speed, f"{name}: roll and rider speeds{speed}")
    _panel(ax[1], t, [(b.label, _of_body(result, b, "radius")) for b in wound],
           "radius r" + radius, "paper roll radii" + radius)
    ax[1].set_xlabel("t" + _f._in(result, "t"))
    paths.append(_f._save(fig, out / f"{stem}_rolls.png"))

    # nips: one row per nip (same scale), then a close-up of the first opening
    forces = {n.name: result[f"{n.name}_normal_force"] for n in scene.nips}
    for page, chunk in enumerate(_chunks(list(forces), _per_page(3.2, 1))):
        paths.append(_nip_forces(result, {n: forces[n] for n in chunk}, forces, name,
                                 nip_label, color,
                                 out / f"{stem}_nip_forces{page_suffix(page)}.png"))

    # free coordinates of every body: rows per body, a flexible body's segments as heat maps
    paths += positions_figures(result, scene, bodies, out, stem, name,
                               lambda ch, pre: _f._in(result, ch, pre), _f._save)

    # slip velocities, one row per nip
    for page, chunk in enumerate(_chunks(list(scene.nips), _per_page(1.6))):
        fig, ax = _rows(len(chunk))
        for i, n in enumerate(chunk):
            unit = _f._in(result, f"{n.name}_slip_velocity")
            _panel(ax[i], t, [(nip_label[n.name], result[f"{n.name}_slip_velocity"])],
                   "slip" + unit, (f"{name}: nip slip velocities{unit}\n" if i == 0 else "")
                   + nip_label[n.name], lw=0.4, colors=[color[n.name]])
            ax[i].axhline(0.0, color="k", lw=0.5)
        ax[-1].set_xlabel("t" + _f._in(result, "t"))
        paths.append(_f._save(fig, out / f"{stem}_slip{page_suffix(page)}.png"))
    spans = [w for w in scene.webs if w.span is not None]
    for w in spans:  # one figure per span: STEM_span.png, or STEM_WEB_span.png
        pre = f"{w.name}_" if len(spans) > 1 else ""
        if _tensions(result, w, pre):
            paths.append(_span_figure(result, scene, bodies, w, pre,
                                      out / f"{stem}_{pre}span.png", name))
    paths += line_figures(result, spans, bodies, out, stem, name,
                          lambda ch, pre: _f._in(result, ch, pre), _f._save)
    return paths + flex_figures(result, scene, out, stem, name, _f._save)


def _nip_forces(result: Result, forces: dict[str, np.ndarray],
                every: dict[str, np.ndarray], name: str, nip_label: dict[str, str],
                color: dict[str, str], path: Path) -> Path:
    """A row per nip of ``forces`` (on the scale of ``every`` nip), then the close-up of
    the first opening of a nip of ``forces``."""
    t = result.t
    kn = _f._in(result, f"{next(iter(forces), '')}_normal_force", "k")
    fig, axes = plt.subplots(len(forces) + 1, 1, figsize=(9, 3.2 + 2.3 * len(forces)),
                             squeeze=False)
    ax = axes[:, 0]
    for i, (n, f) in enumerate(forces.items()):
        _panel(ax[i], t, [(nip_label[n], f / 1e3)], "F_n" + kn,
               (f"{name}: nip normal forces{kn} (F_n = 0: nip open)\n" if i == 0 else "")
               + f"{nip_label[n]}: {np.mean(f <= 0.0):.1%} of samples open", lw=0.4,
               colors=[color[n]])
        tm, fm, used = centred_mean(t, f / 1e3, 0.5)
        ax[i].plot(tm, fm, color="k", lw=0.8, label=f"centred mean over {used:.3g} s")
        ax[i].legend(fontsize=8, loc="lower right")
        if i:
            ax[i].sharex(ax[0])
    top = max([float(np.max(f)) / 1e3 for f in every.values()] + [0.0])
    for a in ax[:-1]:  # one scale, from 0 (nip open) to the largest force of any nip
        a.set_ylim(-0.04 * top - 1e-3, 1.06 * top + 1e-3)
    ax[len(forces) - 1].set_xlabel("t" + _f._in(result, "t"))
    opens = [(tt, n) for n, f in forces.items() if (tt := _first_open(t, f)) is not None]
    if opens:
        t_open, which = min(opens)
        w = (t >= t_open - 0.3) & (t <= t_open + 1.0)
        title = f"close-up: first opening, {nip_label[which]} at t ≈ {t_open:.2f} s{kn}"
    else:
        w = t <= min(t[-1], t[0] + 5.0)
        title = f"first 5 s{kn} (no nip opens in this run)"
    _panel(ax[-1], t[w], [(nip_label[n], f[w] / 1e3) for n, f in forces.items()], "F_n" + kn,
           title + f" (samples every {np.median(np.diff(t)) if len(t) > 1 else 0:g} s)",
           colors=[color[n] for n in forces])
    for line in ax[-1].get_lines():
        line.set_marker(".")
        line.set_markersize(3)
    ax[-1].legend(fontsize=7, loc="best", framealpha=0.9)
    ax[-1].set_xlabel("t" + _f._in(result, "t"))
    return _f._save(fig, path)


def _tensions(result: Result, web: WebPart, pre: str) -> list[str]:
    """The span-tension channels of ``web`` in ``result`` (one span, or each of a line's)."""
    names = [f"{pre}span_tension"] if len(web.spans) == 1 else \
        [f"{pre}span{i}_tension" for i in range(len(web.spans))]
    return [n for n in names if n in result]


def _drive(body: BodyElement) -> bool:
    """Whether ``body`` is a drive of constant radius (a drum: prescribed or on a torque
    input, its radius no state), drawn with its drive torque."""
    return (body.prescribed or bool(body.torque_inputs)) and not body.radius_state


def _body_label(body: BodyElement) -> str:
    """A body in legends and titles: its drawing role and name (``roll front``); the
    segment of a flexible body: the body's name (``drum front, drive end``)."""
    if body.segment_of:
        return f"{body.role} {body.segment_of}, drive end" if _drive(body) else \
            f"{body.role} {body.segment_of}, segment {body.name}"
    return f"{body.role} {body.name}"


def _of_body(result: Result, body: FigureBody, quantity: str) -> np.ndarray:
    """The channel ``NAME_QUANTITY`` of ``body`` (a flexible body's own), else the mean of
    its segments' ``SEGMENT_QUANTITY``."""
    if f"{body.name}_{quantity}" in result:
        return result[f"{body.name}_{quantity}"]
    return np.mean([result[f"{e.name}_{quantity}"] for e in body.elements], axis=0)


def _span_figure(result: Result, scene: Scene, bodies: list[BodyElement], web: WebPart,
                 pre: str, path: Path, name: str) -> Path:
    """A winder line: the span tension of ``web`` (channels ``PRE...``; ``pre`` empty for
    a scene's only span) and its controller's error, the unwind torque, the radii of the
    unwinding roll and of the wound roll the web enters."""
    t = result.t
    span = web.span
    body = {b.name: b for b in bodies}
    unwind = body[span.source]
    entry = next(n for n in scene.nips if n.name == web.entry_nip)
    wound = [body[entry.b]] if body[entry.b].radius_state else []
    error = f"{pre}tension_error"
    fig, ax = _rows(4 if error in result else 3)
    unit = _f._in(result, _tensions(result, web, pre)[0])
    line = len(web.spans) > 1  # a line: each span's length in the legend, legends beside
    _panel(ax[0], t, [(n[len(pre):].replace("_", " ")
                       + (f" (L = {web.spans[i].length:g} m, EA = {web.spans[i].EA:.3g} N)"
                          if line else ""), result[n])
                      for i, n in enumerate(_tensions(result, web, pre))], "T" + unit,
           f"{name}: web span tension{unit}" + ("" if line else
                                               f" (EA = {span.EA:.3g} N, L = {span.length:g} m)"),
           lw=0.6, outside=line)
    rows = 1
    if error in result:
        unit = _f._in(result, error)
        _panel(ax[1], t, [("set-point − T", result[error])], "error" + unit,
               f"tension error of the unwind's controller{unit}: peak "
               f"{np.max(np.abs(result[error])):.3g} N, RMS "
               f"{np.sqrt(np.mean(result[error] ** 2)):.3g} N", lw=0.6)
        ax[1].axhline(0.0, color="k", lw=0.5)
        rows = 2
    unit = _f._in(result, f"{unwind.name}_torque", "k")
    _panel(ax[rows], t, [(_body_label(unwind), result[f"{unwind.name}_torque"] / 1e3)],
           "torque" + unit, f"unwind torque of {unwind.name}{unit} (negative: braking)",
           lw=0.6, outside=line)
    ax[rows].axhline(0.0, color="k", lw=0.5)
    unit = _f._in(result, f"{unwind.name}_radius")
    _panel(ax[rows + 1], t, [(_body_label(b), result[f"{b.name}_radius"])
                             for b in [unwind, *wound]], "radius r" + unit,
           "radii of the unwinding and the wound rolls" + unit, outside=line)
    ax[-1].set_xlabel("t" + _f._in(result, "t"))
    return _f._save(fig, path)


