"""The winder as one ODE system: Pinocchio model + drive + the scene's effects.

State vector ``y = (z, φ, ż, ω, r, [drive states], [effect states])``; the drum of a
speed profile is prescribed and carries no state.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from ._drive import SpeedProfile, TorqueDrive, make_drive
from ._errors import ArgumentError, SimulationError, state_text
from ._model import DRUM, ROLL, ROLL_Z, WinderModel
from ._planar import AT_CORE, CORE_AUTO, WINDING
from ._scene import Scene
from ._variable_mass import VariableMassModel
from .effects import EFFECTS, Context, Effect
from .effects.contact import Contact

__all__ = ["WinderSystem", "CHANNELS", "BASE_STATES"]

BASE_STATES = ("z", "roll_angle", "z_dot", "roll_speed", "radius")

#: Result channels of spec §8, in order (first column ``t``).
CHANNELS = ("t", "drum_speed", "drum_torque", "roll_speed", "roll_accel", "roll_angle",
            "radius", "mass", "inertia", "mass_rate", "inertia_rate", "z", "z_dot",
            "normal_force", "friction_force", "slip_velocity")
#: Extra channels (winder's own): drum angle, web speed, roll vertical acceleration,
#: web momentum force, penetration.
EXTRA_CHANNELS = ("drum_angle", "web_speed", "z_accel", "web_force", "penetration")


class WinderSystem:
    """Right-hand side and outputs of a scene. Build once, evaluate many times.

    Parameters
    ----------
    scene: a validated :class:`~winder.Scene`.
    """

    roll_joint = ROLL

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        wm = WinderModel(scene)
        self.model, self.law = wm.model, wm.law
        self.drum_radius, self.drum_inertia = wm.drum_radius, wm.drum_inertia
        self.vm = VariableMassModel(self.model)
        self.data = self.vm.data
        self.drive = make_drive(scene)
        self.g = 0.0
        self.h_over_2pi = scene.paper.caliper / (2.0 * math.pi)
        self.effects: list[Effect] = sorted(
            (EFFECTS[name](scene) for name in scene.effects.enabled()
             if name in EFFECTS),  # web_tension, rider_load: no force here
            key=lambda e: e.order)
        names = list(BASE_STATES) + list(self.drive.states)
        self._drive_index = len(BASE_STATES)
        for eff in self.effects:
            eff.index = len(names)
            names.extend(eff.states)
        self.state_names = tuple(names)
        for eff in self.effects:
            eff.configure(self)
        self._active = [e for e in self.effects if type(e).apply is not Effect.apply]
        self.contact: Contact | None = next(
            (e for e in self.effects if isinstance(e, Contact)), None)
        self._Y = self.model.inertias[ROLL]
        self._fext = pin.StdVec_Force()
        for _ in range(self.model.njoints):
            self._fext.append(pin.Force.Zero())
        self._free_drum = isinstance(self.drive, TorqueDrive)
        self._tau = np.zeros(self.model.nv)
        if isinstance(self.drive, TorqueDrive):
            self._tau[0] = self.drive.torque  # [drum.drive] torque until set_drum_torque
        self.core = CORE_AUTO
        self.r_core = scene.roll.core_radius
        self.ctx = Context()
        self.nfev = 0

    # ---- state ----------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return len(self.state_names)

    def initial_state(self) -> np.ndarray:
        """Spec §6: ``r = initial_radius``, ``ω = initial_speed``, ``φ = 0``, ``F_t = 0``,
        ``ż = 0``, ``z`` at static equilibrium on the contact (``R + r`` without)."""
        roll = self.scene.roll
        r, w = roll.initial_radius, roll.initial_speed
        m = self.law.mass(r)
        if roll.initial_height is not None:
            z = roll.initial_height
        elif self.contact is not None:
            z = self.contact.initial_height(m, r, self.radius_rate(r, w), self.g)
        else:
            z = self.drum_radius + r
        y = np.zeros(self.n_states)
        y[:5] = (z, 0.0, 0.0, w, r)
        y[self._drive_index:self._drive_index + len(self.drive.states)] = \
            self.drive.initial_state()
        ctx = self._fill(0.0, y)
        for eff in self.effects:
            if eff.states:
                y[eff.index:eff.index + len(eff.states)] = eff.initial_state(self, ctx)
        return y

    def set_drum_torque(self, torque: float) -> None:
        """Input torque of a free drum (drive kind ``torque``) [N·m]."""
        if not self._free_drum:
            raise ArgumentError("drum_torque is an input only with [drum.drive] kind = "
                                "'torque'; this scene prescribes the drum speed")
        self._tau[0] = torque

    def radius_rate(self, r: float, omega: float) -> float:
        """``ṙ`` [m/s] of spec §2 in the current core mode: ``h ω/2π``, or 0 at the core."""
        core = self.core
        if core == AT_CORE or (core == CORE_AUTO and r <= self.r_core and omega < 0.0):
            return 0.0  # at the core: nothing left to unwind
        return self.h_over_2pi * omega

    def set_core_mode(self, core: int) -> None:
        """Lock the core mode of spec §2: ``WINDING`` (``ṙ = h ω/2π``), ``AT_CORE``
        (``ṙ = 0``: the roll sits at its core and turns backwards) or ``CORE_AUTO`` (by the
        state: ``ṙ = 0`` where ``r <= r_c`` and ``ω < 0``; the default). The integrators
        lock it between the core events."""
        if core not in (CORE_AUTO, WINDING, AT_CORE):
            raise ArgumentError(f"core mode must be one of {CORE_AUTO}, {WINDING}, {AT_CORE}, "
                                f"got {core!r}")
        self.core = core

    # ---- evaluation -----------------------------------------------------------------
    def _fill(self, t: float, y: np.ndarray) -> Context:
        c = self.ctx
        c.t, c.y = t, y
        c.z, c.phi, c.z_dot, c.omega, c.r = y[0], y[1], y[2], y[3], y[4]
        di = self._drive_index
        c.theta, c.Omega, omd = self.drive.kinematics(t, y[di:di + 2])
        c.Omega_dot = math.nan if omd is None else omd
        law, r = self.law, c.r
        c.r_dot = rdot = self.radius_rate(r, c.omega)
        c.mass, c.inertia, dm_dr, dJ_dr = law.scalars(r)  # unchecked: trial states may dip
        c.mass_rate = dm_dr * rdot
        c.inertia_rate = dJ_dr * rdot
        c.drum_radius = self.drum_radius
        c.slip_velocity = c.Omega * self.drum_radius - c.omega * r
        c.reset_forces()
        return c

    def _forces(self, c: Context) -> None:
        """Nip forces into the joint-frame ``fext`` (roll at its bottom point, reaction on
        the drum at its top point)."""
        s, co = math.sin(c.phi), math.cos(c.phi)
        fx, fz = c.friction_force + c.web_force, c.normal_force
        # roll: world force (fx, 0, fz) at (0, 0, -r) from the roll axis, in the roll frame
        self._fext[ROLL] = pin.Force(np.array([co * fx + s * fz, 0.0, co * fz - s * fx,
                                               0.0, -c.r * fx, 0.0]))
        # drum: reaction -(F_t, 0, F_n) at (0, 0, R), in the drum frame (rotation θ about y)
        st, ct = math.sin(c.theta), math.cos(c.theta)
        ft, R = c.friction_force, self.drum_radius
        self._fext[DRUM] = pin.Force(np.array([-ct * ft + st * fz, 0.0, -st * ft - ct * fz,
                                               0.0, -R * ft, 0.0]))

    def evaluate(self, t: float, y: np.ndarray) -> tuple[Context, np.ndarray, np.ndarray]:
        """One evaluation: context, ``(q, v)`` stacked, accelerations ``a`` (ABA)."""
        c = self._fill(t, y)
        c.dy = np.empty(len(y))
        for eff in self._active:
            eff.apply(c)
        self.law.write_inertia(c.r, self._Y)
        self._forces(c)
        q = np.array((c.theta, c.z, c.phi))
        v = np.array((c.Omega, c.z_dot, c.omega))
        a = self.vm.aba_into(q, v, self._tau, self._fext)
        return c, np.concatenate((q, v)), a

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """``dy/dt`` (for :func:`scipy.integrate.solve_ivp`)."""
        self.nfev += 1
        c, _, a = self.evaluate(t, y)
        dy = c.dy
        dy[0], dy[1], dy[2], dy[3], dy[4] = c.z_dot, c.omega, a[ROLL_Z - 1], a[ROLL - 1], c.r_dot
        if self._free_drum:
            dy[5], dy[6] = c.Omega, a[DRUM - 1]
        if not math.isfinite(dy[2] + dy[3]):
            raise self.blowup_error(t, y, dy)
        return dy

    def blowup_error(self, t: float, y: np.ndarray, dy: np.ndarray) -> SimulationError:
        """The error for a non-finite derivative: which states, which effects, the state."""
        bad = [n for n, v, d in zip(self.state_names, y, dy, strict=False)
               if not (math.isfinite(v) and math.isfinite(d))]
        effects = ", ".join(e.name for e in self.effects) or "none"
        state = dict(zip(self.state_names, map(float, y), strict=True))
        return SimulationError(
            f"non-finite state or derivative at t = {t:.6g} s in {bad or 'accelerations'} "
            f"(active effects: {effects}); the state was "
            + state_text(state)
            + ". Try a stiff method (method='Radau' or 'BDF') or a tighter rtol.",
            time=t, state=state)

    # ---- outputs --------------------------------------------------------------------
    def channels(self, t: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
        """All result channels (spec §8 plus :data:`EXTRA_CHANNELS`) at times ``t`` for
        states ``Y`` (shape ``(n_states, len(t))``)."""
        names = CHANNELS + EXTRA_CHANNELS
        out = {name: np.empty(len(t)) for name in names}
        out["t"][:] = t
        drive = self.drive
        for i, ti in enumerate(t):
            y = Y[:, i]
            c, qv, a = self.evaluate(float(ti), y)
            omd = a[DRUM - 1] if self._free_drum else c.Omega_dot
            acc = np.array((omd, a[ROLL_Z - 1], a[ROLL - 1]))
            self._forces(c)  # aba_into added −Ẏv in place: rebuild before RNEA adds it
            tau = self.vm.rnea_into(qv[:3], qv[3:], acc, self._fext)
            row = (c.Omega, tau[DRUM - 1], c.omega, a[ROLL - 1], c.phi, c.r, c.mass, c.inertia,
                   c.mass_rate, c.inertia_rate, c.z, c.z_dot, c.normal_force,
                   c.friction_force, c.slip_velocity, c.theta,
                   float(drive.web_speed(ti)) if isinstance(drive, SpeedProfile)
                   else c.Omega * self.drum_radius,
                   a[ROLL_Z - 1], c.web_force, c.penetration)
            for name, value in zip(names[1:], row, strict=True):
                out[name][i] = value
        return out
