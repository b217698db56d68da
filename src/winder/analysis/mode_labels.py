"""Which mode is which: the eigenpairs of a machine's fast states named by their shape, for
the resonance map (:mod:`winder.analysis.modes`).

The fast states are, in order, the free coordinates' positions and velocities, the turning
bodies' rotation speeds, the other states (the nips' friction states, ...) and a flexible
body's segment angles (its twist). A mode's **kinetic energy** is ``½ m |ẋ|²`` per free
coordinate (onto the generalised coordinates of :class:`~winder.analysis.shapes.Shapes`:
a flexible body's bending orders) and ``½ J |θ̇|²`` per turning body; where the eigenvalue
is zero (a free mass: nothing holds it) the displacement ``½ m |x|²`` stands in for it;
with ``flex.rotary_inertia`` each section's rotation rate ``s`` (``SEG.tilt_rate_x``/``_z``)
adds ``½ j_r |s|²`` (``j_r`` half the segment's polar inertia), part of the total that every
share divides. Its
**mechanical share** is the participation of the mechanical states (all but the "other"
ones) in it: ``|l_i r_i|`` summed over them over the sum over all states (``l``, ``r`` the
left and right eigenvectors; unit-free): about 1 for a mode of the bodies, about 0 for a
friction state's relaxation (issue #32: at ``(v + v_min)/σ``, below a drum's torsion).

A label comes from the shape, and only an **oscillating** mode (a complex pair, damping
ratio < 1) with a mechanical share of at least ½ whose shape it is may carry a shape
label:

- each free coordinate takes the eigenpair in which it carries the largest share of the
  kinetic energy, such an oscillating one first (its share ≥ 1/4), every pair at most once.
  A flexible body's bending order (``front.bend.z1``) takes only such an oscillating one
  with at least :data:`SHAPE_SHARE` of its energy in that order: none at a radius where no
  oscillating mode has that shape. A rigid body's coordinate
  (``set.x``) always names one: where none oscillates the real eigenvalue with the largest
  share (the coordinate is overdamped there: frequency 0, damping ratio 1), or a zero
  eigenvalue (free: nothing holds it);
- a mode of the bodies (oscillating or not) whose kinetic energy is at least
  :data:`ROTATION_SHARE` in the sections' rotation (Timoshenko's second spectrum, kHz) takes
  no bounce, bending or torsion label: it is a **rotation mode** ``BODY.rotation.{x,z}{n}``
  (:meth:`Shapes.rotation_label`: the body and axis with the most of it, ``n`` the dominant
  order of its rates on ``cos(nπ y/L)``, ``n = 0 … N − 1``; not unique);
- of the rest, an oscillating mode whose kinetic energy is at least half in the flexible
  bodies' twist is a **torsion mode** ``BODY.torsion{n}`` (:meth:`Shapes.torsion_label`),
  each label once: the mode with the most energy in that order of that body;
- of the rest, a web line's modes take the line's labels by their energy
  (:mod:`winder.analysis.line_modes`: ``span0.tension``, ``dancer.carriage``,
  ``guide1.roller``, ``parent.unwind``; kind ``line``);
- every other mode, the real ones (the friction states' relaxations among them) included,
  is a **slip mode** named by the state (not a position) with the largest entry of its
  eigenvector (``nip_s7.friction``, ``roll.theta_dot``): never a shape label.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from winder.analysis.line_modes import LineCoordinates
from winder.analysis.shapes import Shapes

__all__ = ["Mode", "label_modes", "MECHANICAL_SHARE", "SHAPE_SHARE", "ROTATION_SHARE"]

#: The least mechanical share (participation of the bodies' states) of a labelled
#: oscillating mode.
MECHANICAL_SHARE = 0.5
#: The kinetic-energy share of a coordinate in an oscillating mode it names first.
_BOUNCE_SHARE = 0.25
#: The least kinetic-energy share of a bending order in the oscillating mode it names (the
#: twin drums of a two-drum winder share their order-2 modes through the set: each drum's
#: x2 and z2 12-24 % of them).
SHAPE_SHARE = 0.1
#: The kinetic-energy share of the sections' rotation (flex.rotary_inertia) from which an
#: oscillating mode is a rotation mode: no bounce, bending or torsion label.
ROTATION_SHARE = 0.5


@dataclass(frozen=True)
class Mode:
    """One eigenvalue (of a pair): ``frequency`` [Hz] (damped, 0 for a real eigenvalue),
    ``natural_frequency`` ``|λ|/2π`` [Hz], ``damping_ratio`` [-], ``kind`` (``bounce``,
    ``bending``, ``slip``, ``torsion``, ``rotation`` or ``line``: a web line's tension,
    dancer or roller mode, :mod:`winder.analysis.line_modes`) and ``coordinate``: the free
    coordinate that
    dominates a bounce mode (``BODY.x``/``BODY.z``), a flexible body's bending order
    (``BODY.bend.z1``, :mod:`winder.analysis.shapes`) or torsion order
    (``BODY.torsion1``), a section-rotation order (``BODY.rotation.z0``), or the state that
    dominates a slip mode (a bending or torsion
    label only on an oscillating mode of that shape: module text)."""

    eigenvalue: complex
    kind: str
    coordinate: str = ""

    @property
    def frequency(self) -> float:
        return abs(self.eigenvalue.imag) / (2 * math.pi)

    @property
    def natural_frequency(self) -> float:
        return abs(self.eigenvalue) / (2 * math.pi)

    @property
    def damping_ratio(self) -> float:
        lam = self.eigenvalue
        return -lam.real / abs(lam) if abs(lam) > 0 else 0.0


def mechanical_share(left: np.ndarray, right: np.ndarray, mechanical: np.ndarray
                     ) -> np.ndarray:
    """Per mode (column of the left and right eigenvectors ``left``, ``right``) the
    participation of the states ``mechanical`` (a mask): ``Σ_mech |l_i r_i| / Σ |l_i r_i|``
    [-]; 1 where it is not defined (a defective zero eigenvalue: ``l·r = 0``)."""
    p = np.abs(np.conj(left) * right)
    total = p.sum(axis=0)
    with np.errstate(all="ignore"):
        share = p[mechanical].sum(axis=0) / total
    return np.where(np.isfinite(share) & (total > 0), share, 1.0)


def label_modes(A: np.ndarray, *, shapes: Shapes, n_positions: int, n_speeds: int,
                mass: np.ndarray, inertia: np.ndarray, names: list[str],
                mechanical: np.ndarray, rotary: np.ndarray | None = None,
                line: LineCoordinates | None = None) -> list[Mode]:
    """The modes of the fast states' Jacobian ``A`` (module text): the bounce and bending
    modes in the order of ``shapes.labels`` (those that have one), then a web line's
    modes (``line``: :mod:`winder.analysis.line_modes`, kind ``line``, in the order of its
    labels), then the slip modes
    (slowest first), then the torsion modes (slowest first). ``n_positions`` free
    coordinates (of masses ``mass`` [kg]), ``n_speeds`` turning bodies (``inertia``
    [kg·m²]), ``names`` of the fast states, ``mechanical`` the mask of the bodies' states,
    ``rotary`` per fast state the rotary inertia ``j_r`` [kg·m²] of a section whose
    rotation rate it is (``SEG.tilt_rate_x``/``_z``; 0 elsewhere, None: none)."""
    from scipy.linalg import eig
    from scipy.optimize import linear_sum_assignment

    if A.shape[0] == 0:
        return []
    lam, left, right = eig(A, left=True, right=True)
    nt, ns = n_positions, n_speeds
    keep = [i for i in range(len(lam)) if lam[i].imag >= 0.0]  # one of each pair
    Q = shapes.Q  # onto the generalised coordinates (a flexible body's orders)
    top = float(np.max(np.abs(lam)))
    still = np.abs(lam[keep]) <= 1e-12 * top  # a zero eigenvalue: the displacement counts
    mech = mechanical_share(left[:, keep], right[:, keep], mechanical)
    weight = np.sqrt(np.concatenate([(Q * Q) @ mass, inertia]))

    jr = np.zeros(A.shape[0]) if rotary is None else np.asarray(rotary, dtype=float)
    tilt = np.nonzero(jr > 0.0)[0]  # the sections' rotation rates

    def energy_rows(V: np.ndarray) -> np.ndarray:  # √(m) ẋ, √(J) θ̇, √(j_r) s
        return np.vstack([weight[:, None] * np.vstack([Q @ V[nt:2 * nt],
                                                        V[2 * nt:2 * nt + ns]]),
                          np.sqrt(jr[tilt])[:, None] * V[tilt]])

    V = _split_degenerate(right[:, keep], lam[keep], still, energy_rows, mech)
    moving = np.where(still[None, :], Q @ V[:nt], Q @ V[nt:2 * nt])
    kin = np.vstack([((Q * Q) @ mass)[:, None] * np.abs(moving) ** 2,
                     inertia[:, None] * np.abs(V[2 * nt:2 * nt + ns]) ** 2])
    spin = jr[tilt, None] * np.abs(V[tilt]) ** 2  # the sections' rotation: ½ j_r |s|²
    total = kin.sum(axis=0) + spin.sum(axis=0)
    share = kin[:nt] / np.maximum(total, 1e-300)
    oscillating = lam[keep].imag > 0.0
    good = oscillating & (mech >= MECHANICAL_SHARE)
    # a rotation mode: of the bodies, mostly the sections' rotation (oscillating or not)
    turning = (mech >= MECHANICAL_SHARE) & (spin.sum(axis=0) >= ROTATION_SHARE * total)
    good &= ~turning
    first = good[None, :] & (share >= _BOUNCE_SHARE)
    shaped = np.array([".bend." in c for c in shapes.labels], dtype=bool)[:, None]
    shape_ok = good[None, :] & (share >= SHAPE_SHARE)
    score = np.where(shaped, np.where(shape_ok, share + first, -1.0), share + first)
    rows, cols = linear_sum_assignment(-score)
    bounce = {int(r): keep[int(c)] for r, c in zip(rows, cols, strict=True)
              if score[r, c] >= 0.0}
    out = [Mode(complex(lam[bounce[c]]), "bending" if shaped[c, 0] else "bounce",
                shapes.labels[c]) for c in range(nt) if c in bounce]
    taken = set(bounce.values())
    best: dict[str, tuple[float, int]] = {}  # torsion label -> (energy in it, k)
    rest, rotations = [], []
    for k in (k for k in range(len(keep)) if keep[k] not in taken):
        if turning[k]:
            rotations.append(Mode(complex(lam[keep[k]]), "rotation",
                                  shapes.rotation_label([names[i] for i in tilt],
                                                        V[tilt, k], jr[tilt])))
            continue
        label = shapes.torsion_label(V[2 * nt:2 * nt + ns, k], inertia,
                                     float(total[k])) if good[k] else None
        if label is None:
            rest.append(k)
            continue
        held = best.get(label[0])
        if held is None or label[1] > held[0]:
            if held is not None:  # the weaker of two modes in one order: a slip mode
                rest.append(held[1])
            best[label[0]] = (label[1], k)
        else:
            rest.append(k)
    lines: list[Mode] = []
    if line is not None:  # a web line's tension and dancer modes, by their energy
        part = mechanical_share(left[:, keep], right[:, keep], mechanical | line.states)
        named = line.assign(V, lam[keep], rest, total, part,
                            mechanical_share(left[:, keep], right[:, keep], line.line_states))
        order = {c: i for i, c in enumerate(line.labels)}
        lines = sorted((Mode(complex(lam[keep[k]]), "line", c) for k, c in named.items()),
                       key=lambda m: order[m.coordinate])
        rest = [k for k in rest if k not in named]
    slips = [Mode(complex(lam[keep[k]]), "slip",
                  names[nt + int(np.argmax(np.abs(V[nt:, k])))]) for k in rest]
    torsions = [Mode(complex(lam[keep[k]]), "torsion", c) for c, (_, k) in best.items()]
    slowest = lambda m: abs(m.eigenvalue)  # noqa: E731
    return out + lines + sorted(slips, key=slowest) + sorted(torsions, key=slowest) \
        + sorted(rotations, key=slowest)


def _split_degenerate(V: np.ndarray, lam: np.ndarray, still: np.ndarray, energy_rows,
                      mech: np.ndarray) -> np.ndarray:
    """The eigenvectors ``V`` (columns, eigenvalues ``lam``) with each cluster of equal
    eigenvalues (within 1e-8, not zero: ``still``) spanned anew by one vector per
    coordinate: any basis of such an eigenspace is an eigenbasis (a drum's ``x`` and ``z``
    bending of one order on equal bearings, twin drums' torsion), so the one whose vectors
    each move one of ``m`` coordinates of the space (rows of ``energy_rows(V)``, chosen by
    energy and independence) and none of the others; ``mech`` (changed in place) the cluster's
    least mechanical share. Unchanged where that basis is ill-conditioned."""
    from scipy.linalg import qr

    V = V.copy()
    done = np.zeros(len(lam), dtype=bool)
    for i in range(len(lam)):
        if done[i] or still[i]:
            continue
        group = np.nonzero(~done & ~still & (np.abs(lam - lam[i]) <= 1e-8 * abs(lam[i])))[0]
        done[group] = True
        if len(group) < 2:
            continue
        E = energy_rows(V[:, group])
        # the coordinates by energy, each the most independent of those before (QR with
        # column pivoting): a drum's z5 and x5, not z5 and z7 (one shape's two orders)
        W = E[qr(E.conj().T, pivoting=True, mode="r")[1][:len(group)]]
        if np.linalg.cond(W) < 1e8:
            V[:, group] = V[:, group] @ np.linalg.inv(W)
            mech[group] = np.min(mech[group])
    return V
