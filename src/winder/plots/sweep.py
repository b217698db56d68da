"""The runnability map: web speed against roll diameter, coloured by vibration level, with
the critical-speed lines of the resonance map (:mod:`winder.analysis.modes`) on top.

Each run of a sweep is one row of cells (its web speed) across the radius bands of its
summary; the colour is the band's vibration level (half peak-to-peak nip force over the
mean nip force, :mod:`winder.analysis.sweep_summary`): 1 and above means the roll lifts off.
Where the roll turns ``k`` times per bounce period the imbalance drives the nip at
resonance: at diameter ``d`` that happens at web speed ``v_k(d) = π d f_bounce(d/2) / k``,
drawn for ``k = 1, 2, 3`` from the linearised modes of the panel's scene. When swept keys
other than the web speed exist, each of their combinations gets its own panel. Axes and
panels are labelled with the swept keys in words (all of them for tied keys) and their
units.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

from winder._errors import ArgumentError, WinderError  # noqa: E402
from winder.analysis.modes import mode_map  # noqa: E402
from winder.analysis.sweep_grid import set_path, split_keys  # noqa: E402
from winder.analysis.sweep_table import SweepTable  # noqa: E402
from winder.io.files import atomic_write  # noqa: E402
from winder.scene.keys import find_key, key_unit  # noqa: E402
from winder.scene.load import scene_from_dict  # noqa: E402

__all__ = ["runnability_map", "map_layout", "axis_label", "key_words"]

#: An axis whose keys are all drives' web speeds (``drum.drive.web_speed``,
#: ``drum.NAME.drive.web_speed``, tied or not) is the map's vertical axis when it is swept.
_SPEED_PATH = ("drive", "web_speed")
_ORDERS = ((1, "-"), (2, "--"), (3, ":"))
_MAX_PANELS = 12


def _cell_edges(values: np.ndarray) -> np.ndarray:
    """Edges of cells centred on sorted ``values`` (midpoints; half steps at the ends)."""
    if len(values) == 1:
        half = 0.05 * abs(values[0]) or 0.5
        return np.array([values[0] - half, values[0] + half])
    mid = (values[1:] + values[:-1]) / 2
    return np.concatenate([[2 * values[0] - mid[0]], mid, [2 * values[-1] - mid[-1]]])


def _critical_lines(table: SweepTable, fixed: dict, speeds: np.ndarray,
                    ) -> tuple[np.ndarray, np.ndarray] | str:
    """``(radius, bounce frequency)`` of the panel's scene, or why there are none."""
    data = copy.deepcopy(table.base_scene)
    for key, value in fixed.items():
        set_path(data, key, value)
    try:
        scene = scene_from_dict(data, source="<sweep>")
        edges = table.band_edges
        radii = np.linspace(edges[0], edges[-1], 60)
        mm = mode_map(scene, radii, web_speed=float(np.median(speeds)))
    except WinderError as exc:
        return f"no critical-speed lines: {exc}"
    return mm.radius, mm.bounce_frequency


def _is_speed(axis: str) -> bool:
    """Whether every key of ``axis`` (``"k1,k2"``) is a drive's web speed."""
    return all(tuple(k.split(".")[-2:]) == _SPEED_PATH and k.count(".") >= 2
               for k in split_keys(axis))


def _with_unit(text: str, unit: str) -> str:
    return f"{text} [{unit}]" if unit else text


#: Words for the short forms in key names.
_WORDS = {"com": "centre-of-mass"}


def key_words(path: str, scene: dict) -> str:
    """A scene key in words for an axis: its owner (the table, the part's name, the
    sub-tables) and its meaning, the first clause of its declaration's text when that is
    short, else its name in words: ``drum.drive.web_speed`` → ``drum drive: web speed``,
    ``drum.front.radius`` → ``drum front: drum radius R``. An unknown path stays as it
    is."""
    parts = path.split(".")
    head, rest = parts[0], parts[1:]
    array = isinstance(scene.get(head), list) if scene else False
    owner = [head, *rest[:1]] if array and rest else [head]
    rest = rest[1:] if array else rest
    if not rest:
        return path
    try:
        key = find_key(".".join([head + ("[]" if array else ""), *rest[:-1]]), rest[-1])
    except KeyError:
        return path
    clause = re.split(r";| \(", key.doc)[0].strip()
    meaning = clause if clause and len(clause) <= 40 and ":" not in clause else \
        " ".join(_WORDS.get(w, w) for w in rest[-1].split("_"))
    return f"{' '.join([*owner, *rest[:-1]])}: {meaning}"


def axis_label(axis: str, scene: dict, *, sep: str = ",\n") -> str:
    """The label of a swept axis (``"k1,k2"`` for tied keys): every key in words
    (:func:`key_words`) with its unit (``drum drive: web speed [m/s]``); tied keys of one
    unit share it at the end. ``scene``: the base scene's nested tables (they tell arrays
    of parts from tables)."""
    keys = split_keys(axis)
    units = [key_unit(k, scene) for k in keys]
    words = [key_words(k, scene) for k in keys]
    if len(set(units)) == 1:
        return _with_unit(sep.join(words), units[0])
    return sep.join(_with_unit(k, u) for k, u in zip(words, units, strict=True))


def _value_text(axis: str, value: object, scene: dict) -> str:
    """``"k1, k2 = 20 m/s"``: a panel's fixed value of an axis, with its unit."""
    units = {key_unit(k, scene) for k in split_keys(axis)}
    unit = f" {units.pop()}" if len(units) == 1 and "" not in units and "-" not in units \
        else ""
    shown = f"{value:g}" if isinstance(value, float) else f"{value}"
    return f"{', '.join(key_words(k, scene) for k in split_keys(axis))} = {shown}{unit}"


def map_layout(vary: dict[str, list]) -> tuple[str, list[str]]:
    """``(vertical axis, panel axes)`` of the map of a sweep over ``vary`` (``{axis:
    values}``, an axis of tied keys named ``"k1,k2"``); raises :class:`ArgumentError` when
    it cannot be drawn (checked before a sweep runs): a non-numeric vertical axis, or more
    than 12 panels. The vertical axis is the first of drums' web speeds, else the first."""
    keys = list(vary)
    ykey = next((k for k in keys if _is_speed(k)), keys[0])
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in vary[ykey]):
        raise ArgumentError(f"--plot: the runnability map needs numbers on its vertical "
                            f"axis; {ykey} has values {list(vary[ykey])}")
    others = [k for k in keys if k != ykey]
    panels = math.prod(len(set(vary[k])) for k in others)
    if panels > _MAX_PANELS:
        raise ArgumentError(f"--plot: the runnability map draws one panel per combination "
                            f"of {', '.join(others)}: {panels} panels, at most "
                            f"{_MAX_PANELS}; sweep fewer values")
    return ykey, others


def runnability_map(table: SweepTable, path: str | Path, *, column: str = "vibration_level",
                    title: str = "") -> Path:
    """Draw the runnability map of ``table`` into ``path`` (PNG); returns the path.

    The vertical axis is the web speed when drums' web speeds are swept (with the
    critical-speed lines), else the first swept axis. ``column``: the per-band column that
    colours the cells (``vibration_level`` by default)."""
    frame = table.frame
    if len(frame) == 0:
        raise ArgumentError(f"{table.path}: the sweep has no finished run to draw")
    # one column per axis: tied keys hold equal values, the first stands for them all
    first = {",".join(a): a[0] for a in table.axes}
    ykey, others = map_layout({name: frame[k].tolist() for name, k in first.items()})
    combos = list(itertools.product(*(sorted(set(frame[first[k]])) for k in others))) or [()]
    level = table.bands(column)
    d_edges = 2 * table.band_edges
    ncol = min(3, len(combos))
    nrow = math.ceil(len(combos) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol + 1.2, 4.4 * nrow),
                             squeeze=False, sharex=True, sharey=True, layout="constrained")
    finite = level[np.isfinite(level) & (level > 0)]
    vmin = max(float(np.min(finite)), 1e-3) if len(finite) else 1e-2
    vmax = max(float(np.max(finite)), 1.5) if len(finite) else 10.0
    norm = LogNorm(vmin=vmin, vmax=vmax)
    mesh = None
    for ax, combo in zip(axes.flat, combos, strict=False):
        fixed = dict(zip(others, combo, strict=True))
        mask = np.ones(len(frame), dtype=bool)
        for k, v in fixed.items():
            mask &= (frame[first[k]] == v).to_numpy()
        ys = frame[first[ykey]].to_numpy(dtype=float)[mask]
        order = np.argsort(ys)
        ys, cells = ys[order], level[mask][order]
        mesh = ax.pcolormesh(d_edges, _cell_edges(ys), np.ma.masked_invalid(cells),
                             cmap="magma_r", norm=norm, shading="flat")
        if len(ys) and _is_speed(ykey):
            lines = _critical_lines(table, {k: v for name, v in fixed.items()
                                            for k in split_keys(name)}, ys)
            if isinstance(lines, str):
                ax.text(0.02, 0.02, lines[:80], transform=ax.transAxes, fontsize=7)
            else:
                r, fb = lines
                for k, style in _ORDERS:
                    ax.plot(2 * r, 2 * math.pi * r * fb / k, "c" + style, lw=1.4,
                            label=f"{k}× rotation = bounce mode")
                ax.set_ylim(_cell_edges(ys)[0], _cell_edges(ys)[-1])
                ax.legend(fontsize=7, loc="lower right")
        ax.set_xlim(d_edges[0], d_edges[-1])
        ax.set_title("; ".join(_value_text(k, v, table.base_scene)
                               for k, v in fixed.items()), fontsize=9)
        ax.grid(alpha=0.25)
    for ax in axes.flat[len(combos):]:
        ax.set_visible(False)
    for ax in axes[-1, :]:
        ax.set_xlabel("roll diameter [m]")
    for ax in axes[:, 0]:
        ax.set_ylabel(axis_label(ykey, table.base_scene),
                      fontsize=10 if len(split_keys(ykey)) == 1 else 8)
    cbar = fig.colorbar(mesh, ax=axes.ravel().tolist(), shrink=0.9)
    cbar.set_label(f"{column.replace('_', ' ')} [-]" + (" (≥ 1: lift-off)"
                                                         if column == "vibration_level"
                                                         else ""))
    fig.suptitle(title or "Runnability map", fontsize=11)
    target = Path(path)
    atomic_write(target, lambda tmp: fig.savefig(tmp, dpi=110, format="png"))
    plt.close(fig)
    return target
