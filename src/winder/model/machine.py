"""A machine built from parts: one Pinocchio model, a named state layout, run-time
parameters, and its dynamics written once over a math namespace.

``Machine(scene)`` reads the scene's parts (machines.md §1–§8):

- every body (drum, roll, rider) gets its own joints to the world in one ``pin.Model``:
  prismatic ``x`` and/or ``z`` where it is free, then a revolute joint about ``+y``; the
  first joint's placement holds the fixed coordinates of its centre;
- the state vector is named (:attr:`Machine.state_names`): ``BODY.x``, ``BODY.z``,
  ``BODY.theta`` for the joint coordinates, ``BODY.x_dot``, ``BODY.z_dot``,
  ``BODY.theta_dot`` for their rates, ``ROLL.radius`` for paper rolls and what the force
  elements add (``NIP.friction`` for slip relaxation); a drum with a speed profile is
  prescribed and has no state;
- every scene number the dynamics reads is a named run-time parameter
  (:attr:`Machine.param_names`), so one compiled model serves every value of them;
- :meth:`Machine.evaluate` is the dynamics: kinematics of bodies and nips, the force
  elements of :mod:`winder.forces`, the variable-mass ``−Ẏv``, and Pinocchio's ABA (and
  RNEA for the drive torques) through a backend: numeric (``pin.aba``) or symbolic
  (CasADi, for the generated code).

Locked modes (the integrators lock them within a step and switch at located events):
per nip the contact mode (:data:`AUTO`, :data:`FREE`, :data:`IN_CONTACT`), per wound
roll the core mode of spec §2 (:data:`CORE_AUTO`, :data:`WINDING`, :data:`AT_CORE`).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from winder.model.mass_law import paper_roll_mass

__all__ = ["Machine", "Body", "Nip", "Web", "Evaluation", "AUTO", "FREE", "IN_CONTACT", "CORE_AUTO",
           "WINDING", "AT_CORE"]

AUTO, FREE, IN_CONTACT = -1, 0, 1
CORE_AUTO, WINDING, AT_CORE = -1, 0, 1
_COORDS = ("x", "z")


@dataclass
class Body:
    """A body of the machine (machines.md §1). ``joints`` maps ``x``/``z``/``theta`` to
    Pinocchio joint ids; ``kind`` is ``drum``, ``roll`` or ``rider``."""

    name: str
    kind: str
    sense: int
    free: tuple[str, ...]
    centre: tuple[float, float]
    part: Any
    joints: dict[str, int] = field(default_factory=dict)
    prescribed: bool = False  # a drum with a speed profile
    torque_input: bool = False  # a drum or an unwinding roll with a torque drive
    unwinding: bool = False  # a paper roll that pays off its web (machines.md §1)
    controlled: bool = False  # an unwinding roll under tension control


@dataclass
class Nip:
    """A nip between bodies ``a`` and ``b`` (machines.md §2)."""

    name: str
    a: Body
    b: Body
    part: Any
    index: int


@dataclass
class Web:
    """A web (machines.md §3, §5): it enters its wound roll ``entry.b`` at the nip ``entry``
    from the drum ``entry.a``, under a constant tension or that of its ``span`` from the
    unwinding roll ``unwind``. ``key`` prefixes the names of its parameters (``web.tension``)
    and ``channel`` its channels (``web_speed``, ``web_force``): empty for a scene's only
    web, else ``NAME.`` and ``NAME_``; ``span_key``/``span_channel`` likewise for its span
    (``span.tension``, ``span_tension``, ``tension_error``), empty when it is the only span
    (machines.md §9)."""

    name: str
    part: Any
    entry: Nip
    span: Any = None
    unwind: Body | None = None
    key: str = ""
    channel: str = ""
    span_key: str = ""
    span_channel: str = ""


class Machine:
    """The machine of a scene: model, layout, parameters, modes, channels, dynamics.

    Parameters
    ----------
    scene: a :class:`~winder.Scene` (its parts: ``drums``, ``rolls``, ``riders``,
        ``nips``, ``webs``; an object with only ``web`` is read as that one web).

    ``webs`` lists the :class:`Web` s; ``web``, ``entry`` are the first web's part and
    entry nip, ``span``, ``unwind`` the first span and its unwinding roll (None without).
    """

    def __init__(self, scene: Any) -> None:
        from winder.forces import DRIVES, FORCES

        self.scene = scene
        fx = scene.effects
        self.bodies: list[Body] = []
        for d in scene.drums:
            self.bodies.append(Body(d.name, "drum", int(d.sense), (), tuple(d.centre), d,
                                    prescribed=d.drive.kind == "speed_profile",
                                    torque_input=d.drive.kind == "torque"))
        for r in scene.rolls:
            drive = getattr(r, "drive", None)
            kind = drive.kind if drive is not None else None
            self.bodies.append(Body(r.name, "roll", int(r.sense), tuple(r.free),
                                    tuple(r.centre), r, torque_input=kind == "torque",
                                    unwinding=r.kind == "unwinding",
                                    controlled=kind == "tension_control"))
        self.body = {b.name: b for b in self.bodies}
        for x in scene.riders:  # initial guess: on top of the roll it rides
            ridden = self.body[x.rides]
            z = ridden.centre[1] + ridden.part.initial_radius + x.radius
            self.bodies.append(Body(x.name, "rider", 1, ("z",), (float(x.x), z), x))
        self.body = {b.name: b for b in self.bodies}
        self.nips = [Nip(n.name, self.body[n.a], self.body[n.b], n, i)
                     for i, n in enumerate(scene.nips)]
        self.nip = {n.name: n for n in self.nips}
        parts = tuple(getattr(scene, "webs", None) or ()) or \
            ((scene.web,) if getattr(scene, "web", None) is not None else ())
        spans = sum(getattr(w, "span", None) is not None for w in parts)
        self.webs: list[Web] = []
        for w in parts:
            name = getattr(w, "name", None) or w.entry_nip
            span = getattr(w, "span", None)
            several, spanned = len(parts) > 1, spans > 1
            self.webs.append(Web(name, w, self.nip[w.entry_nip], span,
                                 self.body[span.source] if span is not None else None,
                                 f"{name}." if several else "", f"{name}_" if several else "",
                                 f"{name}." if spanned else "", f"{name}_" if spanned else ""))
        first = self.webs[0] if self.webs else None
        self.web = first.part if first is not None else None
        self.entry = first.entry if first is not None else None
        self.rolls = [b for b in self.bodies if b.kind == "roll"]
        spanned = next((w for w in self.webs if w.span is not None), None)
        self.span = spanned.span if spanned is not None else None
        self.unwind = spanned.unwind if spanned is not None else None
        if self.span is not None and not fx.web_tension:
            from winder._errors import ModelError

            raise ModelError(f"{scene.source}: [effects] web_tension = false with a "
                             "[web.span]: the span's tension is the web_tension effect; "
                             "valid: web_tension = true, or no [web.span]")
        self.model = self._build_model()
        self.param_names: list[str] = []
        self.param_values: list[float] = []
        self.state_names: list[str] = []
        self.state_initial: list[float] = []
        self.channel_names: list[str] = []
        self.mode_names: list[str] = []
        self.switch_names: list[str] = []
        self._declare_base()
        drives = {b.part.drive.kind for b in self.bodies if b.controlled}
        self.forces = sorted([*(FORCES[n]() for n in fx.enabled() if n in FORCES),
                              *(DRIVES[k]() for k in sorted(drives))], key=lambda f: f.order)
        for f in self.forces:
            f.declare(self)
        self._index = {n: i for i, n in enumerate(self.state_names)}
        self._pindex = {n: i for i, n in enumerate(self.param_names)}

    # ---- structure --------------------------------------------------------------------
    def _build_model(self) -> pin.Model:
        model = pin.Model()
        model.name = self.scene.name
        for b in self.bodies:
            parent = 0
            cx, cz = b.centre
            placement = pin.SE3(np.eye(3), np.array([0.0 if "x" in b.free else cx, 0.0,
                                                     0.0 if "z" in b.free else cz]))
            for coord in _COORDS:
                if coord in b.free:
                    jm = pin.JointModelPX() if coord == "x" else pin.JointModelPZ()
                    parent = model.addJoint(parent, jm, placement, f"{b.name}.{coord}")
                    placement = pin.SE3.Identity()
                    b.joints[coord] = parent
            parent = model.addJoint(parent, pin.JointModelRY(), placement, f"{b.name}.theta")
            b.joints["theta"] = parent
            model.appendBodyToJoint(parent, pin.Inertia(1.0, np.zeros(3), np.eye(3)),
                                    pin.SE3.Identity())
        model.gravity = pin.Motion.Zero()
        return model

    def parameter(self, name: str, value: float) -> None:
        """Register a run-time parameter ``name`` with its scene ``value``."""
        if name in self.param_names:
            raise ValueError(f"parameter {name!r} declared twice")
        self.param_names.append(name)
        self.param_values.append(float(value))

    def state(self, name: str, initial: float) -> None:
        """Register a state ``name`` with its initial value (spec §7)."""
        self.state_names.append(name)
        self.state_initial.append(float(initial))

    def channel(self, name: str) -> None:
        """Register a result channel ``name``."""
        if name not in self.channel_names:
            self.channel_names.append(name)

    def mode(self, name: str, switches: tuple[str, ...]) -> None:
        """Register a locked mode slot and its switching functions."""
        self.mode_names.append(name)
        self.switch_names.extend(switches)

    def _declare_base(self) -> None:
        # joint coordinates, then their rates
        qs = [(b, c) for b in self.bodies for c in (*b.free, "theta")
              if not (c == "theta" and b.prescribed)]
        for b, c in qs:
            init = 0.0 if c == "theta" else (b.centre[0] if c == "x" else b.centre[1])
            self.state(f"{b.name}.{c}", init)
        for b, c in qs:
            self.state(f"{b.name}.{c}_dot", self._initial_rate(b, c))
        for b in self.bodies:
            part = b.part
            if b.kind == "drum":
                self.parameter(f"{b.name}.radius", part.radius)
                self.parameter(f"{b.name}.inertia", part.inertia)
                self.parameter(f"{b.name}.mass", part.mass)
                dr = part.drive
                if b.prescribed:
                    aw, vw = dr.web_acceleration, dr.web_speed
                    self.parameter(f"{b.name}.web_acceleration", aw)
                    self.parameter(f"{b.name}.web_speed", vw)
                    self.parameter(f"{b.name}.ratio", dr.ratio)
                    self.parameter(f"{b.name}.ramp_time", vw / aw if aw > 0 else 0.0)
                else:
                    self.parameter(f"{b.name}.torque", dr.torque)
            elif b.kind == "roll":
                self.state(f"{b.name}.radius", part.initial_radius)
                self.parameter(f"{b.name}.core_radius", part.core_radius)
                self.parameter(f"{b.name}.core_mass", part.core_mass)
                self.parameter(f"{b.name}.core_inertia", part.core_inertia)
                self.parameter(f"{b.name}.width", part.width)
                self.parameter(f"{b.name}.density", part.density)
                self.parameter(f"{b.name}.caliper", part.caliper)
                if b.unwinding:  # the run ends where it reaches its core
                    self.mode(f"{b.name}.end", (f"{b.name}.exhausted",))
                else:
                    self.mode(f"{b.name}.core", (f"{b.name}.unwound", f"{b.name}.forward"))
                if b.torque_input:
                    self.parameter(f"{b.name}.torque", part.drive.torque)
            else:
                self.parameter(f"{b.name}.radius", part.radius)
                self.parameter(f"{b.name}.inertia", part.inertia)
                self.parameter(f"{b.name}.mass", part.mass)
        for b in self.bodies:
            for ch in ("speed", "angle", "torque", "accel"):
                self.channel(f"{b.name}_{ch}")
            for c in b.free:
                for ch in ("", "_dot", "_accel"):
                    self.channel(f"{b.name}_{c}{ch}")
            if b.kind == "roll":
                for ch in ("radius", "mass", "inertia", "mass_rate", "inertia_rate"):
                    self.channel(f"{b.name}_{ch}")
        for n in self.nips:
            for ch in ("normal_force", "friction_force", "slip_velocity", "penetration"):
                self.channel(f"{n.name}_{ch}")
        for w in self.webs:
            self.channel(f"{w.channel}web_speed")

    def _initial_rate(self, b: Body, c: str) -> float:
        """Spec §7: translational velocities 0; a roll its initial speed, a torque-driven
        drum ``web_speed / R``, a rider 0 (joint rate ``θ̇ = s · speed``)."""
        if c != "theta":
            return 0.0
        if b.kind == "roll":
            return b.sense * b.part.initial_speed
        if b.kind == "drum":
            return b.sense * b.part.drive.web_speed / b.part.radius
        return 0.0

    # ---- names ------------------------------------------------------------------------
    @property
    def n_states(self) -> int:
        return len(self.state_names)

    def index(self, name: str) -> int:
        """Position of state ``name`` in the state vector."""
        try:
            return self._index[name]
        except KeyError:
            raise KeyError(f"no state {name!r}; states: {', '.join(self.state_names)}") \
                from None

    def radius(self, y: Any, body: Body) -> float:
        """Radius [m] of ``body`` in state ``y``: a roll's is a state, a drum's or a
        rider's its part's."""
        return float(y[self.index(f"{body.name}.radius")]) if body.kind == "roll" \
            else float(body.part.radius)

    def param_index(self, name: str) -> int:
        """Position of parameter ``name`` in the parameter vector."""
        try:
            return self._pindex[name]
        except KeyError:
            raise KeyError(f"no parameter {name!r}; parameters: "
                           f"{', '.join(self.param_names)}") from None

    def parameters(self) -> np.ndarray:
        """The scene's parameter vector."""
        return np.array(self.param_values, dtype=float)

    def structure_key(self) -> str:
        """A hash of everything that changes the generated code: the model, the layout,
        the parameter, mode, switch and channel names and the force elements."""
        h = hashlib.sha256()
        for i in range(1, self.model.njoints):
            M = self.model.jointPlacements[i]
            h.update(f"{self.model.names[i]}:{self.model.joints[i].shortname()}:"
                     f"{self.model.parents[i]}:{M.translation.tolist()}".encode())
        for group in (self.state_names, self.param_names, self.mode_names,
                      self.switch_names, self.channel_names,
                      [f.name for f in self.forces],
                      [f"{b.name}:{b.kind}:{b.sense}:{b.prescribed}:{b.torque_input}:"
                       f"{b.unwinding}:{b.controlled}" for b in self.bodies],
                      [self.span.source if self.span is not None else ""],
                      [f"{n.name}:{n.a.name}:{n.b.name}:{n.part.contact.law}"
                       for n in self.nips],
                      [self.entry.name if self.entry else ""],
                      *([f"{w.name}:{w.entry.name}:{w.unwind.name if w.unwind else ''}"
                         for w in self.webs],) * (len(self.webs) > 1),
                      [f"{x.name}:{len(x.part.load)}" for x in self.bodies
                       if x.kind == "rider"]):
            h.update(("|".join(group) + "#").encode())
        return h.hexdigest()[:16]

    # ---- dynamics ---------------------------------------------------------------------
    def evaluate(self, backend: Any, t: Any, x: Any, p: Any, modes: Any, *,
                 static: bool = False, outputs: bool = True) -> Evaluation:
        """One evaluation of the dynamics (see :class:`Evaluation`)."""
        ev = Evaluation(self, backend, t, x, p, modes, static=static)
        ev.run(outputs=outputs)
        return ev


class BodyState:
    """Kinematics of one body in one evaluation [SI, world frame]: centre ``cx, cz`` and
    velocity ``vx, vz``; joint angle ``theta`` and rate ``omega`` (about ``+y``); radius
    ``r`` and rate ``r_dot``; paper rolls: ``mass, inertia, dm_dr, dJ_dr``; force
    accumulators ``fx, fz`` [N] and ``ty`` (about ``+y`` through the centre) [N·m];
    ``t_contact`` the part of ``ty`` reported as its torque channel."""

    __slots__ = ("body", "cx", "cz", "vx", "vz", "theta", "omega", "alpha_prescribed", "r",
                 "r_dot", "mass", "inertia", "dm_dr", "dJ_dr", "fx", "fz", "ty", "e")

    def __init__(self, body: Body) -> None:
        self.body = body
        self.fx = self.fz = self.ty = 0.0
        self.alpha_prescribed = None
        self.e = 0.0

    @property
    def speed(self) -> Any:
        """Speed in the operation sense ``s θ̇`` [rad/s]."""
        return self.body.sense * self.omega

    @property
    def mass_rate(self) -> Any:
        return self.dm_dr * self.r_dot

    @property
    def inertia_rate(self) -> Any:
        return self.dJ_dr * self.r_dot


class NipState:
    """Kinematics of one nip (machines.md §2): normal ``nx, nz``, tangent ``tx, tz``,
    penetration ``delta`` and rate ``delta_dot``, surface speeds ``u_a, u_b``, slip
    ``v_s``; the contact writes ``normal_force``, ``friction_force`` and
    ``steady_friction``."""

    __slots__ = ("nip", "nx", "nz", "tx", "tz", "delta", "delta_dot", "u_a", "u_b", "v_s",
                 "normal_force", "friction_force", "steady_friction", "mode")

    def __init__(self, nip: Nip) -> None:
        self.nip = nip
        self.normal_force = self.friction_force = self.steady_friction = 0.0


class Evaluation:
    """Everything one evaluation of the machine computes, shared by the force elements.

    ``M`` the math namespace; ``bodies``/``nips`` the kinematics by name; ``rates`` the
    state derivatives; ``channels`` the result channels; ``switches`` the switching
    functions (> 0: the other side of the mode).
    """

    def __init__(self, machine: Machine, backend: Any, t: Any, x: Any, p: Any, modes: Any,
                 *, static: bool) -> None:
        self.machine, self.backend, self.M = machine, backend, backend.M
        self.t, self._x, self._p, self.modes = t, x, p, modes
        self.static = static
        self.rates: dict[str, Any] = {}
        self.channels: dict[str, Any] = {}
        self.switches: dict[str, Any] = {}
        self.bodies: dict[str, BodyState] = {}
        self.nips: dict[str, NipState] = {}
        self.fext_extra: dict[str, list[Any]] = {}  # local-frame spatial forces by body
        #: actuator torques about the bodies' axes [N·m], operation sense (drives)
        self.drive_torques: dict[str, Any] = {}
        #: dT/dt of each web's span [N/s] by web name (web_tension sets it)
        self.span_rates: dict[str, Any] = {}
        self.gravity: Any = 0.0  # [m/s²], set by the gravity effect

    # access by name
    def x(self, name: str) -> Any:
        return self._x[self.machine.index(name)]

    def p(self, name: str) -> Any:
        return self._p[self.machine.param_index(name)]

    def mode(self, name: str) -> Any:
        return self.modes[self.machine.mode_names.index(name)]

    def set_rate(self, name: str, value: Any) -> None:
        self.rates[name] = value

    def set_channel(self, name: str, value: Any) -> None:
        self.channels[name] = value

    def add_force(self, body: str, fx: Any, fz: Any, px: Any = 0.0, pz: Any = 0.0) -> None:
        """World force ``(fx, fz)`` [N] on ``body`` at ``(px, pz)`` relative to its centre
        [m]."""
        bs = self.bodies[body]
        bs.fx = bs.fx + fx
        bs.fz = bs.fz + fz
        bs.ty = bs.ty + (pz * fx - px * fz)

    def add_spatial_force(self, body: str, f: list[Any]) -> None:
        """A spatial force ``[f; τ]`` in the body's joint frame (e.g. ``−Ẏv``)."""
        old = self.fext_extra.get(body)
        self.fext_extra[body] = f if old is None else [a + b for a, b in zip(old, f, strict=True)]

    # ---- the steps ----------------------------------------------------------------------
    def run(self, *, outputs: bool) -> None:
        self._kinematics()
        self._joint_vectors()
        self._nip_kinematics()
        for f in self.machine.forces:
            if self.static:
                f.static(self)
            else:
                f.apply(self)
        if self.static:
            return
        self._dynamics(outputs)

    def _kinematics(self) -> None:
        m, M, t = self.machine, self.M, self.t
        for b in m.bodies:
            bs = BodyState(b)
            n = b.name
            bs.cx = self.x(f"{n}.x") if "x" in b.free else b.centre[0]
            bs.cz = self.x(f"{n}.z") if "z" in b.free else b.centre[1]
            bs.vx = self.x(f"{n}.x_dot") if "x" in b.free else 0.0
            bs.vz = self.x(f"{n}.z_dot") if "z" in b.free else 0.0
            if b.prescribed:  # machines.md §6: Ω = ratio·min(a_w t, v_w)/R
                R, k = self.p(f"{n}.radius"), self.p(f"{n}.ratio")
                aw, vw, tr = (self.p(f"{n}.web_acceleration"), self.p(f"{n}.web_speed"),
                              self.p(f"{n}.ramp_time"))
                ramp = t < tr
                s = b.sense
                bs.theta = s * k / R * M.if_else(ramp, 0.5 * aw * t * t,
                                                 0.5 * aw * tr * tr + vw * (t - tr))
                bs.omega = s * k / R * M.if_else(ramp, aw * t, vw)
                bs.alpha_prescribed = s * k / R * M.if_else(ramp, aw, 0.0)
            else:
                bs.theta = self.x(f"{n}.theta")
                bs.omega = self.x(f"{n}.theta_dot")
            if b.kind == "roll":
                r = self.x(f"{n}.radius")
                rc = self.p(f"{n}.core_radius")
                k = math.pi * self.p(f"{n}.density") * self.p(f"{n}.width")
                bs.mass, bs.inertia, bs.dm_dr, bs.dJ_dr = paper_roll_mass(
                    r, rc, self.p(f"{n}.core_mass"), self.p(f"{n}.core_inertia"), k)
                h2pi = self.p(f"{n}.caliper") / (2.0 * math.pi)
                speed = bs.speed
                bs.r = r
                if b.unwinding:  # machines.md §1: ṙ = −h·speed/2π, down to the core
                    bs.r_dot = -h2pi * speed
                    self.switches[f"{n}.exhausted"] = rc - r
                else:
                    core = self.mode(f"{n}.core")
                    at_core = M.logic_or(core == AT_CORE, M.logic_and(
                        core == CORE_AUTO, M.logic_and(r <= rc, speed < 0.0)))
                    bs.r_dot = M.if_else(at_core, 0.0, h2pi * speed)
                    self.switches[f"{n}.unwound"] = rc - r
                    self.switches[f"{n}.forward"] = speed
                self.set_rate(f"{n}.radius", bs.r_dot)
            else:
                bs.r = self.p(f"{n}.radius")
                bs.r_dot = 0.0
                bs.mass = self.p(f"{n}.mass")
                bs.inertia = self.p(f"{n}.inertia")
                bs.dm_dr = bs.dJ_dr = 0.0
            self.bodies[n] = bs

    def _nip_kinematics(self) -> None:
        M = self.M
        for nip in self.machine.nips:
            a, b = self.bodies[nip.a.name], self.bodies[nip.b.name]
            ns = NipState(nip)
            dx, dz = b.cx - a.cx, b.cz - a.cz
            dist = M.sqrt(dx * dx + dz * dz)
            ns.nx, ns.nz = dx / dist, dz / dist
            ns.tx, ns.tz = ns.nz, -ns.nx
            ns.delta = a.r + b.r - dist
            ns.delta_dot = 0.0 if self.static else \
                a.r_dot + b.r_dot - (ns.nx * (b.vx - a.vx) + ns.nz * (b.vz - a.vz))
            ns.u_a = a.vx * ns.tx + a.vz * ns.tz + a.omega * a.r
            ns.u_b = b.vx * ns.tx + b.vz * ns.tz - b.omega * b.r
            ns.v_s = ns.u_a - ns.u_b
            ns.mode = self.mode(f"{nip.name}.contact") if \
                f"{nip.name}.contact" in self.machine.mode_names else FREE
            self.nips[nip.name] = ns

    def inertia_parameters(self, bs: BodyState, *, rate: bool = False) -> list[Any]:
        """The 10 dynamic parameters of the body (about its joint origin; ``rate``: their
        time derivative ``dY/dr · ṙ``). Centre of mass at ``(e, 0, 0)`` in the body frame
        (imbalance); the polar inertia ``J`` is about the axis."""
        if rate:
            m, J = bs.mass_rate, bs.inertia_rate
        else:
            m, J = bs.mass, bs.inertia
        if bs.body.kind == "roll":
            L = self.p(f"{bs.body.name}.width")
            it = 0.5 * J + m * L * L / 12.0
        else:
            it = 0.5 * J
        return [m, m * bs.e, 0.0, 0.0, it, 0.0, J, 0.0, 0.0, it]

    def _joint_vectors(self) -> None:
        """``q, v`` of the Pinocchio model from the body kinematics."""
        model = self.machine.model
        self.q: list[Any] = [0.0] * model.nq
        self.v: list[Any] = [0.0] * model.nv
        for b in self.machine.bodies:
            bs = self.bodies[b.name]
            for c in b.free:
                j = b.joints[c] - 1
                self.q[j], self.v[j] = (bs.cx, bs.vx) if c == "x" else (bs.cz, bs.vz)
            j = b.joints["theta"] - 1
            self.q[j], self.v[j] = bs.theta, bs.omega

    def _dynamics(self, outputs: bool) -> None:
        mach, M, be = self.machine, self.M, self.backend
        model = mach.model
        nj = model.njoints - 1
        q, v = self.q, self.v
        tau: list[Any] = [0.0] * model.nv
        dyn: list[Any] = [0.0] * (10 * nj)
        fext: list[Any] = [0.0] * (6 * nj)
        for b in mach.bodies:
            bs = self.bodies[b.name]
            j = b.joints["theta"] - 1
            if b.torque_input:
                self.drive_torques[b.name] = self.p(f"{b.name}.torque")
            if b.name in self.drive_torques:
                tau[j] = b.sense * self.drive_torques[b.name]
            dyn[10 * j:10 * j + 10] = self.inertia_parameters(bs)
            co, si = M.cos(bs.theta), M.sin(bs.theta)
            f6 = [co * bs.fx - si * bs.fz, 0.0, si * bs.fx + co * bs.fz, 0.0, bs.ty, 0.0]
            extra = self.fext_extra.get(b.name)
            if extra is not None:
                f6 = [a + e for a, e in zip(f6, extra, strict=True)]
            fext[6 * j:6 * j + 6] = f6
        g = [0.0, 0.0, -self.gravity]
        self.dyn, self.fext, self.g = dyn, fext, g
        ddq = be.aba(q, v, tau, dyn, fext, g)
        for b in mach.bodies:
            for c in (*b.free, "theta"):
                if c == "theta" and b.prescribed:
                    continue
                j = b.joints[c] - 1
                self.set_rate(f"{b.name}.{c}", v[j])
                self.set_rate(f"{b.name}.{c}_dot", ddq[j])
        self.ddq = ddq
        if outputs:
            self._channels(ddq)

    def joint_velocity(self, body: str) -> list[Any]:
        """Spatial velocity ``[v; ω]`` of ``body`` in its frame (Pinocchio's kinematics)."""
        b = self.machine.body[body]
        return self.backend.velocity(self, b.joints["theta"] - 1)

    def _channels(self, ddq: list[Any]) -> None:
        mach, be = self.machine, self.backend
        acc = list(ddq)
        for b in mach.bodies:
            if b.prescribed:
                acc[b.joints["theta"] - 1] = self.bodies[b.name].alpha_prescribed
        tau = be.rnea(self.q, self.v, acc, self.dyn, self.fext, self.g)
        ch = self.set_channel
        for b in mach.bodies:
            bs, n, s = self.bodies[b.name], b.name, b.sense
            j = b.joints["theta"] - 1
            ch(f"{n}_speed", s * bs.omega)
            ch(f"{n}_angle", s * bs.theta)
            ch(f"{n}_accel", s * acc[j])
            if b.prescribed:
                ch(f"{n}_torque", s * tau[j])  # inverse dynamics (RNEA)
            elif b.name in self.drive_torques:
                ch(f"{n}_torque", self.drive_torques[b.name])  # the input or the controller
            else:
                ch(f"{n}_torque", s * bs.ty)
            for c in b.free:
                jc = b.joints[c] - 1
                ch(f"{n}_{c}", self.q[jc])
                ch(f"{n}_{c}_dot", self.v[jc])
                ch(f"{n}_{c}_accel", acc[jc])
            if b.kind == "roll":
                ch(f"{n}_radius", bs.r)
                ch(f"{n}_mass", bs.mass)
                ch(f"{n}_inertia", bs.inertia)
                ch(f"{n}_mass_rate", bs.mass_rate)
                ch(f"{n}_inertia_rate", bs.inertia_rate)
        for nip in mach.nips:
            ns = self.nips[nip.name]
            ch(f"{nip.name}_normal_force", ns.normal_force)
            ch(f"{nip.name}_friction_force", ns.friction_force)
            ch(f"{nip.name}_slip_velocity", ns.v_s)
            ch(f"{nip.name}_penetration", ns.delta)
        for w in mach.webs:
            a = self.bodies[w.entry.a.name]
            ch(f"{w.channel}web_speed", a.omega * a.r)
