"""Math namespaces: the same force and mass-law code runs on floats and on CasADi symbols.

Every piece of physics in :mod:`winder.forces`, :mod:`winder.parts` and :mod:`winder.model`
(the machine, the mass law) is written once over a namespace ``mathns`` with the functions
below; :data:`NUMERIC` evaluates it on floats (the numeric Pinocchio path),
:data:`SYMBOLIC` builds CasADi ``SX`` expressions (the generated code). Branches on
states must go through ``mathns.if_else`` / ``mathns.fmax`` so that the generated code
stays branch-free.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["MathNamespace", "NUMERIC", "SYMBOLIC"]


def _if_else(c: Any, a: Any, b: Any) -> Any:
    return a if c else b


def _power_abs(x: float, p: float) -> float:
    return abs(x) ** p


@dataclass(frozen=True)
class MathNamespace:
    """The functions a piece of physics may call on its (numeric or symbolic) values."""

    name: str
    sin: Callable[[Any], Any]
    cos: Callable[[Any], Any]
    tanh: Callable[[Any], Any]
    sqrt: Callable[[Any], Any]
    fabs: Callable[[Any], Any]
    fmax: Callable[[Any, Any], Any]
    fmin: Callable[[Any, Any], Any]
    if_else: Callable[[Any, Any, Any], Any]
    logic_and: Callable[[Any, Any], Any]
    logic_or: Callable[[Any, Any], Any]
    power_abs: Callable[[Any, Any], Any]  # |x|^p


NUMERIC = MathNamespace("numeric", math.sin, math.cos, math.tanh, math.sqrt, abs, max, min,
                        _if_else, lambda a, b: a and b, lambda a, b: a or b, _power_abs)


def _symbolic() -> MathNamespace:
    import casadi as ca

    return MathNamespace("symbolic", ca.sin, ca.cos, ca.tanh, ca.sqrt, ca.fabs, ca.fmax,
                         ca.fmin, ca.if_else,
                         ca.logic_and, ca.logic_or, lambda x, p: ca.power(ca.fabs(x), p))


class _Lazy:
    """:data:`SYMBOLIC` built on first use (casadi is imported only when code is generated)."""

    _ns: MathNamespace | None = None

    def __getattr__(self, item: str) -> Any:
        if _Lazy._ns is None:
            _Lazy._ns = _symbolic()
        return getattr(_Lazy._ns, item)


SYMBOLIC: MathNamespace = _Lazy()  # type: ignore[assignment]
