"""A centred moving mean with valid-only edges, and the bounce it leaves: a coordinate less
its mean over a window centred on each sample, drawn only where the whole window lies in the
run (no padding, no extrapolation: no edge artefact at the start or the end of a run)."""

from __future__ import annotations

import numpy as np

__all__ = ["window_samples", "centred_mean", "bounce", "dirichlet_gain"]


def window_samples(t: np.ndarray, window: float) -> int:
    """The odd number of samples ``w = 2h + 1`` of a centred window reaching ``h ≈
    window/2`` [s] either side on the time axis ``t`` (its median step), at most about
    half of the run (so that at least half of the samples have a whole window; a run
    shorter than twice ``window`` gets a shorter one: the caller states
    :func:`centred_mean`'s window). At least 1."""
    n = len(t)
    dt = float(np.median(np.diff(t))) if n > 1 else 0.0
    h = int(round(window / (2 * dt))) if dt > 0 else 0
    return 2 * max(0, min(h, (n - 1) // 4)) + 1


def centred_mean(t: np.ndarray, y: np.ndarray, window: float = 0.5
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """``(times, mean, window used [s])``: the mean of ``y`` over the ``w`` samples centred
    on each sample (:func:`window_samples`), at the samples whose whole window lies in the
    run only (the first and last ``(w − 1)/2`` samples have none and are left out). The
    sums are taken about the middle value, so a constant ``y`` gives its value exactly."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    w = window_samples(t, window)
    h = (w - 1) // 2
    if len(t) == 0:
        return t, y, 0.0
    ref = y[len(y) // 2]
    c = np.concatenate([[0.0], np.cumsum(y - ref)])
    mean = (c[w:] - c[:-w]) / w + ref
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    return t[h:len(t) - h], mean, w * dt


def bounce(t: np.ndarray, y: np.ndarray, window: float = 0.5
           ) -> tuple[np.ndarray, np.ndarray, float]:
    """``(times, y − centred mean, window used [s])`` (:func:`centred_mean`): the motion
    about the slow drift of ``y`` (a roll's rise with its radius), where a whole window
    lies in the run."""
    tm, mean, used = centred_mean(t, y, window)
    h = (len(t) - len(tm)) // 2
    return tm, np.asarray(y, dtype=float)[h:len(t) - h] - mean, used


def dirichlet_gain(frequency: float, dt: float, w: int) -> float:
    """The gain of the centred mean of ``w`` samples ``dt`` [s] apart for a sine of
    ``frequency`` [Hz] (zero phase): ``sin(π f w dt) / (w sin(π f dt))``; the bounce of
    that sine is its amplitude times ``1 −`` the gain."""
    x = np.pi * frequency * dt
    return float(np.sin(w * x) / (w * np.sin(x))) if np.sin(x) != 0 else 1.0
