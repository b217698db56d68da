"""The two routes of the generated code give the same machine: route ``py`` (Pinocchio's
ABA and RNEA written over the ``pin.Model``, the default: no C++ build) against route
``cpp`` (Pinocchio's own templated algorithms on ``casadi::SX``), for every shipped scene:
the right-hand side, its Jacobian, the channels and the switching functions at the initial
state and at perturbed states, evaluated as CasADi Functions (no C compile)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import winder
from winder._errors import ArgumentError
from winder.model import backends
from winder.model.backends import SymbolicBackend, default_route
from winder.model.machine import Machine
from winder.solve.system import MachineSystem

ca = pytest.importorskip("casadi")
SCENES = sorted((Path(__file__).resolve().parents[2] / "models").glob("*.toml"))


def _functions(m: Machine, route: str) -> ca.Function:
    t = ca.SX.sym("t")
    x = ca.SX.sym("x", m.n_states)
    p = ca.SX.sym("p", len(m.param_names))
    modes = ca.SX.sym("m", len(m.mode_names))
    ev = m.evaluate(SymbolicBackend(m.model, route), t, x, p, modes)
    xdot = ca.vertcat(*[ev.rates[n] for n in m.state_names])
    outs = [xdot, ca.jacobian(xdot, x),
            ca.vertcat(*[ev.channels[n] for n in m.channel_names]),
            ca.vertcat(*[ev.switches[n] for n in m.switch_names])]
    return ca.Function(f"f_{route}", [t, x, p, modes], [ca.densify(o) for o in outs])


@pytest.fixture(scope="module")
def generator() -> None:
    from winder.model.pin_casadi import generator_path, unavailable_reason

    if generator_path(build=False) is None:
        pytest.skip(f"route cpp: {unavailable_reason()} (make pin-casadi builds it)")


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_routes_give_the_same_machine(path: Path, generator: None) -> None:
    system = MachineSystem(winder.load_scene(path), backend="pinocchio")
    m = system.machine
    x0 = system.initial_state()
    p = np.asarray(system.params, float)
    modes = system.modes
    f_py, f_cpp = _functions(m, "py"), _functions(m, "cpp")
    rng = np.random.default_rng(len(m.state_names))
    worst = 0.0
    for k in range(3):
        x = x0 * (1 + 1e-3 * k * rng.standard_normal(x0.size))
        for a, b in zip(f_py(0.5, x, p, modes), f_cpp(0.5, x, p, modes), strict=True):
            a, b = np.asarray(a), np.asarray(b)
            scale = max(float(np.max(np.abs(b), initial=0.0)), 1e-300)
            worst = max(worst, float(np.max(np.abs(a - b), initial=0.0)) / scale)
    # measured: at most 8.1e-16 of each output's largest entry (paper_winding; the
    # flexible winder 1.2e-16)
    assert worst < 1e-14, worst


def test_default_route_needs_no_generator(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(backends.ROUTE_ENV, raising=False)
    assert default_route() == "py"
    monkeypatch.setenv(backends.ROUTE_ENV, "cpp")
    assert default_route() == "cpp"
    monkeypatch.setenv(backends.ROUTE_ENV, "fortran")
    with pytest.raises(ArgumentError, match="WINDER_ROUTE='fortran' is unknown; valid: cpp, py"):
        default_route()
