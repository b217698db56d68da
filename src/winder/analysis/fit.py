"""Calibration to a mill's measurements: :func:`fit`, output-error least squares on the
exact sensitivities of the simulated channels to scene keys.

The residuals ``(y_model(θ) − y_measured) / σ`` of every fitted channel at every sample
in the window are minimised by Levenberg–Marquardt with bounds
(:mod:`winder.analysis.fit_lm`; the Jacobian is the weighted sensitivity matrix of
:class:`~winder.analysis.fit_model.ForwardModel`: CVODES's forward sensitivities of the
one symbolic definition, no finite differences), in parameters scaled by their first
guesses; it stops where the step is below 1e-6 of every standard error. One simulation with
sensitivities serves the residual and the Jacobian of each step (``evaluations`` counts
them).

Noise: ``sigma`` per channel is its measurement standard deviation [the channel's unit].
Where it is not given it is estimated from the residuals, ``σ̂² = RSS_c / (N_c − n_θ
N_c/N)``, and the fit repeated with those weights until they settle (for one channel:
the estimate is the unweighted least-squares one, ``σ̂²`` the usual unbiased one).

Statistics at the optimum: covariance ``(JᵀJ)⁻¹`` of the weighted Jacobian ``J``,
standard errors, 95 % intervals (Student's t with ``N − n_θ`` degrees of freedom where a
σ was estimated, else the normal quantile), correlation. Identifiability: the singular
values of ``J`` with each column scaled by its parameter's value (the response to a
relative change); where the smallest is below :data:`IDENTIFIABLE` of the largest, the
parameters weighted in its direction (``weakest``) act together and are not identifiable
(their standard errors are infinite).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from winder._errors import ArgumentError, ArgumentTypeError, SimulationError
from winder.analysis.fit_data import ParamSpec, Table, parse_params, read_table
from winder.analysis.fit_lm import levenberg_marquardt
from winder.analysis.fit_model import ForwardModel, key_value
from winder.analysis.fit_result import FitResult
from winder.scene.keys import key_unit
from winder.scene.load import Scene
from winder.solve.simulate import _as_scene

__all__ = ["fit", "FitResult", "IDENTIFIABLE", "DEFAULT_RTOL", "statistics"]

#: Smallest ratio of the least to the largest scaled singular value of an identifiable fit.
IDENTIFIABLE = 1e-6
#: CVODES's relative tolerance in a fit unless given.
DEFAULT_RTOL = 1e-8
#: Reweightings of estimated noise levels at most.
_REWEIGHTS = 4


def _channels(table: Table, channels: Any, sigma: Any, outputs: Mapping[str, tuple[str, str]]
              ) -> tuple[list[str], dict[str, float | None]]:
    """The fitted channels and their given σ (None: to estimate)."""
    if channels is None:
        names = list(table.columns)
        for n in names:
            if n not in outputs:
                raise ArgumentError(f"data ({table.source}): column {n!r} is not a channel "
                                    f"of this scene; valid: {', '.join(outputs)}")
    elif isinstance(channels, str):
        names = [channels]
    elif isinstance(channels, Mapping):
        names = list(channels)
        if sigma is None:
            sigma = dict(channels)
    elif isinstance(channels, Sequence):
        names = list(channels)
    else:
        raise ArgumentTypeError(f"channels: expected channel names, got "
                                f"{type(channels).__name__}")
    if not names:
        raise ArgumentError(f"channels: none to fit (the data ({table.source}) has no "
                            "channel columns besides t)")
    for n in names:
        if not isinstance(n, str) or n not in outputs:
            raise ArgumentError(f"channels: {n!r} is not a channel of this scene; valid: "
                                f"{', '.join(outputs)}")
        if n not in table.columns:
            raise ArgumentError(f"channels: {n!r} is not a column of the data "
                                f"({table.source}); columns: {', '.join(table.columns)}")
        unit = table.units.get(n)
        want = outputs[n][1]
        if unit is None:
            raise ArgumentError(f"data ({table.source}): column {n!r} has no unit; give it "
                                f"as '{n} [{want}]'")
        if unit != want:
            raise ArgumentError(f"data ({table.source}): column {n!r} is in {unit!r}, the "
                                f"channel in {want!r}")
    if len(set(names)) != len(names):
        raise ArgumentError("channels: a channel is given twice")
    given: dict[str, float | None] = dict.fromkeys(names)
    if sigma is not None:
        items = sigma.items() if isinstance(sigma, Mapping) else \
            [(n, sigma) for n in names]
        for n, s in items:
            if n not in given:
                raise ArgumentError(f"sigma: {n!r} is not a fitted channel")
            if s is None:
                continue
            if isinstance(s, bool) or not isinstance(s, int | float) or \
                    not (math.isfinite(s) and s > 0):
                raise ArgumentError(f"sigma: {n}: {s!r} must be a finite number > 0")
            given[n] = float(s)
    return names, given


def _window(table: Table, t_start: float | None, t_end: float | None,
            duration: float) -> np.ndarray:
    t = table.t
    lo = float(t[0]) if t_start is None else t_start
    hi = float(t[-1]) if t_end is None else t_end
    for name, v in (("t_start", lo), ("t_end", hi)):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ArgumentError(f"{name}: {v!r} must be a finite number [s]")
    if t[0] < 0.0:
        raise ArgumentError(f"data ({table.source}): t starts at {t[0]:.6g} s, before the "
                            "run starts (0 s)")
    if not lo < hi:
        raise ArgumentError(f"t_start, t_end: {lo:.6g} s, {hi:.6g} s: need t_start < t_end")
    if hi > duration:
        raise ArgumentError(f"t_end: {hi:.6g} s is after the run's end (the scene's "
                            f"duration {duration:.6g} s)")
    if lo > t[-1] or hi < t[0]:
        raise ArgumentError(f"t_start, t_end: [{lo:.6g}, {hi:.6g}] s holds no sample of "
                            f"the data ({table.source}: {t[0]:.6g} to {t[-1]:.6g} s)")
    return (t >= lo) & (t <= hi)


_MODELS: dict[str, ForwardModel] = {}


def _model(scene: Scene, keys: list[str], names: list[str], t: np.ndarray,
           rtol: float) -> ForwardModel:
    """The forward model (its CasADi functions take ~0.1–1 s to build): the last one
    again for the same scene, keys, channels, samples and tolerance (repeated fits)."""
    import hashlib
    import json

    h = hashlib.sha256(json.dumps([scene.to_dict(), keys, names, rtol], sort_keys=True,
                                  default=repr).encode() + t.tobytes()).hexdigest()
    model = _MODELS.get(h)
    if model is None:
        _MODELS.clear()
        model = _MODELS[h] = ForwardModel(scene, keys, names, t, rtol=rtol)
    model.evaluations = 0
    return model


def _bounds(spec: ParamSpec, v0: float) -> tuple[float, float]:
    lo = spec.lo if spec.lo is not None else (0.0 if v0 > 0 else -math.inf)
    hi = spec.hi if spec.hi is not None else (0.0 if v0 < 0 else math.inf)
    if not lo <= v0 <= hi:
        raise ArgumentError(f"params: {spec.key}: the scene's value {v0:.6g} (the first "
                            f"guess) is outside the bounds {lo:.6g}:{hi:.6g}")
    return lo, hi


def statistics(J: np.ndarray, scale: np.ndarray, *, dof: float | None) -> dict[str, Any]:
    """The statistics of a weighted least-squares optimum (module docstring) from its
    weighted Jacobian ``J`` (residuals × parameters, per parameter unit) and the
    parameters' scales: ``covariance``, ``std``, ``correlation``, ``quantile`` (Student's
    t with ``dof`` degrees of freedom, the normal one for ``None``), the scaled
    ``singular_values``, the ``weakest`` direction (unit norm, its largest weight
    positive) and whether the fit is ``identifiable``."""
    from scipy.stats import t as student

    Js = J * scale[None, :]
    _, sv, vt = np.linalg.svd(Js, full_matrices=False)
    weak = vt[-1] / np.linalg.norm(vt[-1])
    weak = weak * np.sign(weak[np.argmax(np.abs(weak))])
    identifiable = bool(sv[-1] > IDENTIFIABLE * sv[0])
    if identifiable:
        cov_s = np.linalg.inv(Js.T @ Js)
    else:
        cov_s = np.linalg.pinv(Js.T @ Js)
        for j in np.flatnonzero(np.abs(weak) > 1e-3):
            cov_s[j, :] = cov_s[:, j] = np.nan
            cov_s[j, j] = np.inf
    cov = cov_s * np.outer(scale, scale)
    std = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    q = float(student.ppf(0.975, dof)) if dof is not None else 1.959963984540054
    return {"covariance": cov, "std": std, "correlation": corr, "quantile": q,
            "singular_values": sv, "weakest": weak, "identifiable": identifiable}


def fit(scene: Scene | str | os.PathLike, data: Any, params: Any, *,
        channels: Any = None, sigma: Any = None, t_start: float | None = None,
        t_end: float | None = None, rtol: float | None = None,
        bounds: Mapping[str, tuple[float | None, float | None]] | None = None,
        max_evaluations: int = 100, progress: Any = None) -> FitResult:
    """Fit scene keys to measured channels (module docstring: the method and statistics).

    Parameters
    ----------
    scene: the machine (its values are the first guesses), or the path of its file.
    data: the measurements: a :class:`~winder.Result`, a mapping of columns (``t`` [s] and
        channel names, units in ``"name [unit]"`` names), or a CSV, NPZ or Parquet file
        (:mod:`winder.analysis.fit_data`); samples need not be uniform.
    params: key paths as in ``winder sweep`` (``contact.stiffness``,
        ``nip.front_nip.contact.stiffness``), optionally ``KEY=LO:HI`` or ``(KEY, LO, HI)``.
        Default bounds: ``[0, ∞)`` for a positive first guess.
    channels: the fitted channels (default every data column), a list or a mapping name
        → σ.
    sigma: a σ for all channels or a mapping channel → σ [channel units]; default:
        estimated from the residuals.
    t_start, t_end: the fitted window [s] (default the data's).
    rtol: CVODES's relative tolerance (default :data:`DEFAULT_RTOL`).
    bounds: key → ``(LO, HI)`` (either ``None``), besides ``KEY=LO:HI``.
    max_evaluations: simulations with sensitivities at most.
    progress: a callable taking a line of text (each evaluation's cost), or None.

    Raises
    ------
    ArgumentError: an unknown key, channel or column, a column without its unit or in
        another one, non-finite data, a window outside the data or the run, a parameter
        that no fitted channel sees. FitEventError: an event (lift-off, core) inside the
        window, naming it and a window without it.
    """
    start = time.perf_counter()
    scene = _as_scene(scene, "fit")
    specs = parse_params(params)
    if bounds:
        extra = {s.key: s for s in specs}
        for k, (lo, hi) in bounds.items():
            if k not in extra:
                raise ArgumentError(f"bounds: {k!r} is not one of the params")
            extra[k] = ParamSpec(k, lo, hi)
        specs = list(extra.values())
    keys = [s.key for s in specs]
    theta0 = np.array([key_value(scene, k) for k in keys])
    lims = np.array([_bounds(s, v) for s, v in zip(specs, theta0, strict=True)])
    table = read_table(data)
    if rtol is None:
        rtol = DEFAULT_RTOL
    if isinstance(rtol, bool) or not isinstance(rtol, int | float) or \
            not (0 < rtol <= 1e-3):
        raise ArgumentError(f"rtol: {rtol!r} must be in (0, 1e-3]")
    from winder.solve.system import MachineSystem

    outputs = MachineSystem(scene).outputs
    names, given = _channels(table, channels, sigma, outputs)
    duration = scene.to_dict().get("scene", {}).get("duration")
    rows = _window(table, t_start, t_end, math.inf if duration is None else float(duration))
    t = table.t[rows]
    measured = np.array([table.columns[n][rows] for n in names])
    n_th = len(keys)
    if measured.size <= n_th:
        raise ArgumentError(f"data: {measured.size} values in the window for {n_th} "
                            "parameters; give more samples")
    model = _model(scene, keys, names, t, float(rtol))
    scale = np.where(theta0 != 0, np.abs(theta0), 1.0)
    cache: dict[bytes, Any] = {}
    report = progress or (lambda line: None)

    def evaluate(z: np.ndarray) -> Any:
        k = np.asarray(z, dtype=float).tobytes()
        if k not in cache:
            cache.clear()
            cache[k] = model.evaluate(z * scale)
            ev = cache[k]
            r = (ev.y - measured) / w[:, None]
            report(f"fit: evaluation {model.evaluations}: cost {0.5 * float(np.sum(r**2)):.6g}"
                   f" at " + ", ".join(f"{n}={v:.6g}" for n, v in zip(keys, z * scale,
                                                                       strict=True)))
        return cache[k]

    def residual(z: np.ndarray) -> np.ndarray:
        ev = evaluate(z)
        return ((ev.y - measured) / w[:, None]).ravel()

    def jacobian(z: np.ndarray) -> np.ndarray:
        ev = evaluate(z)
        return (ev.S / w[:, None, None] * scale[None, None, :]).reshape(-1, n_th)

    # first weights: the given σ, else the channel's initial residual RMS
    first = model.evaluate(theta0)
    w = np.array([given[n] if given[n] is not None else
                  max(float(np.sqrt(np.mean((first.y[i] - measured[i]) ** 2))),
                      1e-12 * max(float(np.max(np.abs(measured[i]))), 1e-300))
                  for i, n in enumerate(names)])
    cache[(theta0 / scale).tobytes()] = first
    report(f"fit: evaluation 1: cost "
           f"{0.5 * float(np.sum(((first.y - measured) / w[:, None]) ** 2)):.6g} at the "
           "first guess " + ", ".join(f"{n}={v:.6g}" for n, v in zip(keys, theta0,
                                                                     strict=True)))
    seen = np.sqrt(np.sum((first.S / w[:, None, None]) ** 2, axis=(0, 1))) * scale
    for j, k in enumerate(keys):
        if not seen[j] > 1e-12 * max(float(np.max(seen)), 1e-300) or seen[j] == 0.0:
            raise ArgumentError(f"params: {k}: no fitted channel sees it (its sensitivity "
                                f"is zero in {', '.join(names)}); fit channels it acts on")
    z = theta0 / scale
    iterations = 0
    estimated = [i for i, n in enumerate(names) if given[n] is None]
    counts = np.array([measured.shape[1]] * len(names), dtype=float)
    n_all = float(measured.size)
    converged, message = False, ""
    for passes in range(_REWEIGHTS):
        sol = levenberg_marquardt(lambda v: (residual(v), jacobian(v)), z,
                                  lims[:, 0] / scale, lims[:, 1] / scale,
                                  max_evaluations=max(2, max_evaluations
                                                      - model.evaluations + 1),
                                  failures=(SimulationError, ArgumentError))
        iterations += sol.iterations
        z = sol.x
        converged, message = sol.converged, sol.message
        if not estimated or (sol.iterations == 0 and passes > 0):
            break
        ev = evaluate(z)
        rss = np.sum((ev.y - measured) ** 2, axis=1)
        dof = counts - n_th * counts / n_all
        new = w.copy()
        for i in estimated:
            new[i] = max(math.sqrt(rss[i] / dof[i]), 1e-300)
        change = np.max(np.abs(new[estimated] / w[estimated] - 1.0))
        w = new  # the cached simulation stays valid: only the weights change
        if len(names) == 1 or change < 2e-2 or model.evaluations >= max_evaluations:
            break
    theta = z * scale
    ev = evaluate(z)
    J = (ev.S / w[:, None, None]).reshape(-1, n_th)  # weighted, per key unit
    r = ((ev.y - measured) / w[:, None]).ravel()
    stats = statistics(J, scale, dof=n_all - n_th if estimated else None)
    std = stats["std"]
    q = stats["quantile"]
    units = {k: key_unit(k, scene.to_dict()) for k in keys}
    return FitResult(
        scene=scene, keys=tuple(keys), units=units, initial=theta0, estimates=theta,
        std=std, ci95=np.column_stack([theta - q * std, theta + q * std]),
        covariance=stats["covariance"], correlation=stats["correlation"],
        channels=tuple(names),
        channel_units={n: outputs[n][1] for n in names},
        sigma=dict(zip(names, map(float, w), strict=True)),
        sigma_estimated={n: given[n] is None for n in names}, t=t,
        measured=dict(zip(names, measured, strict=True)),
        fitted=dict(zip(names, ev.y, strict=True)), cost=0.5 * float(r @ r),
        iterations=iterations, evaluations=model.evaluations, converged=converged,
        message=message, singular_values=stats["singular_values"],
        weakest=dict(zip(keys, map(float, stats["weakest"]), strict=True)),
        identifiable=stats["identifiable"], quantile=q, wall_time=time.perf_counter() - start)
