"""One run of a sweep reduced to a summary: nip forces, lift-off and bounce per radius band.

The roll's radius grows through the run; the summary splits it into bands (edges
``[m]``, the same for every run of a sweep) and reports per band:

- ``nip_force_peak`` [N]: the largest nip normal force ``F_n`` sampled in the band;
- ``nip_force_rms`` [N]: the root mean square of ``F_n`` over the band's samples;
- ``liftoff_share_band`` [-]: the share of the band's samples with the roll in the air
  (``F_n = 0``);
- ``bounce_amplitude`` [m]: the largest half peak-to-peak nip penetration ``δ`` over a
  window of ``window`` seconds whose mean radius lies in the band;
- ``vibration_level`` [-]: the largest half peak-to-peak ``F_n`` over such a window,
  divided by the window's mean ``F_n`` (the roll's weight on average): 1 means the nip
  force swings down to zero, i.e. lift-off.

and for the whole run: ``liftoff_share``, the radii of the first and last sample in the air
(``liftoff_radius_first``, ``liftoff_radius_last``), ``vibration_start_radius`` (mean
radius of the first window whose vibration level reaches ``threshold``), the number of
located lift-offs and touch-downs (``contact_events``), the final radius and time.
Bands a run never reaches hold NaN; without the nip (``[effects] contact = false``)
every nip quantity is NaN.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ._result import Result
from ._scene import Scene

__all__ = ["BAND_COLUMNS", "SCALAR_COLUMNS", "default_band_edges", "summarise",
           "empty_summary"]

#: Per-band list columns of a summary (one value per radius band).
BAND_COLUMNS = ("nip_force_peak", "nip_force_rms", "liftoff_share_band", "bounce_amplitude",
                "vibration_level")
#: Scalar float columns of a summary.
SCALAR_COLUMNS = ("liftoff_share", "liftoff_radius_first", "liftoff_radius_last",
                  "vibration_start_radius", "contact_events", "final_radius", "t_reached")


def end_radius(scene: Scene, t_end: float | None = None) -> float:
    """Radius [m] the roll reaches at ``t_end`` [s] (default: the scene's duration) when
    the paper arrives at the web speed without slip: ``r² = r₀² + h v t/π``."""
    T = scene.scene.duration if t_end is None else float(t_end)
    r0 = scene.roll.initial_radius
    v = scene.drum.drive.web_speed
    return math.sqrt(r0**2 + scene.paper.caliper * v * T / math.pi)


def default_band_edges(scenes: Sequence[Scene], t_end: float | None, n: int) -> np.ndarray:
    """``n + 1`` equal band edges [m] from the smallest initial radius of ``scenes`` to 2 %
    beyond the largest no-slip end radius (:func:`end_radius`)."""
    lo = min(s.roll.initial_radius for s in scenes)
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


def empty_summary(n_bands: int) -> dict[str, Any]:
    """A summary with every quantity NaN (a run that produced no samples)."""
    out: dict[str, Any] = {c: [math.nan] * n_bands for c in BAND_COLUMNS}
    out.update({c: math.nan for c in SCALAR_COLUMNS})
    return out


def summarise(result: Result, edges: np.ndarray, *, window: float = 0.5,
              threshold: float = 0.5) -> dict[str, Any]:
    """The summary of ``result`` over the radius bands ``edges`` [m] (module docstring).

    ``window`` [s]: length of the windows for bounce amplitude and vibration level;
    ``threshold`` [-]: vibration level at which vibration counts as started."""
    edges = np.asarray(edges, dtype=float)
    nb = len(edges) - 1
    out = empty_summary(nb)
    t = result.t
    if len(t) == 0:
        return out
    r = result["radius"]
    out["final_radius"] = float(r[-1])
    out["t_reached"] = float(t[-1])
    out["contact_events"] = float(result.meta.get("events", math.nan))
    if "contact" not in result.meta.get("effects", ["contact"]):
        return out
    fn, pen = result["normal_force"], result["penetration"]
    idx = _band_index(r, edges)
    air = fn <= 0.0
    out["nip_force_peak"] = _band_max(idx, fn, nb).tolist()
    out["nip_force_rms"] = np.sqrt(_band_mean(idx, fn**2, nb)).tolist()
    out["liftoff_share_band"] = _band_mean(idx, air.astype(float), nb).tolist()
    out["liftoff_share"] = float(np.mean(air))
    if np.any(air):
        out["liftoff_radius_first"] = float(r[np.argmax(air)])
        out["liftoff_radius_last"] = float(r[len(air) - 1 - np.argmax(air[::-1])])
    w = _windows(t, window)
    n = len(t) // w
    if n == 0:
        return out
    fw, pw, rw = (x[:n * w].reshape(n, w) for x in (fn, pen, r))
    mean_f = fw.mean(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        level = np.where(mean_f > 0, (fw.max(axis=1) - fw.min(axis=1)) / 2 / mean_f, np.nan)
    bounce = (pw.max(axis=1) - pw.min(axis=1)) / 2
    r_mid = rw.mean(axis=1)
    widx = _band_index(r_mid, edges)
    out["bounce_amplitude"] = _band_max(widx, bounce, nb).tolist()
    out["vibration_level"] = _band_max(widx, np.nan_to_num(level, nan=-np.inf), nb).tolist()
    started = np.flatnonzero(level >= threshold)
    if len(started):
        out["vibration_start_radius"] = float(r_mid[started[0]])
    return out
