"""The quasi-steady operating point of a winding machine and its linear modes, for the
resonance map (:mod:`winder.analysis.modes`).

At each radius of the wound roll (the roll the web enters, ``[web] entry_nip``) the machine
is linearised with its exact Jacobian (:func:`winder.jacobian`) about its quasi-steady
**operating point**:

- every speed-profile drum at its full speed ``ratio · v / R`` (``v`` the web speed);
- every roll and rider turning so that its surface speed stays constant: the rotation
  accelerations are ``ω̇ = −ω ṙ/r`` for a paper roll (its slow deceleration as it grows)
  and ``0`` for a rider; the nip slip and the friction states take the values that carry
  these accelerations against the web forces (slip-relaxation friction at its steady value
  ``F_t = F_ss(v_s)``, ``dF_t/dt = 0``);
- every free translational coordinate (``x``, ``z``) in balance: its acceleration is 0
  with the translational velocities 0 (the nips' damping sees only the radius growth
  ``δ̇ = ṙ``);
- angles 0, the imbalance off (``com_offset = 0``: it is the excitation), the other
  paper rolls at their initial radius; a flexible body (issue #25) turning as a whole in
  its steady twist: its segments' angles are unknowns too, with ``θ̇_i = Ω`` (a driven
  drum's speed) or ``θ̇_i = θ̇_0`` (a free roll or rider, segment 0 its reference).

These unknowns (positions, rotation speeds, friction states) solve ``rhs = target`` by
damped Newton steps on the exact Jacobian from touching positions and no-slip speeds (the
nips held in contact while solving, checked in contact after). The Jacobian restricted to
the fast states (positions and velocities of the free coordinates, rotation speeds,
friction states, a flexible body's segment angles; the other angles and radii are slow or
absent) gives the modes, named by their shapes (:mod:`winder.analysis.mode_labels`): each
free coordinate (a flexible body's: each order of its shape, ``front.bend.z1``,
:mod:`winder.analysis.shapes`) names one **bounce mode** (``set.x``, ``set.z``,
``rider.z``; ``roll.z`` for a single-drum scene), the flexible bodies' twist the torsion
modes (``front.torsion1``), the rest are slip modes. A scene without a winding operating
point (:func:`winding_reason`) has the modes of its initial state
(:meth:`_Linearisation.initial`).
"""

from __future__ import annotations

import math

import numpy as np

from winder._args import number, show
from winder._errors import ArgumentError, ArgumentTypeError
from winder.analysis.line_modes import line_coordinates
from winder.analysis.linearise import jacobian
from winder.analysis.mode_labels import Mode, label_modes
from winder.analysis.shapes import Shapes
from winder.model.locked_modes import AUTO, IN_CONTACT, ModeKind
from winder.parts import BodyElement, body_elements
from winder.parts.drum import DRIVE_KEYS
from winder.scene.load import Scene
from winder.solve.equilibrium import EquilibriumError, nip_key, resting_state
from winder.solve.system import MachineSystem

__all__ = ["Mode", "operating_point", "winding_reason", "WEB_SPEED_MAX"]

WEB_SPEED_MAX = DRIVE_KEYS["web_speed"].hi  # [m/s], as in a scene
#: Most Newton steps of one operating point.
_NEWTON_STEPS = 200
#: A scaled residual (each equation over its largest Jacobian entry: a step in the unknowns'
#: units) at which the operating point is solved where stiff nips leave no descent (the
#: Jacobian's condition number reaches 1e15).
_ROUND_OFF = 1e-12
#: Units of the equations' residuals, by the ending of the state's name.
_RATE_UNIT = {"x_dot": " m/s²", "z_dot": " m/s²", "theta_dot": " rad/s²", "friction": " N/s"}


def _where_drive(scene: Scene, body: BodyElement) -> str:
    return scene.naming.key(body.table, body.name, "drive")


def _check_type(scene: Scene, where: str) -> None:
    if not isinstance(scene, Scene):
        raise ArgumentTypeError(f"{where}: scene must be a winder.Scene (winder.load_scene), "
                                f"got {show(scene)} ({type(scene).__name__})")


def winding_reason(scene: Scene) -> str | None:
    """Why ``scene`` has no winding operating point to map over the radius of a wound roll
    (``[effects] contact = false``; no wound roll: no ``[web]``), or None: the resonance
    map then holds the modes of its initial state (:func:`winder.mode_map`)."""
    _check_type(scene, "winding_reason")
    if not scene.effects.contact:
        return "[effects] contact = false: the bodies are apart"
    if scene.web is None:
        return "no wound roll (no [web])"
    return None


def _check_scene(scene: Scene, where: str) -> None:
    """An :class:`ArgumentError` if the scene has no winding operating point."""
    _check_type(scene, where)
    if not scene.effects.contact:
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs the nip: "
                            "[effects] contact = false; valid: contact = true")
    if scene.web is None:
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs a wound roll "
                            "and the web entering it ([web] entry_nip); this scene has no "
                            "[web]")
    for b in body_elements(scene):  # a body with a drive speed runs prescribed (a pull
        # roll on a torque input turns at the speed its spans balance, as an idler)
        if b.drive_web_speed() is not None and not b.prescribed and not b.roles.roller:
            raise ArgumentError(f"{where}: {scene.source}: the resonance map needs "
                                f"{_where_drive(scene, b)} kind = 'speed_profile' (its "
                                f"web speed is the operating speed), got "
                                f"{b.part.drive.kind!r}")
    if not scene.effects.gravity or scene.scene.gravity == 0.0:
        raise ArgumentError(f"{where}: {scene.source}: the resonance map needs the roll's "
                            "weight on the nip, but [effects] gravity = "
                            f"{str(scene.effects.gravity).lower()} and [scene] gravity = "
                            f"{scene.scene.gravity!r}; valid: gravity on and > 0")
    for n in scene.nips:
        if n.friction.mu == 0.0:
            key = scene.naming.key("nip", n.name, "friction", "mu")
            raise ArgumentError(f"{where}: {scene.source}: {key} = 0: without friction the "
                                "drum does not drive the roll, so there is no winding "
                                "operating point and no slip mode; valid: mu > 0")


def _radius_state(body: BodyElement) -> str:
    """The radius state of a paper roll (a flexible roll's segments share their roll's)."""
    return f"{getattr(body, 'roll_key', body.name)}.radius"


def _entry_drive(scene: Scene) -> BodyElement:
    """The body element the web wraps before its entry nip (side ``a``: the drum; a
    flexible drum's drive segment)."""
    nip = next(n for n in scene.nips if n.name == scene.web.entry_nip)
    return next(b for b in body_elements(scene) if b.name == nip.a or
                (b.segment_of == nip.a and b.drive_web_speed() is not None))


def _web_speed(where: str, scene: Scene, web_speed: float | None, lo_open: bool) -> float:
    """The operating web speed [m/s]: the argument, or the ``web_speed`` of the drum the web
    wraps; finite, ``> 0`` (``>= 0`` where ``lo_open`` is false)."""
    if web_speed is None:
        drum = _entry_drive(scene)
        v = drum.drive_web_speed()
        if lo_open and not v > 0.0:
            key = _where_drive(scene, drum)
            raise ArgumentError(f"{where}: web_speed is not given and the scene's {key} "
                                f"web_speed is {v!r} ({scene.source}); valid: a web speed "
                                "> 0 m/s")
        return v
    return number(where, "web_speed", web_speed, lo=0.0, lo_open=lo_open,
                  hi=WEB_SPEED_MAX, unit="m/s")


class _Linearisation:
    """The machine of a scene at its operating points (see the module docstring): one
    :class:`MachineSystem` with the imbalance off and the drums at full speed ``v``."""

    def __init__(self, scene: Scene, v: float, *, winding: bool = True,
                 roll: str | None = None, where: str = "mode_map") -> None:
        """``winding`` false: the machine as the scene has it (its drives' ramps), for the
        modes at its :meth:`initial` state (no wound roll, or contact off). ``roll``: the
        paper roll whose radius is the map's (default the wound roll; a web's unwinding
        roll: its line's modes against the parent's radius, the other paper rolls at their
        initial radius)."""
        self.scene, self.v = scene, v
        self.system = sys_ = MachineSystem(scene)
        m = self.machine = sys_.machine
        p = sys_.params
        for b in m.bodies:
            if f"{b.name}.com_offset" in m.param_names:
                p[m.param_index(f"{b.name}.com_offset")] = 0.0
        for b in m.bodies if winding else ():  # the prescribed ones at full speed from t = 0
            b.hold_operating_speed(m, p, v)
        self.t = 0.0
        #: the roll whose radius is the map's: the wound roll (the web's), or None; or the
        #: unwinding roll named by ``roll`` (:attr:`unwinding`)
        self.roll = m.entry.b if m.entry is not None else None
        unwinding = [w.unwind.name for w in m.webs if w.unwind is not None]
        if roll is not None and roll not in unwinding and \
                (self.roll is None or roll != self.roll.name):
            wound = f"the wound roll {self.roll.name!r} (the default) or " \
                if self.roll is not None else ""
            raise ArgumentError(f"{where}: roll = {roll!r} is not a roll whose radius the "
                                f"map can follow in {scene.source}; valid: {wound}a web's "
                                "unwinding roll ("
                                f"{', '.join(map(repr, unwinding)) or 'none here'})")
        #: the map follows an unwinding roll's radius (its line's modes)
        self.unwinding = roll in unwinding
        if self.unwinding:
            self.roll = m.body[roll]
        if self.roll is not None:
            self.i_r = m.index(_radius_state(self.roll))
            self.rc = self.roll.least_radius
        names = m.state_names
        self.positions = [m.index(f"{b.name}.{c}") for b in m.bodies for c in b.free]
        self.coords = [f"{b.name}.{c}" for b in m.bodies for c in b.free]
        self.velocities = [m.index(f"{n}_dot") for n in self.coords]
        self.speeds = [m.index(f"{b.name}.theta_dot") for b in m.bodies if not b.prescribed]
        #: the modes' generalised coordinates: a flexible body's bending orders in place
        #: of its segments' x/z (:mod:`winder.analysis.shapes`)
        self.shapes = Shapes(m.bodies, self.coords,
                             [b.name for b in m.bodies if not b.prescribed])
        self.labels = self.shapes.labels
        # a flexible body's segment angles are elastic (its twist): fast, and in the
        # balance the twist that carries the torques, turning with the body: θ̇_i = Ω (the
        # drive's speed) on a driven body, θ̇_i = θ̇_0 on a free one (θ_0 its reference:
        # slow, as a rigid body's angle, its segments' θ_i, i ≥ 1, standing for the twists
        # θ_i − θ_0 in the fast states: see fast_jacobian; the forces see only the
        # differences, so θ_0 among the fast states would add an exact zero eigenvalue)
        self.angles: list[int] = []
        self.twists: dict[int, tuple[int | None, float]] = {}  # θ_i -> (θ_0, or None: Ω)
        for whole in dict.fromkeys(b.segment_of for b in m.bodies if b.segment_of):
            segs = [b for b in m.bodies if b.segment_of == whole]
            drive = next((b for b in segs if b.prescribed), None)
            turning = [m.index(f"{b.name}.theta") for b in segs if not b.prescribed]
            self.angles += turning if drive is not None else turning[1:]
            spin = drive.sense * drive.operating_speed(v) if winding and drive else 0.0
            for i in turning if drive is not None else turning[1:]:
                self.twists[i] = (None, spin) if drive is not None else (turning[0], 0.0)
        slow = {m.index(f"{b.name}.theta") for b in m.bodies if not b.prescribed}
        slow -= set(self.angles)
        slow |= {m.index(_radius_state(b)) for b in m.bodies if b.radius_state}
        # a flexible body's sections' rotations (flex.rotary_inertia): elastic, fast,
        # states of the bodies (not friction states)
        self.tilts = [i for i, n in enumerate(names) if ".tilt_" in n]
        taken = set(self.positions) | set(self.velocities) | set(self.speeds) | slow
        taken |= set(self.angles) | set(self.tilts)
        self.others = [i for i in range(len(names)) if i not in taken]  # friction, ...
        self._sets()
        self.paper = {m.index(f"{b.name}.theta_dot"): m.index(_radius_state(b))
                      for b in m.bodies if b.radius_state}
        self._speed_slots = np.arange(len(self.positions),
                                      len(self.positions) + len(self.speeds))
        self.v_ref = min((n.part.friction.slip_velocity for n in m.nips), default=1.0)
        self.contact = np.array([mode.kind is ModeKind.CONTACT for mode in m.modes])
        self.idle: list[str] = []  # states without dynamics, found at the first solve
        self._idle_checked = False

    def _drop_idle(self, y: np.ndarray) -> None:
        """Drop from the unknowns, the equations and the modes every state besides the
        positions and speeds whose rate is identically zero (its row of the exact Jacobian
        vanishes at ``y`` and at a perturbed state, and its rate is 0): with an effect off
        such a state (a friction state without relaxation, say) has no dynamics, stays at
        its initial value and would only make the Newton matrix singular."""
        self._idle_checked = True
        rng = np.random.default_rng(0)
        y2 = y.copy()
        y2[self.unknowns] *= 1.0 + 1e-3 * rng.standard_normal(len(self.unknowns))
        idle = []
        sys_ = self.system
        for yy in (y, y2):
            f, J = sys_.rhs(self.t, yy), sys_.jac(self.t, yy)
            idle.append({i for i in self.others if f[i] == 0.0 and not np.any(J[i])})
        drop = idle[0] & idle[1]
        if not drop:
            return
        self.idle = [self.machine.state_names[i] for i in sorted(drop)]
        self.others = [i for i in self.others if i not in drop]
        self._sets()

    def _sets(self) -> None:
        """The balance's unknowns and their equations (rates), the modes' fast states."""
        twists = list(self.twists)
        self.unknowns = self.positions + self.speeds + self.others + twists + self.tilts
        self.equations = self.velocities + self.speeds + self.others + twists + self.tilts
        self.fast = self.positions + self.velocities + self.speeds + self.others + self.angles \
            + self.tilts

    # ---- the operating point ------------------------------------------------------------
    def _radius_of(self, y: np.ndarray, name: str) -> float:
        return self.machine.body[name].radius_of(y, self.machine)

    def _speed_radius(self, y: np.ndarray) -> np.ndarray:
        """Radius [m] of each body whose speed is an unknown."""
        return np.array([self._radius_of(y, b.name) for b in self.machine.bodies
                         if not b.prescribed])

    def guess(self, r: float) -> np.ndarray:
        """The initial guess at radius ``r`` [m], already near the solution: no-slip speeds
        from the drums, then every free body resting on the bodies below it with each nip
        at the static penetration of its law under the load it carries (closed form,
        :func:`~winder.solve.equilibrium.resting_state`; the nips' damping sees the radius
        growth), friction states 0."""
        m = self.machine
        y = np.array(m.state_initial, dtype=float)
        y[self.i_r] = r
        # no slip, θ̇_b = −θ̇_a r_a / r_b across each nip, from the drums
        omega = {b.name: b.sense * b.operating_speed(self.v)
                 for b in m.bodies if b.prescribed}
        for b in m.bodies:  # a flexible drum's segments turn with its driven one
            whole = next((omega[o.name] for o in m.bodies if o.name in omega
                          and b.segment_of is not None and o.segment_of == b.segment_of), None)
            if whole is not None:
                omega.setdefault(b.name, whole)
        for _ in m.nips:
            for n in m.nips:
                a, b = n.a.name, n.b.name
                ra, rb = self._radius_of(y, a), self._radius_of(y, b)
                if a in omega and b not in omega:
                    omega[b] = -omega[a] * ra / rb
                elif b in omega and a not in omega:
                    omega[a] = -omega[b] * rb / ra
        line = m.entry.a.surface_speed(self.v) if m.entry is not None else 0.0
        for w in m.webs:  # a web line at the line's speed: its unwinding roll and rollers
            for s in w.spans:
                b = s.upstream
                if b is not None and not b.prescribed:
                    omega[b.name] = b.sense * line / self._radius_of(y, b.name)
        for b in m.bodies:
            if not b.prescribed and b.name in omega:
                y[m.index(f"{b.name}.theta_dot")] = omega[b.name]
        movable = {b.name for b in m.bodies if b.free}
        return resting_state(m, y, self.system.params, movable, t=self.t, rates=True).state

    def _guess(self, r: float, where: str) -> np.ndarray:
        """:meth:`guess`; a nip too soft for its load or a body that cannot reach its
        supports there is an :class:`ArgumentError` naming the key."""
        try:
            return self.guess(r)
        except EquilibriumError as exc:
            raise ArgumentError(f"{where}: at radius = {r:g} m: {exc}") from None

    def continued(self, r: float, where: str, prev: tuple[np.ndarray, np.ndarray]
                  ) -> tuple[np.ndarray, np.ndarray]:
        """``(start, guess)`` at radius ``r`` [m] continuing ``prev`` = ``(solution,
        guess)`` of the previous radius: the guess at ``r`` plus the previous solution's
        departure from its own guess (the slip, the friction, the positions' correction)."""
        g = self._guess(r, where)
        y_prev, g_prev = prev
        y = g.copy()
        u = self.unknowns
        y[u] = g[u] + (y_prev[u] - g_prev[u])
        return y, g

    def _residual(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``rhs − target`` on the equations and its exact Jacobian in the unknowns."""
        f = self.system.rhs(self.t, y)
        J = self.system.jac(self.t, y)
        for i_w, i_r in self.paper.items():  # constant surface speed: ω̇ = −ω ṙ / r
            f[i_w] += y[i_w] * f[i_r] / y[i_r]
            J[i_w, i_w] += (f[i_r] + y[i_w] * J[i_r, i_w]) / y[i_r]
        for i, (ref, omega) in self.twists.items():  # a steady twist: θ̇_i = θ̇_0 or Ω
            if ref is None:
                f[i] -= omega
            else:
                f[i] -= f[ref]
                J[i] -= J[ref]
        return f[self.equations], J[np.ix_(self.equations, self.unknowns)]

    def _scales(self, y: np.ndarray) -> np.ndarray:
        """The natural scale of each unknown: 1 m for a position (its steps are judged
        relative to 1 m), the slip speed ``v_ref/r`` [rad/s] for a rotation speed, 1 N for
        a friction state (or the value, where larger)."""
        m = self.machine
        s = []
        for i in self.unknowns:
            name = m.state_names[i]
            if name.endswith("theta_dot"):
                s.append(self.v_ref / self._radius_of(y, name[:-len(".theta_dot")]))
            else:
                s.append(1.0)
        return np.array(s)

    def _newton(self, y: np.ndarray) -> tuple[bool, np.ndarray, np.ndarray]:
        """Globalised Newton from ``y`` (changed in place): the exact Jacobian, rows scaled
        by their largest entry at the start, each step limited so that no surface speed
        moves by more than half the slip velocity (the slip law saturates beyond a few
        ``v_ref``), then halved until the scaled residual decreases (Armijo); converged at a
        step below 1e-10 of the unknowns' scale, or where no step descends any more with the
        scaled residual at round-off (:data:`_ROUND_OFF`). Returns
        ``(converged, scaled residual, raw residual)``."""
        u = self.unknowns
        floor = np.ones(len(u))  # [m], [rad/s], [N]
        res, J = self._residual(y)
        D = 1.0 / np.maximum(np.max(np.abs(J), axis=1), 1e-300)
        merit = np.linalg.norm(D * res)
        for _ in range(_NEWTON_STEPS):
            if not (np.all(np.isfinite(J)) and np.isfinite(merit)):
                return False, D * res, res
            # least squares: singular where a nip carries no load yet (δ = 0)
            step = np.linalg.lstsq(J, -res, rcond=None)[0]
            x0 = y[u].copy()
            if np.all(np.abs(step) <= 1e-10 * np.maximum(np.abs(x0), floor)):
                y[u] = x0 + step
                res, _ = self._residual(y)
                return True, D * res, res
            big = np.abs(step[self._speed_slots]) * self._speed_radius(y)
            step *= min(1.0, float(np.min(self.v_ref / 2 / np.maximum(big, 1e-300),
                                          initial=np.inf)))
            lam = 1.0
            while lam > 1e-6:
                y[u] = x0 + lam * step
                res_n, J_n = self._residual(y)
                m_n = np.linalg.norm(D * res_n)
                if np.isfinite(m_n) and m_n <= (1 - 1e-4 * lam) * merit or m_n == 0:
                    break
                lam /= 2
            else:  # no descent left: solved if the residual is at round-off
                y[u] = x0
                return bool(np.max(np.abs(D * res)) <= _ROUND_OFF), D * res, res
            res, J, merit = res_n, J_n, m_n
        return False, D * res, res

    def _trust_region(self, y: np.ndarray) -> bool:
        """Levenberg–Marquardt (MINPACK) on the exact Jacobian in the unknowns' natural
        scales, from ``y`` (changed in place): the fallback where the line search stalls."""
        from scipy.optimize import least_squares

        u = self.unknowns
        s = self._scales(y)
        res0, J0 = self._residual(y)
        D = 1.0 / np.maximum(np.max(np.abs(J0 * s[None, :]), axis=1), 1e-300)
        x0 = y[u] / s
        cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

        def both(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            key = z.tobytes()
            if key not in cache:
                cache.clear()
                yy = y.copy()
                yy[u] = z * s
                r_, J_ = self._residual(yy)
                cache[key] = (D * r_, D[:, None] * J_ * s[None, :])
            return cache[key]

        sol = least_squares(lambda z: both(z)[0], x0, jac=lambda z: both(z)[1], method="lm",
                            xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=100 * len(u))
        y[u] = sol.x * s
        return bool(np.all(np.isfinite(sol.fun)))

    def solve(self, r: float, where: str, start: np.ndarray | None = None) -> np.ndarray:
        """The operating point at radius ``r`` [m] (an :class:`ArgumentError` if none):
        globalised Newton steps (:meth:`_newton`; Levenberg–Marquardt where they stall)
        from ``start`` (the previous radius of a map, continued) or :meth:`guess`, to a
        step below 1e-10 of the unknowns' scale (1 m, 1 rad/s, 1 N or their value)."""
        sys_ = self.system
        converged, scaled, raw = False, np.array([np.inf]), np.array([np.inf])
        y = self._guess(r, where) if start is None else start.copy()
        sys_.modes[self.contact] = IN_CONTACT  # smooth while solving
        try:
            with np.errstate(all="ignore"):
                if not self._idle_checked:
                    self._drop_idle(y)
                for attempt in ("newton", "trust_region", "guess"):
                    if attempt == "guess":
                        if start is None:
                            break
                        y = self._guess(r, where)
                        start = None
                    elif attempt == "trust_region":
                        self._trust_region(y)
                    converged, scaled, raw = self._newton(y)
                    if converged:
                        break
        except (np.linalg.LinAlgError, FloatingPointError, ArithmeticError):
            converged = False
        except Exception as exc:  # a non-finite rhs on the way: no balance
            if type(exc).__name__ != "SimulationError":
                raise
            converged = False
        finally:
            sys_.modes[self.contact] = AUTO
        v = self.v
        nips = "the nip cannot" if len(self.machine.nips) == 1 else "the nips cannot"
        saturated = self._saturated(y)
        if converged and saturated:  # gross slip: the friction cannot hold the speeds
            raise ArgumentError(f"{where}: at radius = {r:g} m and web_speed = {v:g} m/s "
                                f"{nips} carry the roll's torque and weight: no operating "
                                f"point without gross slip ({saturated[2:]}); valid: a lower "
                                "web speed or a smaller radius")
        if not converged:
            bad = np.where(np.isfinite(scaled), np.abs(scaled), np.inf)
            k = int(np.argmax(bad)) if len(bad) == len(self.equations) else 0
            name = self.machine.state_names[self.equations[k]]
            unit = _RATE_UNIT.get(name.rsplit(".", 1)[-1], "")
            value = raw[k] if len(raw) == len(self.equations) else math.nan
            raise ArgumentError(f"{where}: at radius = {r:g} m and web_speed = {v:g} m/s "
                                f"{nips} carry the roll's torque and weight: no operating "
                                f"point (the equation of d({name})/dt did not converge: "
                                f"residual {value:.3g}{unit}{saturated}); valid: a "
                                "lower web speed or a smaller radius")
        sw = sys_.switches(self.t, y)
        names = self.machine.switch_names
        for n in self.machine.nips:
            g = sw[names.index(f"{n.name}.contact")]
            over = sw[names.index(f"{n.name}.overlap")]  # δ − min(r_a, r_b), as the guard
            if not g > 0.0:
                raise ArgumentError(f"{where}: at radius = {r:g} m nip {n.name!r} opens at "
                                    "the operating point (no normal force): no bounce mode "
                                    "about a lasting contact there")
            if not over < 0.0:
                delta = over + min(self._radius_of(y, n.a.name), self._radius_of(y, n.b.name))
                raise ArgumentError(f"{where}: at radius = {r:g} m the load compresses nip "
                                    f"{n.name!r} by {delta:.4g} m, more than a radius (one "
                                    "axis would lie inside the other body); valid: a smaller "
                                    f"radius or a stiffer nip ({nip_key(self.machine, n)})")
        return y

    def _saturated(self, y: np.ndarray) -> str:
        """``; nip 'N' slips at v_s …`` for each nip whose friction is saturated at the
        last iterate ``y`` (``|v_s| > 2 v_ref``: ``tanh > 0.96``), else ``""``."""
        try:
            with np.errstate(all="ignore"):
                modes = self.system.modes.copy()
                modes[self.contact] = IN_CONTACT  # as solved
                ev = self.system.evaluate_numeric(self.t, y, modes, outputs=False)
        except Exception:  # noqa: BLE001 - only a diagnosis: the error is raised anyway
            return ""
        out = []
        for n in self.machine.nips:
            ns = ev.nips[n.name]
            vs, fn = float(ns.v_s), float(ns.normal_force)
            if np.isfinite(vs) and abs(vs) > 2 * n.part.friction.slip_velocity and fn > 0:
                out.append(f"; nip {n.name!r} slips at v_s = {vs:.3g} m/s, its friction "
                           f"saturated at mu F_n = {n.part.friction.mu * fn:.4g} N")
        return "".join(out)

    def fast_jacobian(self, y: np.ndarray) -> np.ndarray:
        """The exact Jacobian on the fast states (:attr:`fast`) at ``y``. A free flexible
        body's segment angle ``θ_i`` (i ≥ 1) stands for its twist ``θ_i − θ_0`` (``θ_0``
        slow): its row is ``d(θ_i − θ_0)/dt``, the rows of ``θ_i`` and ``θ_0`` subtracted
        (the columns are already the twist's: the forces depend on angle differences
        only)."""
        J = jacobian(self.system, self.t, y)
        rows = J[self.fast]
        at = {i: k for k, i in enumerate(self.fast)}
        for i, (ref, _) in self.twists.items():
            if ref is not None:
                rows[at[i]] -= J[ref]
        return rows[:, self.fast]

    # ---- the modes ----------------------------------------------------------------------
    def modes(self, y: np.ndarray) -> list[Mode]:
        """Bounce and bending modes (in the order of the generalised coordinates
        :attr:`labels` that have one: a flexible body's bending orders ``BODY.bend.z1`` …
        only where an oscillating mode has that shape), then slip modes (slowest first),
        then torsion modes ``BODY.torsion{n}`` (slowest first), at ``y``
        (:func:`~winder.analysis.mode_labels.label_modes`)."""
        ev = self.system.evaluate_numeric(self.t, y, outputs=False)
        mass = np.array([float(ev.bodies[c.rsplit(".", 1)[0]].mass) for c in self.coords])
        inertia = np.array([float(ev.bodies[b.name].inertia)
                            for b in self.machine.bodies if not b.prescribed])
        others = set(self.others)
        names = [self.machine.state_names[i] for i in self.fast]
        # a section's rotary inertia j_r = J_seg/2 on its rotation rate (flex_beam's
        # _rotary_bending: ṡ = 2 g/J_seg)
        p, m = self.system.params, self.machine
        rotary = np.array([0.5 * float(p[m.param_index(f"{n.split('.', 1)[0]}.inertia")])
                           if ".tilt_rate_" in n else 0.0 for n in names])
        line = line_coordinates(m, p, names, {b: float(s.inertia)
                                              for b, s in ev.bodies.items()})
        return label_modes(self.fast_jacobian(y), shapes=self.shapes,
                           n_positions=len(self.positions), n_speeds=len(self.speeds),
                           mass=mass, inertia=inertia, names=names,
                           mechanical=np.array([i not in others for i in self.fast],
                                               dtype=bool), rotary=rotary, line=line)

    def initial(self) -> np.ndarray:
        """The machine's initial state (``winder run``'s at ``t = 0``: the static balance
        of machines.md §7) with the imbalance off, its idle states dropped: where the scene
        has no winding operating point (:func:`winding_reason`)."""
        y = self.system.initial_state()
        with np.errstate(all="ignore"):
            self._drop_idle(y)
        return y


def _linearisation(scene: Scene, where: str, web_speed: float | None, lo_open: bool,
                   roll: str | None = None) -> _Linearisation:
    _check_scene(scene, where)
    if roll is not None and not isinstance(roll, str):
        raise ArgumentTypeError(f"{where}: roll must be a roll's name (str), got "
                                f"{show(roll)} ({type(roll).__name__})")
    return _Linearisation(scene, _web_speed(where, scene, web_speed, lo_open=lo_open),
                          roll=roll, where=where)


def _core_key(lin: _Linearisation) -> str:
    """The scene key of the wound roll's core radius, the smallest radius of a map."""
    return lin.scene.naming.key(lin.roll.table, lin.roll.name, lin.roll.least_radius_key)


def _radius(where: str, lin: _Linearisation, radius: float) -> float:
    key = _core_key(lin)
    return number(where, "radius", radius, lo=lin.rc, unit="m",
                  valid=f"a finite radius >= {key} = {lin.rc:g} m")


def operating_point(scene: Scene, radius: float, *, web_speed: float | None = None
                    ) -> tuple[MachineSystem, float, np.ndarray]:
    """``(system, t, y)`` of the quasi-steady operating point (module docstring) at
    ``radius`` [m] of the wound roll (``>=`` its core radius) and ``web_speed`` [m/s]
    (``>= 0``; default the scene's). ``system.params`` hold the drums at full speed and the
    imbalance off.

    Raises
    ------
    ArgumentError: a radius or web speed out of range, a scene without a winding operating
        point (no nip, no web, no weight, no friction, a torque drive), or a radius and
        speed at which the nips cannot carry the rolls' torques or weights.
    """
    where = "operating_point"
    lin = _linearisation(scene, where, web_speed, lo_open=False)
    r = _radius(where, lin, radius)
    return lin.system, lin.t, lin.solve(r, where)
