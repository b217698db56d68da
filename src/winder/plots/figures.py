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
from winder.plots.layout import DPI  # noqa: E402
from winder.plots.smooth import centred_mean  # noqa: E402
from winder.scene.load import Scene  # noqa: E402

__all__ = ["paper_figures", "closeup_end", "CLOSEUP_STEP",
           "normal_force_envelope", "window_mean", "nip_colours", "NIP_COLOURS",
           "MODE_COLOURS", "collected"]

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
        if fig.get_layout_engine() is None:  # a figure laid out by its own engine keeps it
            fig.tight_layout()
        if _COLLECTED is not None:
            png = io.BytesIO()
            fig.savefig(png, dpi=DPI, format="png")
            _COLLECTED.append((path, png.getvalue()))
        else:
            atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=DPI, format="png"))
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
    spin ω with the conserved ``J ω`` (Fig. 2). A result of a scene of parts:
    :func:`winder.plots.run.run_figures` draws :func:`winder.plots.machine.machine_figures`.
    """
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
    tm, mean, used = centred_mean(t, torque, 0.5)
    zoom.plot(tm, mean, color="k", lw=0.8, label=f"centred mean over {used:.3g} s")
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


def window_mean(t: np.ndarray, y: np.ndarray, window: float = 0.5
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(mid time, mean)`` of ``y`` over consecutive windows of ``window`` [s] (the
    samples left over at the end are dropped; a run shorter than one window is one
    window)."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else window
    w = max(1, min(int(round(window / dt)), len(t)))
    n = len(t) // w
    return t[:n * w].reshape(n, w).mean(axis=1), y[:n * w].reshape(n, w).mean(axis=1)


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
