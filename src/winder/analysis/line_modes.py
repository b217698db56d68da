"""Which mode of a web line is which (machines.md §11, issue #34): the tension and dancer
modes named by their shape, for the resonance map (:mod:`winder.analysis.mode_labels`).

A web line's states carry a mode's energy, each by its own measure: its rollers' and its
unwinding roll's rotation ``½ J |δω|²`` and its dancers' carriages ``½ m_d |δḋ|²`` the
kinetic energy (with the bodies' own, :func:`~winder.analysis.mode_labels.label_modes`),
its spans' strain ``½ (L/EA) |δT|²`` and the carriages' springs ``½ k |δd|²`` the line's
elastic energy. Its **line coordinates**:

- the moving ones: ``DANCER.carriage`` (a dancer's carriage), ``ROLLER.roller`` (an idler,
  a pull roll or a dancer's roller turning), ``ROLL.unwind`` (the unwinding roll turning,
  with its drive); a mode's share of one is its kinetic energy over the mode's whole
  kinetic energy;
- the spans: ``SPAN.tension`` (``span0.tension``: the span's state's own name); a mode's
  share of one is its strain energy over the line's whole elastic energy.

The dancers' carriages name first, each the mode (of those no bounce, bending, torsion or
rotation label took) in which it has the largest share, an oscillating one first, each
mode at most once (one assignment maximising the shares, as the bounce modes are named):
a dancer's mode is the one in which its carriage moves the most; then the other moving
coordinates the modes left, the same way; then the spans (a span's transport relaxation ``v/L``,
a real eigenvalue: damping ratio 1, damped frequency 0). A label needs a share of at
least :data:`LINE_SHARE` and a mode of the bodies and the line (a participation of their
states ``>= ½``: not a nip's friction relaxation nor a controller's integral alone; of the
line's own states, rotation speeds of its rollers included, at least :data:`LINE_PART`:
not a bounce of the winder's rolls).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["LineCoordinates", "line_coordinates", "line_summary", "LINE_SHARE"]

#: The least share of its energy measure a line coordinate has in the mode it names.
LINE_SHARE = 0.05
#: The least participation of the line's states in a mode a line coordinate names.
LINE_PART = 0.25


@dataclass(frozen=True)
class LineCoordinates:
    """A machine's line coordinates over its fast states: ``labels``, per label the weight
    of each fast state in its energy (``weights``, rows per label: ``J`` on a rotation
    speed, ``m_d`` on a carriage's speed, ``L/EA`` on a span's tension), ``moving`` which
    labels are moving ones (the rest: spans); ``kinetic``: the weights of the kinetic
    energies the bodies' own does not hold (the carriages'), ``elastic``: of the line's
    elastic energy (the spans' strain, the carriages' springs); ``states``: the mask of the
    line's states that are not the bodies' (tensions, carriages)."""

    labels: tuple[str, ...]
    weights: np.ndarray
    moving: np.ndarray
    kinetic: np.ndarray
    elastic: np.ndarray
    states: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.labels)
        if self.weights.ndim != 2 or self.weights.shape[0] != n or self.moving.shape != (n,):
            raise ValueError(f"weights, moving: shapes {self.weights.shape}, "
                             f"{self.moving.shape}; valid: ({n}, fast), ({n},)")
        fast = self.weights.shape[1:]
        if not self.kinetic.shape == self.elastic.shape == self.states.shape == fast:
            raise ValueError("kinetic, elastic, states: one entry per fast state")

    @property
    def line_states(self) -> np.ndarray:
        """The mask of the line's fast states: its own and its rollers' and unwinding
        rolls' rotation speeds."""
        return self.states | np.any(self.weights[self.moving] != 0.0, axis=0)

    def assign(self, V: np.ndarray, lam: np.ndarray, free: list[int], kinetic: np.ndarray,
               participation: np.ndarray, line: np.ndarray) -> dict[int, str]:
        """``{mode: label}`` of the modes ``free`` (columns of the eigenvectors ``V``,
        eigenvalues ``lam``; ``kinetic`` the bodies' kinetic energy of each mode,
        ``participation`` that of the bodies' and the line's states, ``line`` that of the
        line's states, :attr:`line_states`): module text."""
        from scipy.optimize import linear_sum_assignment

        P = np.abs(V[:, free]) ** 2
        energy = self.weights @ P  # (labels, modes)
        moving = np.maximum(kinetic[free] + self.kinetic @ P, 1e-300)
        elastic = np.maximum(self.elastic @ P, 1e-300)
        share = energy / np.where(self.moving[:, None], moving[None, :], elastic[None, :])
        ok = (participation[free] >= 0.5) & (line[free] >= LINE_PART)
        bonus = (lam[free].imag > 0.0)[None, :] & (share >= LINE_SHARE)
        score = np.where(ok[None, :] & (share >= LINE_SHARE), share + bonus, -1.0)
        out: dict[int, str] = {}
        carriage = np.array([c.endswith(".carriage") for c in self.labels], dtype=bool)
        for group in (carriage, self.moving & ~carriage, ~self.moving):
            rows = np.nonzero(group)[0]
            cols = [j for j in range(len(free)) if free[j] not in out]
            if not len(rows) or not cols:
                continue
            sub = score[np.ix_(rows, cols)]
            r_, c_ = linear_sum_assignment(-sub)
            out.update({free[cols[c]]: self.labels[rows[r]]
                        for r, c in zip(r_, c_, strict=True) if sub[r, c] >= 0.0})
        return out


def line_coordinates(machine: Any, params: np.ndarray, fast: list[str],
                     inertia: Mapping[str, float]) -> LineCoordinates | None:
    """The line coordinates (module text) of ``machine``'s webs with spans over its fast
    states named ``fast``, the weights from ``params`` (the spans' ``length``, ``EA``, the
    dancers' ``dancer_mass``, ``dancer_stiffness``) and ``inertia`` (per body its inertia
    [kg·m²] at the state: a paper roll's ``J(r)``); None where no web has a span or none
    of its states is fast."""
    at = {n: i for i, n in enumerate(fast)}
    p = lambda name: float(params[machine.param_index(name)])  # noqa: E731
    labels: list[str] = []
    rows: list[dict[int, float]] = []
    moving: list[bool] = []
    kinetic = np.zeros(len(fast))
    elastic = np.zeros(len(fast))
    states = np.zeros(len(fast), dtype=bool)

    def add(label: str, state: str, weight: float, is_moving: bool) -> None:
        if state in at:
            labels.append(label)
            rows.append({at[state]: weight})
            moving.append(is_moving)

    for w in machine.webs:
        if not w.spans or w.unwind is None:
            continue
        u = w.unwind.name
        add(f"{u}.unwind", f"{u}.theta_dot", inertia.get(u, 0.0), True)
        for s in w.spans:
            k = s.key
            add(f"{k}tension", f"{k}tension", p(f"{k}length") / p(f"{k}EA"), False)
            if f"{k}tension" in at:
                elastic[at[f"{k}tension"]] += p(f"{k}length") / p(f"{k}EA")
                states[at[f"{k}tension"]] = True
            roller = s.downstream
            if roller is None:
                continue
            n = roller.name
            add(f"{n}.roller", f"{n}.theta_dot", inertia.get(n, 0.0), True)
            if roller.roles.dancer is not None and f"{n}.position_dot" in at:
                add(f"{n}.carriage", f"{n}.position_dot", p(f"{n}.dancer_mass"), True)
                kinetic[at[f"{n}.position_dot"]] += p(f"{n}.dancer_mass")
                states[at[f"{n}.position_dot"]] = True
                if f"{n}.position" in at:
                    elastic[at[f"{n}.position"]] += p(f"{n}.dancer_stiffness")
                    states[at[f"{n}.position"]] = True
    if not labels:
        return None
    W = np.zeros((len(labels), len(fast)))
    for j, row in enumerate(rows):
        for i, w_ in row.items():
            W[j, i] = w_
    return LineCoordinates(tuple(labels), W, np.array(moving, dtype=bool), kinetic, elastic,
                           states)


def line_summary(mm: Any) -> list[str]:
    """The summary lines of a map ``mm`` (:class:`~winder.analysis.modes.ModeMap`) over an
    unwinding roll's radius: each line mode from the first to the last radius, then where
    a harmonic of the roll's rotation meets one."""
    out = []
    for c, f in mm.line.items():
        z, nat = mm.line_damping[c], mm.line_natural[c]
        ok = np.nonzero(np.isfinite(f))[0]
        if not len(ok):
            out.append(f"line mode {c}: no mode of this shape over the map")
            continue
        i, j = ok[0], ok[-1]
        kind = "real (no oscillation): |λ|/2π" if np.all(f[ok] == 0) else "damped"
        shown = nat if np.all(f[ok] == 0) else f
        out.append(f"line mode {c} {kind} {shown[i]:.2f} -> {shown[j]:.2f} Hz, damping "
                   f"ratio {z[i]:.3f} -> {z[j]:.3f}" + ("" if len(ok) == len(f) else
                                                        f" (at {len(ok)} of {len(f)} radii)"))
    crossings = mm.crossings(mm.line_shown)
    out += [f"{h} rotation of {mm.roll} meets {c} at r = {rc:.4f} m"
            for c, h, rc in crossings]
    return out or ["no line mode over the map"]
