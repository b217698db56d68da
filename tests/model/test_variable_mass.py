"""Oracle tests of the variable-mass core (spec section 3).

Each test pairs a problem with its exact solution; each tolerance is chosen so that a
dropped or doubled ``Ẏ v`` term fails (``scale`` = 0 or 2 is run as a self-check).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.integrate import solve_ivp

import winder
from winder import FunctionMassLaw, PaperRollLaw, VariableMassModel


def _models() -> list[pin.Model]:
    manip = pin.buildSampleModelManipulator()
    humanoid = pin.buildSampleModelHumanoidRandom()  # free-flyer root + chains
    planar = pin.Model()
    j = planar.addJoint(0, pin.JointModelPZ(), pin.SE3.Identity(), "z")
    j = planar.addJoint(j, pin.JointModelRevoluteUnaligned(np.array([0.0, -1.0, 0.0])),
                        pin.SE3.Identity(), "phi")
    planar.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    return [manip, humanoid, planar]


@pytest.mark.parametrize("model", _models(), ids=["manipulator", "humanoid", "planar"])
def test_zero_rate_equals_pinocchio(model: pin.Model) -> None:
    rng = np.random.default_rng(1)
    vm = VariableMassModel(model)
    data = model.createData()
    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, tau, a = (rng.standard_normal(model.nv) for _ in range(3))
        fext = [pin.Force.Random() for _ in range(model.njoints)]
        np.testing.assert_allclose(vm.aba(q, v, tau, fext),
                                   pin.aba(model, data, q, v, tau, pin.StdVec_Force(fext)),
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(vm.rnea(q, v, a, fext),
                                   pin.rnea(model, data, q, v, a, pin.StdVec_Force(fext)),
                                   rtol=0, atol=1e-11)


@pytest.mark.parametrize("model", _models(), ids=["manipulator", "humanoid", "planar"])
def test_rnea_inverts_aba_with_rates(model: pin.Model) -> None:
    rng = np.random.default_rng(2)
    vm = VariableMassModel(model)
    for j in range(1, model.njoints):
        Yd = rng.standard_normal((6, 6))
        vm.set_body(j, rate=Yd + Yd.T)  # indefinite on purpose
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v, tau = rng.standard_normal(model.nv), rng.standard_normal(model.nv)
    a = vm.aba(q, v, tau)
    np.testing.assert_allclose(vm.rnea(q, v, a), tau, rtol=0, atol=1e-9)
    # and the rate really acts: without it, the accelerations differ
    plain = pin.aba(model, model.createData(), q, v, tau)
    assert np.linalg.norm(a - plain) > 1e-3


def test_bad_arguments_name_the_argument() -> None:
    """Wrong values raise ArgumentError, wrong types ArgumentTypeError, each naming the
    argument and what is valid."""
    model = pin.buildSampleModelManipulator()
    vm = VariableMassModel(model)
    q, v, z = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
    E, T = winder.ArgumentError, winder.ArgumentTypeError
    with pytest.raises(T, match="model must be a pinocchio.Model, got None"):
        VariableMassModel(None)
    with pytest.raises(E, match="one pin.Force per joint"):
        vm.aba(q, v, z, [pin.Force.Zero()] * 2)
    with pytest.raises(T, match=r"fext\[1\] is a float"):
        vm.rnea(q, v, z, [pin.Force.Zero(), 3.0] + [pin.Force.Zero()] * 5)
    with pytest.raises(E, match=r"joint_id 7 is not a moving joint.*valid: 1="):
        vm.set_body(model.njoints, rate=np.zeros((6, 6)))
    with pytest.raises(E, match=r"joint_id -1 is not a moving joint"):
        vm.rate(-1)
    for bad in (1.5, "1", True):
        with pytest.raises(T, match="joint_id must be an integer"):
            vm.set_body(bad, rate=np.zeros((6, 6)))
    with pytest.raises(E, match=r"rate must be symmetric.*up to 1"):
        vm.set_body(1, rate=np.triu(np.ones((6, 6))))
    with pytest.raises(E, match=r"rate has non-finite entries at \[\[0, 0\]\]"):
        vm.set_body(1, rate=np.diag([np.nan, 1, 1, 1, 1, 1]))
    with pytest.raises(E, match=r"got shape \(3, 3\)"):
        vm.set_body(1, rate=np.eye(3))
    with pytest.raises(T, match="rate must be a pin.Inertia or a symmetric 6x6 array"):
        vm.set_body(1, rate="fast")
    with pytest.raises(T, match="inertia must be a pin.Inertia, got 3.0"):
        vm.set_body(1, inertia=3.0)
    with pytest.raises(E, match=rf"q must have shape \({model.nq},\)"):
        vm.aba(q[:-1], v, z)
    with pytest.raises(E, match="tau has non-finite entries"):
        vm.aba(q, v, np.full(model.nv, np.inf))
    with pytest.raises(E, match="a must have shape"):
        vm.rnea(q, v, np.zeros(2))
    with pytest.raises(E, match=r"momentum_flux: mass_rate must be finite, got nan"):
        vm.momentum_flux(q, 1, mass_rate=math.nan, velocity=np.zeros(3), point=np.zeros(3))
    with pytest.raises(E, match=r"velocity must have shape \(3,\)"):
        vm.momentum_flux(q, 1, mass_rate=1.0, velocity=np.zeros(2), point=np.zeros(3))


@pytest.mark.parametrize("method", ["mass", "polar_inertia", "mass_derivative",
                                    "polar_inertia_derivative", "properties", "inertia",
                                    "rate"])
@pytest.mark.parametrize("r", [-5.0, 0.0, 0.07, math.nan, math.inf, -math.inf])
def test_paper_roll_law_refuses_radii_off_the_roll(method: str, r: float) -> None:
    """The laws hold for r >= r_c: any other radius names ``r``, its value and the range."""
    args = (r, 1.0) if method == "rate" else (r,)
    with pytest.raises(winder.ArgumentError, match=rf"PaperRollLaw\.\w+: r = {r!r} is out of "
                                                    r"range; valid: a finite radius r >= "
                                                    r"core_radius = 0.075 m"):
        getattr(ROLL, method)(*args)
    with pytest.raises(winder.ArgumentTypeError, match=r"r expected a number, got '0.3'"):
        getattr(ROLL, method)(*(("0.3", 1.0) if method == "rate" else ("0.3",)))


def test_paper_roll_law_at_the_core_and_overflow() -> None:
    """At r = r_c the law gives the core exactly; a radius whose inertia overflows and a
    non-finite rate are refused."""
    assert ROLL.mass(0.075) == 30.0 and ROLL.polar_inertia(0.075) == 0.12
    with pytest.raises(winder.ArgumentError, match=r"r = 1e\+100 m: the roll's inertia "
                                                    "overflows"):
        ROLL.inertia(1e100)
    with pytest.raises(winder.ArgumentError, match=r"rate: s_dot must be finite, got inf"):
        ROLL.rate(0.3, math.inf)


@pytest.mark.parametrize("field, value, match", [
    ("core_radius", 0.0, r"core_radius must be > 0 m, got 0.0"),
    ("core_mass", -30.0, r"core_mass must be > 0 kg, got -30.0"),
    ("core_inertia", math.nan, r"core_inertia must be finite, got nan"),
    ("width", math.inf, r"width must be finite, got inf"),
    ("density", -1.0, r"density must be >= 0 kg/m³, got -1.0"),
    ("com_offset", -1e-3, r"com_offset must be >= 0 m, got -0.001"),
    ("com_offset", 0.07, r"com_offset = 0.07 m is out of range; valid: >= 0 and < "
                         r"min\(core_radius, √\(core_inertia/core_mass\)\) = 0.0632456 m"),
    ("com_offset", 1.0, r"com_offset = 1.0 m is out of range"),
])
def test_paper_roll_law_arguments(field: str, value: float, match: str) -> None:
    kw = {"core_radius": 0.075, "core_mass": 30.0, "core_inertia": 0.12, "width": 2.0,
          "density": 800.0, "com_offset": 0.0, field: value}
    with pytest.raises(winder.ArgumentError, match=rf"PaperRollLaw: {match}"):
        PaperRollLaw(**kw)
    kw[field] = "a"
    with pytest.raises(winder.ArgumentTypeError, match=rf"PaperRollLaw: {field} expected a "
                                                        "number, got 'a'"):
        PaperRollLaw(**kw)


def test_set_body_writes_the_users_model() -> None:
    model = pin.buildSampleModelManipulator()
    vm = VariableMassModel(model)
    Y = pin.Inertia(3.5, np.array([0.1, 0.0, 0.2]), np.diag([1.0, 2.0, 3.0]))
    vm.set_body(2, inertia=Y)
    assert model.inertias[2].isApprox(Y)


def _prismatic(axis: str) -> pin.Model:
    model = pin.Model()
    joint = {"x": pin.JointModelPX(), "z": pin.JointModelPZ()}[axis]
    j = model.addJoint(0, joint, pin.SE3.Identity(), "slider")
    model.appendBodyToJoint(j, pin.Inertia(1.0, np.zeros(3), np.eye(3)), pin.SE3.Identity())
    return model


def _point_mass(m: float, dm: float) -> tuple[pin.Inertia, np.ndarray]:
    Yd = pin.Inertia.Zero()
    Yd.mass = dm
    return pin.Inertia(m, np.zeros(3), 0.1 * m * np.eye(3)), Yd.matrix() + np.diag(
        [0, 0, 0, 0.1 * dm, 0.1 * dm, 0.1 * dm])


@pytest.mark.parametrize("scale", [1.0, 0.0, 2.0])
def test_raindrop(scale: float) -> None:
    """Mass m0 + λt accreting from rest, falling: v = −g (m0 t + λt²/2)/(m0 + λt)."""
    m0, lam, g, T = 1.0, 0.7, 9.81, 3.0
    model = _prismatic("z")
    vm = VariableMassModel(model)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        Y, Yd = _point_mass(m0 + lam * t, lam)
        vm.set_body(1, inertia=Y, rate=scale * Yd)
        return np.array([y[1], vm.aba(y[:1], y[1:], np.zeros(1))[0]])

    sol = solve_ivp(rhs, (0, T), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12)
    exact = -g * (m0 * T + lam * T**2 / 2) / (m0 + lam * T)
    err = abs(sol.y[1, -1] - exact) / abs(exact)
    if scale == 1.0:
        assert err < 1e-10
    else:
        assert err > 1e-2  # a dropped or doubled term is caught


@pytest.mark.parametrize("scale", [1.0, 0.0, 2.0])
def test_rocket_tsiolkovsky(scale: float) -> None:
    """Ejection at relative speed u_e through the flux helper: Δv = u_e ln(m0/m)."""
    m0, burn, ue, T = 10.0, 1.5, 300.0, 4.0
    model = _prismatic("x")
    model.gravity = pin.Motion.Zero()
    vm = VariableMassModel(model)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        Y, Yd = _point_mass(m0 - burn * t, -burn)
        vm.set_body(1, inertia=Y, rate=scale * Yd)
        q, v = y[:1], y[1:]
        f = vm.momentum_flux(q, 1, mass_rate=-burn, velocity=np.array([v[0] - ue, 0, 0]),
                             point=np.array([q[0], 0.0, 0.0]))
        fext = [pin.Force.Zero(), f]
        return np.array([v[0], vm.aba(q, v, np.zeros(1), fext)[0]])

    sol = solve_ivp(rhs, (0, T), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12)
    exact = ue * math.log(m0 / (m0 - burn * T))
    err = abs(sol.y[1, -1] - exact) / exact
    assert (err < 1e-10) if scale == 1.0 else (err > 1e-2)


ROLL = PaperRollLaw(core_radius=0.075, core_mass=30.0, core_inertia=0.12, width=2.0,
                    density=800.0)


def _roll_model() -> pin.Model:
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelRevoluteUnaligned(np.array([0.0, -1.0, 0.0])),
                       pin.SE3.Identity(), "roll")
    model.appendBodyToJoint(j, ROLL.inertia(ROLL.core_radius), pin.SE3.Identity())
    model.gravity = pin.Motion.Zero()
    return model


def _spin(scale: float, web: bool, h: float = 1e-3, w0: float = 40.0, T: float = 20.0):
    vm = VariableMassModel(_roll_model())

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        w, r = y
        rdot = h * w / (2 * math.pi)
        vm.set_body(1, inertia=ROLL.inertia(r), rate=scale * ROLL.rate(r, rdot))
        fext = [pin.Force.Zero(), pin.Force.Zero()]
        if web:  # mass arrives at the surface speed, tangentially, at the bottom point
            fext[1] = vm.momentum_flux(np.zeros(1), 1, mass_rate=ROLL.mass_derivative(r) * rdot,
                                       velocity=np.array([w * r, 0, 0]),
                                       point=np.array([0, 0, -r]))
        return np.array([vm.aba(np.zeros(1), y[:1], np.zeros(1), fext)[0], rdot])

    return solve_ivp(rhs, (0, T), [w0, ROLL.core_radius], method="DOP853", rtol=1e-12,
                     atol=1e-13, dense_output=True)


@pytest.mark.parametrize("scale", [1.0, 0.0, 2.0])
def test_free_spinning_roll_keeps_J_omega(scale: float) -> None:
    h, w0 = 1e-3, 40.0
    sol = _spin(scale, web=False, h=h, w0=w0)
    w, r = sol.y
    J = np.array([ROLL.polar_inertia(x) for x in r])
    J0 = ROLL.polar_inertia(ROLL.core_radius)
    drift = np.max(np.abs(J * w - J0 * w0)) / (J0 * w0)
    # closed form t(r)
    rc, k = ROLL.core_radius, 0.5 * ROLL.density * math.pi * ROLL.width
    t_exact = 2 * math.pi / (h * J0 * w0) * ((ROLL.core_inertia - k * rc**4) * (r - rc)
                                             + k * (r**5 - rc**5) / 5)
    t_err = np.max(np.abs(t_exact - sol.t)) / sol.t[-1]
    assert r[-1] > 1.4 * rc  # the roll really grew: J changed by a factor > 2
    if scale == 1.0:
        assert drift < 1e-10 and t_err < 1e-9
    else:
        assert drift > 1e-2 and t_err > 1e-3


@pytest.mark.parametrize("scale", [1.0, 0.0])
def test_roll_fed_at_surface_speed_keeps_omega(scale: float) -> None:
    sol = _spin(scale, web=True)
    drift = np.max(np.abs(sol.y[0] - 40.0)) / 40.0
    assert (drift < 1e-11) if scale == 1.0 else (drift > 1e-2)


def _flyer_law() -> FunctionMassLaw:
    """Smooth m(t), moving c(t), non-isotropic rotating I(t)."""
    def mass(t):
        return 5.0 + 2.0 * math.sin(0.7 * t), 1.4 * math.cos(0.7 * t)

    def com(t):
        c = np.array([0.1 * math.sin(t), 0.05 * t, -0.02 * math.cos(2 * t)])
        dc = np.array([0.1 * math.cos(t), 0.05, 0.04 * math.sin(2 * t)])
        return c, dc

    def inertia(t):
        A = np.array([[2.0, 0.3, 0.1], [0.3, 1.0, -0.2], [0.1, -0.2, 0.5]])
        B = np.array([[0.2, 0.0, 0.1], [0.0, -0.1, 0.05], [0.1, 0.05, 0.3]])
        s, ds = math.sin(1.3 * t), 1.3 * math.cos(1.3 * t)
        return A + 0.5 * s * B, 0.5 * ds * B

    return FunctionMassLaw(mass, com, inertia)


@pytest.mark.parametrize("scale", [1.0, 0.0, 2.0])
def test_free_flyer_momentum_conserved(scale: float) -> None:
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "flyer")
    law = _flyer_law()
    model.appendBodyToJoint(j, law.inertia(0.0), pin.SE3.Identity())
    model.gravity = pin.Motion.Zero()
    vm = VariableMassModel(model)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, v = y[:7].copy(), y[7:]
        q[3:] /= np.linalg.norm(q[3:])
        vm.set_body(1, inertia=law.inertia(t), rate=scale * law.rate(t, 1.0))
        a = vm.aba(q, v, np.zeros(6))
        R = pin.Quaternion(q[3:]).matrix()
        x, y_, z, w = q[3:]
        wx, wy, wz = v[3:]
        dquat = 0.5 * np.array([w * wx + y_ * wz - z * wy, w * wy + z * wx - x * wz,
                                w * wz + x * wy - y_ * wx, -x * wx - y_ * wy - z * wz])
        return np.concatenate([R @ v[:3], dquat, a])

    def momentum(t: float, y: np.ndarray) -> np.ndarray:
        q = y[:7].copy()
        q[3:] /= np.linalg.norm(q[3:])
        pin.forwardKinematics(model, vm.data, q)
        h = pin.Force(law.inertia(t).matrix() @ y[7:])
        return vm.data.oMi[1].act(h).vector

    y0 = np.concatenate([pin.neutral(model), [0.3, -0.2, 0.1, 1.0, -0.5, 2.0]])
    sol = solve_ivp(rhs, (0, 3.0), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    h0, h1 = momentum(0.0, sol.y[:, 0]), momentum(sol.t[-1], sol.y[:, -1])
    rel = np.linalg.norm(h1 - h0) / np.linalg.norm(h0)
    assert (rel < 1e-9) if scale == 1.0 else (rel > 1e-2)


@pytest.mark.parametrize("law, s", [(ROLL, 0.3), (PaperRollLaw(0.075, 30, 0.12, 2, 800, 0.004),
                                                   0.5), (_flyer_law(), 0.8)])
def test_rate_matches_finite_differences(law: winder.MassLaw, s: float) -> None:
    eps = 1e-6 * max(1.0, s)
    fd = (law.inertia(s + eps).matrix() - law.inertia(s - eps).matrix()) / (2 * eps)
    np.testing.assert_allclose(law.rate(s, 1.0), fd, rtol=1e-7, atol=1e-7 * np.abs(fd).max())


def test_rate_given_as_inertia_attributes() -> None:
    """An indefinite Ẏ built from attributes is accepted: a rate is not an inertia, so
    its rotational part need not be positive (Pinocchio's Inertia does not check it)."""
    model = _roll_model()
    vm = VariableMassModel(model)
    Yd = pin.Inertia.Zero()
    Yd.mass = 2.0
    Yd.lever = np.array([0.0, 0.0, 0.0])
    Yd.inertia = np.diag([1.0, -3.0, 0.5])
    vm.set_body(1, rate=Yd)
    np.testing.assert_allclose(vm.rate(1), Yd.matrix())
