"""The linear plant of a machine about the operating point of ``winder modes``, for gains,
Bode plots and margins (:func:`linearise`, a python-control ``StateSpace``).

The operating point is the quasi-steady one of the resonance map
(:mod:`winder.analysis.operating_point`: drums at full speed, rolls at constant surface
speed, free coordinates in balance, imbalance off) at a radius of the wound roll. There

    δẋ = A δx + B δu,      δy = C δx + D δu

with ``A`` the exact generated Jacobian (:func:`winder.jacobian`, as ``winder modes``
takes it) and ``B = ∂ẋ/∂u``, ``C = ∂y/∂x``, ``D = ∂y/∂u`` CasADi's exact derivatives of
the same symbolic expression (:func:`winder.analysis.control.casadi_model`,
contact-closed); no finite differences.

**States.** The model holds the *fast* states of ``winder modes``: the free coordinates'
positions and velocities, the rotation speeds of the free bodies, the friction, span
tension and controller states. The angles (pure integrals of the speeds, which nothing
else sees with the imbalance off) and the rolls' radii (growing over minutes, a caliper
per turn) are frozen at the operating point (a flexible body's segment angles are its
twists, fast; a free one's first segment angle is its reference, frozen, and its other
segments' angles stand for their twists from it): the model is the plant at one diameter,
and a map over the radius is the gain-scheduling family. So its poles are exactly the
eigenvalues ``winder modes`` reports (:func:`winder.modes_at`), and a state with no
dynamics there (a friction state without relaxation) is left out, as there.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from winder._errors import ArgumentError
from winder.analysis.control import model_of
from winder.analysis.operating_point import _linearisation, _radius
from winder.scene.load import Scene
from winder.solve.simulate import _as_scene

__all__ = ["linearise", "save_plant", "PLANT_SUFFIXES", "poles_with_damping"]

#: The file types :func:`save_plant` writes: NumPy's and MATLAB's (scipy's ``savemat``).
PLANT_SUFFIXES = (".npz", ".mat")


def linearise(scene: Scene | str | os.PathLike, radius: float, *,
              inputs: Sequence[str] | None = None, outputs: Sequence[str] | None = None,
              web_speed: float | None = None) -> Any:
    """The linear plant (a ``control.StateSpace``) of ``scene`` at ``radius`` [m] of the
    wound roll and ``web_speed`` [m/s] (default the scene's), about the operating point of
    ``winder modes`` (module docstring: the fast states, exact derivatives).

    ``inputs``: names among the scene's plant inputs (default all): ``ROLL_torque`` [N·m]
    per torque-driven unwinding roll, ``ROLL_tension_setpoint`` [N], ``DRUM_web_speed``
    [m/s] per speed-profile drum (a perturbation of its speed). ``outputs``: result
    channels as the scene names them (default all).

    States, inputs and outputs are named (``sys.state_labels``, ``input_labels``,
    ``output_labels``); ``sys.units`` maps each name to its unit, and
    ``sys.operating_point`` holds ``radius`` [m], ``web_speed`` [m/s], ``t`` [s], the full
    state ``x`` (every state, ``state_names``), the inputs ``u`` and the outputs ``y``
    there.

    Raises
    ------
    ArgumentError: a radius or web speed out of range, a scene without a winding operating
        point (as :func:`winder.modes_at`), an unknown input or output.
    """
    import casadi as ca
    import control

    where = "linearise"
    scene = _as_scene(scene, where)
    lin = _linearisation(scene, where, web_speed, lo_open=False)
    r = _radius(where, lin, radius)
    y = lin.solve(r, where)
    system, t = lin.system, lin.t
    model = model_of(system, inputs=inputs, outputs=outputs, where=where, x0=y)
    fast = list(lin.fast)
    A = lin.fast_jacobian(y)  # a free flexible body's angles: its twists
    x, u, p = (ca.SX.sym(n, k) for n, k in (("x", model.n_states),
                                            ("u", len(model.input_names)),
                                            ("p", len(model.param_names))))
    xdot, out = model.f(x, u, p), model.h(x, u, p)
    derivatives = ca.Function("derivatives", [x, u, p],
                              [ca.densify(ca.jacobian(xdot, u)), ca.densify(ca.jacobian(out, x)),
                               ca.densify(ca.jacobian(out, u)), out])
    p0 = model.parameters(t)
    B, C, D, y0 = (np.array(v, dtype=float).reshape(v.shape)
                   for v in derivatives(y, model.u0, p0))
    B, C = B[fast, :], C[:, fast]
    states = [model.state_names[i] for i in fast]
    plant = control.ss(A, B, C, D, states=states, inputs=list(model.input_names),
                       outputs=list(model.output_names), name=scene.name or "winder")
    plant.units = {**{n: model.state_units[i] for n, i in zip(states, fast, strict=True)},
                   **dict(zip(model.input_names, model.input_units, strict=True)),
                   **dict(zip(model.output_names, model.output_units, strict=True))}
    plant.operating_point = {"radius": r, "web_speed": lin.v, "t": t, "x": y.copy(),
                             "state_names": model.state_names, "u": model.u0.copy(),
                             "y": y0.ravel().copy(), "p": np.asarray(p0, dtype=float).copy(),
                             "param_names": model.param_names}
    return plant


def poles_with_damping(plant: Any) -> list[tuple[complex, float, float]]:
    """``(pole, natural frequency [Hz], damping ratio)`` of each pole of ``plant`` (one of
    each complex pair, its positive imaginary part), slowest first. A pole in the right
    half-plane has a negative damping ratio (−1 for a positive real pole)."""
    lam = np.linalg.eigvals(np.asarray(plant.A)) if plant.nstates else np.empty(0)
    out = []
    for v in sorted((complex(v) for v in lam if v.imag >= 0.0), key=lambda v: (abs(v), v.real)):
        wn = abs(v)
        out.append((v, wn / (2 * math.pi), -v.real / wn if wn > 0 else 0.0))
    return out


def save_plant(plant: Any, path: str | os.PathLike) -> Path:
    """Write ``plant`` (from :func:`linearise`) to ``path``, atomically: ``.npz`` (NumPy)
    or ``.mat`` (MATLAB, scipy's ``savemat``): ``A``, ``B``, ``C``, ``D``, the names of
    the ``states``, ``inputs`` and ``outputs`` with their units (``state_units``, ...),
    the ``poles``, and the operating point (``radius`` [m], ``web_speed`` [m/s], ``x_op``
    over ``x_op_names``, ``u_op``, ``y_op``, and ``p_op`` over ``p_op_names``: the
    parameters ``casadi_model``'s ``f`` and ``h`` take there, drums at full speed)."""
    from winder.io.files import atomic_write

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in PLANT_SUFFIXES:
        raise ArgumentError(f"save_plant: {str(path)!r} must end in "
                            f"{' or '.join(PLANT_SUFFIXES)}")
    op = plant.operating_point
    units = plant.units

    def names(labels: Sequence[str]) -> np.ndarray:
        return np.array(list(labels), dtype=object if suffix == ".mat" else str)

    data = {"A": np.asarray(plant.A), "B": np.asarray(plant.B), "C": np.asarray(plant.C),
            "D": np.asarray(plant.D),
            "states": names(plant.state_labels), "inputs": names(plant.input_labels),
            "outputs": names(plant.output_labels),
            "state_units": names([units[n] for n in plant.state_labels]),
            "input_units": names([units[n] for n in plant.input_labels]),
            "output_units": names([units[n] for n in plant.output_labels]),
            "poles": np.linalg.eigvals(np.asarray(plant.A)),
            "radius": float(op["radius"]), "web_speed": float(op["web_speed"]),
            "x_op": op["x"], "x_op_names": names(op["state_names"]), "u_op": op["u"],
            "y_op": op["y"], "p_op": op["p"], "p_op_names": names(op["param_names"])}

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            if suffix == ".mat":
                from scipy.io import savemat

                savemat(fh, data)
            else:
                np.savez(fh, **data)

    return atomic_write(path, write)
