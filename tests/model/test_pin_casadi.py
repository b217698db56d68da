"""winder.model.pin_casadi: Pinocchio's own ABA/RNEA/kinematics on casadi SX.

Oracle: the numeric ``pin.aba``/``pin.rnea``/``pin.forwardKinematics`` of the same model with
``model.inertias`` set from the same dynamic parameters and ``model.gravity`` from the same g.
"""

from __future__ import annotations

import threading
from pathlib import Path

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from winder import ArgumentTypeError
from winder.model import pin_casadi
from winder.model.pin_casadi import PinCasadiError, functions, generator_path

# Measured worst relative errors over the draws below: aba 4e-16, rnea 0, vel 0 (rnea and the
# kinematics run the same operations in the same order); over 2000 draws aba reaches 1.5e-14.
# The tolerance is above that and far below any modelling error.
RTOL = 1e-12


def winder_model(rider_x: float = 0.0) -> pin.Model:
    """Two drums (RY at x = -/+0.525 m), a roll (PX, PZ, RY), a rider (PZ at x = rider_x, RY).

    Bodies are appended to the RY joints only: the PX/PZ joints are massless carriages.
    """
    model = pin.Model()
    body = pin.Inertia(10.0, np.array([0.01, 0.0, 0.02]), np.diag([1.0, 2.0, 1.5]))
    for x in (-0.525, 0.525):
        j = model.addJoint(0, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([x, 0.0, 0.0])),
                           f"drum{x:+}")
        model.appendBodyToJoint(j, body, pin.SE3.Identity())
    j = model.addJoint(0, pin.JointModelPX(), pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.6])),
                       "roll_x")
    j = model.addJoint(j, pin.JointModelPZ(), pin.SE3.Identity(), "roll_z")
    j = model.addJoint(j, pin.JointModelRY(), pin.SE3.Identity(), "roll")
    model.appendBodyToJoint(j, body, pin.SE3.Identity())
    j = model.addJoint(0, pin.JointModelPZ(), pin.SE3(np.eye(3), np.array([rider_x, 0.0, 1.1])),
                       "rider_z")
    j = model.addJoint(j, pin.JointModelRevoluteUnaligned(np.array([0.0, 1.0, 0.0])),
                       pin.SE3.Identity(), "rider")
    model.appendBodyToJoint(j, body, pin.SE3.Identity())
    return model


@pytest.fixture(scope="module")
def fns() -> pin_casadi.PinFunctions:
    if generator_path(build=True) is None:
        pytest.skip(f"pin_casadi generator unavailable: {pin_casadi.unavailable_reason()}")
    return functions(winder_model())


def random_inertia(rng: np.random.Generator) -> pin.Inertia:
    """A physical inertia: mass > 0, centre of mass off the origin, positive-definite I_c."""
    a = rng.normal(size=(3, 3))
    return pin.Inertia(rng.uniform(0.5, 50.0), rng.normal(scale=0.3, size=3),
                       a @ a.T + 0.1 * np.eye(3))


def draw(model: pin.Model, rng: np.random.Generator, massless: tuple[int, ...]) -> dict:
    """Random state, inputs and parameters; joints in ``massless`` get all-zero parameters."""
    nj = model.njoints - 1
    dyn = np.concatenate([np.zeros(10) if i in massless else
                          random_inertia(rng).toDynamicParameters() for i in range(1, nj + 1)])
    return {"q": rng.uniform(-2, 2, model.nq), "v": rng.normal(size=model.nv),
            "u": rng.normal(scale=10, size=model.nv), "dyn": dyn,
            "fext": rng.normal(scale=5, size=6 * nj), "g": rng.normal(scale=10, size=3)}


def numeric(model: pin.Model, x: dict) -> tuple[pin.Model, pin.Data, list[pin.Force]]:
    """A copy of ``model`` with the drawn inertias and gravity, its data and fext list."""
    m = model.copy()
    for i in range(1, m.njoints):
        p = x["dyn"][10 * (i - 1):10 * i]
        m.inertias[i] = pin.Inertia.Zero() if p[0] == 0 else pin.Inertia.FromDynamicParameters(p)
    m.gravity = pin.Motion(x["g"], np.zeros(3))
    fext = [pin.Force.Zero()] + [pin.Force(x["fext"][6 * (i - 1):6 * i])
                                 for i in range(1, m.njoints)]
    return m, m.createData(), fext


def rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(np.ravel(a) - b) / max(np.linalg.norm(b), 1.0))


MASSLESS = {"all bodies massive": (), "carriages massless": (3, 4, 6)}


@pytest.mark.parametrize("massless", MASSLESS.values(), ids=MASSLESS.keys())
def test_aba_matches_pinocchio(fns: pin_casadi.PinFunctions, massless: tuple[int, ...]) -> None:
    model = winder_model()
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = draw(model, rng, massless)
        m, d, fext = numeric(model, x)
        expected = pin.aba(m, d, x["q"], x["v"], x["u"], fext)
        got = fns.aba(x["q"], x["v"], x["u"], x["dyn"], x["fext"], x["g"]).full()
        assert rel(got, expected) < RTOL


@pytest.mark.parametrize("massless", MASSLESS.values(), ids=MASSLESS.keys())
def test_rnea_matches_pinocchio(fns: pin_casadi.PinFunctions, massless: tuple[int, ...]) -> None:
    model = winder_model()
    rng = np.random.default_rng(2)
    for _ in range(20):
        x = draw(model, rng, massless)
        m, d, fext = numeric(model, x)
        expected = pin.rnea(m, d, x["q"], x["v"], x["u"], fext)
        got = fns.rnea(x["q"], x["v"], x["u"], x["dyn"], x["fext"], x["g"]).full()
        assert rel(got, expected) < RTOL


def test_vel_matches_forward_kinematics(fns: pin_casadi.PinFunctions) -> None:
    model = winder_model()
    data = model.createData()
    rng = np.random.default_rng(3)
    for _ in range(20):
        q, v = rng.uniform(-2, 2, model.nq), rng.normal(size=model.nv)
        pin.forwardKinematics(model, data, q, v)
        expected = np.concatenate([data.v[i].vector for i in range(1, model.njoints)])
        assert rel(fns.vel(q, v).full(), expected) < RTOL


def test_aba_inverts_rnea(fns: pin_casadi.PinFunctions) -> None:
    """rnea(q, v, aba(q, v, tau)) = tau: the two generated graphs against each other."""
    model = winder_model()
    x = draw(model, np.random.default_rng(4), (3, 4, 6))
    args = (x["dyn"], x["fext"], x["g"])
    ddq = fns.aba(x["q"], x["v"], x["u"], *args)
    assert rel(fns.rnea(x["q"], x["v"], ddq, *args).full(), x["u"]) < RTOL  # measured 1.7e-15


def test_sx_arguments_inline_into_a_larger_graph(fns: pin_casadi.PinFunctions) -> None:
    """Called with SX, the functions become part of the caller's graph: the roll's mass as a
    function of a symbol r, differentiated through ABA, matches a central difference."""
    model = winder_model()
    x = draw(model, np.random.default_rng(5), (3, 4, 6))
    r = ca.SX.sym("r")
    dyn = ca.SX(x["dyn"])
    roll = slice(10 * 4, 10 * 5)  # joint 5 is the roll's RY joint
    dyn[roll] = ca.SX(x["dyn"][roll]) * (1 + r)  # scale mass, first moment and inertia
    ddq = fns.aba(x["q"], x["v"], x["u"], dyn, x["fext"], x["g"])
    composite = ca.Function("rhs", [r], [ddq, ca.jacobian(ddq, r)])
    value, slope = (np.ravel(a.full()) for a in composite(0.3))
    x_num = dict(x, dyn=np.array(x["dyn"]))
    x_num["dyn"][roll] *= 1.3
    m, d, fext = numeric(model, x_num)
    assert rel(value, pin.aba(m, d, x["q"], x["v"], x["u"], fext)) < RTOL  # measured 9e-17
    h = 1e-6
    fd = (np.ravel(fns.aba(x["q"], x["v"], x["u"], _scaled(x["dyn"], roll, 1.3 + h),
                           x["fext"], x["g"]).full())
          - np.ravel(fns.aba(x["q"], x["v"], x["u"], _scaled(x["dyn"], roll, 1.3 - h),
                             x["fext"], x["g"]).full())) / (2 * h)
    assert rel(slope, fd) < 1e-8  # central difference error at h = 1e-6: measured 8e-10


def _scaled(dyn: np.ndarray, part: slice, factor: float) -> np.ndarray:
    out = np.array(dyn)
    out[part] *= factor
    return out


def test_cached_in_memory_and_on_disk(fns: pin_casadi.PinFunctions,
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    model = winder_model()
    assert functions(model) is fns  # same model text: the loaded functions of this process
    monkeypatch.setattr(pin_casadi, "_loaded", {})

    def no_generator(build: bool = True) -> Path | None:
        raise AssertionError("the disk cache should have been used")

    monkeypatch.setattr(pin_casadi, "generator_path", no_generator)
    again = functions(model)
    assert again is not fns
    x = draw(model, np.random.default_rng(6), ())
    args = (x["q"], x["v"], x["u"], x["dyn"], x["fext"], x["g"])
    assert np.array_equal(again.aba(*args).full(), fns.aba(*args).full())


def test_concurrent_generation_both_succeed(fns: pin_casadi.PinFunctions,
                                            tmp_path: Path) -> None:
    """Two writers of one model's folder at once: both return, the folder is complete."""
    binary = generator_path(build=False)
    assert binary is not None
    text = pin_casadi._model_text(winder_model(rider_x=0.123))
    final = tmp_path / "models" / "m"
    barrier, errors = threading.Barrier(2), []

    def write() -> None:
        barrier.wait()
        try:
            pin_casadi._generate(binary, text, final)
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=write) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert sorted(p.name for p in final.parent.iterdir()) == ["m"]  # no temporary left
    assert pin_casadi._complete(final)


def test_generator_failure_is_reported(fns: pin_casadi.PinFunctions, tmp_path: Path) -> None:
    binary = generator_path(build=False)
    assert binary is not None
    with pytest.raises(PinCasadiError, match=r"generator .* failed \(exit 1\)"):
        pin_casadi._generate(binary, "not a pinocchio model", tmp_path / "m")
    assert not (tmp_path / "m").exists()


def test_missing_gxx_gives_none_and_a_reason(monkeypatch: pytest.MonkeyPatch,
                                             tmp_path: Path) -> None:
    monkeypatch.setenv("WINDER_PIN_CASADI_DIR", str(tmp_path))
    monkeypatch.setattr(pin_casadi.shutil, "which", lambda name: None)
    assert generator_path(build=True) is None
    assert "g++ is not on PATH" in (pin_casadi.unavailable_reason() or "")
    assert generator_path(build=False) is None
    assert "not built" in (pin_casadi.unavailable_reason() or "")


def test_model_type_checked() -> None:
    with pytest.raises(ArgumentTypeError, match="pinocchio.Model"):
        functions("model.txt")  # type: ignore[arg-type]
