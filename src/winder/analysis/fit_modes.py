"""Fitting scene keys to measured modes (:func:`fit_modes`): frequencies, and damping
ratios where known, of labelled modes against the wound roll's radius (from a run-up
spectrum or an operational modal analysis), labelled as ``winder modes`` labels them
(``roll.z``, ``set.x``, ``rider.z``, ...).

At each radius the machine's operating point ``y*`` (:mod:`winder.analysis.
operating_point`) and its fast Jacobian ``A`` give the modes. Their derivatives are exact:
``∂λ/∂θ = wᴴ (dA/dθ) v / (wᴴ v)`` (``v``, ``w`` the right and left eigenvectors), with
``dA/dθ`` CasADi's directional derivative of the symbolic Jacobian along ``(dy*/dθ,
dp/dθ)`` and ``dy*/dθ`` the implicit function theorem on the operating point's equations
(:meth:`_Linearisation._residual`), ``dp/dθ`` the key → parameter map (as in
:func:`winder.fit`, with the operating point's overrides: imbalance off, drums at full
speed). A mode's frequency is its damped one ``|Im λ|/2π`` [Hz], as ``winder modes``
reports it; its damping ratio ``−Re λ/|λ|``.

The least squares (:mod:`winder.analysis.fit_lm`) and the statistics are
:func:`winder.fit`'s; the result is a
:class:`~winder.FitResult` whose ``t`` holds the radii (``abscissa``), channels
``frequency`` [Hz] and ``damping`` [-] (NaN where not measured).
"""

from __future__ import annotations

import csv
import math
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from winder._errors import ArgumentError, ArgumentTypeError
from winder.analysis.fit import IDENTIFIABLE, statistics
from winder.analysis.fit_data import parse_params
from winder.analysis.fit_lm import levenberg_marquardt
from winder.analysis.fit_model import key_value, scene_with
from winder.analysis.fit_result import FitResult
from winder.analysis.operating_point import _linearisation, _web_speed
from winder.model.machine import Machine
from winder.scene.keys import key_unit
from winder.scene.load import Scene
from winder.solve.simulate import _as_scene

__all__ = ["fit_modes", "read_modes", "ModeModel"]

_WHERE = "fit_modes"


def read_modes(data: Any) -> dict[str, np.ndarray]:
    """The measured modes: columns ``radius`` [m], ``mode`` (its label), ``frequency``
    [Hz] and optionally ``damping`` [-] (NaN where unknown), from a mapping of columns, a
    sequence of row mappings or a CSV file (header ``radius,mode,frequency[,damping]``,
    units in brackets allowed)."""
    if isinstance(data, str | os.PathLike):
        try:
            with open(data, encoding="utf-8", newline="") as fh:
                rows = list(csv.DictReader(fh))
        except (OSError, UnicodeDecodeError) as exc:
            raise ArgumentError(f"modes_data: {os.fspath(data)!r} cannot be read: {exc}") \
                from None
        data = [{k.split("[")[0].strip(): v for k, v in r.items()} for r in rows]
    if isinstance(data, Sequence) and not isinstance(data, str):
        if not data or not all(isinstance(r, Mapping) for r in data):
            raise ArgumentTypeError("modes_data: expected rows (mappings) or columns")
        data = {k: [r.get(k) for r in data] for k in data[0]}
    if not isinstance(data, Mapping):
        raise ArgumentTypeError(f"modes_data: expected columns radius, mode, frequency"
                                f"[, damping], got {type(data).__name__}")
    for need in ("radius", "mode", "frequency"):
        if need not in data:
            raise ArgumentError(f"modes_data: no column {need!r} (columns: "
                                f"{', '.join(map(str, data))})")
    out: dict[str, np.ndarray] = {"mode": np.array([str(v).strip() for v in data["mode"]])}
    for name in ("radius", "frequency", "damping"):
        if name not in data:
            continue
        try:
            v = np.array([math.nan if x in (None, "") else float(x) for x in data[name]])
        except (TypeError, ValueError):
            raise ArgumentError(f"modes_data: column {name!r} is not numbers") from None
        if v.shape != out["mode"].shape:
            raise ArgumentError(f"modes_data: column {name!r} has {v.size} values, 'mode' "
                                f"{out['mode'].size}")
        bad = np.flatnonzero(~np.isfinite(v)) if name != "damping" else \
            np.flatnonzero(np.isinf(v))
        if len(bad):
            raise ArgumentError(f"modes_data: column {name!r} row {bad[0] + 1} is "
                                f"{float(v[bad[0]])!r}, not finite")
        out[name] = v
    if len(out["mode"]) == 0:
        raise ArgumentError("modes_data: no rows")
    return out


class ModeModel:
    """The labelled modes' frequencies and damping ratios at radii, and their exact
    derivatives with respect to the keys (module docstring)."""

    def __init__(self, scene: Scene, keys: Sequence[str], radius: np.ndarray,
                 labels: Sequence[str], web_speed: float | None) -> None:
        import casadi as ca

        from winder.analysis.control import _symbolic

        self.scene, self.keys = scene, tuple(keys)
        self.radius, self.labels = np.asarray(radius, float), list(labels)
        self.web_speed = web_speed
        lin = _linearisation(scene, _WHERE, web_speed, lo_open=False)
        self._structure = lin.machine.structure_key()
        x, _, p, xdot, _, _ = _symbolic(lin.system, [], [])
        dx, dp = ca.SX.sym("dx", x.shape[0]), ca.SX.sym("dp", p.shape[0])
        J = ca.jacobian(xdot, x)
        dJ = ca.reshape(ca.jtimes(ca.vec(J), ca.vertcat(x, p), ca.vertcat(dx, dp)), J.shape)
        self._dJ = ca.Function("dJ", [x, p, dx, dp], [dJ])
        self._Jp = ca.Function("Jp", [x, p], [ca.jacobian(xdot, p)])
        self.evaluations = 0

    def _params(self, theta: np.ndarray) -> np.ndarray:
        """The operating point's run-time parameters of the scene with the keys at
        ``theta`` (imbalance off, prescribed drives at full speed from t = 0)."""
        sc = scene_with(self.scene, dict(zip(self.keys, map(float, theta), strict=True)))
        m = Machine(sc)
        if m.structure_key() != self._structure:
            raise ArgumentError(f"params: {', '.join(self.keys)}: a value changes the "
                                "machine's structure; such a key cannot be fitted")
        p = np.asarray(m.parameters(), dtype=float)
        for b in m.bodies:
            if f"{b.name}.com_offset" in m.param_names:
                p[m.param_index(f"{b.name}.com_offset")] = 0.0
        v = _web_speed(_WHERE, sc, self.web_speed, lo_open=False)
        for b in m.bodies:
            b.hold_operating_speed(m, p, v)
        return p

    def _dparams(self, theta: np.ndarray) -> np.ndarray:
        """``dp/dθ`` by central differences, Richardson-extrapolated (exact for a linear
        map)."""
        D = np.zeros((len(self._params(theta)), len(theta)))
        for j in range(len(theta)):
            h = 1e-4 * abs(theta[j]) if theta[j] != 0 else 1e-6

            def diff(step: float, j: int = j) -> np.ndarray:
                a, b = theta.copy(), theta.copy()
                a[j] += step
                b[j] -= step
                return (self._params(a) - self._params(b)) / (2 * step)

            D[:, j] = (4 * diff(h / 2) - diff(h)) / 3
        return D

    def evaluate(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                    np.ndarray]:
        """``(frequency [Hz], damping [-], ∂frequency/∂θ, ∂damping/∂θ)`` of each row."""
        theta = np.asarray(theta, dtype=float)
        self.evaluations += 1
        sc = scene_with(self.scene, dict(zip(self.keys, map(float, theta), strict=True)))
        lin = _linearisation(sc, _WHERE, self.web_speed, lo_open=False)
        D = self._dparams(theta)
        n = len(self.radius)
        f, z = np.empty(n), np.empty(n)
        df, dz = np.empty((n, len(theta))), np.empty((n, len(theta)))
        cache: dict[float, tuple[Any, ...]] = {}
        for k, (r, label) in enumerate(zip(self.radius, self.labels, strict=True)):
            if r not in cache:
                cache[r] = self._at(lin, float(r), D)
            modes, lam, dlam = cache[r]
            label = str(label)
            if label not in modes:
                raise ArgumentError(f"modes_data: row {k + 1}: mode {label!r} is not a mode "
                                    f"of this scene at radius {r:g} m; valid: "
                                    f"{', '.join(modes)}")
            i = modes[label]
            lm, dl = lam[i], dlam[i]
            f[k] = abs(lm.imag) / (2 * math.pi)
            df[k] = np.sign(lm.imag) * dl.imag / (2 * math.pi)
            mag = abs(lm)
            z[k] = -lm.real / mag
            dmag = (lm.real * dl.real + lm.imag * dl.imag) / mag
            dz[k] = -(dl.real * mag - lm.real * dmag) / mag**2
        return f, z, df, dz

    def _at(self, lin: Any, r: float, D: np.ndarray) -> tuple[dict[str, int], np.ndarray,
                                                             np.ndarray]:
        """The modes at radius ``r``: label → eigenvalue index, the eigenvalues and their
        derivatives (eigenvalues × keys)."""
        y = lin.solve(r, _WHERE)
        A = lin.fast_jacobian(y)
        lam, V = np.linalg.eig(A)
        W = np.linalg.inv(V)  # rows: left eigenvectors with W V = I
        labelled = {}
        for mode in lin.modes(y):
            labelled.setdefault(mode.coordinate,
                                int(np.argmin(np.abs(lam - mode.eigenvalue))))
        p = np.concatenate([lin.system.params, [lin.t]])
        # dy*/dθ: the operating point's equations F(y, p) = 0 (implicit function theorem)
        _, Fu = lin._residual(y)
        Jp = np.array(self._Jp(y, p))[:, :-1]
        for i_w, i_r in lin.paper.items():  # ω̇ + ω ṙ / r
            Jp[i_w] += y[i_w] / y[i_r] * Jp[i_r]
        for i, (ref, _) in lin.twists.items():
            if ref is not None:
                Jp[i] -= Jp[ref]
        Fp = Jp[lin.equations] @ D
        dY = np.zeros((len(y), D.shape[1]))
        dY[lin.unknowns] = -np.linalg.solve(Fu, Fp)
        at = {i: k for k, i in enumerate(lin.fast)}
        dlam = np.empty((len(lam), D.shape[1]), dtype=complex)
        for j in range(D.shape[1]):
            dJ = np.array(self._dJ(y, p, dY[:, j], np.concatenate([D[:, j], [0.0]])))
            rows = dJ[lin.fast]
            for i, (ref, _) in lin.twists.items():
                if ref is not None:
                    rows[at[i]] -= dJ[ref]
            dA = rows[:, lin.fast]
            dlam[:, j] = np.einsum("ij,ji->i", W @ dA, V)
        return labelled, lam, dlam


def fit_modes(scene: Scene | str | os.PathLike, modes_data: Any, params: Any, *,
              sigma: Mapping[str, float] | None = None, web_speed: float | None = None,
              max_evaluations: int = 50, progress: Any = None) -> FitResult:
    """Fit scene keys to measured modes (module docstring).

    ``modes_data``: :func:`read_modes`'s columns (``radius`` [m], ``mode`` label,
    ``frequency`` [Hz], ``damping`` [-] where known). ``params``: key paths as in
    :func:`winder.fit`. ``sigma``: ``{"frequency": Hz, "damping": -}`` (default:
    estimated from the residuals). ``web_speed`` [m/s]: the operating point's (default
    the scene's).

    Raises ArgumentError for an unknown key, a label that is not a mode of the scene, a
    radius outside the roll's range, non-finite values.
    """
    start = time.perf_counter()
    scene = _as_scene(scene, _WHERE)
    specs = parse_params(params)
    keys = [s.key for s in specs]
    theta0 = np.array([key_value(scene, k) for k in keys])
    lo = np.array([s.lo if s.lo is not None else (0.0 if v > 0 else -np.inf)
                   for s, v in zip(specs, theta0, strict=True)])
    hi = np.array([s.hi if s.hi is not None else (0.0 if v < 0 else np.inf)
                   for s, v in zip(specs, theta0, strict=True)])
    data = read_modes(modes_data)
    has_damping = "damping" in data and bool(np.any(np.isfinite(data["damping"])))
    names = ["frequency", *(["damping"] if has_damping else [])]
    measured = {"frequency": data["frequency"]}
    if has_damping:
        measured["damping"] = data["damping"]
    model = ModeModel(scene, keys, data["radius"], list(data["mode"]), web_speed)
    scale = np.where(theta0 != 0, np.abs(theta0), 1.0)
    given = {n: (sigma or {}).get(n) for n in names}
    report = progress or (lambda line: None)
    cache: dict[bytes, Any] = {}

    def evaluate(zv: np.ndarray) -> Any:
        k = np.asarray(zv, float).tobytes()
        if k not in cache:
            cache.clear()
            f, d, df, dd = model.evaluate(zv * scale)
            cache[k] = ({"frequency": f, "damping": d}, {"frequency": df, "damping": dd})
            report(f"fit_modes: evaluation {model.evaluations}")
        return cache[k]

    def rows(zv: np.ndarray, w: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
        y, S = evaluate(zv)
        r, J = [], []
        for n in names:
            ok = np.isfinite(measured[n])
            r.append((y[n][ok] - measured[n][ok]) / w[n])
            J.append(S[n][ok] / w[n] * scale[None, :])
        return np.concatenate(r), np.vstack(J)

    y0, _ = evaluate(theta0 / scale)
    w = {n: given[n] if given[n] is not None else max(
        float(np.sqrt(np.nanmean((y0[n] - measured[n]) ** 2))), 1e-12)
        for n in names}
    zv = theta0 / scale
    iterations, converged, message = 0, False, ""
    for _ in range(4):
        weights = dict(w)
        sol = levenberg_marquardt(lambda v, ws=weights: rows(v, ws), zv, lo / scale,
                                  hi / scale, max_evaluations=max_evaluations)
        zv, iterations = sol.x, iterations + sol.iterations
        converged, message = sol.converged, sol.message
        est = [n for n in names if given[n] is None]
        if not est:
            break
        y, _ = evaluate(zv)
        n_all = sum(int(np.sum(np.isfinite(measured[n]))) for n in names)
        new = dict(w)
        for n in est:
            ok = np.isfinite(measured[n])
            dof = ok.sum() * (1 - len(keys) / n_all)
            new[n] = max(math.sqrt(float(np.sum((y[n][ok] - measured[n][ok]) ** 2)) / dof),
                         1e-300)
        change = max(abs(new[n] / w[n] - 1) for n in est)
        w = new
        if len(names) == 1 or change < 2e-2:
            break
    theta = zv * scale
    r, Js = rows(zv, w)
    n_all = len(r)
    stats = statistics(Js / scale[None, :], scale,
                       dof=n_all - len(keys) if any(given[n] is None for n in names)
                       else None)
    y, _ = evaluate(zv)
    q, std = stats["quantile"], stats["std"]
    return FitResult(
        scene=scene, keys=tuple(keys), units={k: key_unit(k, scene.to_dict()) for k in keys},
        initial=theta0, estimates=theta, std=std,
        ci95=np.column_stack([theta - q * std, theta + q * std]),
        covariance=stats["covariance"], correlation=stats["correlation"],
        channels=tuple(names), channel_units={"frequency": "Hz", "damping": "-"},
        sigma={n: float(w[n]) for n in names},
        sigma_estimated={n: given[n] is None for n in names}, t=data["radius"],
        measured={n: measured[n] for n in names}, fitted={n: y[n] for n in names},
        cost=0.5 * float(r @ r), iterations=iterations, evaluations=model.evaluations,
        converged=converged, message=message, singular_values=stats["singular_values"],
        weakest=dict(zip(keys, map(float, stats["weakest"]), strict=True)),
        identifiable=stats["identifiable"], quantile=q,
        wall_time=time.perf_counter() - start,
        extra={"modes": list(data["mode"]), "identifiable_limit": IDENTIFIABLE},
        abscissa=("radius", "m"))
