"""Mode shapes of flexible bodies (issue #25): a mode's segment displacements projected
onto ``sin(nπ y/L)`` at the segment centres, for the resonance map's labels.

A flexible body of ``N`` segments has its centres at ``y_i = (i + ½) L/N`` (``i = 0`` at
the drive end). The vectors ``φ_n(i) = sin(nπ y_i/L)``, ``n = 1 … N``, are orthogonal
(the discrete sine transform DST-II: ``|φ_n|² = N/2``, ``|φ_N|² = N``), so a mode's
kinetic energy in one direction of the body, ``½ m_s Σ_i |u̇_i|²`` over its equal
segments, splits exactly into the shares ``½ m_s |φ_n·u̇|²/|φ_n|²`` of the orders ``n``.
The generalised coordinates of the modes are therefore, per flexible body and direction,
``BODY.bend.x1 … BODY.bend.xN`` (``z`` likewise) in place of the segments' ``x``/``z``,
and each takes the eigenpair in which it carries the largest share, exactly as a rigid
body's free coordinate (``BODY.z``) does. A body carried by its nips (a wound roll, the
rider in ``z``) bounces as a whole: a uniform displacement projects onto ``n = 1`` with
``8/π² = 81 %`` of its energy, so its bounce mode is ``BODY.bend.z1``.

Torsion: the segments' rotation speeds of a flexible body, where they carry most of a
mode's kinetic energy, name a **torsion mode** ``BODY.torsion{n}``: the dominant order of
their projection onto the body's own torsion shapes (:func:`torsion_basis`: held at the
drive segment, or free–free); a mode whose energy is mostly a free body's rigid rotation is
a slip mode, no torsion mode. Only an oscillating mode of the bodies carries a bending or
torsion label (:mod:`winder.analysis.mode_labels`); a mode mostly in the sections' rotation
(``flex.rotary_inertia``) is a rotation mode ``BODY.rotation.{x,z}{n}``
(:meth:`Shapes.rotation_label`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["sine_basis", "orders", "torsion_basis", "Shapes"]


def sine_basis(n: int) -> np.ndarray:
    """``(N, N)``: row ``k − 1`` is ``sin(kπ y_i/L)`` at the centres ``y_i = (i + ½)L/N``."""
    i = np.arange(n) + 0.5
    return np.sin(np.outer(np.arange(1, n + 1), i) * np.pi / n)


def orders(u: np.ndarray) -> np.ndarray:
    """The shares [-] of the orders ``n = 1 … N`` in ``Σ|u_i|²`` of a shape ``u`` (complex
    or real, over the segment centres in order): ``|φ_n·u|²/|φ_n|²``, normalised; they sum
    to 1 (the basis is orthogonal and complete)."""
    phi = sine_basis(len(u))
    e = np.abs(phi @ np.asarray(u)) ** 2 / np.sum(phi * phi, axis=1)
    return e / max(float(e.sum()), 1e-300)


@dataclass(frozen=True)
class _Group:
    body: str       # the flexible body's name
    coord: str      # x, z or theta
    rows: tuple[int, ...]  # per segment in order: its row, or -1 (prescribed: no state)


class Shapes:
    """The generalised coordinates of a machine's modes: ``labels`` (one per free
    coordinate: a rigid body's ``BODY.x``/``BODY.z``, a flexible body's
    ``BODY.bend.{x,z}{n}``) and the orthonormal map ``Q`` from the free coordinates'
    velocities to theirs; the torsion groups of the turning segments."""

    def __init__(self, bodies: Sequence, coords: list[str], speeds: list[str]) -> None:
        """``bodies``: the machine's bodies (:class:`~winder.parts.BodyElement`);
        ``coords``: the free coordinates ``NAME.x``/``NAME.z`` in the state's order;
        ``speeds``: the bodies whose rotation speed is a state, in that order."""
        nt = len(coords)
        self.Q = np.zeros((nt, nt))
        self.labels: list[str] = []
        seen: set[tuple[str, str]] = set()
        self.torsion: list[_Group] = []
        #: a flexible body's segment name -> (the body's name, its index)
        self.segment = {b.name: (b.segment_of, b.index) for b in bodies if b.segment_of}
        row = 0
        for j, c in enumerate(coords):
            name, axis = c.rsplit(".", 1)
            body = next(b for b in bodies if b.name == name)
            whole = body.segment_of
            if whole is None:
                self.Q[row, j] = 1.0
                self.labels.append(c)
                row += 1
                continue
            if (whole, axis) in seen:
                continue
            seen.add((whole, axis))
            segs = sorted((b for b in bodies if b.segment_of == whole), key=lambda b: b.index)
            cols = [coords.index(f"{b.name}.{axis}") for b in segs]
            phi = sine_basis(len(segs))
            phi /= np.linalg.norm(phi, axis=1)[:, None]
            for k in range(len(segs)):
                self.Q[row, cols] = phi[k]
                self.labels.append(f"{whole}.bend.{axis}{k + 1}")
                row += 1
        for whole in dict.fromkeys(b.segment_of for b in bodies if b.segment_of):
            segs = sorted((b for b in bodies if b.segment_of == whole), key=lambda b: b.index)
            rows = tuple(speeds.index(b.name) if b.name in speeds else -1 for b in segs)
            self.torsion.append(_Group(whole, "theta", rows))

    def torsion_label(self, omega: np.ndarray, inertia: np.ndarray, total: float
                      ) -> tuple[str, float] | None:
        """``(BODY.torsion{n}, share)`` of a mode whose rotation speeds of the turning
        bodies are ``omega`` (complex, in the order of ``speeds``; ``inertia`` [kg·m²]
        alike) and whose kinetic energy is ``total``: where the flexible bodies' segments'
        rotation carries at least half of it, the body with the most of it and the
        dominant order of its shape in :func:`torsion_basis`, ``share`` [-] the part of
        the kinetic energy in that body's rotation times that order's part of its shape;
        ``None`` where the twist does not dominate (a slip mode: a free body turning as a
        whole)."""
        best, rotation = None, 0.0
        for g in self.torsion:
            live = [r for r in g.rows if r >= 0]
            e = float(np.sum(inertia[live] * np.abs(omega[live]) ** 2))
            rotation += e
            if best is None or e > best[1]:
                best = (g, e)
        # the flexible bodies' rotation together (twin drums share a mode through their
        # nips), the body with the most of it names the mode
        if best is None or not rotation >= 0.5 * total:
            return None
        g, e = best
        fixed = g.rows[0] < 0
        w = np.array([omega[r] for r in g.rows if r >= 0])
        if not fixed and np.sum(np.abs(w - w.mean()) ** 2) <= len(w) * abs(w.mean()) ** 2:
            return None  # mostly the rigid rotation
        phi = torsion_basis(len(g.rows), fixed)
        share = np.abs(phi @ w) ** 2 / np.sum(phi * phi, axis=1)
        k = int(np.argmax(share))
        return (f"{g.body}.torsion{k + 1}",
                e / max(total, 1e-300) * share[k] / max(float(np.sum(np.abs(w) ** 2)), 1e-300))


    def rotation_label(self, names: list[str], rates: np.ndarray, inertia: np.ndarray
                       ) -> str:
        """``BODY.rotation.{x,z}{n}`` of a mode whose sections' rotation rates are ``rates``
        (complex) on the states ``names`` (``SEG.tilt_rate_x``/``_z``; rotary inertias
        ``inertia`` [kg·m²]): the body and axis with the most of their energy
        ``½ j_r |s|²``, ``n`` the dominant order of its rates on ``cos(nπ y/L)`` at the
        segment centres, ``n = 0 … N − 1`` (DCT-II, orthogonal; a section's rotation in a
        bending mode ``sin(nπ y/L)`` is ``∝ cos(nπ y/L)``)."""
        groups: dict[tuple[str, str], dict[int, complex]] = {}
        for name, s, j in zip(names, rates, inertia, strict=True):
            seg, state = name.split(".", 1)
            body, index = self.segment[seg]
            groups.setdefault((body, state[-1]), {})[index] = complex(np.sqrt(j) * s)
        (body, axis), w = max(groups.items(),
                              key=lambda g: sum(abs(x) ** 2 for x in g[1].values()))
        n = max(w) + 1
        u = np.zeros(n, dtype=complex)
        for i, x in w.items():
            u[i] = x
        basis = np.cos(np.outer(np.arange(n), np.arange(n) + 0.5) * np.pi / n)
        share = np.abs(basis @ u) ** 2 / np.sum(basis * basis, axis=1)
        return f"{body}.rotation.{axis}{int(np.argmax(share))}"


def torsion_basis(n: int, fixed: bool) -> np.ndarray:
    """The torsion shapes of a chain of ``n`` segments, one row per order ``1 … n − 1``:
    held at segment 0 (a prescribed drive; over segments ``1 … n − 1``)
    ``sin((2k − 1)π i/(2n − 1))``, free–free ``cos(kπ (i + ½)/n)`` (orthogonal to the
    rigid rotation); both are exactly the chain's own modes (uniform springs and disks)
    and orthogonal, so a chain's mode ``k`` is labelled ``k``. Not the bending's
    ``sin(nπ y/L)``: on a shaft held at one end or free at both its first torsion mode
    would project mostly onto ``n = 2``."""
    k = np.arange(1, n)[:, None]
    if fixed:
        return np.sin((2 * k - 1) * np.pi * np.arange(1, n)[None, :] / (2 * n - 1))
    return np.cos(k * np.pi * (np.arange(n)[None, :] + 0.5) / n)
