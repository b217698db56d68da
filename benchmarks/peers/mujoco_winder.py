"""The single-drum winder in MuJoCo: MJCF written from a scene, stepped from Python.

This is how a MuJoCo user would build the winder of ``shared/spec/winder-model.md``
today. MuJoCo integrates the joints; everything MuJoCo has no model for is computed in
Python between steps and applied through ``qfrc_applied``:

- the roll's mass and inertia, overwritten every step from the radius ``r`` (spec §2);
- the nip (spec §4): the normal force and the relaxed slip force, exactly the winder's
  laws (MuJoCo's own contact is a different law; it is switched off, so that a comparison
  measures the mass terms and not two contact models);
- the radius ``r`` and the slip force ``F_t``, two states MuJoCo does not know.

Two *ways* differ only in the variable-mass terms:

- ``"overwrite"`` (way a): the overwrite alone, ``M(r) q̈ = Q − C − G``. It is the zero
  relative velocity convention: the added paper silently arrives with the roll's own
  velocity. The web-momentum force is therefore *not* added: on top of the overwrite it
  would count the arriving paper's momentum twice.
- ``"corrected"`` (way b): the overwrite plus the term MuJoCo lacks, ``−(∂M/∂r·ṙ) q̇``
  (spec §3), and the web-momentum force ``ṁ u`` when the scene has it: the winder's
  equations.

Three things a fair build must get right (each is checked in ``tests/test_peers.py``):

- *Simple bodies ignore a mass overwrite*: MuJoCo's compiler marks bodies whose frame is
  their inertia frame as "simple" and reuses their compile-time mass in the factorisation
  of ``M``. The roll is declared non-simple after compilation (``body_simple``,
  ``dof_simplenum``), which keeps ``qpos``; ``mj_setConst`` would work too but resets
  ``qpos`` to the reference pose and costs a full constant recomputation per step.
- The web momentum must not be added on top of the bare overwrite (see above).
- ``qfrc_applied`` and the overwritten mass are held over a step: RK4's four stages all
  see the start-of-step forces, so every MuJoCo integrator here is first order.

The radius follows the roll angle exactly, ``r = r₀ + h (φ − φ₀)/2π`` (one caliper per
revolution), floored at the core (spec §2); ``F_t`` relaxes exactly for a held target
(``F_t ← F_ss + (F_t − F_ss) e^{−λ Δt}``), which is stable at any step.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import mujoco
import numpy as np

import winder

__all__ = ["WAYS", "INTEGRATORS", "CLOCK", "MujocoWinder", "MujocoRun", "mjcf",
           "mass_properties", "initial_state"]

#: The clock of every timing in the study: this process's CPU time [s]. For this
#: single-threaded work it equals the wall time on an idle core, and unlike the wall time
#: it is not inflated by other processes on a shared machine.
CLOCK = time.process_time

#: MuJoCo ways: bare overwrite (a); overwrite plus ``−(∂M/∂r·ṙ) q̇`` and the web flux (b);
#: the web flux on top of the bare overwrite (the double count).
WAYS = ("overwrite", "corrected", "overwrite+flux")
#: MuJoCo integrators compared (``mjOption.integrator``).
INTEGRATORS = {"Euler": mujoco.mjtIntegrator.mjINT_EULER,
               "RK4": mujoco.mjtIntegrator.mjINT_RK4,
               "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST}
#: Result channels the MuJoCo runs report (names as in ``winder.Result``).
CHANNELS = ("roll_speed", "radius", "z", "z_dot", "roll_angle", "normal_force",
            "friction_force", "drum_torque", "drum_speed", "mass", "inertia")


def mass_properties(scene: winder.Scene, r: float) -> tuple[float, float, float]:
    """Spec §2: roll mass ``m`` [kg], polar inertia about the roll axis ``J`` [kg·m²] and
    transverse inertia about the centre of mass [kg·m²] at radius ``r`` [m]."""
    ro, rpl = scene.roll, scene.paper.density * math.pi * scene.roll.width
    rc, L = ro.core_radius, ro.width
    mp = rpl * (r * r - rc * rc)
    m = ro.core_mass + mp
    J = ro.core_inertia + 0.5 * rpl * (r ** 4 - rc ** 4)
    # core: half its polar inertia plus the rod term; paper: hollow cylinder (spec §2)
    trans = (0.5 * ro.core_inertia + ro.core_mass * L * L / 12.0
             + mp * (3.0 * (r * r + rc * rc) + L * L) / 12.0)
    return m, J, trans


def _com_offset(scene: winder.Scene) -> float:
    return scene.roll.com_offset if scene.effects.imbalance else 0.0


def _gravity(scene: winder.Scene) -> float:
    return scene.scene.gravity if scene.effects.gravity else 0.0


def initial_state(scene: winder.Scene) -> tuple[float, float, float, float, float]:
    """Spec §6: ``(z [m], φ [rad], ż [m/s], ω [rad/s], r [m])``; ``z`` at static equilibrium
    on the nip (``F_n = m g``), or ``R + r`` without contact."""
    r = scene.roll.initial_radius
    z = scene.drum.radius + r
    if scene.effects.contact:
        m = mass_properties(scene, r)[0]
        w = m * _gravity(scene) / scene.contact.stiffness
        delta = w if scene.contact.law == "linear" else w ** (1.0 / scene.contact.exponent)
        z -= delta
    return z, 0.0, 0.0, scene.roll.initial_speed, r


def mjcf(scene: winder.Scene) -> str:
    """MJCF of the scene: a drum hinged about ``+y`` at the origin and a roll on a slide
    along ``z`` with a hinge about ``−y`` (spec §1), its centre of mass at ``+x`` by
    ``com_offset``. MuJoCo's contact is disabled; geoms are for looks only."""
    d, ro = scene.drum, scene.roll
    m, J, trans = mass_properties(scene, ro.initial_radius)
    e = _com_offset(scene)
    L = ro.width
    jd_t = 0.5 * d.inertia + d.mass * L * L / 12.0
    return f"""<mujoco model="winder {scene.name}">
  <option timestep="0.001" gravity="0 0 {-_gravity(scene)!r}">
    <flag contact="disable"/>
  </option>
  <worldbody>
    <body name="drum">
      <joint name="drum" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 0" mass="{d.mass!r}" diaginertia="{jd_t!r} {d.inertia!r} {jd_t!r}"/>
      <geom type="cylinder" size="{d.radius!r} {L / 2!r}" euler="90 0 0" contype="0"
            conaffinity="0"/>
    </body>
    <body name="roll">
      <joint name="z" type="slide" axis="0 0 1"/>
      <joint name="phi" type="hinge" axis="0 -1 0"/>
      <inertial pos="{e!r} 0 0" mass="{m!r}"
                diaginertia="{trans!r} {J - m * e * e!r} {trans!r}"/>
      <geom type="cylinder" size="{ro.core_radius!r} {L / 2!r}" euler="90 0 0" contype="0"
            conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""


@dataclass
class MujocoRun:
    """Channels of one MuJoCo run on the output grid ``t`` [s], and its cost."""

    t: np.ndarray
    channels: dict[str, np.ndarray]
    cpu: float                      # [s] stepping loop, outputs included (CLOCK)
    steps: int
    way: str
    integrator: str
    dt: float                       # [s] MuJoCo time step
    first_lift_off: float = math.nan  # [s] start of the first step with F_n = 0 (contact)
    bad_qacc: int = 0                 # MuJoCo's non-finite-acceleration resets (blow-ups)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.channels[name]

    @property
    def us_per_step(self) -> float:
        """CPU time per step [µs]."""
        return 1e6 * self.cpu / self.steps


class MujocoWinder:
    """The winder scene as a MuJoCo model plus the Python side that MuJoCo lacks.

    ``way`` is one of :data:`WAYS`: ``"overwrite"`` (a), ``"corrected"`` (b), or
    ``"overwrite+flux"`` (the double count: the web-momentum force added on top of the bare
    overwrite; kept to show that pitfall). Only ``speed_profile`` drives are built: the
    drum speed is prescribed by applying ``J_d Ω̇`` to its hinge, and the drum torque is
    reported as ``J_d Ω̇ + R F_t`` (spec §5).
    """

    def __init__(self, scene: winder.Scene, way: str = "corrected") -> None:
        if way not in WAYS:
            raise ValueError(f"way must be one of {', '.join(WAYS)}, got {way!r}")
        if scene.drum.drive.kind != "speed_profile":
            raise ValueError(f"only the speed_profile drive is built, got "
                             f"{scene.drum.drive.kind!r}")
        self.scene, self.way = scene, way
        self.model = mujoco.MjModel.from_xml_string(mjcf(scene))
        # Simple bodies keep their compile-time mass in M's factorisation: declare
        # everything non-simple so that the per-step overwrite of the roll takes effect.
        self.model.body_simple[:] = 0
        self.model.dof_simplenum[:] = 0
        self.data = mujoco.MjData(self.model)
        self.roll = self.model.body("roll").id
        self.i_z = int(self.model.joint("z").dofadr[0])
        self.i_phi = int(self.model.joint("phi").dofadr[0])
        self.i_drum = int(self.model.joint("drum").dofadr[0])
        self.nip, self.apply = self._build()

    def _build(self):  # noqa: ANN202  (two closures over the scene's constants)
        """The per-step Python side as two closures (locals are the fastest Python).

        ``nip(z, ż, ω, r, Ω) → (F_n, F_ss, ṙ)``: spec §2 and §4 at a state.
        ``apply(t, r, F_t) → (F_n, F_ss, Ω)``: overwrite the roll's mass and inertia at radius
        ``r`` and write the generalised forces of this way into ``qfrc_applied``, from the
        current ``qpos``/``qvel``."""
        sc, d = self.scene, self.data
        fx, co, fr, ro = sc.effects, sc.contact, sc.friction, sc.roll
        R, Jd = sc.drum.radius, sc.drum.inertia
        aw, vw = sc.drum.drive.web_acceleration, sc.drum.drive.web_speed
        t_ramp = vw / aw if aw > 0 else 0.0
        drum_acc_torque = Jd * aw / R
        rc, mcore, Jcore, L = ro.core_radius, ro.core_mass, ro.core_inertia, ro.width
        rc2, rc4 = rc * rc, rc ** 4
        rpl = sc.paper.density * math.pi * L
        h2pi = sc.paper.caliper / (2.0 * math.pi)
        e = _com_offset(sc)
        ee = e * e
        contact, web, relax = fx.contact, fx.web_momentum, fx.slip_relaxation
        linear = co.law == "linear"
        k, c, pexp, alpha = co.stiffness, co.damping, co.exponent, co.hc_damping
        mu, vref = fr.mu, fr.slip_velocity
        mass_terms = self.way == "corrected"
        flux = web and self.way in ("corrected", "overwrite+flux")
        ct_core = 0.5 * Jcore + mcore * L * L / 12.0
        L2 = L * L
        qpos, qvel, qfrc = d.qpos, d.qvel, d.qfrc_applied
        body_mass = self.model.body_mass
        inert = self.model.body_inertia[self.roll]
        b, iz, ip, idr = self.roll, self.i_z, self.i_phi, self.i_drum
        tanh, cos = math.tanh, math.cos

        def nip(z: float, zd: float, w: float, r: float, Om: float
                ) -> tuple[float, float, float]:
            rdot = 0.0 if (w < 0.0 and r <= rc) else h2pi * w
            if not contact:
                return 0.0, 0.0, rdot
            delta = R + r - z
            fn = 0.0
            if delta > 0.0:
                ddot = rdot - zd
                fn = (k * delta + c * ddot if linear
                      else k * delta ** pexp * (1.0 + alpha * ddot))
                if fn < 0.0:
                    fn = 0.0
            return fn, mu * fn * tanh((Om * R - w * r) / vref), rdot

        def apply(t: float, r: float, ft: float) -> tuple[float, float, float]:
            z, phi, zd, w, Om = qpos[iz], qpos[ip], qvel[iz], qvel[ip], qvel[idr]
            r2 = r * r
            mm = mcore + rpl * (r2 - rc2)
            body_mass[b] = mm
            tr = ct_core + (mm - mcore) * (3.0 * (r2 + rc2) + L2) / 12.0
            inert[0] = tr
            inert[1] = Jcore + 0.5 * rpl * (r2 * r2 - rc4) - mm * ee
            inert[2] = tr
            fn, fss, rdot = nip(z, zd, w, r, Om)
            tq = r * (ft if relax else fss)
            fz = fn
            if flux or mass_terms:
                md = 2.0 * rpl * r * rdot                     # ṁ
                if flux:
                    tq += r * md * (Om * R if contact else w * r)
                if mass_terms:                                # −(∂M/∂r ṙ) q̇
                    mec = md * e * cos(phi)
                    fz -= md * zd + mec * w
                    tq -= mec * zd + md * r2 * w
            qfrc[iz] = fz
            qfrc[ip] = tq
            qfrc[idr] = drum_acc_torque if t < t_ramp else 0.0
            return fn, fss, Om

        return nip, apply

    def reset(self) -> tuple[float, float]:
        """Spec §6's initial state into ``qpos``/``qvel``; returns ``(r [m], F_t [N])``."""
        mujoco.mj_resetData(self.model, self.data)
        z0, phi0, zd0, w0, r0 = initial_state(self.scene)
        d, dr = self.scene.drum, self.scene.drum.drive
        self.data.qpos[self.i_z], self.data.qpos[self.i_phi] = z0, phi0
        self.data.qvel[self.i_z], self.data.qvel[self.i_phi] = zd0, w0
        self.data.qvel[self.i_drum] = 0.0 if dr.web_acceleration > 0 else dr.web_speed / d.radius
        return r0, 0.0

    def run(self, t_end: float, dt: float, output_step: float,
            integrator: str = "Euler") -> MujocoRun:
        """Step from spec §6's initial state to ``t_end`` [s] with MuJoCo time step ``dt``
        [s]; sample the channels every ``output_step`` [s] (a multiple of ``dt``)."""
        sc, m_, d = self.scene, self.model, self.data
        every = round(output_step / dt)
        n_steps = round(t_end / dt)
        if (abs(every * dt - output_step) > 1e-9 * output_step
                or abs(n_steps * dt - t_end) > 1e-9 * t_end or n_steps % every):
            raise ValueError(f"output_step {output_step!r} and t_end {t_end!r} must be "
                             f"multiples of dt {dt!r}")
        m_.opt.timestep = dt
        m_.opt.integrator = INTEGRATORS[integrator]
        r, ft = self.reset()
        R, Jd = sc.drum.radius, sc.drum.inertia
        aw, vw = sc.drum.drive.web_acceleration, sc.drum.drive.web_speed
        t_ramp = vw / aw if aw > 0 else 0.0
        rc = sc.roll.core_radius
        h2pi = sc.paper.caliper / (2.0 * math.pi)
        relax, contact = sc.effects.slip_relaxation, sc.effects.contact
        vmin_s, inv_sigma = sc.friction.min_speed, 1.0 / sc.friction.relaxation_length
        iz, ip, idr = self.i_z, self.i_phi, self.i_drum
        qpos, qvel = d.qpos, d.qvel
        nip, apply, step, exp = self.nip, self.apply, mujoco.mj_step, math.exp
        n_out = n_steps // every + 1
        t_out = np.arange(n_out) * output_step
        out = np.empty((len(CHANNELS), n_out))

        def record(j: int, r: float, ft: float) -> None:
            z, zd, w, Om = qpos[iz], qvel[iz], qvel[ip], qvel[idr]
            fn, fss, _ = nip(z, zd, w, r, Om)
            ftn = ft if relax else fss
            omd = aw / R if t_out[j] < t_ramp else 0.0
            m, J, _ = mass_properties(sc, r)
            out[:, j] = (w, r, z, zd, qpos[ip], fn, ftn, Jd * omd + R * ftn, Om, m, J)

        record(0, r, ft)
        j = 1
        lift = math.nan
        cpu0 = CLOCK()
        for i in range(n_steps):
            phi = qpos[ip]
            fn, fss, Om = apply(i * dt, r, ft)
            if fn <= 0.0 and lift != lift and contact:
                lift = i * dt
            step(m_, d)
            # the two states MuJoCo does not know: radius (one caliper per turn, floored
            # at the core) and the relaxed slip force (exact for the held target)
            r += h2pi * (qpos[ip] - phi)
            if r < rc:
                r = rc
            if relax:
                ft = fss + (ft - fss) * exp(-(abs(Om * R) + vmin_s) * inv_sigma * dt)
            if (i + 1) % every == 0:
                record(j, r, ft)
                j += 1
        cpu = CLOCK() - cpu0
        return MujocoRun(t_out, dict(zip(CHANNELS, out, strict=True)), cpu, n_steps,
                         self.way, integrator, dt, first_lift_off=lift,
                         bad_qacc=int(d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number))

    def bare_step_cost(self, n: int = 20000, integrator: str = "Euler") -> float:
        """CPU time of ``mj_step`` alone on this model [µs per step], no Python side."""
        self.model.opt.integrator = INTEGRATORS[integrator]
        self.reset()
        step, m_, d = mujoco.mj_step, self.model, self.data
        t0 = CLOCK()
        for _ in range(n):
            step(m_, d)
        return 1e6 * (CLOCK() - t0) / n
