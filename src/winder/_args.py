"""Argument checks of the Python API: a bad argument raises :class:`~winder.ArgumentError`
(a wrong value) or :class:`~winder.ArgumentTypeError` (a wrong type) naming the function,
the argument, the value given and what is valid."""

from __future__ import annotations

import math
import numbers
import sys
from collections.abc import Callable
from typing import Any

from winder._errors import ArgumentError, ArgumentTypeError

__all__ = ["show", "range_text", "check_real", "real_argument", "number", "integer",
           "RTOL_MAX", "ATOL_MAX", "COMPILED_MAX_RHS", "STEPWISE_MAX_RHS", "STEPWISE_STATES"]

#: The largest relative tolerance a scene, :func:`winder.simulate` or the CLI accepts [-]
#: (beyond it the integrators' error control means nothing).
RTOL_MAX = 0.1
#: The largest absolute tolerance [state units: m, rad, m/s, rad/s, N] a scene,
#: :func:`winder.simulate`, the :class:`~winder.Stepper` or the CLI accepts: 1 mm on a
#: position whose nip penetration is µm, 1 mN on a friction state. Beyond it the error
#: control no longer sees the contact (an atol of 1e300 lets a roll sink through its drum).
ATOL_MAX = 1e-3

# The default evaluation budgets (``max_rhs`` when neither the call nor ``[solver]`` gives
# one; :func:`winder.solve.budgets.default_max_rhs`), each about a minute of its path's work.
#: On the compiled methods (DOPRI5, ROS2, RK4 in C): 0.2–3 µs an evaluation (the paper
#: scene with a 1e12 N/m nip stops on DOPRI5 after 6 s).
COMPILED_MAX_RHS = 50_000_000
#: On a step-wise path (scipy's RK45, RK23, DOP853, Radau, BDF, LSODA; RK4 on the numeric
#: backend), per backend, for a machine of at most :data:`STEPWISE_STATES` states: one step
#: at a time from Python costs 16–83 µs of CPU an evaluation of the generated right-hand side
#: (DOP853 the least, BDF the most: its Newton iterations and LU solves) and 350–400 µs on
#: the numeric Pinocchio path (the paper scene with a 1e12 N/m nip; docs/speed.md: the
#: time each method takes to stop).
STEPWISE_MAX_RHS = {"compiled": 300_000, "pinocchio": 30_000}
#: Above this many states a step-wise path's default budget shrinks in proportion: an
#: evaluation costs more with the machine (the implicit methods' Jacobians and LU solves:
#: 250–280 µs of CPU on the 213 states of the flexible two-drum winder against 25–95 µs on
#: the paper scene's 6, single-threaded BLAS).
STEPWISE_STATES = 50


def show(value: Any, limit: int = 60) -> str:
    """``repr(value)`` cut to about ``limit`` characters (messages stay one line)."""
    try:
        text = repr(value)
    except ValueError:  # an integer of more digits than Python converts to text
        return f"<an integer of {value.bit_length()} bits>"
    if len(text) <= limit:
        return text
    size = f"{len(value)} characters" if isinstance(value, str | bytes) else \
        f"{len(text)} characters as text"
    return f"{text[:limit - 20]}... ({size})"


def range_text(lo: float | None, lo_open: bool = False, hi: float | None = None,
               unit: str = "") -> str:
    """``> 0 and <= 10 m`` and the like; with ``lo`` None, ``hi`` bounds ``|value|``."""
    u = f" {unit}" if unit else ""
    if lo is None:
        return "any finite number" if hi is None else f"|value| <= {hi:g}{u}"
    text = f"{'>' if lo_open else '>='} {lo:g}{u}"
    return text if hi is None else f"{text} and <= {hi:g}{u}"


def _as_float(value: Any) -> float | None:
    """``value`` as a float (an integer beyond the float range as ``±inf``), or None when it
    is not a real number (``bool`` and ``numpy.bool_`` are not numbers here)."""
    np = sys.modules.get("numpy")  # not imported yet: no numpy.bool_ to meet (no NumPy
    # just to check a scene)
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or (
            np is not None and isinstance(value, np.bool_)):
        return None
    try:
        return float(value)
    except OverflowError:  # an integer beyond the float range
        return math.inf if value > 0 else -math.inf


def check_real(value: Any, *, lo: float | None = None, lo_open: bool = False,
               hi: float | None = None, unit: str = "") -> tuple[float, str | None, bool]:
    """``(x, problem, wrong_type)``: ``value`` as a float and, if it is not a finite real
    number in ``[lo, hi]`` (``(lo, hi]`` when ``lo_open``; ``|value| <= hi`` when ``lo`` is
    None), what is wrong with it (``"must be finite, got nan"``) and whether its type is."""
    x = _as_float(value)
    if x is None:
        return math.nan, f"expected a number, got {show(value)} ({type(value).__name__})", True
    if not math.isfinite(x):
        return x, f"must be finite, got {show(value)}", False
    if (lo is not None and (x <= lo if lo_open else x < lo)) or \
            (hi is not None and (x if lo is not None else abs(x)) > hi):
        return x, f"must be {range_text(lo, lo_open, hi, unit)}, got {show(value)}", False
    return x, None, False


def real_argument(name: str, value: Any, ok: Callable[[float], bool], valid: str) -> float:
    """``value`` as a float if it is a real number (:func:`check_real`'s conversion) with
    ``ok(value)``; else :class:`~winder.ArgumentTypeError` (not a number) or
    :class:`~winder.ArgumentError` naming ``name``, the value and ``valid`` (the valid
    range, in words). For arguments whose range is not an interval (``inf`` allowed, whole
    numbers) or whose message names a scene key."""
    v = _as_float(value)
    if v is None:
        raise ArgumentTypeError(f"{name} must be a real number ({valid}), got {value!r} of "
                                f"type {type(value).__name__}")
    if not ok(v):
        raise ArgumentError(f"{name} = {show(value)} is out of range; valid: {valid}")
    return v


def number(where: str, name: str, value: Any, *, lo: float | None = None,
           lo_open: bool = False, hi: float | None = None, unit: str = "",
           valid: str | None = None) -> float:
    """``value`` as a finite float in range (:func:`check_real`), else an
    :class:`ArgumentError` or :class:`ArgumentTypeError` naming ``where`` (the function,
    ``"PaperRollLaw.mass"``) and ``name`` (the argument); ``valid`` replaces the generated
    description of the range in the message."""
    x, problem, wrong_type = check_real(value, lo=lo, lo_open=lo_open, hi=hi, unit=unit)
    if problem is None:
        return x
    if wrong_type:
        raise ArgumentTypeError(f"{where}: {name} {problem}")
    if valid is not None:
        problem = f"= {show(value)} is out of range; valid: {valid}"
    raise ArgumentError(f"{where}: {name} {problem}")


def integer(where: str, name: str, value: Any, *, lo: int, hi: int) -> int:
    """``value`` as an int in ``[lo, hi]`` (bool and non-integral numbers are refused)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ArgumentTypeError(f"{where}: {name} must be an integer, got {show(value)} "
                                f"({type(value).__name__})")
    if not lo <= int(value) <= hi:
        raise ArgumentError(f"{where}: {name} = {value!r} is out of range; valid: an integer "
                            f"{lo} … {hi}")
    return int(value)
