"""A machine built from parts: one Pinocchio model, a named state layout, run-time
parameters, and its dynamics written once over a math namespace.

``Machine(scene)`` assembles the scene's body elements (:mod:`winder.parts`: drums, paper
rolls, riders, ...) and force elements (:mod:`winder.forces`), which the scene gives
(``scene.elements()``), and knows no kind of body (machines.md §1–§8):

- every body gets its joints in one ``pin.Model``, hung off its parent (the world unless
  the body declares another body): prismatic ``x`` and/or ``z`` where it is free, then a
  revolute joint about ``+y``; the first joint's placement holds the fixed coordinates of
  its centre;
- the state vector is named (:attr:`Machine.state_names`): ``BODY.x``, ``BODY.z``,
  ``BODY.theta`` for the joint coordinates, ``BODY.x_dot``, ``BODY.z_dot``,
  ``BODY.theta_dot`` for their rates, then what the bodies (``ROLL.radius``) and the
  force elements (``NIP.friction`` for slip relaxation) add; a body whose rotation is
  prescribed has no ``θ`` state;
- every scene number the dynamics reads is a named run-time parameter
  (:attr:`Machine.param_names`), so one compiled model serves every value of them;
- every result channel has a unit (:attr:`Machine.channel_units`); a flexible body keeps
  the body-level channels of its rigid self (:mod:`winder.model.whole_body`);
- :meth:`Machine.evaluate` is the dynamics: the bodies' kinematics and the nips', the
  force elements in the order their declarations give (:mod:`winder.model.element_order`),
  the variable-mass ``−Ẏv``, and Pinocchio's ABA (and RNEA for the drive torques) through a
  backend: numeric (``pin.aba``) or symbolic (CasADi, for the generated code).

Locked modes (:mod:`winder.model.locked_modes`): the integrators lock them within a step
and switch at located events.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from winder._schema import Channel
from winder.model.channels import BODY_CHANNELS, COORD_CHANNELS, NIP_CHANNELS, WEB_SPEED
from winder.model.element_order import order_elements
from winder.model.locked_modes import FREE, ModeKind, ModeSlot
from winder.model.slices import assemble_nips, entry_slice, entry_slices
from winder.model.spans import Span, line_spans
from winder.model.whole_body import declare_wholes, write_wholes

__all__ = ["Machine", "Nip", "Web", "Evaluation", "BodyState", "NipState"]

_COORDS = ("x", "z")


@dataclass
class Nip:
    """A nip between bodies ``a`` and ``b`` (machines.md §2); a slice of the scene's nip
    ``whole`` (one of ``count``, ``slice_length`` [m] long) against a flexible body
    (:mod:`winder.model.slices`)."""

    name: str
    a: Any
    b: Any
    part: Any
    index: int
    whole: str | None = None
    count: int = 1
    slice_length: float | None = None


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
    unwind: Any = None
    key: str = ""
    channel: str = ""
    span_key: str = ""
    span_channel: str = ""
    #: the nips its forces act at: ``[entry]``, or every slice into a flexible roll
    entries: list[Nip] = field(default_factory=list)
    #: its spans in order from the unwinding roll (:class:`Span`; none without a span)
    spans: list[Span] = field(default_factory=list)
    #: the bodies by name, for the rollers its spans end at (given by the machine)
    rollers: dict[str, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        if not self.entries:
            self.entries = [self.entry]
        if not self.spans and self.span is not None:
            self.spans = line_spans(self.part, self.unwind, self.rollers, self.span_key,
                                    self.span_channel)


class Machine:
    """The machine of a scene: model, layout, parameters, modes, channels, dynamics.

    Parameters
    ----------
    scene: a :class:`~winder.Scene` (its parts: ``drums``, ``rolls``, ``riders``,
        ``nips``, ``webs``; an object with only ``web`` is read as that one web); its
        ``elements()`` gives the body elements and the force elements.
    bodies, forces: the body elements (:class:`winder.parts.BodyElement`) and force
        elements (:class:`winder.forces.ForceElement`) instead of the scene's.

    ``bodies`` lists the body elements; ``webs`` the :class:`Web` s; ``web``, ``entry`` are
    the first web's part and entry nip, ``span``, ``unwind`` the first span and its
    unwinding roll (None without).
    """

    def __init__(self, scene: Any, *, bodies: Any = None, forces: Any = None) -> None:
        self.scene = scene
        effects = scene.effects
        if bodies is None or forces is None:
            own_bodies, own_forces = scene.elements()
            bodies = own_bodies if bodies is None else bodies
            forces = own_forces if forces is None else forces
        self.bodies: list[Any] = list(bodies)
        self.body = {b.name: b for b in self.bodies}
        self.nips = assemble_nips(scene.nips, self.body, self.bodies, Nip)
        self.nip = {n.name: n for n in self.nips}
        self._assemble_webs(scene)
        #: the bodies whose mass properties change in time (:attr:`BodyElement.variable_mass`)
        self.variable_bodies = [b for b in self.bodies if b.variable_mass]
        if self.span is not None and not effects.web_tension:
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
        self.channel_units: dict[str, str] = {}
        #: every channel's declaration and owner (:meth:`channel`), by its name
        self.channel_owners: dict[str, tuple[Channel, str]] = {}
        self.modes: list[ModeSlot] = []
        self.mode_names: list[str] = []
        self.switch_names: list[str] = []
        self._declare_base()
        self.forces = order_elements(list(forces))
        for f in self.forces:
            f.declare(self)
        #: the flexible bodies as wholes: their rigid selves' channels
        self.wholes = declare_wholes(self)
        self._index = {n: i for i, n in enumerate(self.state_names)}
        self._pindex = {n: i for i, n in enumerate(self.param_names)}

    def _assemble_webs(self, scene: Any) -> None:
        parts = tuple(getattr(scene, "webs", None) or ()) or \
            ((scene.web,) if getattr(scene, "web", None) is not None else ())
        spans = sum(getattr(w, "span", None) is not None for w in parts)
        self.webs: list[Web] = []
        for w in parts:
            name = getattr(w, "name", None) or w.entry_nip
            span = getattr(w, "span", None)
            several, spanned = len(parts) > 1, spans > 1
            self.webs.append(Web(name, w, entry_slice(self.nips, w.entry_nip), span,
                                 self.body[span.source] if span is not None else None,
                                 f"{name}." if several else "", f"{name}_" if several else "",
                                 f"{name}." if spanned else "", f"{name}_" if spanned else "",
                                 entry_slices(self.nips, w.entry_nip), rollers=self.body))
        first = self.webs[0] if self.webs else None
        self.web = first.part if first is not None else None
        self.entry = first.entry if first is not None else None
        spanned_web = next((w for w in self.webs if w.span is not None), None)
        self.span = spanned_web.span if spanned_web is not None else None
        self.unwind = spanned_web.unwind if spanned_web is not None else None

    # ---- structure --------------------------------------------------------------------
    def _build_model(self) -> pin.Model:
        """One ``pin.Model``: each body's joints hung off its parent's last joint (the
        world for ``parent = None``), its centre in the parent's joint frame."""
        model = pin.Model()
        model.name = self.scene.name
        for b in self.bodies:
            parent = 0 if b.parent is None else self.body[b.parent].joints["theta"]
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

    def channel(self, declared: Channel, owner: str = "") -> str:
        """Register the result channel ``declared`` of ``owner`` (a part's name, or a web's
        prefix: :meth:`~winder._schema.Channel.of`) in its declared unit (SI, machines.md
        §9); return its name."""
        if not isinstance(declared, Channel):
            raise TypeError(f"Machine.channel: a Channel declaration, got {declared!r}")
        name = declared.of(owner)
        if name not in self.channel_names:
            self.channel_names.append(name)
            self.channel_units[name] = declared.unit
            self.channel_owners[name] = (declared, owner)
        return name

    def mode(self, name: str, switches: tuple[str, ...], kind: ModeKind, *, owner: str,
             state: str | None = None, param: str | None = None) -> None:
        """Register a locked mode slot of ``kind`` belonging to the part ``owner`` and its
        switching functions (see :class:`~winder.model.locked_modes.ModeSlot`)."""
        mode = ModeSlot(name, kind, owner, tuple(switches), state, param)
        self.modes.append(mode)
        self.mode_names.append(name)
        self.switch_names.extend(switches)

    def mode_slots(self, kind: ModeKind) -> list[int]:
        """Positions of the mode slots of ``kind``."""
        return [i for i, m in enumerate(self.modes) if m.kind is kind]

    def _declare_base(self) -> None:
        # joint coordinates, then their rates
        qs = [(b, c) for b in self.bodies for c in (*b.free, "theta")
              if not (c == "theta" and b.prescribed)]
        for b, c in qs:
            init = 0.0 if c == "theta" else (b.centre[0] if c == "x" else b.centre[1])
            self.state(f"{b.name}.{c}", init)
        for b, c in qs:
            self.state(f"{b.name}.{c}_dot", b.initial_rate(c))
        for b in self.bodies:
            b.declare(self)
        for b in self.bodies:
            for ch in BODY_CHANNELS:
                self.channel(ch, b.name)
            for c in b.free:
                for ch in COORD_CHANNELS[c]:
                    self.channel(ch, b.name)
            for ch in b.CHANNELS:
                self.channel(ch, b.name)
        for n in self.nips:
            for ch in NIP_CHANNELS:
                self.channel(ch, n.name)
        for w in self.webs:
            self.channel(WEB_SPEED, w.channel)

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
        the parameter, mode, switch and channel names, the bodies and force elements."""
        h = hashlib.sha256()
        for i in range(1, self.model.njoints):
            placement = self.model.jointPlacements[i]
            h.update(f"{self.model.names[i]}:{self.model.joints[i].shortname()}:"
                     f"{self.model.parents[i]}:{placement.translation.tolist()}".encode())
        for group in (self.state_names, self.param_names, self.mode_names,
                      self.switch_names, self.channel_names,
                      [f"{f.name}:{f.structure_tag(self)}" for f in self.forces],
                      [f"{b.name}:{b.structure_tag()}" for b in self.bodies],
                      [self.span.source if self.span is not None else ""],
                      [f"{n.name}:{n.a.name}:{n.b.name}" for n in self.nips],
                      [self.entry.name if self.entry else ""],
                      *([f"{w.name}:{w.entry.name}:{w.unwind.name if w.unwind else ''}"
                         for w in self.webs],) * (len(self.webs) > 1)):
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
    ``r`` and rate ``r_dot``; ``mass, inertia, dm_dr, dJ_dr``; the centre-of-mass offset
    ``com_offset`` [m] on its own ``x`` axis; force accumulators ``fx, fz`` [N] and ``ty``
    (about ``+y`` through the centre) [N·m]."""

    __slots__ = ("body", "cx", "cz", "vx", "vz", "theta", "omega", "alpha_prescribed", "r",
                 "r_dot", "mass", "inertia", "dm_dr", "dJ_dr", "fx", "fz", "ty", "com_offset")

    def __init__(self, body: Any) -> None:
        self.body = body
        self.fx = self.fz = self.ty = 0.0
        self.alpha_prescribed = None
        self.com_offset = 0.0

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
    """Everything one evaluation of the machine computes, shared by the body and force
    elements.

    ``mathns`` the math namespace (:mod:`winder.model.mathns`); ``bodies``/``nips`` the
    kinematics by name; ``rates`` the state derivatives; ``channels`` the result channels;
    ``switches`` the switching functions (> 0: the other side of the mode). The quantities
    the force elements declare they provide (``"gravity"``, ``"drive_torque"``,
    ``"span_rate"``, ``"spatial_force"``, ...) go through :meth:`provide` and
    :meth:`provided`.
    """

    def __init__(self, machine: Machine, backend: Any, t: Any, x: Any, p: Any, modes: Any,
                 *, static: bool) -> None:
        self.machine, self.backend, self.mathns = machine, backend, backend.mathns
        self.t, self._x, self._p, self.modes = t, x, p, modes
        self.static = static
        self.rates: dict[str, Any] = {}
        self.channels: dict[str, Any] = {}
        self.switches: dict[str, Any] = {}
        self.bodies: dict[str, BodyState] = {}
        self.nips: dict[str, NipState] = {}
        self._provided: dict[str, dict[str, Any]] = {}

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

    def output(self, declared: Channel, owner: str, value: Any) -> None:
        """Write the channel ``declared`` of ``owner`` (its name
        :meth:`~winder._schema.Channel.of`, as :meth:`Machine.channel` registered it)."""
        self.channels[declared.of(owner)] = value

    def provide(self, quantity: str, key: str, value: Any) -> None:
        """Write ``quantity`` of ``key`` (a body's, a web's; ``""`` for the machine's), as
        the element declared in its ``provides``."""
        self._provided.setdefault(quantity, {})[key] = value

    def provided(self, quantity: str, key: str = "", default: Any = None) -> Any:
        """``quantity`` of ``key`` as some element provided it, else ``default``."""
        return self._provided.get(quantity, {}).get(key, default)

    def add_force(self, body: str, fx: Any, fz: Any, px: Any = 0.0, pz: Any = 0.0) -> None:
        """World force ``(fx, fz)`` [N] on ``body`` at ``(px, pz)`` relative to its centre
        [m]."""
        bs = self.bodies[body]
        bs.fx = bs.fx + fx
        bs.fz = bs.fz + fz
        bs.ty = bs.ty + (pz * fx - px * fz)

    def add_torque(self, body: str, ty: Any) -> None:
        """Torque ``ty`` [N·m] about ``+y`` on ``body`` (a force couple: part of its
        ``NAME_torque`` channel, as :meth:`add_force`'s moments are)."""
        bs = self.bodies[body]
        bs.ty = bs.ty + ty

    def add_spatial_force(self, body: str, f: list[Any]) -> None:
        """Add to the ``"spatial_force"`` of ``body``: ``[f; τ]`` in its joint frame (e.g.
        ``−Ẏv``)."""
        old = self.provided("spatial_force", body)
        self.provide("spatial_force", body,
                     f if old is None else [a + b for a, b in zip(old, f, strict=True)])

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
        for b in self.machine.bodies:
            bs = BodyState(b)
            n = b.name
            bs.cx = self.x(f"{n}.x") if "x" in b.free else b.centre[0]
            bs.cz = self.x(f"{n}.z") if "z" in b.free else b.centre[1]
            bs.vx = self.x(f"{n}.x_dot") if "x" in b.free else 0.0
            bs.vz = self.x(f"{n}.z_dot") if "z" in b.free else 0.0
            if not b.prescribed:  # else the body's kinematics sets them
                bs.theta = self.x(f"{n}.theta")
                bs.omega = self.x(f"{n}.theta_dot")
            b.kinematics(self, bs)
            self.bodies[n] = bs

    def _nip_kinematics(self) -> None:
        mathns = self.mathns
        for nip in self.machine.nips:
            a, b = self.bodies[nip.a.name], self.bodies[nip.b.name]
            ns = NipState(nip)
            dx, dz = b.cx - a.cx, b.cz - a.cz
            dist = mathns.sqrt(dx * dx + dz * dz)
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
        time derivative ``dY/dr · ṙ``). Centre of mass at ``(com_offset, 0, 0)`` in the
        body frame (imbalance); the polar inertia ``J`` is about the axis, the transverse
        one the body's (:meth:`~winder.parts.BodyElement.transverse_inertia`)."""
        if rate:
            m, J = bs.mass_rate, bs.inertia_rate
        else:
            m, J = bs.mass, bs.inertia
        it = bs.body.transverse_inertia(self, m, J)
        return [m, m * bs.com_offset, 0.0, 0.0, it, 0.0, J, 0.0, 0.0, it]

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
        mach, mathns, be = self.machine, self.mathns, self.backend
        model = mach.model
        nj = model.njoints - 1
        q, v = self.q, self.v
        tau: list[Any] = [0.0] * model.nv
        dyn: list[Any] = [0.0] * (10 * nj)
        fext: list[Any] = [0.0] * (6 * nj)
        for b in mach.bodies:
            bs = self.bodies[b.name]
            j = b.joints["theta"] - 1
            own = b.drive_torque(self)
            if own is not None:
                self.provide("drive_torque", b.name, own)
            drive = self.provided("drive_torque", b.name)
            if drive is not None:
                tau[j] = b.sense * drive
            dyn[10 * j:10 * j + 10] = self.inertia_parameters(bs)
            co, si = mathns.cos(bs.theta), mathns.sin(bs.theta)
            f6 = [co * bs.fx - si * bs.fz, 0.0, si * bs.fx + co * bs.fz, 0.0, bs.ty, 0.0]
            extra = self.provided("spatial_force", b.name)
            if extra is not None:
                f6 = [a + e for a, e in zip(f6, extra, strict=True)]
            fext[6 * j:6 * j + 6] = f6
        g = [0.0, 0.0, -self.provided("gravity", default=0.0)]
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
        out = self.output
        speed, angle, torque, accel = BODY_CHANNELS
        for b in mach.bodies:
            bs, n, s = self.bodies[b.name], b.name, b.sense
            j = b.joints["theta"] - 1
            out(speed, n, s * bs.omega)
            out(angle, n, s * bs.theta)
            out(accel, n, s * acc[j])
            drive = self.provided("drive_torque", b.name)
            if b.prescribed:
                out(torque, n, s * tau[j])  # inverse dynamics (RNEA)
            elif drive is not None:
                out(torque, n, drive)  # the input or the controller
            else:
                out(torque, n, s * bs.ty)
            for c in b.free:
                jc = b.joints[c] - 1
                position, rate, acceleration = COORD_CHANNELS[c]
                out(position, n, self.q[jc])
                out(rate, n, self.v[jc])
                out(acceleration, n, acc[jc])
            b.outputs(self, bs)
        normal, friction, slip, penetration = NIP_CHANNELS
        for nip in mach.nips:
            ns = self.nips[nip.name]
            out(normal, nip.name, ns.normal_force)
            out(friction, nip.name, ns.friction_force)
            out(slip, nip.name, ns.v_s)
            out(penetration, nip.name, ns.delta)
        for w in mach.webs:
            a = self.bodies[w.entry.a.name]
            out(WEB_SPEED, w.channel, a.omega * a.r)
        write_wholes(self, mach.wholes)
