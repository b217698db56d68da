"""Oracles for the machine engine (issue #14): the generated C against Pinocchio on
numbers, the route-"py" algorithms against Pinocchio, the exact Jacobian against finite
differences, the static valley in closed form, energy and momentum conservation, and the
drive torques against their expressions.

Every tolerance is about 10x the error measured when the test was written (in the
comment next to it). The generated code goes to a temporary cache of this module, never
the user's.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

import machines as mc
import numpy as np
import pinocchio as pin
import pytest

from winder.model.backends import NumericBackend
from winder.model.locked_modes import AT_CORE, AUTO, CORE_AUTO, FREE, IN_CONTACT, WINDING
from winder.model.machine import Machine

casadi = pytest.importorskip("casadi")


@pytest.fixture(scope="module", autouse=True)
def _private_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("WINDER_CACHE_DIR", str(tmp_path_factory.mktemp("winder-cache")))
        yield


def _generate(machine: Machine) -> Any:
    from winder.model.codegen import generate

    return generate(machine)


# ---- random states -------------------------------------------------------------------------
def _touching_centre(m: Machine, x: np.ndarray, body: str) -> tuple[float, float]:
    """A centre of ``body`` (a roll or rider) touching what carries it, at the radii and
    positions in ``x``: the drums below a roll (one: on top; two: in the valley), the roll
    below a rider."""
    b = m.body[body]
    r = x[m.index(f"{body}.radius")] if b.table == "roll" else b.part.radius
    if b.table == "rider":
        ridden = m.body[b.part.rides]
        cz = x[m.index(f"{ridden.name}.z")] if "z" in ridden.free else ridden.centre[1]
        return b.part.x, cz + x[m.index(f"{ridden.name}.radius")] + r
    drums = [n.a for n in m.nips if n.b is b and n.a.table == "drum"]
    if len(drums) == 1:
        d = drums[0]
        return d.centre[0], d.centre[1] + d.part.radius + r
    (d1, d2) = drums[:2]
    half = 0.5 * abs(d2.centre[0] - d1.centre[0])
    R = d1.part.radius + r
    return 0.5 * (d1.centre[0] + d2.centre[0]), d1.centre[1] + math.sqrt(R * R - half * half)


def random_state(m: Machine, rng: np.random.Generator) -> tuple[float, np.ndarray, np.ndarray]:
    """``(t, x, modes)``: radii between the core and 0.3 m (sometimes exactly at the core
    or below it), centres within ±0.2 mm of touching (nips open and closed), centre rates
    ±2 cm/s (δ̇ of both signs), spins up to ±1000 rad/s (slip of both signs), friction
    states ±2 kN, modes drawn from all three of each kind; ``t`` on the ramp and after."""
    x = np.array(m.state_initial, dtype=float)
    for b in m.variable_bodies:
        rc = b.part.core_radius
        u = rng.uniform()
        x[m.index(f"{b.name}.radius")] = rc - 1e-4 if u < 0.1 else (
            rc if u < 0.2 else rng.uniform(rc, 0.3))
    for b in m.bodies:
        if b.free:
            cx, cz = _touching_centre(m, x, b.name)
            for c, nominal in (("x", cx), ("z", cz)):
                if c in b.free:
                    x[m.index(f"{b.name}.{c}")] = nominal + rng.uniform(-2e-4, 2e-4)
                    x[m.index(f"{b.name}.{c}_dot")] = rng.uniform(-0.02, 0.02)
        if not b.prescribed:
            x[m.index(f"{b.name}.theta")] = rng.uniform(-math.pi, math.pi)
            x[m.index(f"{b.name}.theta_dot")] = rng.uniform(-1000.0, 1000.0)
    for n in m.nips:
        if f"{n.name}.friction" in m.state_names:
            x[m.index(f"{n.name}.friction")] = rng.uniform(-2000.0, 2000.0)
    modes = np.array([rng.choice([AUTO, FREE, IN_CONTACT]) if n.endswith(".contact")
                      else rng.choice([CORE_AUTO, CORE_AUTO, WINDING, AT_CORE])
                      for n in m.mode_names], dtype=float)
    return float(rng.uniform(0.0, 120.0)), x, modes


def _numeric(m: Machine, be: NumericBackend, t: float, x: np.ndarray, p: np.ndarray,
             modes: np.ndarray) -> tuple[Any, dict[str, np.ndarray]]:
    ev = m.evaluate(be, t, x, p, modes)
    return ev, {
        "rhs": np.array([float(ev.rates[n]) for n in m.state_names]),
        "out": np.array([float(ev.channels[n]) for n in m.channel_names]),
        "sw": np.array([float(ev.switches[n]) for n in m.switch_names]),
    }


# ---- 1. generated code against the numeric Pinocchio path -----------------------------------
VARIANTS: dict[str, Any] = {
    "two_drum": lambda: mc.two_drum(),
    "two_drum_torque_hc": lambda: mc.two_drum(drive="torque", law="hunt_crossley"),
    "single_drum_z": lambda: mc.single_drum(),
    "single_drum_xz_torque_hc": lambda: mc.single_drum(drive="torque", law="hunt_crossley",
                                                       free=("x", "z")),
    **{f"two_drum_no_{e}": (lambda e=e: mc.two_drum(**{e: False})) for e in mc.EFFECTS},
    "two_drum_no_friction_relaxation": lambda: mc.two_drum(slip_relaxation=False,
                                                           imbalance=False),
}


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_generated_equals_pinocchio_path(variant: str) -> None:
    """``rhs``, ``out`` and ``sw`` of the generated C equal the numeric path (``pin.aba``,
    ``pin.rnea`` on floats) on random states, per component relative to its largest size
    over the samples. Every region is sampled: nips open and closed, δ̇ and slip of both
    signs, each contact and core mode, a roll at its core (ṙ = 0)."""
    m = Machine(VARIANTS[variant]())
    g = _generate(m)
    be = NumericBackend(m.model)
    p = m.parameters()
    rng = np.random.default_rng(zlib.crc32(variant.encode()))
    diff = {k: [] for k in ("rhs", "out", "sw")}
    size = {k: [] for k in ("rhs", "out", "sw")}
    seen: set[tuple[str, ...]] = set()
    for _ in range(300):
        t, x, modes = random_state(m, rng)
        ev, num = _numeric(m, be, t, x, p, modes)
        for k in diff:
            gen = g.call(k, t, x, p, modes)
            diff[k].append(np.abs(gen - num[k]))
            size[k].append(np.abs(num[k]))
        for ns in ev.nips.values():
            seen.add(("open" if ns.delta < 0 else "closed",))
            seen.add(("delta_dot", str(np.sign(float(ns.delta_dot)))))
            seen.add(("slip", str(np.sign(float(ns.v_s)))))
            seen.add(("contact mode", str(int(ns.mode))))
            seen.add(("pressing" if float(ns.normal_force) > 0 else "no force",))
        for b in m.variable_bodies:
            seen.add(("core mode", str(int(ev.mode(f"{b.name}.core")))))
            seen.add(("r_dot", "zero" if ev.bodies[b.name].r_dot == 0.0 else "winding"))
    modes_drawn = (AUTO, FREE, IN_CONTACT) if m.scene.effects.contact else (FREE,)
    expected = {("open",), ("closed",), ("no force",),
                *((("pressing",),) if m.scene.effects.contact else ()),
                *(("delta_dot", s) for s in ("1.0", "-1.0")),
                *(("slip", s) for s in ("1.0", "-1.0")),
                *(("contact mode", str(k)) for k in modes_drawn),
                *(("core mode", str(k)) for k in (CORE_AUTO, WINDING, AT_CORE)),
                ("r_dot", "zero"), ("r_dot", "winding")}
    assert expected <= seen, f"regions not sampled: {expected - seen}"
    for k in diff:
        d, s = np.array(diff[k]), np.array(size[k])
        rel = d.max(axis=0) / np.maximum(s.max(axis=0), 1e-300)
        names = {"rhs": m.state_names, "out": m.channel_names, "sw": m.switch_names}[k]
        worst = int(np.argmax(rel)) if rel.size else 0
        # measured over all variants: 5.0e-16 (rhs), 2.8e-15 (out), 0 (sw)
        assert rel.size == 0 or rel.max() < 3e-14, \
            f"{k} {names[worst]}: relative error {rel.max():.3g}"


# ---- 2. route "py" against Pinocchio ----------------------------------------------------------
_JOINTS = (pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ, pin.JointModelRX,
           pin.JointModelRY, pin.JointModelRZ,
           lambda: pin.JointModelRevoluteUnaligned(np.array([0.6, -0.48, 0.64])),
           lambda: pin.JointModelPrismaticUnaligned(np.array([0.0, 0.8, -0.6])))


def _random_model(rng: np.random.Generator, n: int) -> pin.Model:
    """A tree of ``n`` 1-DoF joints of every kind, random placements and inertias (centre
    of mass off the joint)."""
    model = pin.Model()
    for i in range(n):
        parent = int(rng.integers(0, i + 1))
        jm = _JOINTS[int(rng.integers(0, len(_JOINTS)))]()
        j = model.addJoint(parent, jm, pin.SE3.Random(), f"j{i}")
        model.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    return model


@pytest.mark.parametrize("seed", range(6))
def test_route_py_equals_pinocchio(seed: int) -> None:
    """``SpatialFunctions.aba/rnea/vel`` on numbers equal ``pin.aba``/``pin.rnea``/
    ``forwardKinematics`` with random ``q, v, τ``, inertias, ``fext`` and gravity."""
    import casadi as ca

    from winder.model.spatial import SpatialFunctions

    rng = np.random.default_rng(seed)
    pin.seed(seed)
    model = _random_model(rng, 2 + seed)
    data = model.createData()
    nv, nj = model.nv, model.njoints - 1
    f = SpatialFunctions(model)
    q, v, u = (ca.SX.sym(s, nv) for s in "qvu")
    dyn, fext, g = ca.SX.sym("dyn", 10 * nj), ca.SX.sym("fext", 6 * nj), ca.SX.sym("g", 3)
    F = ca.Function("F", [q, v, u, dyn, fext, g],
                    [f.aba(q, v, u, dyn, fext, g), f.rnea(q, v, u, dyn, fext, g),
                     ca.vertcat(*f.vel(q, v))])
    worst = 0.0
    for _ in range(10):
        qn, vn, un = (rng.uniform(-2, 2, nv) for _ in range(3))
        gn = rng.normal(0.0, 5.0, 3)
        inertias = [pin.Inertia.Random() for _ in range(nj)]
        forces = [pin.Force.Random() for _ in range(nj)]
        for i, Y in enumerate(inertias):
            model.inertias[i + 1] = Y
        model.gravity = pin.Motion(np.concatenate([gn, np.zeros(3)]))
        fx = pin.StdVec_Force()
        fx.append(pin.Force.Zero())
        for fo in forces:
            fx.append(fo)
        dn = np.concatenate([Y.toDynamicParameters() for Y in inertias])
        fn = np.concatenate([fo.vector for fo in forces])
        a_py, tau_py, vel_py = (np.array(o).ravel() for o in F(qn, vn, un, dn, fn, gn))
        a_ref = pin.aba(model, data, qn, vn, un, fx)
        tau_ref = pin.rnea(model, data, qn, vn, un, fx)
        pin.forwardKinematics(model, data, qn, vn)
        vel_ref = np.concatenate([data.v[i].vector for i in range(1, model.njoints)])
        for got, ref in ((a_py, a_ref), (tau_py, tau_ref), (vel_py, vel_ref)):
            worst = max(worst, np.max(np.abs(got - ref)) / max(1.0, np.max(np.abs(ref))))
    # measured: 1.7e-15 (largest over the seeds)
    assert worst < 2e-14


# ---- 3. exact Jacobian against central differences --------------------------------------------
@pytest.mark.parametrize("variant", ["two_drum", "single_drum_xz_torque_hc"])
def test_jacobian_against_finite_differences(variant: str) -> None:
    """``jac`` equals central differences of ``rhs`` away from the kinks of the laws (each
    contact mode locked IN_CONTACT or FREE, the core WINDING, radii off the load points).
    Error per entry scaled by the state's size ``s_k = max(|x_k|, 1e-3)``, relative to the
    row's largest scaled entry."""
    m = Machine(VARIANTS[variant]())
    g = _generate(m)
    p = m.parameters()
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(20):
        t, x, modes = random_state(m, rng)
        for b in m.variable_bodies:
            x[m.index(f"{b.name}.radius")] = rng.uniform(0.06, 0.29)
        modes = np.array([rng.choice([IN_CONTACT, FREE]) if n.endswith(".contact")
                          else WINDING for n in m.mode_names], dtype=float)
        J = g.call("jac", t, x, p, modes)
        s = np.maximum(np.abs(x), 1e-3)
        Jfd = np.empty_like(J)
        for k in range(len(x)):
            h = 1e-5 * s[k]
            a, b = x.copy(), x.copy()
            a[k] += h
            b[k] -= h
            Jfd[:, k] = (g.call("rhs", t, a, p, modes) - g.call("rhs", t, b, p, modes)) / (2 * h)
        row = np.maximum((np.abs(J) * s).max(axis=1, keepdims=True), 1e-300)
        worst = max(worst, float(np.max(np.abs(J - Jfd) * s / row)))
    # measured: 6.0e-9 (two_drum), 3.2e-8 (single drum, x and z, Hunt-Crossley)
    assert worst < 3e-7


# ---- 4. the symmetric valley at rest ----------------------------------------------------------
def test_symmetric_valley_static_balance() -> None:
    """Two drums at x = ∓0.525, the set free in x and z with a rider on top, no web
    tension, no imbalance: the set sits at x = 0, each drum nip carries
    ``(m g + F_rider)/(2 cos α)`` and the rider nip ``m_rider g + L q(r)``."""
    from winder.solve.equilibrium import static_state

    sc = mc.two_drum(imbalance=False, values={"web.tension": 0.0})
    m = Machine(sc)
    eq = static_state(m)
    x = eq.state
    be = NumericBackend(m.model)
    modes = np.full(len(m.mode_names), float(AUTO))
    modes[[i for i, n in enumerate(m.mode_names) if n.endswith(".core")]] = CORE_AUTO
    ev = m.evaluate(be, 0.0, x, m.parameters(), modes)
    ch = ev.channels
    roll, rd = sc.rolls[0], sc.riders[0]
    g = sc.scene.gravity
    r = x[m.index("set.radius")]
    m_set = roll.core_mass + math.pi * roll.density * roll.width * (r * r - roll.core_radius ** 2)
    (r0, q0), (r1, q1) = rd.load
    q = q0 + (q1 - q0) * (r - r0) / (r1 - r0)
    rider_nip = rd.mass * g + roll.width * q
    cos_a = x[m.index("set.z")] / math.hypot(0.525, x[m.index("set.z")])
    drum_nip = (m_set * g + rider_nip) / (2.0 * cos_a)
    # measured: x 3e-43 m; nips 1.3e-14 (rider), 2.5e-14 (drums) relative; residual 7.5e-15
    # of the largest force; accelerations 9.2e-12 m/s²
    assert abs(x[m.index("set.x")]) < 1e-12
    assert ch["rider_nip_normal_force"] == pytest.approx(rider_nip, rel=3e-13)
    assert ch["front_nip_normal_force"] == pytest.approx(drum_nip, rel=3e-13)
    assert ch["rear_nip_normal_force"] == pytest.approx(drum_nip, rel=3e-13)
    assert eq.residual < 1e-6 * eq.scale
    # the balance is at rest: no acceleration of the free coordinates
    for c in ("set.x", "set.z", "rider.z"):
        assert abs(ev.rates[f"{c}_dot"]) < 1e-10


# ---- nip and web forces against the spec's formulas --------------------------------------------
def _spec_body(m: Machine, b: Any, t: float,
               x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """Centre [m], centre velocity [m/s], joint rate [rad/s], radius [m] and its rate [m/s]
    of body ``b`` from the state, by the spec (machines.md §1, §6; winder-model §2)."""
    c = np.array([x[m.index(f"{b.name}.{k}")] if k in b.free else b.centre[i]
                  for i, k in enumerate("xz")])
    cd = np.array([x[m.index(f"{b.name}.{k}_dot")] if k in b.free else 0.0 for k in "xz"])
    if b.prescribed:
        dr = b.part.drive
        w = b.sense * dr.ratio * min(dr.web_acceleration * t, dr.web_speed) / b.part.radius
    else:
        w = x[m.index(f"{b.name}.theta_dot")]
    if b.table == "roll":
        return c, cd, w, x[m.index(f"{b.name}.radius")], \
            b.part.caliper / (2 * math.pi) * b.sense * w
    return c, cd, w, b.part.radius, 0.0


@pytest.mark.parametrize("variant", ["two_drum", "single_drum_xz_torque_hc"])
def test_nip_channels_against_the_spec_formulas(variant: str) -> None:
    """machines.md §2 and winder-model §4 written out here from the state: ``δ``, ``δ̇``,
    ``v_s``, ``F_n`` (clamped law) and ``F_t = μ F_n tanh(v_s/v_ref)`` equal the generated
    channels (slip relaxation off, contact modes AUTO, core WINDING)."""
    make = VARIANTS[variant]
    sc = make()
    sc.effects.slip_relaxation = False
    m = Machine(sc)
    g = _generate(m)
    p = m.parameters()
    rng = np.random.default_rng(14)
    worst, seen = 0.0, set()
    for _ in range(200):
        t, x, _ = random_state(m, rng)
        modes = np.array([AUTO if n.endswith(".contact") else WINDING for n in m.mode_names],
                         dtype=float)
        out = dict(zip(m.channel_names, g.call("out", t, x, p, modes), strict=True))

        for nip in m.nips:
            ca_, cad, wa, ra, rda = _spec_body(m, nip.a, t, x)
            cb, cbd, wb, rb, rdb = _spec_body(m, nip.b, t, x)
            d = cb - ca_
            n = d / np.linalg.norm(d)
            tt = np.array([n[1], -n[0]])
            delta = ra + rb - np.linalg.norm(d)
            ddot = rda + rdb - n @ (cbd - cad)
            vs = (cad @ tt + wa * ra) - (cbd @ tt - wb * rb)
            c = nip.part.contact
            if c.law == "linear":
                fu = c.stiffness * delta + c.damping * ddot
            else:
                fu = c.stiffness * np.sign(delta) * abs(delta) ** c.exponent \
                    * (1 + c.hc_damping * ddot)
            fn = max(fu, 0.0) if delta > 0 else 0.0
            f = nip.part.friction
            ft = f.mu * fn * math.tanh(vs / f.slip_velocity)
            seen.add((delta > 0, ddot > 0, fn > 0))
            for ch, val, scale in (("penetration", delta, 1e-3), ("slip_velocity", vs, 1.0),
                                   ("normal_force", fn, c.stiffness * 1e-4 ** (
                                       c.exponent if c.law != "linear" else 1.0)),
                                   ("friction_force", ft, c.stiffness * 1e-4 ** (
                                       c.exponent if c.law != "linear" else 1.0))):
                worst = max(worst, abs(out[f"{nip.name}_{ch}"] - val) / max(abs(val), scale))
    assert {(True, True, True), (True, False, True), (False, True, False),
            (False, False, False)} <= seen
    # measured: 0 (two_drum), 3.0e-16 (single drum, Hunt-Crossley)
    # the forces scale with k δ, and δ = r_a + r_b − |d| carries the round-off of |d| (one
    # ulp of about 1 m, 1.1e-16 m, against the scale 1e-4 m): measured 1.7e-12 with
    # CasADi 3.8.2 and NumPy 2.4.6 (the two compute |d| in another order; 0 before)
    assert worst < 2e-11


def test_web_forces_on_the_roll() -> None:
    """machines.md §3 on a roll on top of one drum (``n = +z``, ``t = +x``): the tension
    adds ``−T`` along x and ``+r T`` about +y (joint sense); the web momentum adds
    ``ṁ u_a`` along x and ``−r ṁ u_a`` about +y, ``u_a = Ω R``."""
    vals = {"roll.com_offset": 0.0, "roll.caliper": 1e-3}
    base = Machine(mc.single_drum(free=("x", "z"), web_momentum=False, values=vals))
    mom = Machine(mc.single_drum(free=("x", "z"), values=vals))
    gb, gm = _generate(base), _generate(mom)
    x = np.array(base.state_initial, dtype=float)
    r = 0.2
    x[base.index("roll.radius")] = r
    x[base.index("roll.z")] = 0.5 + r - 1e-4
    x[base.index("roll.theta_dot")] = -30.0
    modes = np.array([AUTO, WINDING] if base.mode_names[0].endswith(".contact")
                     else [WINDING, AUTO], dtype=float)
    t = 10.0
    p0 = base.parameters()
    p1 = p0.copy()
    T = 700.0
    p1[base.param_index("web.tension")] = T
    p0[base.param_index("web.tension")] = 0.0
    roll = mom.body["roll"].part
    k = math.pi * roll.density * roll.width
    mass = roll.core_mass + k * (r * r - roll.core_radius ** 2)
    J = roll.core_inertia + 0.5 * k * (r ** 4 - roll.core_radius ** 4)
    ia, ith = base.index("roll.x_dot"), base.index("roll.theta_dot")
    d_tension = gb.call("rhs", t, x, p1, modes) - gb.call("rhs", t, x, p0, modes)
    mdot = 2 * k * r * roll.caliper / (2 * math.pi) * 30.0  # ṙ = h/2π · speed, speed 30
    drive = mom.body["drum"].part.drive
    u_a = drive.web_acceleration * t  # Ω R on the ramp
    d_mom = gm.call("rhs", t, x, p0, modes) - gb.call("rhs", t, x, p0, modes)
    got = np.array([d_tension[ia] * mass, d_tension[ith] * J, d_mom[ia] * mass, d_mom[ith] * J])
    want = np.array([-T, r * T, mdot * u_a, -r * mdot * u_a])
    # measured: 4.4e-16 relative
    np.testing.assert_allclose(got, want, rtol=5e-15)


def test_imbalanced_roll_against_lagrange() -> None:
    """A roll free in z only, its centre of mass at ``(e, 0, 0)`` in its frame (joint about
    +y: world offset ``(e cos θ, −e sin θ)``), gravity, constant radius (caliper 0). From
    ``T = ½ m ż² − m e cos θ ż θ̇ + ½ J θ̇²`` (``J`` about the axis) and
    ``V = m g (z − e sin θ)``:
    ``m z̈ − m e cos θ θ̈ = −m g − m e sin θ θ̇²``, ``−m e cos θ z̈ + J θ̈ = m g e cos θ``."""
    e = 0.02
    sc = mc.free_roll(free=("z",), contact=False, slip_relaxation=False,
                      values={"roll.caliper": 0.0, "roll.com_offset": e,
                              "roll.initial_radius": 0.3})
    m = Machine(sc)
    g = _generate(m)
    p = m.parameters()
    roll = sc.rolls[0]
    k = math.pi * roll.density * roll.width
    r, rc = roll.initial_radius, roll.core_radius
    mass = roll.core_mass + k * (r * r - rc * rc)
    J = roll.core_inertia + 0.5 * k * (r ** 4 - rc ** 4)
    grav = sc.scene.gravity
    rng = np.random.default_rng(7)
    modes = np.full(len(m.mode_names), float(WINDING))
    worst = 0.0
    for _ in range(50):
        x = np.array(m.state_initial, dtype=float)
        th, w = rng.uniform(-math.pi, math.pi), rng.uniform(-50.0, 50.0)
        x[m.index("roll.theta")], x[m.index("roll.theta_dot")] = th, w
        x[m.index("roll.z_dot")] = rng.uniform(-1.0, 1.0)
        A = np.array([[mass, -mass * e * math.cos(th)], [-mass * e * math.cos(th), J]])
        b = np.array([-mass * grav - mass * e * math.sin(th) * w * w,
                      mass * grav * e * math.cos(th)])
        want = np.linalg.solve(A, b)
        dx = g.call("rhs", 0.0, x, p, modes)
        got = np.array([dx[m.index("roll.z_dot")], dx[m.index("roll.theta_dot")]])
        worst = max(worst, float(np.max(np.abs(got - want) / np.abs(want).max())))
    # measured: 1.1e-15
    assert worst < 1e-14


# ---- integration helper ----------------------------------------------------------------------
def _integrate(system: Any, y0: np.ndarray, t_out: np.ndarray, rtol: float,
               atol: float) -> np.ndarray:
    from winder.solve import integrators as integ

    y = np.array(y0, dtype=float)
    Y = np.empty((len(y), len(t_out)))
    stats = np.zeros(5, np.int64)
    t, h, k = float(t_out[0]), 0.0, 0
    modes = system.modes.copy()
    while t < t_out[-1]:
        status, t, h, k = system.kernels.dopri5(system.fns, system.table, t,
                                                float(t_out[-1]), y, system.params, modes,
                                                rtol, atol, h, math.inf, t_out, Y, k, 10 ** 8,
                                                stats)
        assert status in (integ.DONE, integ.PAUSED), status
    return Y


def _energy(m: Machine, t: float, x: np.ndarray, p: np.ndarray,
            loads: dict[str, float]) -> float:
    """Kinetic and gravity energy of every body (Pinocchio, the inertias of the model at
    this state), spring energy ``k δ²/2`` of the closed nips, and ``F z`` of constant
    vertical loads ``loads`` [N] by body."""
    be = NumericBackend(m.model)
    modes = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                     dtype=float)
    ev = m.evaluate(be, t, x, p, modes)
    be._load(ev.dyn, ev.fext, ev.g)
    q, v = np.array(ev.q, float), np.array(ev.v, float)
    e = pin.computeKineticEnergy(m.model, be.data, q, v) \
        + pin.computePotentialEnergy(m.model, be.data, q)
    for n in m.nips:
        d = float(ev.nips[n.name].delta)
        e += 0.5 * p[m.param_index(f"{n.name}.stiffness")] * max(d, 0.0) ** 2
    for body, f in loads.items():
        e += f * float(ev.bodies[body].cz)
    return e


# ---- 5. energy of the conservative subset ----------------------------------------------------
def test_energy_conserved_by_the_conservative_subset() -> None:
    """The conservative subset: rigid bodies of constant mass (caliper 0: the radius, hence
    m and J, stays put whatever the speed; so −Ẏv and web momentum vanish), linear springs
    without damping, μ = 0, no web tension, drums free (torque 0), gravity, imbalance, the
    rider's load (a constant force at constant radius). Started off the balance with
    nonzero velocities (the nips bounce, open and close: events), DOPRI5 at rtol 1e-10
    keeps the total energy."""
    from winder.solve.system import MachineSystem

    values: dict[str, Any] = {"set.caliper": 0.0, "set.initial_radius": 0.25,
                              "set.com_offset": 0.01, "web.tension": 0.0,
                              "front.drive.torque": 0.0, "rear.drive.torque": 0.0}
    for n in ("front_nip", "rear_nip", "rider_nip"):
        values[f"{n}.contact.damping"] = 0.0
        values[f"{n}.friction.mu"] = 0.0
    sc = mc.two_drum(drive="torque", slip_relaxation=False, values=values)
    s = MachineSystem(sc)
    m = s.machine
    y0 = s.initial_state()
    # from the balance with the set resting on the drums (δ ≈ 1 mm), fast enough that
    # every nip opens and closes
    for name, v in (("set.x_dot", 0.09), ("set.z_dot", 0.15), ("set.theta_dot", -20.0),
                    ("rider.z_dot", -0.12), ("rider.theta_dot", 30.0)):
        y0[m.index(name)] = v
    ev = m.evaluate(NumericBackend(m.model), 0.0, y0, s.params,
                    np.full(len(m.mode_names), float(AUTO)))
    loads = {"rider": float(ev.channels["rider_load"])}
    t_out = np.linspace(0.0, 0.5, 51)
    Y = _integrate(s, y0, t_out, 1e-10, 1e-12)
    E = np.array([_energy(m, t, Y[:, i], s.params, loads) for i, t in enumerate(t_out)])
    kin0 = E[0] - _energy(m, 0.0, s.initial_state(), s.params, loads)
    drift = np.max(np.abs(E - E[0])) / kin0
    ch = s.channels(t_out, Y)
    for n in ("front_nip", "rear_nip", "rider_nip"):  # the nips bounce: open and closed
        fn = ch[f"{n}_normal_force"]
        assert np.any(fn == 0.0) and np.any(fn > 0.0), n
    # measured: 2.6e-11 of the 15 kJ put in
    assert drift < 3e-10


# ---- 6. drive torques ---------------------------------------------------------------------------
@pytest.mark.parametrize("drive", ["speed_profile", "torque"])
def test_drive_torques(drive: str) -> None:
    """Speed profile: the torque channel of each drum is ``J Ω̇ + R F_t`` (``Ω̇`` of the
    profile, ``F_t`` its nip's friction; the friction pulls ``−R F_t`` on the drum).
    Torque drive: ``J Ω̇ = τ − R F_t`` and the channel is the input ``τ``. Generated and
    numeric paths alike, random states."""
    m = Machine(mc.two_drum(drive=drive, values={"rear.drive.torque": -75.0}))
    g = _generate(m)
    be = NumericBackend(m.model)
    p = m.parameters()
    rng = np.random.default_rng(6)
    worst, ramp = 0.0, set()
    for _ in range(100):
        t, x, modes = random_state(m, rng)
        ev, num = _numeric(m, be, t, x, p, modes)
        out = dict(zip(m.channel_names, g.call("out", t, x, p, modes), strict=True))
        for d in m.bodies:
            if d.table != "drum":
                continue
            n = d.name
            nip = next(k for k in m.nips if k.a is d)
            R, J = d.part.radius, d.part.inertia
            Ft = float(ev.nips[nip.name].friction_force)
            if drive == "speed_profile":
                dr = d.part.drive
                ramp.add(t < dr.web_speed / dr.web_acceleration)
                accel = dr.ratio * dr.web_acceleration / R if t < dr.web_speed / \
                    dr.web_acceleration else 0.0
                expect = {"torque": J * accel + R * Ft, "accel": accel}
            else:
                tau = p[m.param_index(f"{n}.torque")]
                expect = {"torque": tau, "accel": (tau - R * Ft) / J}
            for ch, val in expect.items():
                scale = max(abs(val), R * abs(Ft), 1.0)
                for got in (out[f"{n}_{ch}"], ev.channels[f"{n}_{ch}"]):
                    worst = max(worst, abs(got - val) / scale)
    if drive == "speed_profile":
        assert ramp == {True, False}
    # measured: 3.4e-14 (speed profile), 4.5e-16 (torque)
    assert worst < 3e-13


# ---- 7. a free-flying roll gaining mass from rest ------------------------------------------------
@pytest.mark.parametrize("variable_mass", [True, False])
def test_free_flying_roll_keeps_world_momentum(variable_mass: bool) -> None:
    """Winder-model §3: mass joins from rest (no web, no contact). A roll free in x and z,
    no gravity, spinning so that its radius grows: ``m v`` and ``J ω`` keep their initial
    values through the generated path. With ``variable_mass`` off (overwrite the inertia)
    the velocities stay constant instead, and the oracle must fail."""
    from winder.solve.system import MachineSystem

    sc = mc.free_roll(gravity=False, imbalance=False, contact=False, slip_relaxation=False,
                      variable_mass=variable_mass,
                      values={"roll.caliper": 1e-3, "roll.initial_speed": 40.0})
    s = MachineSystem(sc)
    m = s.machine
    y0 = np.array(m.state_initial, dtype=float)
    y0[m.index("roll.x_dot")], y0[m.index("roll.z_dot")] = 0.7, -0.3
    t_out = np.linspace(0.0, 10.0, 11)
    Y = _integrate(s, y0, t_out, 1e-11, 1e-13)
    ch = s.channels(t_out, Y)
    mass, J = ch["roll_mass"], ch["roll_inertia"]
    assert mass[-1] > 2.0 * mass[0]  # the roll really grew: its mass doubled
    px, pz = mass * ch["roll_x_dot"], mass * ch["roll_z_dot"]
    L = J * ch["roll_speed"]
    err = max(np.max(np.abs(px - px[0])) / abs(px[0]), np.max(np.abs(pz - pz[0])) / abs(pz[0]),
              np.max(np.abs(L - L[0])) / abs(L[0]))
    if variable_mass:
        # measured: 3.7e-12 (off: 8.2)
        assert err < 4e-11
    else:
        assert err > 1e-2


def test_fixture_overrides() -> None:
    """The scene builders: ``values`` paths reach the parts, effects switch off, nothing is
    shared between nips."""
    sc = mc.two_drum(gravity=False, values={"rear_nip.contact.damping": 3.0,
                                            "set.caliper": 1e-4, "scene.gravity": 1.0})
    assert sc.nips[1].contact.damping == 3.0 and sc.nips[0].contact.damping == 1.5e4
    assert sc.rolls[0].caliper == 1e-4 and sc.scene.gravity == 1.0
    assert "gravity" not in sc.effects.enabled() and "contact" in sc.effects.enabled()
    with pytest.raises(KeyError):
        mc.override(sc, {"set.no_such_key": 1.0})
    assert isinstance(sc.web, SimpleNamespace)
