"""``winder.casadi_model``: the CasADi Functions ``f(x, u, p)`` and ``h(x, u, p)`` against
the generated code the solvers run (``MachineSystem.rhs``, the generated Jacobian and
channels), on random states in contact, with the same locked modes."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import winder
from winder.analysis.control import contact_closed_modes
from winder.solve.system import MachineSystem

SCENES = ("paper_winding.toml", "two_drum_winder.toml", "winder_line.toml")


def _random_states(system: MachineSystem, rng: np.random.Generator, n: int) -> list:
    """``(t [s], x)`` near the initial balance (in contact), with random speeds, angles,
    friction states, radii and a time on or past the drums' ramps."""
    y0 = system.initial_state()
    out = []
    for _ in range(n):
        y = y0.copy()
        for k, s in enumerate(system.state_names):
            if s.endswith((".x", ".z")):
                y[k] += rng.uniform(-1e-6, 1e-6) - (3e-6 if s.endswith(".z") else 0.0)
            elif s.endswith(".theta"):
                y[k] = rng.uniform(-3, 3)
            elif s.endswith(("x_dot", "z_dot")):
                y[k] = rng.normal(0, 0.01)
            elif s.endswith("theta_dot"):
                y[k] = rng.uniform(5, 100) * np.sign(y0[k] or 1.0)
            elif s.endswith(".radius"):
                y[k] *= rng.uniform(1.0, 1.5)
            elif s.endswith((".friction", ".tension", ".tension_integral")):
                y[k] += rng.normal(0, 10)
        out.append((float(rng.uniform(0, 80)), y))
    return out


@pytest.fixture(scope="module", params=SCENES)
def built(request, models_dir):
    scene = winder.load_scene(models_dir / request.param)
    system = MachineSystem(scene)
    model = winder.casadi_model(scene)
    system.modes[:] = model.modes
    return system, model


def test_f_equals_rhs_on_random_states(built) -> None:
    """``f`` equals ``MachineSystem.rhs`` (measured: bit for bit, 0.0; the bound allows
    16 ulp of each rate)."""
    system, model = built
    assert model.state_names == system.state_names
    np.testing.assert_array_equal(model.modes, contact_closed_modes(system))
    for t, y in _random_states(system, np.random.default_rng(1), 8):
        p = model.parameters(t)
        got = np.array(model.f(y, model.u0, p)).ravel()
        want = system.rhs(t, y)
        np.testing.assert_allclose(got, want, rtol=16 * np.finfo(float).eps, atol=1e-300)


def test_jacobian_equals_the_generated_jacobian(built) -> None:
    """CasADi's ``∂f/∂x`` equals the generated Jacobian ``MachineSystem.jac`` (measured:
    bit for bit; the bound allows 16 ulp of each row's largest entry)."""
    system, model = built
    x, u, p = ca.SX.sym("x", model.n_states), ca.SX.sym("u", len(model.u0)), \
        ca.SX.sym("p", len(model.p0))
    jac = ca.Function("J", [x, u, p], [ca.densify(ca.jacobian(model.f(x, u, p), x))])
    for t, y in _random_states(system, np.random.default_rng(2), 5):
        got = np.array(jac(y, model.u0, model.parameters(t)))
        want = system.jac(t, y)
        scale = np.max(np.abs(want), axis=1, keepdims=True)
        assert np.all(np.abs(got - want) <= 16 * np.finfo(float).eps * scale)


def test_inputs_are_the_machine_parameters(built) -> None:
    """An input of ``u`` is its run-time parameter: ``f`` with ``u`` changed equals ``rhs``
    with that parameter set (measured: bit for bit)."""
    system, model = built
    t, y = _random_states(system, np.random.default_rng(3), 1)[0]
    for k, (name, param) in enumerate(zip(model.input_names, model.input_parameters,
                                          strict=True)):
        u = model.u0.copy()
        u[k] = u[k] * 1.1 + 1.0
        old = system.params.copy()
        try:
            system.set_input(param, u[k])
            want = system.rhs(t, y)
        finally:
            system.params[:] = old
        got = np.array(model.f(y, u, model.parameters(t))).ravel()
        np.testing.assert_allclose(got, want, rtol=16 * np.finfo(float).eps, atol=1e-300,
                                   err_msg=name)


def test_h_equals_the_generated_channels(built) -> None:
    """``h`` equals the generated channels (measured: bit for bit)."""
    system, model = built
    outs = system.outputs
    for t, y in _random_states(system, np.random.default_rng(4), 3):
        p = model.parameters(t)
        got = np.array(model.h(y, model.u0, p)).ravel()
        gen = system.generated.call("out", t, y, system.params, system.modes)
        names = system.machine.channel_names
        want = [gen[names.index(outs[n][0])] if outs[n][0] in names else 0.0
                for n in model.output_names]
        np.testing.assert_allclose(got, want, rtol=16 * np.finfo(float).eps, atol=1e-300)


def test_named_inputs_outputs_and_units(models_dir) -> None:
    model = winder.casadi_model(models_dir / "winder_line.toml",
                                inputs=["parent_tension_setpoint"],
                                outputs=["span_tension", "parent_speed"])
    f, h = model
    assert f.name_in() == ["x", "u", "p"] and h.name_out() == ["y"]
    assert model.input_units == ("N",) and model.output_units == ("N", "rad/s")
    assert model.u0.tolist() == [1000.0]
    assert model.param_names[-1] == "t" and "span.EA" in model.param_names
    units = dict(zip(model.state_names, model.state_units, strict=True))
    assert units["span.tension"] == "N" and units["set.z_dot"] == "m/s"
    assert units["parent.tension_integral"] == "N·s"


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"inputs": ["nope"]}, r"inputs: 'nope' is not one of .*valid: parent_tension_setpoint"),
    ({"outputs": ["nope"]}, r"outputs: 'nope' is not one of .*valid: front_speed"),
    ({"outputs": "span_tension"}, r"outputs must be a list of names"),
    ({"outputs": ["span_tension", "span_tension"]}, r"'span_tension' is given twice"),
])
def test_bad_names_name_the_argument(models_dir, kwargs, match) -> None:
    with pytest.raises((winder.ArgumentError, winder.ArgumentTypeError), match=match):
        winder.casadi_model(models_dir / "winder_line.toml", **kwargs)
