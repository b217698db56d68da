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

from ._errors import SimulationError
from ._linearise import jacobian
from ._scene import Scene
from ._system import WinderSystem

__all__ = ["Mode", "ModeMap", "operating_point", "modes_at", "mode_map"]


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


def _steady_scene(scene: Scene) -> Scene:
    if not scene.effects.contact:
        raise SimulationError(f"{scene.source}: the resonance map needs the nip: [effects] "
                              "contact = true")
    if scene.drum.drive.kind != "speed_profile":
        raise SimulationError(f"{scene.source}: the resonance map needs [drum.drive] kind = "
                              "'speed_profile' (its web speed is the operating speed)")
    return scene.replace(effects={"imbalance": False})


def operating_point(scene: Scene, radius: float, *, web_speed: float | None = None
                    ) -> tuple[WinderSystem, float, np.ndarray]:
    """``(system, t, y)`` of the quasi-steady operating point at ``radius`` [m]."""
    v = scene.drum.drive.web_speed if web_speed is None else float(web_speed)
    sc = _steady_scene(scene).replace(drum={"drive": {"web_acceleration": 0.0,
                                                      "web_speed": v}})
    system = WinderSystem(sc)
    law, contact = system.law, system.contact
    assert contact is not None
    r = float(radius)
    g = system.g
    m, J = law.mass(r), law.polar_inertia(r)
    w = v / r
    ft = 0.0
    for _ in range(4):  # slip ↔ friction ↔ roll speed
        rdot = system.h_over_2pi * w
        fn = m * g
        mrate = law.mass_derivative(r) * rdot
        tweb = mrate * v if sc.effects.web_momentum else 0.0
        jrate = law.polar_inertia_derivative(r) * rdot if sc.effects.variable_mass else 0.0
        wdot = -v * rdot / r**2
        ft = (J * wdot + jrate * w) / r - tweb
        ratio = ft / (contact.mu * fn) if fn > 0 else 0.0
        if abs(ratio) >= 1.0:
            raise SimulationError(f"at r = {r:g} m the nip cannot carry the roll's torque "
                                  f"(|F_t| = {abs(ft):.3g} N > μ F_n = {contact.mu * fn:.3g} N)")
        vs = contact.v_ref * math.atanh(ratio)
        w = (v - vs) / r
    rdot = system.h_over_2pi * w
    z = contact.initial_height(m, r, rdot, g)
    y = np.zeros(system.n_states)
    y[:5] = (z, 0.0, 0.0, w, r)
    if sc.effects.slip_relaxation:
        y[5] = ft
    return system, 1.0, y


def modes_at(scene: Scene, radius: float, *, web_speed: float | None = None) -> list[Mode]:
    """Modes of the linearised winder at ``radius`` [m], bounce first."""
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
    """The resonance map over ``radii`` (default: core to the radius at the end of the
    scene's run, ``n`` points)."""
    v = scene.drum.drive.web_speed if web_speed is None else float(web_speed)
    if radii is None:
        rc = scene.roll.initial_radius
        # r² − r_c² = h v t/π at no slip
        r_end = math.sqrt(rc**2 + scene.paper.caliper * v * scene.scene.duration / math.pi)
        radii = np.linspace(rc, r_end, n)
    radii = np.asarray(radii, dtype=float)
    cols = np.full((4, len(radii)), np.nan)
    for i, r in enumerate(radii):
        ms = modes_at(scene, float(r), web_speed=v)
        cols[0, i], cols[1, i] = ms[0].frequency, ms[0].damping_ratio
        if len(ms) > 1:
            cols[2, i], cols[3, i] = ms[1].natural_frequency, ms[1].damping_ratio
    f1 = v / (2 * math.pi * radii)
    return ModeMap(radii, cols[0], cols[1], cols[2], cols[3], f1, 2 * f1,
                   2 * math.pi * radii * cols[0], v)
