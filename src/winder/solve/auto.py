"""``method="auto"`` on the compiled backend: the integrator chosen by a short probe.

The probe integrates the machine from the run's start over a short window
(:data:`PROBE_WINDOW`, at most :data:`PROBE_SHARE` of the run) with the compiled DOPRI5,
and sets its mean step against the step DOPRI5's stability allows, ``3.3/ρ`` with ``ρ``
the spectral radius of the exact Jacobian at the start (power iteration, from below: a
low ``ρ`` errs towards the second probe). A mean step above :data:`STIFF_RATIO` times the
stable one: the step is the accuracy's, an explicit method is the right one, DOPRI5.
(DOPRI5's own stiffness test, ``h·|Δf|/|Δy| > 3.25``, flags none of the flexible two-drum
winder's steps, held at 0.8–0.9 of the stable step by eigenvalues near −1.0e5 s⁻¹, the
set's torsion at its core before it had its own Rayleigh β_t (−1.3e5, the rider's
rocking, before its β_φ; both issue #33; now −8.9e3, the rider nip's friction
relaxation): measured, so it is not used.) Otherwise the same window is integrated with
RODAS4 (the exact sparse Jacobian, ``rosenbrock.c``) and the faster of the two by this
thread's CPU time (``time.thread_time``: what other processes on the machine do does not
count) is chosen
(a DOPRI5 probe under :data:`MIN_PROBE_CPU` keeps DOPRI5: nothing measurable to gain),
RODAS4 only where it takes less than :data:`MARGIN` of DOPRI5's time (a close call stays
with DOPRI5, whose results are the shipped references'). ``docs/work_precision.md``
lists what it picks for every shipped scene; ``Result.meta["auto"]`` holds the probe's
numbers.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from winder.solve.cint import ROSENBROCK

__all__ = ["choose_method", "Choice", "PROBE_WINDOW", "PROBE_SHARE", "STIFF_RATIO", "MARGIN",
           "MIN_PROBE_CPU", "spectral_radius"]

#: The probe's window [s] from the run's start.
PROBE_WINDOW = 0.05
#: The probe's window is at most this share of the run.
PROBE_SHARE = 0.02
#: DOPRI5's mean step above this many times its stable step ``3.3/ρ``: DOPRI5 without a
#: second probe.
STIFF_RATIO = 2.0
#: DOPRI5's stability boundary on the negative real axis (|hλ|).
DOPRI5_BOUNDARY = 3.3
#: RODAS4 is chosen where its probe took less than this share of DOPRI5's CPU time.
MARGIN = 0.7
#: A DOPRI5 probe under this CPU time [s]: DOPRI5 (nothing measurable to gain; the
#: timings of shorter probes are noise).
MIN_PROBE_CPU = 0.005
#: The probe's evaluation budget per method (a probe never takes long).
PROBE_BUDGET = 400_000


@dataclass(frozen=True)
class Choice:
    """What ``auto`` chose and why: ``probe`` holds per method its ``cpu`` [s],
    ``rhs`` evaluations, ``steps``, and for DOPRI5 ``rho`` [1/s], ``h_mean`` and
    ``h_stable`` [s]."""

    method: str
    reason: str
    window: float
    probe: dict[str, dict[str, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.method not in ("DOPRI5", *ROSENBROCK):
            raise ValueError(f"method: DOPRI5 or a Rosenbrock method, got {self.method!r}")
        if not (math.isfinite(self.window) and self.window >= 0.0):
            raise ValueError(f"window must be finite and >= 0 s, got {self.window!r}")


def _probe(system: Any, method: str, rtol: float, atol: float, t0: float, t1: float,
           y0: np.ndarray) -> dict[str, float]:
    k = system.kernels
    run = k.dopri5 if method == "DOPRI5" else functools.partial(
        k.rodas, order=ROSENBROCK[method][0], reuse=ROSENBROCK[method][1])
    y, m = np.array(y0, dtype=float), system.modes.copy()
    stats = np.zeros(8, dtype=np.int64)
    empty_t, empty_y = np.empty(0), np.empty((len(y), 0))
    c0 = time.thread_time()
    status, t, _, _ = run(system.fns, system.table, t0, t1, y, system.params, m, rtol, atol,
                          0.0, math.inf, empty_t, empty_y, 0, PROBE_BUDGET, stats)
    cpu = time.thread_time() - c0
    return {"cpu": cpu, "rhs": int(stats[0]), "steps": int(stats[1]),
            "stiff": int(stats[4]) if method == "DOPRI5" else 0,
            "reached": float(t), "status": int(status)}


def spectral_radius(J: np.ndarray, *, iterations: int = 60) -> float:
    """An estimate of the spectral radius of ``J`` [1/s] by power iteration (the largest
    growth ``|J v|/|v|`` over the last iterations; from below for a dominant real
    eigenvalue)."""
    n = J.shape[0]
    v = np.cos(np.arange(n) * 1.3 + 0.4)  # deterministic, not orthogonal to anything simple
    v /= np.linalg.norm(v)
    best = 0.0
    for i in range(iterations):
        w = J @ v
        norm = float(np.linalg.norm(w))
        if not (norm > 0.0 and math.isfinite(norm)):
            return 0.0 if norm == 0.0 else math.inf
        if i >= iterations // 2:
            best = max(best, norm)
        v = w / norm
    return best


def choose_method(system: Any, rtol: float, atol: float, t0: float, y0: np.ndarray,
                  t_end: float) -> Choice:
    """The compiled method for a run of ``system`` (a compiled
    :class:`~winder.solve.system.MachineSystem`) from ``(t0, y0)`` to ``t_end`` [s]
    (``inf``: open-ended, the Stepper) at ``rtol``, ``atol``."""
    window = PROBE_WINDOW if not math.isfinite(t_end) else min(PROBE_WINDOW,
                                                               PROBE_SHARE * (t_end - t0))
    if window <= 0.0:
        return Choice("DOPRI5", "no window to probe", 0.0)
    d = _probe(system, "DOPRI5", rtol, atol, t0, t0 + window, y0)
    if d["cpu"] < MIN_PROBE_CPU:  # decided before the Jacobian is needed (built lazily)
        return Choice("DOPRI5", f"DOPRI5's probe took {1e3 * d['cpu']:.2g} ms of CPU: "
                      "nothing measurable to gain", window, {"DOPRI5": d})
    rho = spectral_radius(system.jac(t0, np.asarray(y0, dtype=float)))
    h_mean = (d["reached"] - t0) / max(d["steps"], 1)
    h_stable = DOPRI5_BOUNDARY / rho if rho > 0.0 else math.inf
    d["rho"], d["h_mean"], d["h_stable"] = rho, h_mean, h_stable
    ratio = h_mean / h_stable
    if ratio > STIFF_RATIO:
        return Choice("DOPRI5", f"DOPRI5's mean step {h_mean:.3g} s is {ratio:.3g} times "
                      f"its stable step 3.3/rho = {h_stable:.3g} s: the accuracy's",
                      window, {"DOPRI5": d})
    r = _probe(system, "RODAS4", rtol, atol, t0, t0 + window, y0)
    # over the window each reached, per simulated second
    speed_d = d["cpu"] / max(d["reached"] - t0, 1e-300)
    speed_r = r["cpu"] / max(r["reached"] - t0, 1e-300)
    probe = {"DOPRI5": d, "RODAS4": r}
    if r["status"] in (0, 1) and speed_r < MARGIN * speed_d:
        return Choice("RODAS4", f"DOPRI5's mean step is {ratio:.3g} times its stable step "
                      f"(stability-held); RODAS4 took {speed_r / speed_d:.2f} of its CPU time",
                      window, probe)
    return Choice("DOPRI5", f"DOPRI5's mean step is {ratio:.3g} times its stable step "
                  f"(stability-held), but RODAS4 took {speed_r / speed_d:.2f} of its CPU time",
                  window, probe)
