"""The paper's figures from a result (matplotlib, PNG)."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ._files import atomic_write, safe_stem  # noqa: E402
from ._result import Result  # noqa: E402
from ._scene import Scene  # noqa: E402

__all__ = ["paper_figures", "campbell_figure", "normal_force_envelope"]


def _save(fig: plt.Figure, path: Path) -> Path:
    try:
        fig.tight_layout()
        atomic_write(path, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    finally:
        plt.close(fig)
    return path


def _label(text: object, limit: int = 80) -> str:
    """Scene text as plain title text: no control characters, no mathtext (``$``)."""
    return re.sub(r"[\x00-\x1f\x7f]", "?", str(text))[:limit].replace("$", r"\$")


def _first_liftoff(result: Result) -> float | None:
    fn = result["normal_force"]
    idx = np.flatnonzero(fn <= 0.0)
    return float(result.t[idx[0]]) if len(idx) else None


def paper_figures(result: Result, out_dir: str | Path, *, scene: Scene | None = None,
                  closeup: Result | None = None) -> list[Path]:
    """Write the paper's figures for ``result`` into ``out_dir``; returns the paths.

    With contact: speeds + drum torque (Figs. 4/5), roll vertical velocity + radius
    (Fig. 6), roll angular velocity + acceleration (Fig. 7), nip normal force with a
    close-up of the first lift-off (Fig. 8; ``closeup`` is a finely sampled result of
    that window, re-simulated from ``scene`` when not given). Without contact: the free
    spin ω with the conserved ``J ω`` (Fig. 2).
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
        ax[0].set_ylabel("ω [rad/s]")
        ax[0].set_title(f"{name}: free spin, paper added from rest (Fig. 2)")
        jw = result["inertia"] * result["roll_speed"]
        ax[1].plot(t, jw, color="C2", label="J ω")
        ax[1].set_ylabel("J ω [kg m²/s]")
        span = np.ptp(jw) / max(abs(jw[0]), 1e-300)
        ax[1].set_title(f"angular momentum J ω (relative variation {span:.1e})")
        ax[1].set_ylim(jw[0] * 0.9, jw[0] * 1.1) if jw[0] > 0 else None
        ax[1].set_xlabel("t [s]")
        for a in ax:
            a.grid(True, alpha=0.3)
            a.legend()
        return [_save(fig, out / f"{stem}_fig2_free_spin.png")]

    fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    ax[0].plot(t, result["drum_speed"], label="drum Ω")
    ax[0].plot(t, result["roll_speed"], label="roll ω", alpha=0.8)
    ax[0].set_ylabel("speed [rad/s]")
    ax[0].set_ylim(0, 1.05 * max(np.max(result["roll_speed"]), np.max(result["drum_speed"])))
    R = float(result.meta.get("drum_radius", 0.5))
    eq = np.flatnonzero(np.diff(np.sign(result["radius"] - R)))
    if len(eq):
        ax[0].axvline(t[eq[0]], color="k", ls=":", label=f"r = R at {t[eq[0]]:.0f} s")
    ax[0].legend()
    ax[0].set_title(f"{name}: drum and roll speed, drum torque "
                    f"({'with' if web else 'without'} web momentum, Fig. {4 if web else 5})")
    ax[1].plot(t, result["drum_torque"], color="C3", lw=0.6)
    ax[1].set_ylabel("drum torque [N m]")
    lo, hi = np.percentile(result["drum_torque"][t > 45], [0.5, 99.5]) if t[-1] > 50 else \
        np.percentile(result["drum_torque"], [0.5, 99.5])
    pad = 0.3 * (hi - lo) + 1.0
    ax[1].set_ylim(lo - pad, hi + pad)
    ax[1].axhline(0.0, color="k", lw=0.5)
    ax[1].set_xlabel("t [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig{4 if web else 5}_speeds_torque.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    ax[0].plot(t, result["z_dot"] * 1e3, lw=0.5)
    ax[0].set_ylabel("roll vertical velocity ż [mm/s]")
    ax[0].set_title(f"{name}: roll vertical velocity and radius (Fig. 6)")
    ax[1].plot(t, result["radius"], label="roll radius r")
    ax[1].plot(t, result["z"] - result["z"][0], label="rise of the roll axis z − z₀")
    ax[1].set_ylabel("[m]")
    ax[1].set_xlabel("t [s]")
    ax[1].legend()
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig6_vertical_velocity_radius.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    ax[0].plot(t, result["roll_speed"], lw=0.6)
    ax[0].set_ylabel("roll speed ω [rad/s]")
    ax[0].set_title(f"{name}: roll angular velocity and acceleration (Fig. 7)")
    ax[1].plot(t, result["roll_accel"], lw=0.4, color="C1")
    ax[1].set_ylabel("roll acceleration ω̇ [rad/s²]")
    ax[1].set_xlabel("t [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig7_roll_speed_accel.png"))

    fig, ax = plt.subplots(2, 1, figsize=(9, 7))
    ax[0].plot(t, result["normal_force"] / 1e3, lw=0.4)
    ax[0].plot(t, result["mass"] * 9.81 / 1e3, color="k", lw=0.8, label="weight m g")
    ax[0].set_ylabel("normal force F_n [kN]")
    ax[0].set_xlabel("t [s]")
    ax[0].set_title(f"{name}: nip normal force (Fig. 8)")
    ax[0].legend()
    t_lift = _first_liftoff(result)
    if closeup is None and t_lift is not None and scene is not None:
        from ._simulate import simulate

        closeup = simulate(scene, t_end=min(t_lift + 2.0, t[-1]), output_step=2e-4)
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
    ax[1].set_ylabel("F_n [N]")
    ax[1].set_xlabel("t [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
    paths.append(_save(fig, out / f"{stem}_fig8_normal_force.png"))
    return paths


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
                    title: str = "", envelopes: dict[str, tuple[str, str]] | None = None
                    ) -> Path:
    """Resonance map (:class:`winder.ModeMap`): the bounce modes (one line per free
    coordinate) and the slowest slip/torsion mode against the radius, the 1×/2×/3× roll
    rotation lines and the drums' rotation, every crossing of a harmonic with a bounce mode
    marked; with ``result``, the simulated normal-force envelopes below on the same radius
    axis (``envelopes``: label → (force channel, radius channel); default the single-drum
    ``normal_force`` against ``radius``)."""
    mm = mode_map
    rows = 2 if result is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 4.2 * rows), sharex=True, squeeze=False)
    ax = axes[0, 0]
    r = mm.radius
    one = len(mm.coordinates) == 1
    for i, c in enumerate(mm.coordinates):
        f = mm.frequencies[c]
        ax.plot(r, np.where(f > 0, f, np.nan), f"C{i}", lw=2,
                label="bounce mode (damped)" if one else f"bounce mode {c} (damped)")
    ax.plot(r, mm.slip_frequency, "C2" if one else "C7", lw=1.0,
            label="slip/torsion mode |λ|/2π (slowest)")
    harmonics = mm.harmonics()
    for name, line in harmonics.items():
        if name in _HARMONIC_STYLE:
            ax.plot(r, line, _HARMONIC_STYLE[name], color="k", lw=1,
                    label=f"{name[:-1]}× roll rotation at {mm.web_speed:g} m/s")
        else:
            ax.plot(r, line, "-.", color="0.45", lw=1, label=f"{name} rotation")
    values = np.concatenate([f[np.isfinite(f) & (f > 0)]
                             for f in (*mm.frequencies.values(), *harmonics.values())])
    log = values.size > 0 and values.max() / values.min() > 30
    if log:
        ax.set_yscale("log")
        ax.set_ylim(max(values.min() * 0.7, 0.1), values.max() * 1.5)
    else:
        ax.set_ylim(0, float(np.nanmax(mm.bounce_frequency)) * 1.1)
    crossings = mm.crossings()
    for c, h, rc in crossings:
        f = float(np.interp(rc, r, mm.frequencies[c]))
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
    ax.legend(fontsize=8 if one else 7, loc="upper right")
    ax.grid(alpha=0.3, which="both" if log else "major")
    ax.set_title(_label(title, 120) or "Resonance map (Campbell chart)")
    if result is not None:
        b = axes[1, 0]
        pairs = envelopes or {"": ("normal_force", "radius")}
        for i, (label, (force, radius)) in enumerate(pairs.items()):
            rr, lo, hi, _ = normal_force_envelope(result, force=force, radius=radius)
            b.fill_between(rr, lo / 1e3, hi / 1e3, color=f"C{i + 1}", alpha=0.5, lw=0,
                           label=label or None)
            b.plot(rr, hi / 1e3, f"C{i + 1}", lw=0.6)
        for _, _, rc in crossings:
            b.axvline(rc, color="C3", lw=0.8, alpha=0.5)
        if len(pairs) > 1:
            b.legend(fontsize=8, loc="upper right")
        b.set_ylabel("normal force envelope [kN]")
        b.grid(alpha=0.3)
        b.set_title("simulated nip normal force (min-max over 0.5 s)", fontsize=10)
    axes[-1, 0].set_xlabel("roll radius r [m]")
    return _save(fig, Path(path))
