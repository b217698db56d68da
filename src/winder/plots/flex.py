"""Figures of flexible bodies (issue #25): deflection along the width at chosen times and
the twist over time, per flexible body; the line load along each sliced nip over time (a
heat map) with its least, largest and mean value.

They are drawn from the result's channels only (``NAME_s{i}_x``, ``NAME_s{i}_z``,
``NAME_twist``, ``NIP_s{i}_normal_force``, ``NIP_line_load_*``) and the scene's parts (each
flexible part's ``flex`` and its length), and called by
:func:`winder.plots.machine.machine_figures` for a scene that has flexible parts."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from winder.io.result import Result

__all__ = ["FlexBody", "flexible_bodies", "deflection", "line_load_map", "flex_figures",
           "SNAPSHOTS"]

#: How many instants the deflection figure draws (evenly from the start to the end).
SNAPSHOTS = 5


@dataclass(frozen=True)
class FlexBody:
    """A flexible part of a scene: its ``name``, ``segments`` N, ``length`` L [m] and
    ``support``: the centre ``(x, z)`` [m] of its line of bearings (a drum), or None
    (riders and rolls: the deflection is taken from the segments' mean)."""

    name: str
    segments: int
    length: float
    support: tuple[float, float] | None

    @property
    def stations(self) -> np.ndarray:
        """The segment centres along the axis, ``(i + ½) L/N`` [m]."""
        return (np.arange(self.segments) + 0.5) * self.length / self.segments


def flexible_bodies(scene: Any) -> list[FlexBody]:
    """The flexible parts of ``scene`` (every body type's parts with a ``flex``)."""
    out = []
    for parts in (getattr(scene, "bodies", None) or {}).values():
        for p in parts:
            flex = getattr(p, "flex", None)
            if flex is None:
                continue
            length = p.length if getattr(p, "length", None) is not None else p.width
            support = tuple(p.centre) if p.__class__.__name__ == "DrumPart" else None
            out.append(FlexBody(p.name, flex.segments, float(length), support))
    return out


def deflection(result: Result, body: FlexBody, coord: str) -> np.ndarray | None:
    """The deflection [m] of ``body`` along ``coord`` (``x`` or ``z``), samples × segments:
    from its line of bearings (a drum), else from the segments' mean (its bending alone);
    None where its segments are not free along ``coord``."""
    names = [f"{body.name}_s{i}_{coord}" for i in range(body.segments)]
    if any(n not in result for n in names):
        return None
    y = np.column_stack([result[n] for n in names])
    if body.support is not None:
        return y - body.support[0 if coord == "x" else 1]
    return y - y.mean(axis=1, keepdims=True)


def line_load_map(result: Result, nip: str, body: FlexBody) -> np.ndarray:
    """The line load [N/m] of each slice of the sliced nip ``nip`` against ``body``,
    samples × slices: ``F_i / (L/N)``."""
    h = body.length / body.segments
    return np.column_stack([result[f"{nip}_s{i}_normal_force"]
                            for i in range(body.segments)]) / h


def _instants(t: np.ndarray) -> list[int]:
    return sorted({int(round(k)) for k in np.linspace(0, len(t) - 1, SNAPSHOTS)})


def flex_figures(result: Result, scene: Any, out: Path, stem: str, name: str,
                 save: Callable[[plt.Figure, Path], Path]) -> list[Path]:
    """``STEM_flex_NAME.png`` per flexible body (its ``z`` and ``x`` deflection along the
    width at :data:`SNAPSHOTS` instants, its twist over time) and
    ``STEM_line_load_NIP.png`` per sliced nip (the heat map of its slices' line load over
    time and along the width, then its least, largest and mean); ``save`` writes a figure.
    Returns the paths."""
    t = result.t
    paths: list[Path] = []
    bodies = {b.name: b for b in flexible_bodies(scene)}
    for b in bodies.values():
        rows = [c for c in ("z", "x") if deflection(result, b, c) is not None]
        fig, ax = plt.subplots(len(rows) + 1, 1, figsize=(9, 1.6 + 2.6 * (len(rows) + 1)),
                               squeeze=False)
        ax = ax[:, 0]
        ref = "from its bearings' line" if b.support is not None else \
            "from the segments' mean (bending only)"
        for a, c in zip(ax, rows, strict=False):
            d = deflection(result, b, c)
            for k in _instants(t):
                a.plot(b.stations, 1e3 * d[k], marker="o", ms=3, label=f"t = {t[k]:.3g} s")
            a.set_ylabel(f"{c} deflection [mm]")
            a.set_title(f"{name}: {b.name} {c} deflection along the width, {ref}",
                        fontsize=10)
            a.grid(True, alpha=0.3)
            a.legend(fontsize=7, loc="best")
        ax[len(rows) - 1].set_xlabel("position along the axis y [m] (0: drive end)")
        twist = f"{b.name}_twist"
        if twist in result:
            ax[-1].plot(t, 1e3 * result[twist], lw=0.6)
        ax[-1].set_ylabel("twist [mrad]")
        ax[-1].set_xlabel("t [s]")
        ax[-1].set_title(f"{b.name}: twist, segment 0 (drive end) less the last segment",
                         fontsize=10)
        ax[-1].grid(True, alpha=0.3)
        paths.append(save(fig, out / f"{stem}_flex_{b.name}.png"))
    for nip in getattr(scene, "nips", ()):
        b = bodies.get(nip.a) or bodies.get(nip.b)
        if b is None or f"{nip.name}_s0_normal_force" not in result:
            continue
        q = line_load_map(result, nip.name, b)
        fig, ax = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
        mesh = ax[0].pcolormesh(t, b.stations, q.T / 1e3, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=ax[0], label="line load [kN/m]")
        ax[0].set_ylabel("position along the width y [m]")
        ax[0].set_title(f"{name}: nip {nip.name} ({nip.a}–{nip.b}), line load of its "
                        f"{b.segments} slices [kN/m]", fontsize=10)
        for key, style in (("max", "-"), ("mean", "--"), ("min", "-")):
            ax[1].plot(t, result[f"{nip.name}_line_load_{key}"] / 1e3, style, lw=0.7,
                       label=key)
        ax[1].set_ylabel("line load [kN/m]")
        ax[1].set_xlabel("t [s]")
        ax[1].set_title(f"nip {nip.name}: least, mean and largest line load along the width",
                        fontsize=10)
        ax[1].grid(True, alpha=0.3)
        ax[1].legend(fontsize=8, loc="best")
        paths.append(save(fig, out / f"{stem}_line_load_{nip.name}.png"))
    return paths
