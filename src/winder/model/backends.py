"""Where the machine's rigid-body algorithms run: Pinocchio on numbers, or Pinocchio's
algorithms on CasADi symbols (for the generated code)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from winder._errors import ArgumentError
from winder.model.mathns import NUMERIC, SYMBOLIC, MathNamespace

__all__ = ["NumericBackend", "SymbolicBackend", "ROUTES", "ROUTE_ENV", "default_route"]


class NumericBackend:
    """``pin.aba``/``pin.rnea`` with ``fext`` on a :class:`pinocchio.Model` (the numeric
    Pinocchio path: the cross-check of the generated code, and the fallback without a C
    compiler)."""

    mathns: MathNamespace = NUMERIC

    def __init__(self, model: pin.Model) -> None:
        self.model = model
        self.data = model.createData()
        nj = model.njoints
        self._fext = pin.StdVec_Force()
        for _ in range(nj):
            self._fext.append(pin.Force.Zero())

    def _load(self, dyn: list[float], fext: list[float], g: list[float]) -> None:
        m = self.model
        for i in range(1, m.njoints):
            d = np.array(dyn[10 * (i - 1):10 * i], dtype=float)
            Y = pin.Inertia.Zero()  # a rate inertia may be indefinite: set attributes
            mass = d[0]
            Y.mass = mass
            com = d[1:4] / mass if mass != 0.0 else np.zeros(3)
            Y.lever = com
            Io = np.array([[d[4], d[5], d[7]], [d[5], d[6], d[8]], [d[7], d[8], d[9]]])
            Y.inertia = Io - mass * (np.dot(com, com) * np.eye(3) - np.outer(com, com))
            m.inertias[i] = Y
            self._fext[i] = pin.Force(np.array(fext[6 * (i - 1):6 * i], dtype=float))
        m.gravity = pin.Motion(np.array([*g, 0.0, 0.0, 0.0], dtype=float))

    def velocity(self, ev: Any, joint: int) -> list[float]:
        pin.forwardKinematics(self.model, self.data, np.array(ev.q, float),
                              np.array(ev.v, float))
        return list(self.data.v[joint + 1].vector)

    def aba(self, q: list[Any], v: list[Any], tau: list[Any], dyn: list[Any],
            fext: list[Any], g: list[Any]) -> list[float]:
        self._load(dyn, fext, g)
        return list(pin.aba(self.model, self.data, np.array(q, float), np.array(v, float),
                            np.array(tau, float), self._fext))

    def rnea(self, q: list[Any], v: list[Any], a: list[Any], dyn: list[Any],
             fext: list[Any], g: list[Any]) -> list[float]:
        self._load(dyn, fext, g)
        return list(pin.rnea(self.model, self.data, np.array(q, float), np.array(v, float),
                             np.array(a, float), self._fext))


#: Routes to Pinocchio's algorithms on CasADi symbols: ``cpp`` (Pinocchio's own templated
#: ABA/RNEA instantiated on ``casadi::SX``, :mod:`winder.model.pin_casadi`) and ``py`` (the
#: same algorithms over the ``pin.Model``'s structure, :mod:`winder.model.spatial`).
ROUTES = ("cpp", "py")


#: The environment variable that picks the route of the generated code.
ROUTE_ENV = "WINDER_ROUTE"


def default_route() -> str:
    """``py`` unless ``WINDER_ROUTE=cpp`` asks for Pinocchio's C++ headers on CasADi
    symbols. Both routes give the same expressions (the two-drum winder's right-hand side:
    516 against 515 CasADi instructions, the flexible one's 8,099 against 7,992), so the
    default needs no generator: no 3-minute, 4 GB g++ build before a first result. The
    ``cpp`` route stays the cross-check (``make test`` builds its generator; the routes'
    generated machines agree to round-off, tests/model/test_routes.py).

    Raises :class:`ArgumentError` naming ``WINDER_ROUTE`` for another value."""
    import os

    route = os.environ.get(ROUTE_ENV, "").strip() or "py"
    if route not in ROUTES:
        raise ArgumentError(f"{ROUTE_ENV}={route!r} is unknown; valid: {', '.join(ROUTES)}")
    return route


class _CppRoute:
    """Pinocchio's templated algorithms on ``casadi::SX``, with :class:`SpatialFunctions`'s
    call signature (velocities as a list of 6-vectors)."""

    def __init__(self, model: pin.Model) -> None:
        from winder.model.pin_casadi import functions

        self.fns = functions(model)
        self.nj = model.njoints - 1

    def vel(self, q: Any, v: Any) -> list[Any]:
        V = self.fns.vel(q, v)
        return [V[6 * i:6 * i + 6] for i in range(self.nj)]

    def aba(self, q: Any, v: Any, tau: Any, dyn: Any, fext: Any, g: Any) -> Any:
        return self.fns.aba(q, v, tau, dyn, fext, g)

    def rnea(self, q: Any, v: Any, a: Any, dyn: Any, fext: Any, g: Any) -> Any:
        return self.fns.rnea(q, v, a, dyn, fext, g)


class SymbolicBackend:
    """Pinocchio's ABA/RNEA/kinematics on CasADi ``SX`` by one of :data:`ROUTES`."""

    def __init__(self, model: pin.Model, route: str = "py") -> None:
        from winder.model.spatial import SpatialFunctions

        if route not in ROUTES:
            raise ArgumentError(f"route = {route!r} is unknown; valid: {', '.join(ROUTES)}")
        self.mathns = SYMBOLIC
        self.route = route
        self.f: Any = _CppRoute(model) if route == "cpp" else SpatialFunctions(model)
        self._vel: Any = None

    @staticmethod
    def _vec(values: list[Any]) -> Any:
        import casadi as ca

        return ca.vertcat(*[ca.SX(v) if isinstance(v, float | int) else v for v in values])

    def velocity(self, ev: Any, joint: int) -> list[Any]:
        if self._vel is None or self._vel[0] is not ev:
            self._vel = (ev, self.f.vel(self._vec(ev.q), self._vec(ev.v)))
        V = self._vel[1][joint]
        return [V[k] for k in range(6)]

    def aba(self, q: list[Any], v: list[Any], tau: list[Any], dyn: list[Any],
            fext: list[Any], g: list[Any]) -> list[Any]:
        v6 = self._vec
        out = self.f.aba(v6(q), v6(v), v6(tau), v6(dyn), v6(fext), v6(g))
        return [out[k] for k in range(out.shape[0])]

    def rnea(self, q: list[Any], v: list[Any], a: list[Any], dyn: list[Any],
             fext: list[Any], g: list[Any]) -> list[Any]:
        v6 = self._vec
        out = self.f.rnea(v6(q), v6(v), v6(a), v6(dyn), v6(fext), v6(g))
        return [out[k] for k in range(out.shape[0])]
