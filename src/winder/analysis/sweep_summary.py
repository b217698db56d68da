"""One run of a sweep reduced to a summary: nip forces, lift-off and bounce per radius band.

The wound roll's radius grows through the run; the summary splits it into bands (edges
``[m]``, the same for every run of a sweep) and reports per band, for each nip:

- ``nip_force_peak`` [N]: the largest nip normal force ``F_n`` sampled in the band;
- ``nip_force_rms`` [N]: the root mean square of ``F_n`` over the band's samples;
- ``liftoff_share_band`` [-]: the share of the band's samples with the nip open
  (``F_n = 0``: the body in the air);
- ``bounce_amplitude`` [m]: the largest half peak-to-peak nip penetration ``δ`` over a
  window of ``window`` seconds whose mean radius lies in the band;
- ``vibration_level`` [-]: the largest half peak-to-peak ``F_n`` over such a window,
  divided by the window's mean ``F_n`` (the load on the nip on average): 1 means the nip
  force swings down to zero, i.e. lift-off.

and for the whole run: ``liftoff_share``, the radii of the first and last sample with the
nip open (``liftoff_radius_first``, ``liftoff_radius_last``), ``vibration_start_radius``
(mean radius of the first window whose vibration level reaches ``threshold``), the number
of located lift-offs and touch-downs (``contact_events``), the final radius and time.
Bands a run never reaches hold NaN; without the nip (``[effects] contact = false``)
every nip quantity is NaN.

A single-drum scene has one nip and these are its columns (:data:`BAND_COLUMNS`,
:data:`SCALAR_COLUMNS`). A scene of parts (channels of machines.md §9) has them per nip,
named ``NIP.column`` (:func:`nip_columns`), and the plain columns summarise all nips:
peaks, RMS, bounce and vibration the largest over the nips, lift-off shares and radii
counting a sample as "in the air" when any nip is open, the vibration start the first
window where any nip reaches ``threshold``. The radius is that of the roll the web enters
(``[web] entry_nip``), else of the first wound roll.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from winder.io.result import Result
from winder.parts import BodyElement, body_elements
from winder.scene.load import Scene

__all__ = ["BAND_COLUMNS", "SCALAR_COLUMNS", "NIP_SCALAR_COLUMNS", "default_band_edges",
           "summarise", "empty_summary", "nip_columns", "scene_nip_names", "wound_roll"]

#: Per-band list columns of a summary (one value per radius band).
BAND_COLUMNS = ("nip_force_peak", "nip_force_rms", "liftoff_share_band", "bounce_amplitude",
                "vibration_level")
#: Scalar float columns of a summary.
SCALAR_COLUMNS = ("liftoff_share", "liftoff_radius_first", "liftoff_radius_last",
                  "vibration_start_radius", "contact_events", "final_radius", "t_reached")
#: Scalar columns a scene of parts also has per nip (``NIP.column``).
NIP_SCALAR_COLUMNS = ("liftoff_share", "liftoff_radius_first", "liftoff_radius_last",
                      "vibration_start_radius")


def nip_columns(nips: Sequence[str]) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The per-nip ``(scalar, per-band)`` column names ``NIP.column`` for nips ``nips``."""
    return (tuple(f"{n}.{c}" for n in nips for c in NIP_SCALAR_COLUMNS),
            tuple(f"{n}.{c}" for n in nips for c in BAND_COLUMNS))


def scene_nip_names(scene_dict: Mapping[str, Any]) -> tuple[str, ...]:
    """Names of the nips with their own columns: those of a scene of parts given as
    :meth:`winder.Scene.to_dict` (none for a single-drum scene, whose one nip has the
    plain columns)."""
    nips = scene_dict.get("nip")
    return tuple(str(n["name"]) for n in nips) if isinstance(nips, list) else ()


def wound_roll(scene: Scene) -> BodyElement:
    """The body element whose radius the bands split (among those whose radius is a
    state, :attr:`~winder.parts.BodyElement.radius_state`): the one at the web's entry nip,
    else the first that winds, else the first."""
    bodies = body_elements(scene)
    rolls = {b.name: b for b in bodies if b.radius_state}
    if scene.web is not None:
        for nip in scene.nips:
            if nip.name == scene.web.entry_nip:
                for side in (nip.b, nip.a):
                    if side in rolls:
                        return rolls[side]
    wound = [b for b in rolls.values() if b.winds]
    return (wound or list(rolls.values()))[0]


def end_radius(scene: Scene, t_end: float | None = None) -> float:
    """Radius [m] the roll reaches at ``t_end`` [s] (default: the scene's duration) when
    the paper arrives at the web speed without slip: ``r² = r₀² + h v t/π``."""
    T = scene.scene.duration if t_end is None else float(t_end)
    # the roll the web enters, at the largest drum web speed
    roll = wound_roll(scene)
    speeds = (b.drive_web_speed() for b in body_elements(scene))
    v = max((abs(s) for s in speeds if s is not None), default=0.0)
    if not roll.winds:
        return roll.initial_radius
    return roll.radius_after(v * T)  # the full web speed from t = 0 (no ramp)


def default_band_edges(scenes: Sequence[Scene], t_end: float | None, n: int) -> np.ndarray:
    """``n + 1`` equal band edges [m] from the smallest initial radius of ``scenes`` to 2 %
    beyond the largest no-slip end radius (:func:`end_radius`)."""
    lo = min(wound_roll(s).initial_radius for s in scenes)
    hi = max(end_radius(s, t_end) for s in scenes) * 1.02
    if not hi > lo:
        hi = lo * 1.02 + 1e-3
    return np.linspace(lo, hi, int(n) + 1)


def _band_index(r: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Band of each radius; below the first edge → band 0, beyond the last → last band."""
    return np.clip(np.searchsorted(edges, r, side="right") - 1, 0, len(edges) - 2)


def _band_max(idx: np.ndarray, x: np.ndarray, nb: int) -> np.ndarray:
    out = np.full(nb, -np.inf)
    np.maximum.at(out, idx, x)
    out[np.isneginf(out)] = np.nan
    return out


def _band_mean(idx: np.ndarray, x: np.ndarray, nb: int) -> np.ndarray:
    count = np.bincount(idx, minlength=nb).astype(float)
    total = np.bincount(idx, weights=x, minlength=nb)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.where(count > 0, count, 1.0), np.nan)


def _windows(t: np.ndarray, window: float) -> int:
    """Samples per window of ``window`` [s] (at least 2)."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else window
    return max(2, int(round(window / dt)))


def empty_summary(n_bands: int, nips: Sequence[str] = ()) -> dict[str, Any]:
    """A summary with every quantity NaN (a run that produced no samples); ``nips``: the
    nips with their own columns (:func:`scene_nip_names`)."""
    scalars, bands = nip_columns(nips)
    out: dict[str, Any] = {c: [math.nan] * n_bands for c in (*BAND_COLUMNS, *bands)}
    out.update({c: math.nan for c in (*SCALAR_COLUMNS, *scalars)})
    return out


def _layout(result: Result) -> tuple[str, dict[str, tuple[str, str]], tuple[str, ...]]:
    """``(radius channel, {nip: (normal force, penetration channel)}, per-nip names)``:
    the channels as the scene's naming calls them in the result (a single-drum scene:
    ``radius``, ``normal_force``, ``penetration``), the nips with their own columns
    (:func:`scene_nip_names`)."""
    from winder.scene.load import scene_from_dict

    scene_dict = result.meta["scene_dict"]
    scene = scene_from_dict(scene_dict)
    out = scene.naming.output_name
    return (out(f"{wound_roll(scene).name}_radius"),
            {n.name: (out(f"{n.name}_normal_force"), out(f"{n.name}_penetration"))
             for n in scene.nips}, scene_nip_names(scene_dict))


def _nip_summary(t: np.ndarray, r: np.ndarray, fn: np.ndarray, pen: np.ndarray,
                 edges: np.ndarray, window: float, threshold: float
                 ) -> tuple[dict[str, Any], np.ndarray, np.ndarray | None]:
    """One nip's columns, its open samples (bool) and its windows' vibration levels."""
    nb = len(edges) - 1
    out: dict[str, Any] = {}
    idx = _band_index(r, edges)
    air = fn <= 0.0
    out["nip_force_peak"] = _band_max(idx, fn, nb)
    out["nip_force_rms"] = np.sqrt(_band_mean(idx, fn**2, nb))
    out["liftoff_share_band"] = _band_mean(idx, air.astype(float), nb)
    out.update(_air_scalars(r, air))
    out["bounce_amplitude"] = np.full(nb, np.nan)
    out["vibration_level"] = np.full(nb, np.nan)
    out["vibration_start_radius"] = math.nan
    w = _windows(t, window)
    n = len(t) // w
    if n == 0:
        return out, air, None
    fw, pw, rw = (x[:n * w].reshape(n, w) for x in (fn, pen, r))
    mean_f = fw.mean(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        level = np.where(mean_f > 0, (fw.max(axis=1) - fw.min(axis=1)) / 2 / mean_f, np.nan)
    bounce = (pw.max(axis=1) - pw.min(axis=1)) / 2
    widx = _band_index(rw.mean(axis=1), edges)
    out["bounce_amplitude"] = _band_max(widx, bounce, nb)
    out["vibration_level"] = _band_max(widx, np.nan_to_num(level, nan=-np.inf), nb)
    out["vibration_start_radius"] = _start_radius(rw.mean(axis=1), level >= threshold)
    return out, air, level


def _air_scalars(r: np.ndarray, air: np.ndarray) -> dict[str, float]:
    """Share of samples in the air and the radii [m] of the first and last of them."""
    out = {"liftoff_share": float(np.mean(air)), "liftoff_radius_first": math.nan,
           "liftoff_radius_last": math.nan}
    if np.any(air):
        out["liftoff_radius_first"] = float(r[np.argmax(air)])
        out["liftoff_radius_last"] = float(r[len(air) - 1 - np.argmax(air[::-1])])
    return out


def _start_radius(r_mid: np.ndarray, started: np.ndarray) -> float:
    """Mean radius [m] of the first window flagged in ``started``, or NaN."""
    hit = np.flatnonzero(started)
    return float(r_mid[hit[0]]) if len(hit) else math.nan


def summarise(result: Result, edges: np.ndarray, *, window: float = 0.5,
              threshold: float = 0.5) -> dict[str, Any]:
    """The summary of ``result`` over the radius bands ``edges`` [m] (module docstring).

    ``window`` [s]: length of the windows for bounce amplitude and vibration level;
    ``threshold`` [-]: vibration level at which vibration counts as started."""
    edges = np.asarray(edges, dtype=float)
    nb = len(edges) - 1
    radius, nips, own = _layout(result)
    out = empty_summary(nb, own)
    t = result.t
    if len(t) == 0:
        return out
    r = result[radius]
    out["final_radius"] = float(r[-1])
    out["t_reached"] = float(t[-1])
    out["contact_events"] = float(result.meta.get("events", math.nan))
    if "contact" not in result.meta.get("effects", ["contact"]):
        return out
    per = {n: _nip_summary(t, r, result[f], result[p], edges, window, threshold)
           for n, (f, p) in nips.items()}
    for n in own:
        out.update({f"{n}.{k}": v.tolist() if isinstance(v, np.ndarray) else v
                    for k, v in per[n][0].items()})
    cols = [c for c, _, _ in per.values()]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # bands no run reached: all NaN
        for c in ("nip_force_peak", "nip_force_rms", "bounce_amplitude", "vibration_level"):
            out[c] = np.nanmax(np.array([col[c] for col in cols]), axis=0).tolist()
    air = np.any([a for _, a, _ in per.values()], axis=0)
    out["liftoff_share_band"] = _band_mean(_band_index(r, edges), air.astype(float),
                                           nb).tolist()
    out.update(_air_scalars(r, air))
    levels = [lv for _, _, lv in per.values() if lv is not None]
    if levels:
        w = _windows(t, window)
        r_mid = r[:len(levels[0]) * w].reshape(len(levels[0]), w).mean(axis=1)
        out["vibration_start_radius"] = _start_radius(
            r_mid, np.any([lv >= threshold for lv in levels], axis=0))
    return out
