"""Compiled backend: the winder's planar equations of motion (spec §3–§5) in numba.

The Pinocchio backend (:class:`~winder.WinderSystem`) evaluates the scene through ABA with
the variable-mass terms; for the winder's three joints the same dynamics reduce to the
2×2 system of spec §3 plus the drum balance of spec §5. This module is that reduction,
compiled. The tests check it against the Pinocchio backend state by state (to round-off)
and run by run; the Pinocchio backend stays the reference and serves any other model.

Scenes are packed into a parameter vector (:func:`pack`); effects that are off are flags
that skip their terms. The nip can be evaluated in a *locked mode* (see :data:`AUTO`):
the integrator of :mod:`winder._integrators` keeps contact or no-contact fixed within a
step and switches exactly at the located event, so the discontinuity of the damped
normal force at touch-down never sits inside a step. The radius floor of spec §2 (a roll
turning backwards unwinds down to its core and no further) is a second locked mode
(:data:`WINDING` or :data:`AT_CORE`, see :func:`core_mode_of`), switched the same way.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ._drive import SpeedProfile
from ._jit import njit
from ._scene import Scene

if TYPE_CHECKING:
    from ._system import WinderSystem

__all__ = ["pack", "evaluate", "switch", "mode_of", "core_mode_of", "N_AUX", "AUX_NAMES",
           "AUTO", "FREE", "IN_CONTACT", "CORE_AUTO", "WINDING", "AT_CORE", "PlanarSystem",
           "channels_into"]

# parameter slots of the packed scene
(P_R, P_JD, P_AW, P_VW, P_TRAMP, P_RC, P_MCORE, P_JCORE, P_RPL, P_H2PI, P_E, P_G, P_LAW,
 P_K, P_C, P_PEXP, P_ALPHA, P_MU, P_VREF, P_SIGMA, P_VMIN, P_VM, P_WEB, P_CONTACT,
 P_RELAX, P_FREE, P_TAU, P_IFT, N_PARAMS) = range(29)

#: Contact modes: ``AUTO`` applies the law with its clamp ``F_n = max(0, ·)`` (what the
#: Pinocchio backend does); ``FREE`` forces ``F_n = 0``; ``IN_CONTACT`` applies the
#: unclamped law, smoothly extended (``δ|δ|^(p-1)``), valid while :func:`switch` > 0.
AUTO, FREE, IN_CONTACT = -1, 0, 1

#: Core modes (spec §2): ``WINDING`` winds and unwinds, ``ṙ = h ω/2π``; ``AT_CORE`` holds
#: the radius at the core, ``ṙ = 0`` (no paper left to unwind while ``ω < 0``);
#: ``CORE_AUTO`` picks by the state: ``ṙ = 0`` where ``r <= r_c`` and ``ω < 0``.
CORE_AUTO, WINDING, AT_CORE = -1, 0, 1

#: Auxiliary outputs of :func:`evaluate`, in order.
AUX_NAMES = ("theta", "drum_speed", "drum_accel", "mass", "inertia", "mass_rate",
             "inertia_rate", "normal_force", "friction_force", "slip_velocity", "web_force",
             "penetration", "z_accel", "roll_accel", "drum_torque", "steady_friction")
N_AUX = len(AUX_NAMES)


def pack(scene: Scene, *, drum_torque: float | None = None) -> np.ndarray:
    """The scene as the parameter vector of the compiled functions; ``drum_torque`` [N·m]
    overrides the input torque of a free drum (default ``[drum.drive] torque``)."""
    fx, d, ro, pa, co, fr = (scene.effects, scene.drum, scene.roll, scene.paper,
                             scene.contact, scene.friction)
    p = np.zeros(N_PARAMS)
    p[P_R], p[P_JD] = d.radius, d.inertia
    free = d.drive.kind == "torque"
    p[P_AW], p[P_VW] = d.drive.web_acceleration, d.drive.web_speed
    p[P_TRAMP] = (d.drive.web_speed / d.drive.web_acceleration
                  if d.drive.web_acceleration > 0 and not free else 0.0)
    p[P_RC], p[P_MCORE], p[P_JCORE] = ro.core_radius, ro.core_mass, ro.core_inertia
    p[P_RPL] = pa.density * math.pi * ro.width
    p[P_H2PI] = pa.caliper / (2.0 * math.pi)
    p[P_E] = ro.com_offset if fx.imbalance else 0.0
    p[P_G] = scene.scene.gravity if fx.gravity else 0.0
    p[P_LAW] = 0.0 if co.law == "linear" else 1.0
    p[P_K], p[P_C], p[P_PEXP], p[P_ALPHA] = co.stiffness, co.damping, co.exponent, co.hc_damping
    p[P_MU], p[P_VREF] = fr.mu, fr.slip_velocity
    p[P_SIGMA], p[P_VMIN] = fr.relaxation_length, fr.min_speed
    p[P_VM], p[P_WEB] = float(fx.variable_mass), float(fx.web_momentum)
    p[P_CONTACT], p[P_RELAX] = float(fx.contact), float(fx.slip_relaxation)
    p[P_FREE] = float(free)
    p[P_TAU] = (d.drive.torque if drum_torque is None else drum_torque) if free else 0.0
    n = 5 + (2 if free else 0)
    p[P_IFT] = float(n) if fx.slip_relaxation else -1.0
    return p


@njit
def _force_unclamped(p: np.ndarray, delta: float, ddot: float) -> float:
    """Contact law without the ``max(0, ·)`` clamp, smoothly extended to ``δ < 0``."""
    if p[P_LAW] == 0.0:
        return p[P_K] * delta + p[P_C] * ddot
    ad = abs(delta)
    pw = delta * ad ** (p[P_PEXP] - 1.0) if ad > 0.0 else 0.0
    return p[P_K] * pw * (1.0 + p[P_ALPHA] * ddot)


@njit
def switch(t: float, y: np.ndarray, p: np.ndarray) -> float:
    """Contact switching function [m]: ``min(δ, F_unclamped/k)``; > 0 exactly where the
    clamped law gives ``F_n > 0``. Its zeros are lift-off and touch-down."""
    r = y[4]
    delta = p[P_R] + r - y[0]
    ddot = p[P_H2PI] * y[3] - y[2]
    f = _force_unclamped(p, delta, ddot) / p[P_K]
    return delta if delta < f else f


@njit
def mode_of(t: float, y: np.ndarray, p: np.ndarray) -> int:
    """The contact mode a step starting at ``y`` runs in (``FREE`` without contact)."""
    if p[P_CONTACT] == 0.0:
        return FREE
    return IN_CONTACT if switch(t, y, p) > 0.0 else FREE


@njit
def core_mode_of(y: np.ndarray, p: np.ndarray) -> int:
    """The core mode a step starting at ``y`` runs in: ``AT_CORE`` where ``r <= r_c`` and
    ``ω <= 0``, else ``WINDING``."""
    return AT_CORE if y[4] <= p[P_RC] and y[3] <= 0.0 else WINDING


@njit
def evaluate(t: float, y: np.ndarray, p: np.ndarray, mode: int, dy: np.ndarray,
             aux: np.ndarray, core: int = CORE_AUTO) -> None:
    """``dy/dt`` of the state ``(z, φ, ż, ω, r, [θ_d, Ω], [F_t])`` into ``dy`` and the
    quantities of :data:`AUX_NAMES` into ``aux``; ``mode`` is the contact mode, ``core``
    the core mode."""
    z, phi, zd, w, r = y[0], y[1], y[2], y[3], y[4]
    R = p[P_R]
    # drive (spec §5)
    if p[P_FREE] != 0.0:
        theta, Om = y[5], y[6]
        Omd = 0.0  # set below from the torque balance
    else:
        a, tr = p[P_AW], p[P_TRAMP]
        if t < tr:
            theta, Om, Omd = 0.5 * a * t * t / R, a * t / R, a / R
        else:
            theta = 0.5 * a * tr * tr / R + p[P_VW] * (t - tr) / R
            Om, Omd = p[P_VW] / R, 0.0
    # mass properties (spec §2)
    rpl = p[P_RPL]
    rc = p[P_RC]
    if core == AT_CORE or (core == CORE_AUTO and r <= rc and w < 0.0):
        rdot = 0.0  # at the core: nothing left to unwind (spec §2)
    else:
        rdot = p[P_H2PI] * w
    m = p[P_MCORE] + rpl * (r * r - rc * rc)
    J = p[P_JCORE] + 0.5 * rpl * (r ** 4 - rc ** 4)
    mrate = 2.0 * rpl * r * rdot
    Jrate = mrate * r * r
    if p[P_VM] != 0.0:
        md, Jd = mrate, Jrate
    else:
        md, Jd = 0.0, 0.0
    # nip (spec §4)
    vs = Om * R - w * r
    fn = 0.0
    fss = 0.0
    delta = 0.0
    if p[P_CONTACT] != 0.0:
        delta = R + r - z
        ddot = rdot - zd
        if mode == IN_CONTACT:
            fn = _force_unclamped(p, delta, ddot)
        elif mode == AUTO and delta > 0.0:
            fn = _force_unclamped(p, delta, ddot)
            if fn < 0.0:
                fn = 0.0
        fss = p[P_MU] * fn * math.tanh(vs / p[P_VREF])
    ift = int(p[P_IFT])
    if ift >= 0:  # slip relaxation: F_t is a state
        ft = y[ift]
        dy[ift] = (abs(Om * R) + p[P_VMIN]) / p[P_SIGMA] * (fss - ft)
    else:
        ft = fss
    # web momentum (spec §3)
    tweb = 0.0
    if p[P_WEB] != 0.0:
        u = Om * R if p[P_CONTACT] != 0.0 else w * r
        tweb = mrate * u
    # M q̈ = Q − (∂M/∂r ṙ) q̇ − C − G  (spec §3)
    e, g = p[P_E], p[P_G]
    s, c = math.sin(phi), math.cos(phi)
    mec = m * e * c
    b0 = fn - (md * zd + md * e * c * w) + m * e * s * w * w - m * g
    b1 = r * (ft + tweb) - (md * e * c * zd + Jd * w) - m * g * e * c
    det = m * J - mec * mec
    zdd = (J * b0 - mec * b1) / det
    phdd = (m * b1 - mec * b0) / det
    if p[P_FREE] != 0.0:
        Omd = (p[P_TAU] - R * ft) / p[P_JD]
        dy[5] = Om
        dy[6] = Omd
        tau = p[P_TAU]
    else:
        tau = p[P_JD] * Omd + R * ft
    dy[0], dy[1], dy[2], dy[3], dy[4] = zd, w, zdd, phdd, rdot
    aux[0], aux[1], aux[2], aux[3], aux[4] = theta, Om, Omd, m, J
    aux[5], aux[6], aux[7], aux[8], aux[9] = mrate, Jrate, fn, ft, vs
    aux[10], aux[11], aux[12], aux[13], aux[14] = tweb, delta, zdd, phdd, tau
    aux[15] = fss


@njit
def channels_into(t: np.ndarray, Y: np.ndarray, p: np.ndarray, out: np.ndarray) -> None:
    """:data:`AUX_NAMES` at each column of ``Y`` into ``out`` (shape ``(N_AUX, len(t))``),
    clamped law (mode ``AUTO``), core mode by the state (``CORE_AUTO``)."""
    n = Y.shape[0]
    dy = np.empty(n)
    aux = np.empty(N_AUX)
    y = np.empty(n)
    for i in range(t.shape[0]):
        for j in range(n):
            y[j] = Y[j, i]
        evaluate(t[i], y, p, AUTO, dy, aux)
        for j in range(N_AUX):
            out[j, i] = aux[j]


class PlanarSystem:
    """The compiled backend with the interface of :class:`~winder.WinderSystem` used by
    :func:`~winder.simulate`: ``rhs``, ``nfev``, ``channels``, ``params``.

    Parameters
    ----------
    scene: the scene; system: its Pinocchio system (state layout, initial state, errors).
    """

    def __init__(self, scene: Scene, system: WinderSystem) -> None:
        self.scene, self.system = scene, system
        self.params = pack(scene)
        self.n_states = system.n_states
        self.nfev = 0
        #: core mode of :meth:`rhs` (:data:`CORE_AUTO`, :data:`WINDING` or :data:`AT_CORE`);
        #: :func:`~winder.simulate` locks it between core events.
        self.core = CORE_AUTO
        self._aux = np.empty(N_AUX)

    def set_drum_torque(self, torque: float) -> None:
        """Input torque of a free drum [N·m] (see :meth:`WinderSystem.set_drum_torque`)."""
        self.system.set_drum_torque(torque)
        self.params[P_TAU] = torque

    def set_core_mode(self, core: int) -> None:
        """Lock the core mode of :meth:`rhs` (see :meth:`WinderSystem.set_core_mode`)."""
        self.system.set_core_mode(core)
        self.core = core

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """``dy/dt`` with the clamped nip law (for scipy's integrators)."""
        self.nfev += 1
        dy = np.empty(self.n_states)
        evaluate(t, y, self.params, AUTO, dy, self._aux, self.core)
        if not math.isfinite(dy[2] + dy[3]):
            raise self.system.blowup_error(t, y, dy)
        return dy

    def channels(self, t: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
        """The result channels of :meth:`WinderSystem.channels`, compiled."""
        t = np.ascontiguousarray(t, dtype=float)
        aux = np.empty((N_AUX, len(t)))
        channels_into(t, np.ascontiguousarray(Y, dtype=float), self.params, aux)
        a = dict(zip(AUX_NAMES, aux, strict=True))
        drive = self.system.drive
        if isinstance(drive, SpeedProfile):
            web = drive.web_speed(t)
        else:
            web = a["drum_speed"] * self.scene.drum.radius
        return {"t": t.copy(), "drum_speed": a["drum_speed"], "drum_torque": a["drum_torque"],
                "roll_speed": Y[3].copy(), "roll_accel": a["roll_accel"],
                "roll_angle": Y[1].copy(), "radius": Y[4].copy(), "mass": a["mass"],
                "inertia": a["inertia"], "mass_rate": a["mass_rate"],
                "inertia_rate": a["inertia_rate"], "z": Y[0].copy(), "z_dot": Y[2].copy(),
                "normal_force": a["normal_force"], "friction_force": a["friction_force"],
                "slip_velocity": a["slip_velocity"], "drum_angle": a["theta"],
                "web_speed": web, "z_accel": a["z_accel"], "web_force": a["web_force"],
                "penetration": a["penetration"]}
