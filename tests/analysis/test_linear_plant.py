"""``winder.linearise``: the linear plant about the operating point of ``winder modes``.
Its bounce poles against the closed-form damped bounce, its poles against
``modes_at``'s eigenvalues, ``B``/``C``/``D`` against central differences of the
generated code, its step response against the nonlinear one (second order: halving the
step quarters the difference), the names, units and files."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.integrate import solve_ivp

import winder
from winder.analysis.control import model_of
from winder.analysis.modes import modes_at
from winder.analysis.operating_point import _linearisation
from winder.analysis.plant import poles_with_damping, save_plant
from winder.model.mass_law import paper_roll_mass


def test_bounce_poles_equal_the_closed_form(paper_scene) -> None:
    """Linear nip with damping, drum at rest: the plant has the poles
    λ = −c/2m ± i√(k/m − (c/2m)²) of ``winder modes`` (measured 1.9e-16 relative)."""
    k, c = 2e7, 2e4
    scene = paper_scene.replace(drum={"drive": {"web_speed": 0.0}})
    assert (scene.contact.stiffness, scene.contact.damping) == (k, c)
    ro = scene.roll
    for r in (0.1, 0.3, 0.6):
        m = paper_roll_mass(r, ro.core_radius, ro.core_mass, ro.core_inertia,
                            math.pi * scene.paper.density * ro.width)[0]
        lam = complex(-c / (2 * m), math.sqrt(k / m - (c / (2 * m)) ** 2))
        plant = winder.linearise(scene, r, web_speed=0.0)
        poles = np.linalg.eigvals(np.asarray(plant.A))
        for want in (lam, lam.conjugate()):
            assert np.min(np.abs(poles - want)) <= 2e-15 * abs(want)


@pytest.mark.parametrize(("name", "radius"), [("paper_winding.toml", 0.3),
                                              ("winder_line.toml", 0.25)])
def test_poles_are_the_modes(models_dir, name, radius) -> None:
    """The plant's poles are ``modes_at``'s eigenvalues (the same Jacobian on the same
    states; measured 0, bit for bit)."""
    scene = winder.load_scene(models_dir / name)
    plant = winder.linearise(scene, radius)
    poles = np.linalg.eigvals(np.asarray(plant.A))
    modes = modes_at(scene, radius)
    assert 2 * len(modes) >= len(poles) >= len(modes)
    for mode in modes:
        assert np.min(np.abs(poles - mode.eigenvalue)) <= 1e-15 * abs(mode.eigenvalue)
    assert sorted(abs(p) for p, _, _ in poles_with_damping(plant)) == \
        pytest.approx(sorted(abs(m.eigenvalue) for m in modes), rel=1e-15)


def test_b_c_d_equal_central_differences(models_dir) -> None:
    """``B = ∂ẋ/∂u``, ``C = ∂y/∂x``, ``D = ∂y/∂u`` (CasADi's exact derivatives) against
    central differences of the generated right-hand side and channels at the operating
    point, relative to each row's largest entry (the difference quotient's error)."""
    scene = winder.load_scene(models_dir / "winder_line.toml")
    outputs = ["span_tension", "parent_speed", "rear_nip_normal_force", "parent_torque"]
    plant = winder.linearise(scene, 0.25, outputs=outputs)
    lin = _linearisation(scene, "test", None, False)
    y = lin.solve(0.25, "test")
    sys_ = lin.system
    np.testing.assert_array_equal(y, plant.operating_point["x"])
    sys_.modes[lin.contact] = 1.0  # IN_CONTACT, as the plant
    model = model_of(sys_, inputs=list(plant.input_labels), outputs=outputs, x0=y)
    fast = lin.fast
    names = sys_.machine.channel_names

    def outs(x: np.ndarray) -> np.ndarray:
        g = sys_.generated.call("out", 0.0, x, sys_.params, sys_.modes)
        return np.array([g[names.index(o)] for o in outputs])

    fd_b, fd_d = np.empty(np.shape(plant.B)), np.empty(np.shape(plant.D))
    for j, param in enumerate(model.input_parameters):
        i = sys_.machine.param_index(param)
        base = sys_.params[i]
        h = 1e-6 * max(1.0, abs(base))
        rates, chans = [], []
        for v in (base + h, base - h):
            sys_.params[i] = v
            rates.append(sys_.rhs(0.0, y)[fast])
            chans.append(outs(y))
        sys_.params[i] = base
        fd_b[:, j] = (rates[0] - rates[1]) / (2 * h)
        fd_d[:, j] = (chans[0] - chans[1]) / (2 * h)
    fd_c = np.empty(np.shape(plant.C))
    for j, k in enumerate(fast):
        h = 1e-7 * max(1.0, abs(y[k]))
        yp, ym = y.copy(), y.copy()
        yp[k] += h
        ym[k] -= h
        fd_c[:, j] = (outs(yp) - outs(ym)) / (2 * h)
    # bounds 10x the measured 2.3e-7 (B), 9.9e-10 (C), 7.1e-11 (D)
    for got, fd, bound in ((plant.B, fd_b, 3e-6), (plant.C, fd_c, 1e-8), (plant.D, fd_d, 1e-9)):
        got = np.asarray(got)
        scale = np.max(np.abs(fd), axis=1, keepdims=True) + 1e-9
        assert np.max(np.abs(got - fd) / scale) <= bound


def _step_error(scene: winder.Scene, radius: float, du: float, T: float,
                outputs: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The largest difference over ``(0, T]`` [s] between the nonlinear and the linear
    response of each output to a step ``du`` of the scene's first input, and the linear
    response's size. The nonlinear run is the plant's own nonlinear system: the fast
    states from the operating point, the slow ones (angles, radii) held, and the
    quasi-steady drift of the operating point (``ω̇ = −ω ṙ/r``) taken off its rates, so
    that the operating point is its equilibrium (neither changes a derivative)."""
    plant = winder.linearise(scene, radius, outputs=outputs)
    lin = _linearisation(scene, "test", None, False)
    y = lin.solve(radius, "test")
    sys_ = lin.system
    sys_.modes[lin.contact] = 1.0
    model = model_of(sys_, inputs=list(plant.input_labels), outputs=outputs, x0=y)
    fast = np.array(lin.fast)
    f0 = sys_.rhs(0.0, y)[fast]
    ip = sys_.machine.param_index(model.input_parameters[0])
    base = sys_.params[ip]
    ts = np.linspace(0.0, T, 11)[1:]

    def run(step: float) -> np.ndarray:
        sys_.params[ip] = base + step

        def full(z: np.ndarray) -> np.ndarray:
            x = y.copy()
            x[fast] = z
            return x

        sol = solve_ivp(lambda t, z: sys_.rhs(0.0, full(z))[fast] - f0, (0.0, T), y[fast],
                        method="Radau", t_eval=ts, rtol=1e-12, atol=1e-14,
                        jac=lambda t, z: sys_.jac(0.0, full(z))[np.ix_(fast, fast)])
        u = model.u0.copy()
        u[0] += step
        sys_.params[ip] = base
        return np.array([np.array(model.h(full(z), u, model.parameters(0.0))).ravel()
                         for z in sol.y.T])

    A, B, C, D = (np.asarray(M) for M in (plant.A, plant.B, plant.C, plant.D))
    n = len(A)
    M = np.zeros((n + 1, n + 1))
    M[:n, :n], M[:n, n] = A, B[:, 0] * du
    linear = np.array([C @ sl.expm(M * t)[:n, n] + D[:, 0] * du for t in ts])
    return np.max(np.abs(run(du) - run(0.0) - linear), axis=0), \
        np.max(np.abs(linear), axis=0)


def test_step_response_is_right_to_second_order(paper_scene) -> None:
    """A step of the drum's speed (``drum_web_speed``, 0.25 and 0.125 mm/s on 20 m/s) at
    r = 0.3 m: the linear plant's response of the roll speed and the nip's friction force
    equals the nonlinear one to second order: halving the step quarters the difference
    (measured ratios 3.85 and 3.83; the difference 2.5e-5 and 2.1e-5 of the response)."""
    outputs = ["roll_speed", "friction_force"]
    big, size = _step_error(paper_scene, 0.3, 2.5e-4, 0.05, outputs)
    small, _ = _step_error(paper_scene, 0.3, 1.25e-4, 0.05, outputs)
    assert np.all(big <= 3e-4 * size)
    assert np.all((3.3 <= big / small) & (big / small <= 4.5)), big / small


def test_names_units_and_files(models_dir, tmp_path) -> None:
    scene = winder.load_scene(models_dir / "winder_line.toml")
    plant = winder.linearise(scene, 0.2, inputs=["parent_tension_setpoint", "rear_web_speed"],
                             outputs=["span_tension", "set_z"])
    assert plant.input_labels == ["parent_tension_setpoint", "rear_web_speed"]
    assert plant.output_labels == ["span_tension", "set_z"]
    assert "span.tension" in plant.state_labels and "set.radius" not in plant.state_labels
    units = plant.units
    assert (units["span.tension"], units["set.z_dot"], units["rear_web_speed"],
            units["set_z"]) == ("N", "m/s", "m/s", "m")
    op = plant.operating_point
    assert op["radius"] == 0.2 and op["web_speed"] == 41.7
    assert op["y"][0] == pytest.approx(1000.0, rel=1e-9)  # the tension at its set-point
    from scipy.io import loadmat

    for suffix in (".npz", ".mat"):
        path = save_plant(plant, tmp_path / f"plant{suffix}")
        data = np.load(path) if suffix == ".npz" else loadmat(path)
        np.testing.assert_array_equal(data["A"], plant.A)
        np.testing.assert_array_equal(data["D"], plant.D)
        names = [str(np.ravel(n)[0]) if suffix == ".mat" else str(n)
                 for n in np.ravel(data["inputs"])]
        assert names == plant.input_labels
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plant.mat", "plant.npz"]


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"radius": 0.01}, r"linearise: radius .* valid: a finite radius >= \[\[roll\]\] 'set'"),
    ({"radius": 0.2, "inputs": ["set_torque"]}, r"inputs: 'set_torque' is not one of"),
    ({"radius": 0.2, "outputs": []}, r"outputs is empty"),
    ({"radius": 0.2, "web_speed": -1.0}, r"web_speed"),
])
def test_bad_arguments_name_the_argument(models_dir, kwargs, match) -> None:
    with pytest.raises(winder.ArgumentError, match=match):
        winder.linearise(models_dir / "winder_line.toml", **kwargs)
