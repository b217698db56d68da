"""The result of :func:`winder.fit`: estimates with their uncertainty, residuals per
channel, convergence and identifiability; its JSON file, table, figure and fitted scene."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from winder._errors import ArgumentError
from winder.scene.load import Scene

__all__ = ["FitResult"]


def _num(v: float) -> float | None:
    """A JSON number (``None`` for NaN; ±inf as ±1e308 is not JSON: ``None`` too)."""
    v = float(v)
    return v if math.isfinite(v) else None


@dataclass(frozen=True, eq=False)
class FitResult:
    """The estimates of the fitted keys ``keys`` [``units``], from ``initial``: standard
    errors ``std``, 95 % intervals ``ci95`` (rows ``[lo, hi]``), ``covariance`` and
    ``correlation`` (key order); per channel its ``sigma`` [channel unit] (given, or
    estimated where ``sigma_estimated``), the samples ``t`` [s], ``measured`` and
    ``fitted`` values; ``cost`` (½ Σ of the squared weighted residuals), ``iterations``,
    ``evaluations`` (simulations with sensitivities), ``converged`` and the optimiser's
    ``message``; identifiability: the scaled ``singular_values``, the ``weakest``
    direction (key → weight, unit norm) and whether the fit is ``identifiable``."""

    scene: Scene
    keys: tuple[str, ...]
    units: dict[str, str]
    initial: np.ndarray
    estimates: np.ndarray
    std: np.ndarray
    ci95: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    channels: tuple[str, ...]
    channel_units: dict[str, str]
    sigma: dict[str, float]
    sigma_estimated: dict[str, bool]
    t: np.ndarray
    measured: dict[str, np.ndarray]
    fitted: dict[str, np.ndarray]
    cost: float
    iterations: int
    evaluations: int
    converged: bool
    message: str
    singular_values: np.ndarray
    weakest: dict[str, float]
    identifiable: bool
    quantile: float
    wall_time: float
    extra: dict[str, Any] = field(default_factory=dict)
    #: what ``t`` holds: the samples' times, or (:func:`winder.fit_modes`) the radii
    abscissa: tuple[str, str] = ("t", "s")

    def __post_init__(self) -> None:
        n = len(self.keys)
        for name in ("initial", "estimates", "std"):
            if np.shape(getattr(self, name)) != (n,):
                raise ArgumentError(f"FitResult: {name} must hold one value per key")
        if np.shape(self.ci95) != (n, 2) or np.shape(self.covariance) != (n, n):
            raise ArgumentError("FitResult: ci95 is (keys, 2), covariance (keys, keys)")

    # ---- views ------------------------------------------------------------------------------
    def __getitem__(self, key: str) -> float:
        """The estimate of ``key``."""
        return float(self.estimates[self.keys.index(key)])

    @property
    def values(self) -> dict[str, float]:
        """key → estimate."""
        return dict(zip(self.keys, map(float, self.estimates), strict=True))

    @property
    def residuals(self) -> dict[str, np.ndarray]:
        """Per channel, measured − fitted [channel unit]."""
        return {n: self.measured[n] - self.fitted[n] for n in self.channels}

    @property
    def rms_residuals(self) -> dict[str, float]:
        """Per channel, the RMS of its residuals [channel unit]."""
        return {n: float(np.sqrt(np.nanmean(r ** 2))) for n, r in self.residuals.items()}

    def not_identifiable(self) -> list[str]:
        """The keys of the weakest direction (weight above 1e-3) when the fit is not
        identifiable, else empty."""
        return [] if self.identifiable else \
            [k for k, v in self.weakest.items() if abs(v) > 1e-3]

    def fitted_scene(self) -> Scene:
        """The scene with the estimates."""
        from winder.analysis.fit_model import scene_with

        return scene_with(self.scene, self.values, "fitted_scene")

    def to_dict(self) -> dict[str, Any]:
        """The FIT.json contents (numbers; ``null`` for a NaN or infinite one)."""
        params = {}
        for j, k in enumerate(self.keys):
            params[k] = {"value": float(self.estimates[j]), "std": _num(self.std[j]),
                         "ci95": [_num(self.ci95[j, 0]), _num(self.ci95[j, 1])],
                         "initial": float(self.initial[j]), "unit": self.units[k]}
        rms = self.rms_residuals
        return {
            "parameters": params,
            "correlation": [[_num(v) for v in row] for row in self.correlation],
            "channels": {n: {"sigma": self.sigma[n], "sigma_estimated":
                             self.sigma_estimated[n], "rms_residual": rms[n],
                             "unit": self.channel_units[n], "samples": int(len(self.t))}
                         for n in self.channels},
            "cost": self.cost, "iterations": self.iterations,
            "evaluations": self.evaluations, "converged": bool(self.converged),
            "message": self.message,
            "identifiability": {"singular_values": [float(v) for v in self.singular_values],
                                "weakest": dict(self.weakest),
                                "identifiable": bool(self.identifiable),
                                "not_identifiable": self.not_identifiable()},
            "window": [float(np.min(self.t)), float(np.max(self.t))],
            "wall_time": self.wall_time,
        }

    def to_json(self, path: str | os.PathLike) -> Path:
        """Write :meth:`to_dict` to ``path`` as JSON, atomically."""
        from winder.io.files import atomic_write

        text = json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n"
        return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))

    def table(self) -> str:
        """The estimates with their intervals, a line per key."""
        lines = [f"{'key':<34s} {'estimate':>13s} {'std':>11s} {'95 % interval':>27s} "
                 f"{'initial':>11s}  unit"]
        for j, k in enumerate(self.keys):
            lo, hi = self.ci95[j]
            lines.append(f"{k:<34s} {self.estimates[j]:>13.7g} {self.std[j]:>11.4g} "
                         f"[{lo:>12.6g}, {hi:>12.6g}] {self.initial[j]:>11.5g}  "
                         f"{self.units[k]}")
        weak = ", ".join(f"{k} {v:+.3f}" for k, v in self.weakest.items())
        sv = self.singular_values
        lines.append(f"cost {self.cost:.6g}, {self.iterations} iterations, "
                     f"{self.evaluations} evaluations, "
                     f"{'converged' if self.converged else 'NOT converged'}; "
                     f"singular values {sv[0]:.4g} .. {sv[-1]:.4g}, weakest: {weak}")
        if not self.identifiable:
            lines.append("NOT identifiable: " + ", ".join(self.not_identifiable())
                         + " act together (only their combination is seen)")
        return "\n".join(lines)

    def plot(self, path: str | os.PathLike | None = None) -> Any:
        """Measured against fitted channels, and the residuals (a matplotlib Figure;
        written atomically to ``path`` when given)."""
        import matplotlib

        if path is not None:
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        n = len(self.channels)
        fig, axes = plt.subplots(2, n, figsize=(5.5 * n, 6), squeeze=False, sharex=True)
        for i, c in enumerate(self.channels):
            unit = self.channel_units[c]
            ax = axes[0, i]
            ax.plot(self.t, self.measured[c], ".", ms=2, color="0.5", label="measured")
            ax.plot(self.t, self.fitted[c], "-", lw=1, color="C3", label="fitted")
            ax.set_ylabel(f"{c} [{unit}]")
            ax.legend(loc="best", fontsize=8)
            ax = axes[1, i]
            ax.plot(self.t, self.residuals[c], ".", ms=2, color="C0")
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_ylabel(f"residual [{unit}]")
            ax.set_xlabel(f"{self.abscissa[0]} [{self.abscissa[1]}]")
        title = ", ".join(f"{k} = {v:.5g} ± {s:.2g}" for k, v, s in
                          zip(self.keys, self.estimates, self.std, strict=True))
        fig.suptitle(title, fontsize=9)
        fig.tight_layout()
        if path is not None:
            from winder.io.files import atomic_write

            suffix = Path(path).suffix.lstrip(".") or "png"
            atomic_write(path, lambda tmp: fig.savefig(tmp, format=suffix, dpi=110))
        return fig
