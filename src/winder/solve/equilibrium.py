"""The initial state of machines.md §7: free translational coordinates in static balance.

Angles 0, translational velocities 0, speeds from the scene; each free ``x``/``z`` solves
the force balance of its body (gravity, rider load, the nips' normal forces at ``δ̇ = 0``
and friction at ``F_t(0)``, the web forces at ``T(0)``). With the ``contact`` effect off
the coordinates an elastic support holds (a flexible body's bearings, a roll's chucks, a
rider's arms: :func:`balance_unknowns`) are still balanced, so a flexible drum on its
bearings starts in its sag; the others start at the scene's ``centre``.

The solve starts where it almost ends (:func:`resting_state`): each free body resting on
the bodies below it, every nip compressed by the static penetration of its law under the
load it carries, in closed form (linear ``δ₀ = F/k``, Hunt–Crossley ``δ₀ = (F/k)^(1/p)``;
the loads accumulated from the top: a rider's weight and load onto the roll it rides, the
roll's weight and that onto its drums). Powell's hybrid method (a trust-region Newton)
finishes it. A nip too soft to carry its load, a body that cannot reach the bodies it rests
on, and a balance that does not converge are refused naming the scene keys that decide
them. The largest force residual is reported with the result; above
:data:`RESIDUAL_LIMIT` of the largest force in the balance the start is refused.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from winder._errors import WinderError
from winder.forces.contact import rest_penetration
from winder.model.backends import NumericBackend
from winder.model.locked_modes import AUTO, CORE_AUTO, FREE, IN_CONTACT, ModeKind
from winder.model.machine import Machine, Nip
from winder.model.slices import entry_slice
from winder.parts import BodyElement as Body
from winder.scene.naming import naming_of

__all__ = ["static_state", "cached_static_state", "resting_state", "Resting", "Equilibrium",
           "EquilibriumError", "RESIDUAL_LIMIT", "balance_keys", "body_key", "nip_key",
           "balance_unknowns"]

#: Largest accepted residual of the static balance, relative to the largest force in it.
RESIDUAL_LIMIT = 1e-6


class EquilibriumError(WinderError, ValueError):
    """No static balance for a body: names the body and the residual."""


@dataclass(frozen=True)
class Equilibrium:
    """The initial state and its static balance: ``residual`` [N] (largest), ``scale``
    [N] (largest force in the balance)."""

    state: np.ndarray
    residual: float
    scale: float


def _forces(machine: Machine, be: NumericBackend, x: np.ndarray, p: np.ndarray,
            modes: np.ndarray, unknowns: list[tuple[str, str, int]]) -> tuple[np.ndarray, float]:
    ev = machine.evaluate(be, 0.0, x, p, modes, static=True)
    res = np.array([ev.bodies[b].fx if c == "x" else ev.bodies[b].fz for b, c, _ in unknowns])
    scale = max([abs(ns.normal_force) for ns in ev.nips.values()]
                + [abs(bs.mass * p[machine.param_index("gravity")])
                   for bs in ev.bodies.values()] if "gravity" in machine.param_names else
                [abs(ns.normal_force) for ns in ev.nips.values()] + [0.0])
    return res, scale


# ---- the scene keys that decide a balance -------------------------------------------------
def body_key(machine: Machine, body: Body) -> str:
    """The scene key that places ``body`` (``[[drum]] 'front' centre``, ``[[roll]] 'set'
    centre``, ``[[rider]] 'rider' x``; the single-drum format: ``[drum] radius``,
    ``[roll] initial_radius``)."""
    return naming_of(machine.scene).key(body.table, body.name, body.place_key)


def nip_key(machine: Machine, nip: Nip, key: str = "stiffness") -> str:
    """The scene key of a nip's contact law (``[[nip]] 'rider_nip' contact stiffness``; the
    single-drum format: ``[contact] stiffness``)."""
    return naming_of(machine.scene).key("nip", nip.part.name, "contact", key)


def balance_keys(machine: Machine, body: Body) -> list[str]:
    """The keys that decide the balance of ``body``: where it is, the stiffness of each
    nip it touches and where the bodies it rests on are."""
    keys = [body_key(machine, body)]
    for n in machine.nips:
        if body in (n.a, n.b):
            keys.append(nip_key(machine, n))
    for n in machine.nips:
        if n.b is body:
            keys.append(body_key(machine, n.a))
    return list(dict.fromkeys(keys))


def _law(machine: Machine, p: np.ndarray, nip: Nip) -> Callable[[str], float]:
    def par(key: str) -> float:
        return float(p[machine.param_index(f"{nip.name}.{key}")])
    return par


def _free_modes(machine: Machine) -> np.ndarray:
    """Every nip open (``FREE``), the core modes automatic: the applied forces alone."""
    return np.array([mode.kind.unloaded for mode in machine.modes], dtype=float)


@dataclass(frozen=True)
class Resting:
    """The closed-form resting state (see :func:`resting_state`): ``state``, and per nip
    its ``load`` [N] and static ``penetration`` [m]."""

    state: np.ndarray
    load: dict[str, float]
    penetration: dict[str, float]


def resting_state(machine: Machine, x: np.ndarray, p: np.ndarray, movable: set[str], *,
                  t: float = 0.0, be: NumericBackend | None = None,
                  rates: bool = False) -> Resting:
    """``x`` with the free coordinates of the bodies in ``movable`` placed where each body
    rests on the bodies below it (the nips where it is ``b`` and ``a`` is fixed or placed
    before it), every nip compressed by the static penetration of its law under the load it
    carries (closed form, :func:`~winder.forces.contact.rest_penetration`). The loads are
    the applied forces with every nip open (gravity, rider load, web and friction states),
    accumulated from the top (a rider's onto the roll it rides, the roll's onto its
    drums) and split over each body's supports along their normals. ``rates``: the nips'
    damping sees the rate ``δ̇`` of the radii in ``x`` (the operating point), else ``δ̇ =
    0``. Geometry and loads are iterated 4 times (the normals turn with the penetrations).

    Raises
    ------
    EquilibriumError: a nip too soft to carry its load (its penetration would reach a
        radius), or a body that cannot reach the bodies it rests on; both name the keys.
    """
    be = be or NumericBackend(machine.model)
    x = np.array(x, dtype=float)
    # a body held along all its free axes by bearings (a roll on chucks) is not placed on
    # the bodies below it: it starts on its bearings' line, the balance finds its sag
    order = [b for b in machine.bodies if b.name in movable and b.free
             and not set(b.free) <= set(b.bearing_axes)]
    rank = {b.name: i for i, b in enumerate(machine.bodies)}
    placed0 = {b.name for b in machine.bodies if b.name not in movable or not b.free}
    supports = {b.name: [n for n in machine.nips if n.b is b and _whole(machine, n) and
                         (n.a.name in placed0 or rank[n.a.name] < rank[b.name])]
                for b in order}
    delta = {n.name: 0.0 for n in machine.nips}
    load = {n.name: 0.0 for n in machine.nips}
    free = _free_modes(machine)

    def centre(b: Body) -> np.ndarray:
        return np.array([x[machine.index(f"{b.name}.x")] if "x" in b.free else b.centre[0],
                         x[machine.index(f"{b.name}.z")] if "z" in b.free else b.centre[1]])

    for _ in range(4):
        ev = machine.evaluate(be, t, x, p, free, static=True)
        radius = {n: float(bs.r) for n, bs in ev.bodies.items()}
        for b in order:  # bottom-up: place each body on its supports
            _place(machine, b, supports[b.name], x, centre, radius, delta)
        ev = machine.evaluate(be, t, x, p, free, static=True)
        dd = {}
        if rates:
            dyn = machine.evaluate(be, t, x, p, free, outputs=False)
            dd = {n: float(ns.delta_dot) for n, ns in dyn.nips.items()}
        normal = {}
        for n in machine.nips:
            d = centre(n.b) - centre(n.a)
            normal[n.name] = d / max(float(np.linalg.norm(d)), 1e-300)
        for b in reversed(order):  # top-down: what each body's supports carry
            bs = ev.bodies[b.name]
            w = -np.array([float(bs.fx), float(bs.fz)])
            for n in machine.nips:
                if n.a is b and n.b.name in supports and n in supports[n.b.name]:
                    w += load[n.name] * normal[n.name]
            _split(b, supports[b.name], w, normal, load)
        for n in machine.nips:
            if n.b.name not in supports or n not in supports[n.b.name]:
                continue
            share = n.count if n.b.segment_of is None else 1  # slices under a rigid b
            d = rest_penetration(n.part.contact.law, _law(machine, p, n),
                                 load[n.name] / share, dd.get(n.name, 0.0))
            ra, rb = radius[n.a.name], radius[n.b.name]
            if not d < min(ra, rb):
                raise EquilibriumError(_too_soft(machine, n, load[n.name], d, min(ra, rb)))
            delta[n.name] = d
    for b in order:
        _place(machine, b, supports[b.name], x, centre, radius, delta)
    return Resting(x, load, delta)


def _whole(machine: Machine, nip: Nip) -> bool:
    """Whether ``nip`` is a support in the resting state: an unsliced nip, a slice under
    a segment of a flexible ``b`` (each carries its own), or the middle slice of a sliced
    nip under a rigid ``b`` (which carries the whole load there, its law ``1/count`` of
    the nip's)."""
    return nip.whole is None or nip.b.segment_of is not None or \
        nip is entry_slice(machine.nips, nip.whole)


def _too_soft(machine: Machine, n: Nip, load: float, d: float, r: float) -> str:
    keys = ("stiffness",) if n.part.contact.law == "linear" else ("stiffness", "exponent")
    return (f"{nip_key(machine, n)} is too soft for the load of {load:.4g} N on nip "
            f"{n.name!r} ({n.part.contact.law}): at rest it would be compressed by {d:.3g} m, "
            f"more than the smaller radius {r:.4g} m of {n.a.name!r} and {n.b.name!r} (one "
            f"axis inside the other body; compression from "
            f"{' and '.join(nip_key(machine, n, k) for k in keys)}); valid: a stiffer nip or "
            "a lighter load, so that the compression stays below that radius")


def _place(machine: Machine, b: Body, sup: list[Nip], x: np.ndarray,
           centre: Callable[[Body], np.ndarray], radius: dict[str, float],
           delta: dict[str, float]) -> None:
    """Put ``b`` on its supports ``sup`` at distances ``r_a + r_b − δ``."""
    if not sup:
        return
    dist = [radius[n.a.name] + radius[b.name] - delta[n.name] for n in sup]
    cx, cz = centre(b)
    if "x" in b.free and "z" in b.free and len(sup) >= 2:  # upper intersection of circles
        p1, p2 = centre(sup[0].a), centre(sup[1].a)
        d1, d2 = dist[0], dist[1]
        base = float(np.linalg.norm(p2 - p1))
        if not (base > abs(d1 - d2) and base < d1 + d2):
            a1, a2 = sup[0].a, sup[1].a
            raise EquilibriumError(
                f"{b.table} {b.name!r} cannot rest on both {a1.name!r} and {a2.name!r}: their "
                f"centres are {base:.4g} m apart, but {b.name!r} reaches {d1:.4g} m from "
                f"{a1.name!r} and {d2:.4g} m from {a2.name!r} (their radii plus its own); "
                f"check {body_key(machine, a1)} and {body_key(machine, a2)} (in metres) "
                f"and {body_key(machine, b)}; valid: centres between {abs(d1 - d2):.4g} and "
                f"{d1 + d2:.4g} m apart")
        s = (d1 * d1 - d2 * d2 + base * base) / (2 * base)
        h = math.sqrt(max(d1 * d1 - s * s, 0.0))
        e = (p2 - p1) / base
        cx, cz = p1 + s * e + h * np.array([-e[1], e[0]]) * (1 if e[0] >= 0 else -1)
    elif "z" in b.free:  # straight down onto the highest support
        heights = []
        for n, d in zip(sup, dist, strict=True):
            ca = centre(n.a)
            if (cx - ca[0]) ** 2 < d * d:
                heights.append(ca[1] + math.sqrt(d * d - (cx - ca[0]) ** 2))
        if not heights:
            a = sup[0].a
            ca = centre(a)
            raise EquilibriumError(
                f"{b.table} {b.name!r} at x = {cx:.6g} m does not reach {a.table} {a.name!r} it "
                f"rests on (centre x = {ca[0]:.6g} m; in contact the centres are at most "
                f"{dist[0]:.4g} m apart, the sum of the two radii); check "
                f"{body_key(machine, b)}; valid: x between {ca[0] - dist[0]:.6g} and "
                f"{ca[0] + dist[0]:.6g} m")
        cz = max(heights)
    else:
        return
    for c in b.free:
        x[machine.index(f"{b.name}.{c}")] = float(cx if c == "x" else cz)


def _split(b: Body, sup: list[Nip], w: np.ndarray, normal: dict[str, np.ndarray],
           load: dict[str, float]) -> None:
    """The normal forces of the supports ``sup`` of ``b`` that carry the force ``w`` [N]
    along their normals (its free components; never negative)."""
    if not sup:
        return
    if "x" in b.free and "z" in b.free and len(sup) >= 2:
        A = np.column_stack([normal[sup[0].name], normal[sup[1].name]])
        try:
            f = np.linalg.solve(A, w)
        except np.linalg.LinAlgError:
            f = np.linalg.lstsq(A, w, rcond=None)[0]
        for n, fi in zip(sup[:2], f, strict=True):
            load[n.name] = max(float(fi), 0.0)
        for n in sup[2:]:
            load[n.name] = 0.0
        return
    axis = [i for i, c in enumerate(("x", "z")) if c in b.free]
    N = np.array([[normal[n.name][i] for i in axis] for n in sup])  # rows: supports
    f = np.linalg.lstsq(N.T, w[axis], rcond=None)[0]
    for n, fi in zip(sup, f, strict=True):
        load[n.name] = max(float(fi), 0.0)


# ---- the static balance -----------------------------------------------------------------
def balance_unknowns(machine: Machine) -> list[tuple[str, str, int]]:
    """The free coordinates the static balance solves for, ``(body, coordinate, state
    index)``: with the ``contact`` effect every free coordinate not fixed at rest
    (:meth:`~winder.parts.BodyElement.fixed_at_rest`); without it those held by an elastic
    support (:attr:`~winder.parts.BodyElement.bearing_axes`: a flexible body's bearings, a
    roll's chucks, a rider's arms), which start in their static balance whether or not
    anything rests on the body. The others start where the scene puts them (§7: a free
    body with no contact beneath it at its ``centre``)."""
    contact = bool(machine.scene.effects.contact)
    out = []
    for b in machine.bodies:
        fixed = b.fixed_at_rest()
        for c in b.free:
            if c not in fixed and (contact or c in b.bearing_axes):
                out.append((b.name, c, machine.index(f"{b.name}.{c}")))
    return out


def static_state(machine: Machine, p: np.ndarray | None = None) -> Equilibrium:
    """The initial state of ``machine`` (spec §7) for parameters ``p`` (default: the
    scene's).

    Raises
    ------
    EquilibriumError: no static balance, naming the body, the residual and the keys that
        decide it (see the module text).
    """
    from scipy.optimize import root

    p = machine.parameters() if p is None else p
    x = np.array(machine.state_initial, dtype=float)
    # every nip touching, its law extended smoothly to δ < 0 (so the balance is smooth);
    # a nip that would pull is opened and the balance solved again (an active set)
    contact = machine.mode_slots(ModeKind.CONTACT)
    modes = np.full(len(machine.mode_names), float(CORE_AUTO))
    modes[contact] = IN_CONTACT
    for b in machine.bodies:
        for c, value in b.fixed_at_rest().items():
            x[machine.index(f"{b.name}.{c}")] = value
    unknowns = balance_unknowns(machine)
    be = NumericBackend(machine.model)
    if not unknowns:
        return Equilibrium(x, 0.0, 0.0)
    idx = [i for _, _, i in unknowns]
    if machine.scene.effects.contact:  # the first guess: each body resting on its nips
        x = resting_state(machine, x, p, {b for b, _, _ in unknowns}, be=be).state

    def residual(u: np.ndarray) -> np.ndarray:
        x[idx] = u
        return _forces(machine, be, x, p, modes, unknowns)[0]

    u0 = x[idx].copy()
    with np.errstate(all="ignore"):
        for _ in range(len(contact) + 1):
            sol = root(residual, u0, method="hybr", options={"xtol": 1e-15})
            x[idx] = sol.x
            ev = machine.evaluate(be, 0.0, x, p, modes, static=True)
            pulling = [i for i in contact if modes[i] == IN_CONTACT
                       and ev.nips[machine.modes[i].owner].normal_force
                       < 0.0]
            if not pulling:
                break
            modes[pulling] = FREE
        modes[contact] = AUTO
        res, scale = _forces(machine, be, x, p, modes, unknowns)
    worst = int(np.argmax(np.where(np.isfinite(res), np.abs(res), np.inf)))
    if not np.all(np.isfinite(res)) or abs(res[worst]) > RESIDUAL_LIMIT * max(scale, 1e-300):
        b, c, _ = unknowns[worst]
        keys = balance_keys(machine, machine.body[b])
        raise EquilibriumError(
            f"no static balance for body {b!r} along {c}: force residual "
            f"{res[worst]:.3g} N (largest force {scale:.3g} N, limit {RESIDUAL_LIMIT:g} of "
            f"it); the balance is decided by {', '.join(keys)} and the loads on it")
    return Equilibrium(x, float(np.max(np.abs(res))), scale)


# ---- the balance cache --------------------------------------------------------------------
def _balance_key(machine: Machine, p: np.ndarray) -> str:
    """Everything the balance depends on: the scene, the parameters, the initial state,
    the source of the physics and of this module, and the numeric libraries' versions."""
    import importlib.metadata
    import json

    from winder.model.codegen import source_hash

    h = hashlib.sha256(machine.structure_key().encode())
    h.update(json.dumps(machine.scene.to_dict(), sort_keys=True, default=repr).encode())
    h.update(np.ascontiguousarray(p, dtype=float).tobytes())
    h.update(np.asarray(machine.state_initial, dtype=float).tobytes())
    h.update(source_hash().encode() + Path(__file__).read_bytes())
    for dist in ("numpy", "scipy", "pin"):
        try:
            h.update(f"{dist}{importlib.metadata.version(dist)}".encode())
        except importlib.metadata.PackageNotFoundError:
            h.update(f"{dist}-none".encode())
    return h.hexdigest()[:24]


def cached_static_state(machine: Machine, p: np.ndarray | None = None) -> Equilibrium:
    """:func:`static_state`, kept on disk (``cache_dir()/balance``) under a key of
    everything it depends on (:func:`_balance_key`): a second run of the same scene and
    parameters reads the state (exactly: floats as hex) and imports no solver. Only
    balances that were found are kept; a refused one is refused again every time. A
    machine whose scene cannot be written out (``to_dict``: the tests' stand-ins) is
    solved every time."""
    import contextlib
    import json
    import os
    import tempfile

    from winder.model.codegen import cache_dir

    p = machine.parameters() if p is None else p
    if not hasattr(machine.scene, "to_dict"):
        return static_state(machine, p)
    path = cache_dir() / "balance" / f"{_balance_key(machine, p)}.json"
    try:
        data = json.loads(path.read_text())
        state = np.array([float.fromhex(v) for v in data["state"]])
        if state.shape == (machine.n_states,):
            return Equilibrium(state, float.fromhex(data["residual"]),
                               float.fromhex(data["scale"]))
    except (OSError, ValueError, KeyError, TypeError):
        pass
    eq = static_state(machine, p)
    text = json.dumps({"state": [float(v).hex() for v in eq.state],
                       "residual": float(eq.residual).hex(), "scale": float(eq.scale).hex()})
    tmp = None
    try:  # atomic; a cache that cannot be written is skipped, and leaves no temporary
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".balance-", suffix=".json")
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
        tmp = None
    except OSError:
        pass
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return eq
