"""The resonance map's figure (a Campbell chart) of a :class:`winder.ModeMap`: its modes
against the wound roll's radius with the rotation harmonics and their crossings, the
simulated normal-force envelopes below; a map of one row (the initial state of a machine
without a wound roll, or with contact off) as markers."""

from __future__ import annotations

from pathlib import Path

import numpy as np

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
    when the labels are nip names, so that a nip has its colour of the run figures)."""
    mm = mode_map
    rows = 2 if result is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(12, 6.5 * rows) if mm.flexible else (8, 4.2 * rows),
                             sharex=True, squeeze=False)
    ax = axes[0, 0]
    r = mm.radius
    single = len(r) == 1  # the initial state (or a map of one radius): markers, no lines
    if single and not np.isfinite(r[0]):  # no wound roll: no radius axis
        r = np.zeros(1)
    one = len(mm.coordinates) == 1
    drawn = mm.shown() if mm.flexible else mm.coordinates  # flexible: orders 1-2, torsion 1
    for i, c in enumerate(drawn):
        f = mm.frequencies[c] if c in mm.frequencies else mm.torsion[c]
        colour = MODE_COLOURS[i % len(MODE_COLOURS)]
        kind = "torsion" if c in mm.torsion else "bending" if ".bend." in c else "bounce"
        style = {"marker": "D" if kind == "torsion" else "o", "ls": "none", "ms": 7} \
            if single else {"lw": 2 if kind == "bounce" else 1.5,
                            "ls": "-" if kind != "torsion" else (0, (5, 1))}
        if single and ".bend.x" in c:  # beside its z order of the same frequency: hollow
            style.update(mfc="none", ms=11, mew=1.5)
        free = single and c in mm.natural and mm.natural[c][0] < FREE_BELOW
        if free:  # a zero eigenvalue: nothing holds it, a mark along the bottom
            ax.plot(r, [0.03 + 0.04 * i], marker="v", ms=8, ls="none", color=colour,
                    transform=ax.get_xaxis_transform(), label=f"{c} free: 0 Hz (nothing "
                    "holds it)")
            continue
        ax.plot(r, np.where(f > 0, f, np.nan), color=colour, **style,
                label="bounce mode (damped)" if one else f"{kind} mode {c} "
                + ("|λ|/2π" if kind == "torsion" else "(damped)"))
        if np.any(f == 0) and not single:  # overdamped (real eigenvalue): a bar at the bottom
            ax.plot(r, np.where(f == 0, 0.02 + 0.025 * i, np.nan), color=colour, lw=4,
                    solid_capstyle="butt", transform=ax.get_xaxis_transform(),
                    label=("bounce mode" if one else c) + " overdamped here (real "
                    "eigenvalue: no oscillation)")
    if not single or np.all(mm.slip_frequency > 0):  # (a NaN: no slip mode)
        ax.plot(r, mm.slip_frequency, "C2" if one else "C7", lw=1.0,
                **({"marker": "s", "ls": "none"} if single else {}),
                label="slip/torsion mode |λ|/2π (slowest)")
    harmonics = mm.harmonics()
    for name, line in harmonics.items():
        if name in _HARMONIC_STYLE:
            if single and not np.all(np.isfinite(line)):
                continue  # no wound roll: no roll rotation
            ax.plot(r, line, *(("x",) if single else (_HARMONIC_STYLE[name],)), color="k",
                    lw=1, label=f"{name[:-1]}× roll rotation at {mm.web_speed:g} m/s")
        elif single:  # a drum's rotation: the same at every radius
            ax.axhline(float(line[0]), ls="-.", color="0.45", lw=1, label=f"{name} rotation")
        else:
            ax.plot(r, line, "-.", color="0.45", lw=1, label=f"{name} rotation")
    shown = [mm.frequencies[c] if c in mm.frequencies else mm.torsion[c] for c in drawn]
    values = np.concatenate([f[np.isfinite(f) & (f > 0)]
                             for f in (*shown, *harmonics.values())])
    log = values.size > 0 and values.max() / values.min() > 30
    if log:
        ax.set_yscale("log")
        ax.set_ylim(max(values.min() * 0.7, 0.1), values.max() * 1.5)
    elif single or not np.any(np.isfinite(mm.bounce_frequency)):
        top = max(float(values.max()) if values.size else 0.0,
                  float(np.nanmax(mm.slip_frequency, initial=0.0)))
        ax.set_ylim(0, top * 1.15 if top > 0 else 1.0)
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
    if mm.initial_state and not np.isfinite(mm.radius[0]):
        ax.set_xlim(-1.0, 1.0)
        ax.set_xticks([])
        axes[-1, 0].set_xlabel(f"the initial state ({mm.initial_reason})")
    elif mm.initial_state:
        axes[-1, 0].set_xlabel(f"roll radius r [m]: the initial state ({mm.initial_reason})")
    else:
        axes[-1, 0].set_xlabel("roll radius r [m]")
    return figures._save(fig, Path(path))  # (looked up: the tests capture it)
