"""Resonance map: nip modes of the winder against roll radius (a Campbell chart).

At each radius the winder is linearised (:func:`winder._linearise.jacobian`) about its
quasi-steady operating point: web speed at its final value, roll on the nip at static
equilibrium under its current weight, slip and friction at the values that carry the
roll's slow deceleration ``ω̇ = −v ṙ/r²``, imbalance off (it is the excitation). The
eigenvalues of the Jacobian restricted to the fast states ``(z, ż, ω, F_t)`` give the
bounce mode (the pair dominated by ``z``) and the slip/torsion mode(s). The roll turns at
``f₁ = v/(2π r)``; where ``n f₁`` crosses the bounce frequency the imbalance drives the
nip at resonance (critical radii). For each radius the web speed at which the 1× line
meets the bounce mode is ``v_crit = 2π r f_bounce``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._args import integer, number, show
from ._errors import ArgumentError, ArgumentTypeError
from ._linearise import jacobian
from ._scene import _MAX, Scene
from ._system import WinderSystem

__all__ = ["Mode", "ModeMap", "operating_point", "modes_at", "mode_map", "MAX_POINTS"]

#: Most radii of one resonance map.
MAX_POINTS = 10_000
WEB_SPEED_MAX = _MAX[("drum.drive", "web_speed")]  # [m/s], as in a scene


@dataclass(frozen=True)
class Mode:
    """One eigenvalue pair: ``frequency`` [Hz] (damped, 0 for a real eigenvalue),
    ``natural_frequency`` ``|λ|/2π`` [Hz], ``damping_ratio`` [-], ``kind``
    (``bounce`` or ``slip``)."""

    eigenvalue: complex
    kind: str

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


def _steady_scene(scene: Scene, where: str) -> Scene:
    """The scene of the quasi-steady operating point (imbalance off: it is the excitation);
    an :class:`ArgumentError` if the scene has no such point."""
    if not isinstance(scene, Scene):
        raise ArgumentTypeError(f"{where}: scene must be a winder.Scene (winder.load_scene), "
                                f"got {show(scene)} ({type(scene).__name__})")
    if not scene.effects.contact:
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs the nip: "
                            "[effects] contact = false; valid: contact = true")
    if scene.drum.drive.kind != "speed_profile":
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs [drum.drive] "
                            f"kind = 'speed_profile' (its web speed is the operating speed), "
                            f"got {scene.drum.drive.kind!r}")
    if not scene.effects.gravity or scene.scene.gravity == 0.0:
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs the roll's "
                            "weight on the nip, but [effects] gravity = "
                            f"{str(scene.effects.gravity).lower()} and [scene] gravity = "
                            f"{scene.scene.gravity!r}; valid: gravity on and > 0")
    if scene.friction.mu == 0.0:
        raise ArgumentError(f"{where}: {scene.source}: [friction] mu = 0: without friction "
                            "the drum does not drive the roll, so there is no winding "
                            "operating point and no slip mode; valid: mu > 0")
    return scene.replace(effects={"imbalance": False})


def _web_speed(where: str, scene: Scene, web_speed: float | None, lo_open: bool) -> float:
    """The operating web speed [m/s]: the argument, or the scene's ``[drum.drive]
    web_speed``; finite, ``> 0`` (``>= 0`` where ``lo_open`` is false)."""
    if web_speed is None:
        v = scene.drum.drive.web_speed
        if lo_open and not v > 0.0:
            raise ArgumentError(f"{where}: web_speed is not given and the scene's "
                                f"[drum.drive] web_speed is {v!r} ({scene.source}); valid: "
                                "a web speed > 0 m/s")
        return v
    return number(where, "web_speed", web_speed, lo=0.0, lo_open=lo_open,
                  hi=WEB_SPEED_MAX, unit="m/s")


def operating_point(scene: Scene, radius: float, *, web_speed: float | None = None
                    ) -> tuple[WinderSystem, float, np.ndarray]:
    """``(system, t, y)`` of the quasi-steady operating point at ``radius`` [m]
    (``>= [roll] core_radius``) and ``web_speed`` [m/s] (``>= 0``; default the scene's).

    Raises
    ------
    ArgumentError: a radius or web speed out of range, a scene without a winding operating
        point (no nip, no weight, no friction, a torque drive), or a radius and speed at
        which the nip cannot carry the roll's torque or weight.
    """
    where = "operating_point"
    steady = _steady_scene(scene, where)
    v = _web_speed(where, scene, web_speed, lo_open=False)
    rc = scene.roll.core_radius
    r = number(where, "radius", radius, lo=rc, unit="m",
               valid=f"a finite radius >= [roll] core_radius = {rc:g} m")
    sc = steady.replace(drum={"drive": {"web_acceleration": 0.0, "web_speed": v}})
    system = WinderSystem(sc)
    law, contact = system.law, system.contact
    assert contact is not None
    g = system.g
    m, J = law.mass(r), law.polar_inertia(r)
    w = v / r
    ft = 0.0
    fn = m * g
    for _ in range(4):  # slip ↔ friction ↔ roll speed
        rdot = system.h_over_2pi * w
        mrate = law.mass_derivative(r) * rdot
        tweb = mrate * v if sc.effects.web_momentum else 0.0
        jrate = law.polar_inertia_derivative(r) * rdot if sc.effects.variable_mass else 0.0
        wdot = -v * rdot / r**2
        ft = (J * wdot + jrate * w) / r - tweb
        ratio = ft / (contact.mu * fn)
        if abs(ratio) >= 1.0:
            raise ArgumentError(f"{where}: at radius = {r:g} m and web_speed = {v:g} m/s the "
                                f"nip cannot carry the roll's torque (|F_t| = {abs(ft):.3g} "
                                f"N > μ F_n = {contact.mu * fn:.3g} N): no operating point; "
                                "valid: a lower web speed or a smaller radius")
        vs = contact.v_ref * math.atanh(ratio)
        w = (v - vs) / r
    rdot = system.h_over_2pi * w
    z = contact.initial_height(m, r, rdot, g)
    if not z > system.drum_radius:
        raise ArgumentError(f"{where}: at radius = {r:g} m the roll's weight {fn:.4g} N "
                            f"compresses the nip by more than the radius (the roll axis "
                            f"would lie inside the drum); valid: a smaller radius or a "
                            f"stiffer nip ([contact] stiffness)")
    y = np.zeros(system.n_states)
    y[:5] = (z, 0.0, 0.0, w, r)
    if sc.effects.slip_relaxation:
        y[5] = ft
    return system, 1.0, y


def modes_at(scene: Scene, radius: float, *, web_speed: float | None = None) -> list[Mode]:
    """Modes of the linearised winder at ``radius`` [m] and ``web_speed`` [m/s] (see
    :func:`operating_point` for the valid range), bounce first."""
    system, t, y = operating_point(scene, radius, web_speed=web_speed)
    A = jacobian(system, t, y)
    fast = [0, 2, 3] + ([5] if system.n_states > 5 else [])
    lam, vec = np.linalg.eig(A[np.ix_(fast, fast)])
    out, used = [], set()
    order = np.argsort(-np.abs(vec[0]) / np.linalg.norm(vec, axis=0))  # z-dominated first
    for i in order:
        if i in used:
            continue
        used.add(i)
        if abs(lam[i].imag) > 0:  # take one of the conjugate pair
            j = int(np.argmin(np.abs(lam - np.conj(lam[i])) + (np.arange(len(lam)) == i)))
            used.add(j)
        out.append(Mode(complex(lam[i]), "bounce" if not out else "slip"))
    return out


@dataclass(frozen=True)
class ModeMap:
    """Modes against radius. Arrays over ``radius`` [m]; frequencies [Hz]; speeds [m/s]."""

    radius: np.ndarray
    bounce_frequency: np.ndarray
    bounce_damping: np.ndarray
    slip_frequency: np.ndarray
    slip_damping: np.ndarray
    rotation_1x: np.ndarray
    rotation_2x: np.ndarray
    critical_web_speed: np.ndarray
    web_speed: float

    def critical_radii(self, order: int = 1) -> list[float]:
        """Radii where ``order × f₁`` crosses the bounce frequency (linear interpolation)."""
        d = self.bounce_frequency - order * self.rotation_1x
        out = []
        for i in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]:
            s = d[i] / (d[i] - d[i + 1])
            out.append(float(self.radius[i] + s * (self.radius[i + 1] - self.radius[i])))
        return out

    def as_columns(self) -> dict[str, np.ndarray]:
        return {"radius": self.radius, "bounce_frequency": self.bounce_frequency,
                "bounce_damping": self.bounce_damping, "slip_frequency": self.slip_frequency,
                "slip_damping": self.slip_damping, "rotation_1x": self.rotation_1x,
                "rotation_2x": self.rotation_2x, "critical_web_speed": self.critical_web_speed}


def mode_map(scene: Scene, radii: np.ndarray | None = None, *,
             web_speed: float | None = None, n: int = 200) -> ModeMap:
    """The resonance map over ``radii`` [m] (each ``>= [roll] core_radius``; default: ``n``
    points, 2 … 10 000, from the initial radius to the radius at the end of the scene's run)
    at ``web_speed`` [m/s] (``> 0``; default the scene's).

    Raises
    ------
    ArgumentError: ``n``, ``radii`` or ``web_speed`` out of range, or a scene without a
        winding operating point (see :func:`operating_point`).
    """
    where = "mode_map"
    _steady_scene(scene, where)
    v = _web_speed(where, scene, web_speed, lo_open=True)
    rc = scene.roll.core_radius
    if radii is None:
        n = integer(where, "n", n, lo=2, hi=MAX_POINTS)
        r0 = scene.roll.initial_radius
        # r² − r_c² = h v t/π at no slip
        r_end = math.sqrt(r0**2 + scene.paper.caliper * v * scene.scene.duration / math.pi)
        radii = np.linspace(r0, r_end, n)
    try:
        radii = np.asarray(radii, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentTypeError(f"{where}: radii must be an array of radii [m], got "
                                f"{show(radii)} ({type(radii).__name__})") from None
    if radii.ndim != 1 or not 1 <= len(radii) <= MAX_POINTS:
        raise ArgumentError(f"{where}: radii must be a 1-D array of 1 … {MAX_POINTS} radii, "
                            f"got shape {radii.shape}")
    bad = ~(np.isfinite(radii) & (radii >= rc))
    if bad.any():
        i = int(np.argmax(bad))
        raise ArgumentError(f"{where}: radii[{i}] = {float(radii[i])!r} is out of range; "
                            f"valid: finite radii >= [roll] core_radius = {rc:g} m")
    cols = np.full((4, len(radii)), np.nan)
    for i, r in enumerate(radii):
        ms = modes_at(scene, float(r), web_speed=v)
        cols[0, i], cols[1, i] = ms[0].frequency, ms[0].damping_ratio
        if len(ms) > 1:
            cols[2, i], cols[3, i] = ms[1].natural_frequency, ms[1].damping_ratio
    f1 = v / (2 * math.pi * radii)
    return ModeMap(radii, cols[0], cols[1], cols[2], cols[3], f1, 2 * f1,
                   2 * math.pi * radii * cols[0], v)
