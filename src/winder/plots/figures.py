"""Figures from a result (matplotlib, PNG): the paper's figures for a single-drum scene,
the machine figures for a scene of parts (drums, rolls, nips, free coordinates).

Each figure is written atomically; inside :func:`collected` the figures are rendered in
memory instead and handed to the caller, who writes them together with its other files
(all or nothing: ``winder run`` commits its result and its figures as one set)."""

from __future__ import annotations

import io
import re
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from winder.io.files import atomic_write, safe_stem  # noqa: E402
from winder.io.result import Result  # noqa: E402
from winder.parts import BodyElement, WebPart, body_elements  # noqa: E402
from winder.scene.load import Scene  # noqa: E402

__all__ = ["paper_figures", "closeup_end", "CLOSEUP_STEP", "machine_figures",
           "campbell_figure", "normal_force_envelope", "window_mean", "nip_colours",
           "NIP_COLOURS", "collected"]

#: The figures rendered inside :func:`collected` (path, PNG bytes); None outside it.
_COLLECTED: list[tuple[Path, bytes]] | None = None


@contextmanager
def collected() -> Iterator[list[tuple[Path, bytes]]]:
    """Inside the block the figure functions render their PNGs into the list yielded,
    ``(path, bytes)`` each, and write nothing: the caller writes them (with
    :func:`winder.io.files.atomic_write_all`, together with its other files)."""
    global _COLLECTED
    previous, _COLLECTED = _COLLECTED, []
    try:
        yield _COLLECTED
    finally:
        _COLLECTED = previous


def _save(fig: plt.Figure, path: Path) -> Path:
    try:
        fig.tight_layout()
        if _COLLECTED is not None:
            png = io.BytesIO()
            fig.savefig(png, dpi=110, format="png")
            _COLLECTED.append((path, png.getvalue()))
        else:
            atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    finally:
        plt.close(fig)
    return path


def _label(text: object, limit: int = 80) -> str:
    """Scene text as plain title text: no control characters, no mathtext (``$``)."""
    return re.sub(r"[\x00-\x1f\x7f]", "?", str(text))[:limit].replace("$", r"\$")


def _in(result: Result, channel: str, prefix: str = "") -> str:
    """`` [unit]`` of ``channel`` from :attr:`Result.units` (``prefix`` ``k`` for values
    drawn in thousands, ``m`` in thousandths: ``[kN]``, ``[mm]``); empty when the result
    has no unit for it (read from a CSV)."""
    unit = result.units.get(channel)
    return f" [{prefix}{unit}]" if unit else ""


def _first_liftoff(result: Result) -> float | None:
    fn = result["normal_force"]
    idx = np.flatnonzero(fn <= 0.0)
    return float(result.t[idx[0]]) if len(idx) else None


#: Sampling [s] of the close-up run of Fig. 8 (:func:`closeup_end`).
CLOSEUP_STEP = 2e-4


def closeup_end(result: Result) -> float | None:
    """End time [s] of the finely sampled run (from t = 0, every :data:`CLOSEUP_STEP`)
    whose close-up of the first lift-off Fig. 8 of :func:`paper_figures` draws: 2 s after
    it, at most the end of ``result``. None when the figure needs none (a scene of parts,
    or no lift-off). The caller runs it (figures draw results, they never simulate)."""
    if "normal_force" not in result:
        return None
    t_lift = _first_liftoff(result)
    return None if t_lift is None else min(t_lift + 2.0, float(result.t[-1]))


def paper_figures(result: Result, out_dir: str | Path, *, scene: Scene | None = None,
                  closeup: Result | None = None) -> list[Path]:
    """Write the paper's figures for ``result`` into ``out_dir``; returns the paths.

    With contact: speeds + drum torque (Figs. 4/5), roll vertical velocity + radius
    (Fig. 6), roll angular velocity + acceleration (Fig. 7), nip normal force with a
    close-up of the first lift-off (Fig. 8; ``closeup`` is a finely sampled result of
    that window, up to :func:`closeup_end`; without it the panel shows the first 60 s of
    ``result``). Without contact: the free
    spin ω with the conserved ``J ω`` (Fig. 2). A result of a scene of parts gets
    :func:`machine_figures` instead.
    """
    if "normal_force" not in result:  # a scene of parts: channels of machines.md §9
        return machine_figures(result, out_dir, scene=scene)
    out = Path(out_dir)
    name = _label(result.meta.get("scene", "result"))  # for titles
    stem = safe_stem(result.meta.get("scene", "result"))  # no scene text picks the directory
    t = result.t
    paths: list[Path] = []
    web = "web_momentum" in result.meta.get("effects", [])
    if np.all(result["normal_force"] == 0.0) and np.all(result["friction_force"] == 0.0):
        fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        ax[0].plot(t, result["roll_speed"], label="roll speed ω")
        ax[0].set_ylabel("ω" + _in(result, "roll_speed"))
        ax[0].set_title(f"{name}: free spin, paper added from rest (Fig. 2)")
        jw = result["inertia"] * result["roll_speed"]
        ax[1].plot(t, jw, color="C2", label="J ω")
        ax[1].set_ylabel("J ω [kg m²/s]")
        span = np.ptp(jw) / max(abs(jw[0]), 1e-300)
        ax[1].set_title(f"angular momentum J ω (relative variation {span:.1e})")
        ax[1].set_ylim(jw[0] * 0.9, jw[0] * 1.1) if jw[0] > 0 else None
        ax[1].set_xlabel("t" + _in(result, "t"))
        for a in ax:
            a.grid(True, alpha=0.3)
            a.legend()
        return [_save(fig, out / f"{stem}_fig2_free_spin.png")]

    fig, ax = plt.subplots(3, 1, figsize=(9, 9.5), sharex=True)
    ax[0].plot(t, result["drum_speed"], label="drum Ω")
    ax[0].plot(t, result["roll_speed"], label="roll ω", alpha=0.8)
    ax[0].set_ylabel("speed" + _in(result, "drum_speed"))
    ax[0].set_ylim(0, 1.05 * max(np.max(result["roll_speed"]), np.max(result["drum_speed"])))
    R = float(result.meta.get("drum_radius", 0.5))
    eq = np.flatnonzero(np.diff(np.sign(result["radius"] - R)))
    if len(eq):
        ax[0].axvline(t[eq[0]], color="k", ls=":", label=f"r = R at {t[eq[0]]:.0f} s")
    ax[0].legend()
    ax[0].set_title(f"{name}: drum and roll speed, drum torque "
                    f"({'with' if web else 'without'} web momentum, Fig. {4 if web else 5})")
    torque = result["drum_torque"]
    _torque_panels(ax[1], ax[2], t, torque, result.units.get("drum_torque", ""))
    ax[2].set_xlabel("t" + _in(result, "t"))
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig{4 if web else 5}_speeds_torque.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    ax[0].plot(t, result["z_dot"] * 1e3, lw=0.5)
    ax[0].set_ylabel("roll vertical velocity ż" + _in(result, "z_dot", "m"))
    ax[0].set_title(f"{name}: roll vertical velocity and radius (Fig. 6)")
    ax[1].plot(t, result["radius"], label="roll radius r")
    ax[1].plot(t, result["z"] - result["z"][0], label="rise of the roll axis z − z₀")
    ax[1].set_ylabel(_in(result, "radius").strip())
    ax[1].set_xlabel("t" + _in(result, "t"))
    ax[1].legend()
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig6_vertical_velocity_radius.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    ax[0].plot(t, result["roll_speed"], lw=0.6)
    ax[0].set_ylabel("roll speed ω" + _in(result, "roll_speed"))
    ax[0].set_title(f"{name}: roll angular velocity and acceleration (Fig. 7)")
    ax[1].plot(t, result["roll_accel"], lw=0.4, color="C1")
    ax[1].set_ylabel("roll acceleration ω̇" + _in(result, "roll_accel"))
    ax[1].set_xlabel("t" + _in(result, "t"))
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig7_roll_speed_accel.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7))
    ax[0].plot(t, result["normal_force"] / 1e3, lw=0.4)
    if scene is not None:  # the weight under the scene's own gravity (none when it is off)
        g = scene.scene.gravity if scene.effects.gravity else 0.0
        ax[0].plot(t, result["mass"] * g / 1e3, color="k", lw=0.8,
                   label=f"weight m g (g = {g:g} m/s²)")
        ax[0].legend()
    ax[0].set_ylabel("normal force F_n" + _in(result, "normal_force", "k"))
    ax[0].set_xlabel("t" + _in(result, "t"))
    ax[0].set_title(f"{name}: nip normal force (Fig. 8)")
    t_lift = _first_liftoff(result)
    if closeup is not None and t_lift is not None:
        tc = closeup.t
        w = (tc >= t_lift - 0.3) & (tc <= t_lift + 1.0)
        ax[1].plot(tc[w], closeup["normal_force"][w], lw=0.8)
        ax[1].set_title(f"close-up: first lift-off at t ≈ {t_lift:.2f} s (F_n = 0: roll in "
                        "the air, spikes: impacts)")
    else:
        w = t <= min(t[-1], 60.0)
        ax[1].plot(t[w], result["normal_force"][w], lw=0.6)
        ax[1].set_title("first 60 s (no lift-off in this run)")
    ax[1].set_ylabel("F_n" + _in(result, "normal_force"))
    ax[1].set_xlabel("t" + _in(result, "t"))
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig8_normal_force.png"))
    return paths


def _torque_panels(full: plt.Axes, zoom: plt.Axes, t: np.ndarray, torque: np.ndarray,
                   unit: str) -> None:
    """The drum torque (in ``unit``, its channel's) twice: ``full`` on its whole range (the
    impacts of a bouncing roll), ``zoom`` on the range of its 0.5–99.5 percentiles (after
    t = 45 s in a long run) with its mean over 0.5 s, saying in its title what it leaves
    out."""
    lo_all, hi_all = float(np.min(torque)), float(np.max(torque))
    u = f" {unit}" if unit else ""
    label = f"drum torque [{unit}]" if unit else "drum torque"
    full.plot(t, torque, color="C3", lw=0.6)
    full.set_ylabel(label)
    full.set_title(f"drum torque, full range {lo_all:.0f} to {hi_all:.0f}{u}", fontsize=10)
    full.axhline(0.0, color="k", lw=0.5)
    late = t > 45 if t[-1] > 50 else np.ones_like(t, dtype=bool)
    lo, hi = np.percentile(torque[late], [0.5, 99.5])
    pad = 0.3 * (hi - lo) + 1.0
    zoom.plot(t, torque, color="C3", lw=0.6)
    zoom.plot(*window_mean(t, torque), color="k", lw=0.8, label="mean over 0.5 s")
    zoom.set_ylim(lo - pad, hi + pad)
    zoom.axhline(0.0, color="k", lw=0.5)
    zoom.set_ylabel(label)
    clipped = np.mean((torque < lo - pad) | (torque > hi + pad))
    zoom.set_title(f"zoom on {lo - pad:.0f} to {hi + pad:.0f}{u}: clipped, {clipped:.2%} of "
                   f"samples lie outside (full range {lo_all:.0f} to {hi_all:.0f}{u} above)",
                   fontsize=10)
    zoom.legend(fontsize=8, loc="upper right")


#: Colours of the nips, by their place in the scene: a nip has the same colour in every
#: figure (run figures, resonance maps). C3 (red) is left out: it marks critical radii.
NIP_COLOURS = ("C0", "C1", "C2", "C4", "C5", "C6", "C8", "C9")


#: Colours of the bounce modes of a resonance map, none of them a nip's (the map's lower
#: panel draws the nips in :data:`NIP_COLOURS`).
MODE_COLOURS = ("#6a3d9a", "#b15928", "#e7298a", "#1b9e77", "#808000", "#17becf")


def nip_colours(scene: Scene) -> dict[str, str]:
    """Colour of each nip of ``scene`` by name (the single-drum nip is ``"nip"``)."""
    return {n.name: NIP_COLOURS[i % len(NIP_COLOURS)] for i, n in enumerate(scene.nips)}


def _parts_scene(result: Result, scene: Scene | None) -> Scene:
    """The scene of ``result``: ``scene`` or the one stored in its meta."""
    if scene is not None:
        return scene
    from winder.scene.load import scene_from_dict

    return scene_from_dict(result.meta["scene_dict"])


def _panel(ax: plt.Axes, t: np.ndarray, lines: list[tuple[str, np.ndarray]], ylabel: str,
           title: str, *, lw: float = 0.8, colors: list[str] | None = None) -> None:
    """One axes: a line per ``(label, values)``, legend naming the parts."""
    for i, (label, y) in enumerate(lines):
        ax.plot(t, y, lw=lw, label=label, color=None if colors is None else colors[i])
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if lines:
        ax.legend(fontsize=8, loc="best")


def _first_open(t: np.ndarray, force: np.ndarray) -> float | None:
    """First time [s] a nip carries no force (open), or None."""
    idx = np.flatnonzero(force <= 0.0)
    return float(t[idx[0]]) if len(idx) else None


def window_mean(t: np.ndarray, y: np.ndarray, window: float = 0.5
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(mid time, mean)`` of ``y`` over consecutive windows of ``window`` [s] (the
    samples left over at the end are dropped; a run shorter than one window is one
    window)."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else window
    w = max(1, min(int(round(window / dt)), len(t)))
    n = len(t) // w
    return t[:n * w].reshape(n, w).mean(axis=1), y[:n * w].reshape(n, w).mean(axis=1)


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
    then a close-up of the first opening of a nip; ``STEM_positions.png``: a row per free
    coordinate (``x``, ``z``) of every body, each ``z`` followed by its bounce (``z`` less
    its mean over 0.5 s, in mm); ``STEM_slip.png``: a row per nip with its slip
    velocity; with a web span, ``STEM_span.png``: the span tension, the controller's
    tension error, the unwind torque and the radii; flexible parts:
    :func:`winder.plots.flex.flex_figures`. ``STEM`` is the scene name made
    file-safe; part names appear only in titles and legends. A nip keeps its colour in
    every figure. Returns the paths.
    """
    scene = _parts_scene(result, scene)
    out = Path(out_dir)
    name = _label(result.meta.get("scene", scene.name))
    stem = safe_stem(result.meta.get("scene", scene.name))
    t = result.t
    paths: list[Path] = []
    color = nip_colours(scene)
    nip_label = {n.name: f"nip {n.name} ({n.a}–{n.b})" for n in scene.nips}
    bodies = body_elements(scene)  # in the machine's order
    drums = [b for b in bodies if _drive(b)]
    turning = [b for b in bodies if not _drive(b)]  # rolls, riders, ...
    wound = [b for b in bodies if b.radius_state]  # their radius is a channel

    # drums: speeds, then one torque row per drum
    fig, ax = _rows(1 + len(drums))
    first = drums[0].name
    unit = _in(result, f"{first}_speed")
    _panel(ax[0], t, [(_body_label(d), result[f"{d.name}_speed"]) for d in drums],
           "speed Ω" + unit, f"{name}: drum speeds{unit}")
    for a, d in zip(ax[1:], drums, strict=True):
        unit = _in(result, f"{d.name}_torque", "k")
        _panel(a, t, [(_body_label(d), result[f"{d.name}_torque"] / 1e3)], "torque" + unit,
               f"{_body_label(d)}: drive torque{unit}", lw=0.4)
        a.plot(*window_mean(t, result[f"{d.name}_torque"] / 1e3), color="k", lw=0.8,
               label="mean over 0.5 s")
        a.legend(fontsize=8, loc="upper left")
        a.axhline(0.0, color="k", lw=0.5)
    ax[-1].set_xlabel("t" + _in(result, "t"))
    paths.append(_save(fig, out / f"{stem}_drums.png"))

    # rolls: speed and radius
    fig, ax = _rows(2, 3.0)
    speed = _in(result, f"{wound[0].name}_speed") if wound else ""
    radius = _in(result, f"{wound[0].name}_radius") if wound else ""
    _panel(ax[0], t, [(_body_label(b), result[f"{b.name}_speed"]) for b in turning],
           "speed ω" + speed, f"{name}: roll and rider speeds{speed}")
    _panel(ax[1], t, [(_body_label(b), result[f"{b.name}_radius"]) for b in wound],
           "radius r" + radius, "paper roll radii" + radius)
    ax[1].set_xlabel("t" + _in(result, "t"))
    paths.append(_save(fig, out / f"{stem}_rolls.png"))

    # nips: one row per nip (same scale), then a close-up of the first opening
    forces = {n.name: result[f"{n.name}_normal_force"] for n in scene.nips}
    kn = _in(result, f"{scene.nips[0].name}_normal_force", "k") if scene.nips else ""
    fig, axes = plt.subplots(len(forces) + 1, 1, figsize=(9, 3.2 + 2.3 * len(forces)),
                             squeeze=False)
    ax = axes[:, 0]
    for i, (n, f) in enumerate(forces.items()):
        _panel(ax[i], t, [(nip_label[n], f / 1e3)], "F_n" + kn,
               (f"{name}: nip normal forces{kn} (F_n = 0: nip open)\n" if i == 0 else "")
               + f"{nip_label[n]}: {np.mean(f <= 0.0):.1%} of samples open", lw=0.4,
               colors=[color[n]])
        tm, fm = window_mean(t, f / 1e3)
        ax[i].plot(tm, fm, color="k", lw=0.8, label="mean over 0.5 s")
        ax[i].legend(fontsize=8, loc="upper left")
        if i:
            ax[i].sharex(ax[0])
    top = max([float(np.max(f)) / 1e3 for f in forces.values()] + [0.0])
    for a in ax[:-1]:  # one scale, from 0 (nip open) to the largest force of any nip
        a.set_ylim(-0.04 * top - 1e-3, 1.06 * top + 1e-3)
    ax[len(forces) - 1].set_xlabel("t" + _in(result, "t"))
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
    ax[-1].legend(fontsize=7, loc="upper right", framealpha=0.9)
    ax[-1].set_xlabel("t" + _in(result, "t"))
    paths.append(_save(fig, out / f"{stem}_nip_forces.png"))

    # free coordinates of every body, one row each
    coords = [(b.name, c) for b in bodies for c in ("x", "z") if f"{b.name}_{c}" in result]
    if coords:
        heights = [c for _, c in coords if c == "z"]
        fig, ax = _rows(len(coords) + len(heights), 2.0)
        i = 0
        for body, c in coords:
            y = result[f"{body}_{c}"]
            unit = _in(result, f"{body}_{c}")
            _panel(ax[i], t, [(f"{body} {c}", y)], c + unit,
                   (f"{name}: free coordinates{unit}\n" if i == 0 else "")
                   + f"{body}: {'horizontal' if c == 'x' else 'vertical'} position {c}{unit}",
                   lw=0.5)
            i += 1
            if c == "z":  # the rise with the radius hides the bounce: show it apart
                _panel(ax[i], t, [(f"{body} z − mean", 1e3 * (y - np.interp(
                    t, *window_mean(t, y))))], _in(result, f"{body}_z", "m").strip(),
                    f"{body}: bounce, z less its mean over 0.5 s"
                    + _in(result, f"{body}_z", "m"), lw=0.4)
                i += 1
        ax[-1].set_xlabel("t" + _in(result, "t"))
        paths.append(_save(fig, out / f"{stem}_positions.png"))

    # slip velocities, one row per nip
    fig, ax = _rows(len(scene.nips))
    for i, n in enumerate(scene.nips):
        unit = _in(result, f"{n.name}_slip_velocity")
        _panel(ax[i], t, [(nip_label[n.name], result[f"{n.name}_slip_velocity"])],
               "slip" + unit, (f"{name}: nip slip velocities{unit}\n" if i == 0 else "")
               + nip_label[n.name], lw=0.4, colors=[color[n.name]])
        ax[i].axhline(0.0, color="k", lw=0.5)
    ax[-1].set_xlabel("t" + _in(result, "t"))
    paths.append(_save(fig, out / f"{stem}_slip.png"))
    spans = [w for w in scene.webs if w.span is not None]
    for w in spans:  # one figure per span: STEM_span.png, or STEM_WEB_span.png
        pre = f"{w.name}_" if len(spans) > 1 else ""
        if _tensions(result, w, pre):
            paths.append(_span_figure(result, scene, bodies, w, pre,
                                      out / f"{stem}_{pre}span.png", name))
    from winder.plots.flex import flex_figures  # flexible parts (issue #25)

    return paths + flex_figures(result, scene, out, stem, name, _save)


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
    """A body in legends and titles: its drawing role and name (``roll front``)."""
    return f"{body.role} {body.name}"


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
    unit = _in(result, _tensions(result, web, pre)[0])
    _panel(ax[0], t, [(n[len(pre):].replace("_", " "), result[n])
                      for n in _tensions(result, web, pre)], "T" + unit,
           f"{name}: web span tension{unit} (EA = {span.EA:.3g} N, L = {span.length:g} m)",
           lw=0.6)
    rows = 1
    if error in result:
        unit = _in(result, error)
        _panel(ax[1], t, [("set-point − T", result[error])], "error" + unit,
               f"tension error of the unwind's controller{unit}: peak "
               f"{np.max(np.abs(result[error])):.3g} N, RMS "
               f"{np.sqrt(np.mean(result[error] ** 2)):.3g} N", lw=0.6)
        ax[1].axhline(0.0, color="k", lw=0.5)
        rows = 2
    unit = _in(result, f"{unwind.name}_torque", "k")
    _panel(ax[rows], t, [(_body_label(unwind), result[f"{unwind.name}_torque"] / 1e3)],
           "torque" + unit, f"unwind torque of {unwind.name}{unit} (negative: braking)",
           lw=0.6)
    ax[rows].axhline(0.0, color="k", lw=0.5)
    unit = _in(result, f"{unwind.name}_radius")
    _panel(ax[rows + 1], t, [(_body_label(b), result[f"{b.name}_radius"])
                             for b in [unwind, *wound]], "radius r" + unit,
           "radii of the unwinding and the wound rolls" + unit)
    ax[-1].set_xlabel("t" + _in(result, "t"))
    return _save(fig, path)


def normal_force_envelope(result: Result, window: float = 0.5, *,
                          force: str = "normal_force", radius: str = "radius"
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(radius, min, max, half peak-to-peak)`` of the channel ``force`` [N] over windows
    of ``window`` [s], against the channel ``radius`` [m]."""
    t, fn, r = result.t, result[force], result[radius]
    dt = float(np.median(np.diff(t))) if len(t) > 1 else window
    w = max(1, int(round(window / dt)))
    n = len(t) // w
    fn, r = fn[:n * w].reshape(n, w), r[:n * w].reshape(n, w)
    lo, hi = fn.min(axis=1), fn.max(axis=1)
    return r.mean(axis=1), lo, hi, (hi - lo) / 2


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
    when the labels are nip names, so that a nip has its colour of the run figures)."""
    mm = mode_map
    rows = 2 if result is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(12, 6.5 * rows) if mm.flexible else (8, 4.2 * rows),
                             sharex=True, squeeze=False)
    ax = axes[0, 0]
    r = mm.radius
    one = len(mm.coordinates) == 1
    drawn = mm.shown() if mm.flexible else mm.coordinates  # flexible: orders 1-2, torsion 1
    for i, c in enumerate(drawn):
        f = mm.frequencies[c] if c in mm.frequencies else mm.torsion[c]
        colour = MODE_COLOURS[i % len(MODE_COLOURS)]
        kind = "torsion" if c in mm.torsion else "bending" if ".bend." in c else "bounce"
        ax.plot(r, np.where(f > 0, f, np.nan), color=colour, lw=2 if kind == "bounce" else 1.5,
                ls="-" if kind != "torsion" else (0, (5, 1)),
                label="bounce mode (damped)" if one else f"{kind} mode {c} "
                + ("|λ|/2π" if kind == "torsion" else "(damped)"))
        if np.any(f == 0):  # overdamped (real eigenvalue): a bar along the bottom
            ax.plot(r, np.where(f == 0, 0.02 + 0.025 * i, np.nan), color=colour, lw=4,
                    solid_capstyle="butt", transform=ax.get_xaxis_transform(),
                    label=("bounce mode" if one else c) + " overdamped here (real "
                    "eigenvalue: no oscillation)")
    ax.plot(r, mm.slip_frequency, "C2" if one else "C7", lw=1.0,
            label="slip/torsion mode |λ|/2π (slowest)")
    harmonics = mm.harmonics()
    for name, line in harmonics.items():
        if name in _HARMONIC_STYLE:
            ax.plot(r, line, _HARMONIC_STYLE[name], color="k", lw=1,
                    label=f"{name[:-1]}× roll rotation at {mm.web_speed:g} m/s")
        else:
            ax.plot(r, line, "-.", color="0.45", lw=1, label=f"{name} rotation")
    shown = [mm.frequencies[c] if c in mm.frequencies else mm.torsion[c] for c in drawn]
    values = np.concatenate([f[np.isfinite(f) & (f > 0)]
                             for f in (*shown, *harmonics.values())])
    log = values.size > 0 and values.max() / values.min() > 30
    if log:
        ax.set_yscale("log")
        ax.set_ylim(max(values.min() * 0.7, 0.1), values.max() * 1.5)
    else:
        ax.set_ylim(0, float(np.nanmax(mm.bounce_frequency)) * 1.1)
    crossings = mm.crossings(drawn)
    for c, h, rc in crossings:
        f = float(np.interp(rc, r, mm.frequencies[c] if c in mm.frequencies
                            else mm.torsion[c]))
        ax.plot([rc], [f], "o", color="C3", ms=5, mfc="none", mew=1.2)
        if one:
            ax.axvline(rc, color="C3", lw=0.8, alpha=0.7)
            ax.annotate(f"{h[:-1]}×: r = {rc:.3f} m", (rc, ax.get_ylim()[1] * 0.02 + 1),
                        rotation=90, fontsize=8, color="C3", va="bottom")
        else:
            ax.annotate(h.split()[0], (rc, f), xytext=(3, 3), textcoords="offset points",
                        fontsize=7, color="C3")
    if crossings and not one:
        ax.plot([], [], "o", color="C3", mfc="none", label="crossing (critical radius)")
    ax.set_ylabel("frequency [Hz]")
    if mm.flexible:  # many modes: the legend beside the chart
        ax.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    else:
        ax.legend(fontsize=8 if one else 7, loc="upper right")
    ax.grid(alpha=0.3, which="both" if log else "major")
    ax.set_title(_label(title, 120) or "Resonance map (Campbell chart)")
    if result is not None:
        b = axes[1, 0]
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
    if len(r) > 1:  # the map's radii (--radius-min/max), the envelope too where it is longer
        span = float(r.max() - r.min())
        ax.set_xlim(float(r.min()) - 0.02 * span, float(r.max()) + 0.02 * span)
    axes[-1, 0].set_xlabel("roll radius r [m]")
    return _save(fig, Path(path))
