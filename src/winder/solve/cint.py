"""The integrators in C, linked into every machine's library (issue #23).

``solve/c/`` holds them: ``events.h`` (the shared mode table, event location and guard),
``dopri5.c``, ``dop853.c`` (DOP853: order 8, 7th-order dense output), ``rk4.c``,
``ros2.c``, ``rosenbrock.c`` (RODAS3/4 with ``sparse_lu.h``; both with ``dense_lu.h``) and
``machine.c`` (the modes and channels of a trajectory).
:func:`link` compiles them once into objects (cached under
:func:`~winder.model.codegen.cache_dir`, keyed by every source and header and the flags:
the generated code's plus ``-ffp-contract=off -std=c99``, so no fused multiply–add
changes a rounding), and :func:`winder.model.codegen.generate` links them with each
machine's generated object into one shared library. :class:`Kernels` calls that library
through ctypes, in chunks (the callers check their budgets, signals and progress between
calls). ``docs/c-integrators.md`` gives the kernels' contract.

Adding an integrator:

1. write it in ``solve/c/NAME.c`` with the contract of ``winder_dopri5`` (``events.h``
   holds the modes, events and guard);
2. add the file to :data:`SOURCES` and its prototype to :meth:`Kernels.__init__`; one that
   calls the Jacobian (``fns[F_JAC]``) calls :meth:`Kernels.jacobian` first (the Jacobian is
   built on first use: until then its address is 0, and ``_check`` refuses it);
3. call it from :mod:`winder.solve.simulate` and test it against a closed form.
"""

from __future__ import annotations

import ctypes
import hashlib
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from winder.model.codegen import Generated, Link, cache_dir, compile_flags, run_compiler

__all__ = ["Kernels", "link", "SOURCES", "EXTRA_CFLAGS", "ROSENBROCK"]

_DIR = Path(__file__).resolve().parent / "c"
#: The translation units (each includes ``events.h``).
SOURCES = ("dopri5.c", "dop853.c", "rk4.c", "ros2.c", "rosenbrock.c", "machine.c")
#: Flags beyond the generated code's: no contraction into FMA.
EXTRA_CFLAGS = ("-ffp-contract=off", "-std=c99")

_dp = ctypes.POINTER(ctypes.c_double)
_ip = ctypes.POINTER(ctypes.c_int64)
_i64, _f64 = ctypes.c_int64, ctypes.c_double
_LINKS: dict[tuple[str, ...], Link] = {}
#: The Rosenbrock methods of ``rosenbrock.c``: ``(scheme, reuse)``, ``reuse`` the most
#: accepted steps one Jacobian serves (RODAS3/4 are not W-methods: a kept Jacobian costs
#: them their order and the steps it saves (flexible two-drum winder, 0.5 s at rtol 1e-6:
#: RODAS4 reuse 4 took 7 times RODAS4 reuse 1's CPU); ROS34PW2 is a W-method: reuse 16 was
#: its fastest of 1, 4, 16, 64 there).
ROSENBROCK = {"RODAS3": (3, 1), "RODAS4": (4, 1), "ROS34PW2": (34, 16)}


def link() -> Link:
    """The integrators' objects (compiled once, cached) for
    :func:`~winder.model.codegen.generate`."""
    flags = (*compile_flags(), *EXTRA_CFLAGS)
    memo = (*flags, str(cache_dir()))
    if memo in _LINKS and all(o.exists() for o in _LINKS[memo].objects):
        return _LINKS[memo]
    h = hashlib.sha256(" ".join(flags).encode())
    for f in sorted(_DIR.glob("*.[ch]")):  # every source and header: the key
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    key = h.hexdigest()[:16]
    root = cache_dir() / "integrators" / key
    objects = tuple(root / f"{Path(s).stem}.o" for s in SOURCES)
    if not all(o.exists() for o in objects):
        root.parent.mkdir(parents=True, exist_ok=True)
        print(f"winder: building the C integrators once ({', '.join(SOURCES)}; cached in "
              f"{root.parent})", file=sys.stderr, flush=True)
        with tempfile.TemporaryDirectory(dir=root.parent, prefix=".build-") as tmp:
            for src, obj in zip(SOURCES, objects, strict=True):
                run_compiler([*flags, "-c", str(_DIR / src), "-o", str(Path(tmp) / obj.name)],
                             f"the C integrators ({src})")
            root.mkdir(exist_ok=True)
            for obj in objects:
                os.replace(Path(tmp) / obj.name, obj)  # atomic per file; a race writes equal
    _LINKS[memo] = result = Link(objects, key)
    return result


def _ptr(a: np.ndarray, dtype: Any, name: str, writable: bool = False) -> Any:
    if a.dtype != dtype or not a.flags.c_contiguous or (writable and not a.flags.writeable):
        raise TypeError(f"{name}: a C-contiguous{' writable' if writable else ''} {dtype} "
                        f"array is needed, got {a.dtype} {a.shape}")
    return a.ctypes.data_as(_ip if dtype == np.int64 else _dp)


class Kernels:
    """The integrators of one machine's library (``MachineSystem.kernels``).

    Each kernel takes the arrays of the contract (``docs/c-integrators.md``): ``fns``
    (the generated functions' addresses), the mode ``table``, the state ``y`` and modes
    ``m`` (updated in place), the parameters ``p``, the output times ``t_out`` and
    samples ``Y_out`` (n, n_out), and ``stats`` (int64 counters), and returns
    ``(status, t, h, k)``.
    """

    def __init__(self, generated: Generated) -> None:
        lib = generated._lib
        if not hasattr(lib, "winder_dopri5"):
            raise TypeError("generated: a machine library linked with the integrators "
                            "(generate(machine, link=cint.link())) is needed")
        self.n_switches = generated.n_switches
        self.n_channels = generated.n_channels
        self.n_states = generated.n_states
        self.n_params = generated.n_params
        self._generated = generated
        adaptive = [_ip, _ip, _i64, _i64, _f64, _f64, _dp, _i64, _dp, _dp, _f64, _f64, _f64,
                    _f64, _dp, _i64, _dp, _i64, _i64, _ip]
        self._dopri5 = self._fn(lib.winder_dopri5, [*adaptive, _i64, _dp, _dp, _ip])
        self._dop853 = self._fn(lib.winder_dop853, [*adaptive, _i64, _dp, _dp, _ip])
        self._ros2 = self._fn(lib.winder_ros2, [*adaptive, _dp, _dp, _ip])
        self._rodas = self._fn(lib.winder_rodas, [*adaptive[:-1], _i64, _i64, _ip, _dp, _dp,
                                                  _ip])
        self._rk4 = self._fn(lib.winder_rk4, [_ip, _ip, _i64, _i64, _f64, _f64, _dp, _i64, _dp,
                                              _dp, _f64, _dp, _i64, _dp, _i64, _ip, _dp, _dp,
                                              _ip])
        self._modes = self._fn(lib.winder_modes, [_ip, _ip, _i64, _i64, _f64, _dp, _i64, _dp,
                                                  _dp, _i64])
        self._channels = self._fn(lib.winder_channels, [_ip, _ip, _i64, _i64, _dp, _i64, _dp,
                                                        _i64, _dp, _dp, _dp, _i64])
        self._repeat = lib.winder_repeat
        self._repeat.restype = ctypes.c_double
        self._repeat.argtypes = [_ip, _i64, _i64, _f64, _dp, _dp, _dp, _dp]
        self._lib = lib  # keep the library loaded

    def _sizes(self, y: np.ndarray, p: np.ndarray) -> None:
        """The state and parameters have the machine's lengths (the generated code writes
        and reads that many values)."""
        if y.shape != (self.n_states,) or p.shape != (self.n_params,):
            raise ValueError(f"y and p must hold {self.n_states} states and {self.n_params} "
                             f"parameters, got {y.shape} and {p.shape}")

    @staticmethod
    def _fn(fn: Any, argtypes: list[Any]) -> Any:
        fn.restype = ctypes.c_int
        fn.argtypes = argtypes
        return fn

    def jacobian(self, fns: np.ndarray) -> np.ndarray:
        """``fns`` with the Jacobian's address (``fns[F_JAC]``, written in place): its
        library built on first use (:meth:`winder.model.codegen.Generated.jacobian`)."""
        if fns[1] == 0:
            fns[1] = self._generated.jacobian()
        return fns

    def dopri5(self, fns: np.ndarray, table: np.ndarray, t0: float, t1: float,
               y: np.ndarray, p: np.ndarray, m: np.ndarray, rtol: float, atol: float,
               h: float, max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
               budget: int, stats: np.ndarray) -> tuple[int, float, float, int]:
        """DOPRI5 from ``t0`` towards ``t1`` [s] until done, an event that ends the run,
        or ``budget`` evaluations (``PAUSED``); ``h <= 0``: it picks the first step."""
        return self._explicit(self._dopri5, fns, table, t0, t1, y, p, m, rtol, atol, h,
                              max_step, t_out, Y_out, k, budget, stats)

    def dop853(self, fns: np.ndarray, table: np.ndarray, t0: float, t1: float,
               y: np.ndarray, p: np.ndarray, m: np.ndarray, rtol: float, atol: float,
               h: float, max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
               budget: int, stats: np.ndarray) -> tuple[int, float, float, int]:
        """DOP853 (``dop853.c``: Hairer's explicit method of order 8, scipy's tableau,
        error estimator, step control and 7th-order dense output; DOPRI5's first-step
        guess; a non-finite extra stage ends with ``NON_FINITE``) as :meth:`dopri5`: 12
        evaluations a step, 3 more on a step whose dense output is used (samples, events);
        ``stats[4]`` counts Hairer's stiff steps (``h·|Δf|/|Δy| > 6.1``)."""
        return self._explicit(self._dop853, fns, table, t0, t1, y, p, m, rtol, atol, h,
                              max_step, t_out, Y_out, k, budget, stats)

    def _explicit(self, fn: Any, fns: np.ndarray, table: np.ndarray, t0: float, t1: float,
                  y: np.ndarray, p: np.ndarray, m: np.ndarray, rtol: float, atol: float,
                  h: float, max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
                  budget: int, stats: np.ndarray) -> tuple[int, float, float, int]:
        """One call of an explicit kernel (DOPRI5's arguments) with ``fn``."""
        n = _check(fns, table, y, m, t_out, Y_out, stats, jacobian=False)
        self._sizes(y, p)
        tr, hr, kr = _f64(), _f64(), _i64()
        status = fn(
            _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
            self.n_switches, float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
            _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(rtol),
            float(atol), float(h), float(max_step), _ptr(t_out, np.float64, "t_out"),
            t_out.shape[0], _ptr(Y_out, np.float64, "Y_out", True), int(k), int(budget),
            _ptr(stats, np.int64, "stats", True), stats.shape[0], ctypes.byref(tr),
            ctypes.byref(hr), ctypes.byref(kr))
        return _result(status, tr, hr, kr)

    def ros2(self, fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
             p: np.ndarray, m: np.ndarray, rtol: float, atol: float, h: float,
             max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int, budget: int,
             stats: np.ndarray) -> tuple[int, float, float, int]:
        """The Rosenbrock ROS2 on the exact Jacobian, as :meth:`dopri5` (``stats`` needs
        5 counters: ``stats[4]`` counts Jacobians; the Jacobian built on first use)."""
        n = _check(self.jacobian(fns), table, y, m, t_out, Y_out, stats)
        self._sizes(y, p)
        if stats.shape[0] < 5:
            raise ValueError("stats must hold 5 counters")
        tr, hr, kr = _f64(), _f64(), _i64()
        status = self._ros2(
            _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
            self.n_switches, float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
            _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(rtol),
            float(atol), float(h), float(max_step), _ptr(t_out, np.float64, "t_out"),
            t_out.shape[0], _ptr(Y_out, np.float64, "Y_out", True), int(k), int(budget),
            _ptr(stats, np.int64, "stats", True), ctypes.byref(tr), ctypes.byref(hr),
            ctypes.byref(kr))
        return _result(status, tr, hr, kr)

    def rodas(self, fns: np.ndarray, table: np.ndarray, t0: float, t1: float,
              y: np.ndarray, p: np.ndarray, m: np.ndarray, rtol: float, atol: float,
              h: float, max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
              budget: int, stats: np.ndarray, *, order: int = 4,
              reuse: int = 1) -> tuple[int, float, float, int]:
        """RODAS3 (``order=3``), RODAS4 (``order=4``) or the W-method ROS34PW2
        (``order=34``) of ``rosenbrock.c`` (stiffly accurate, L-stable Rosenbrock methods
        on the exact Jacobian, factored on its sparsity), as :meth:`dopri5`; ``reuse``
        >= 1: the most steps one Jacobian serves (1: a new one every step). ``stats``
        needs 8 counters: [4] Jacobians, [5] factorisations, [6] dense fallbacks, [7]
        L + U nonzeros."""
        n = _check(self.jacobian(fns), table, y, m, t_out, Y_out, stats)
        self._sizes(y, p)
        if stats.shape[0] < 8:
            raise ValueError("stats must hold 8 counters")
        if order not in (3, 4, 34):
            raise ValueError(f"order must be 3 (RODAS3), 4 (RODAS4) or 34 (ROS34PW2), got "
                             f"{order!r}")
        if int(reuse) < 1:
            raise ValueError(f"reuse must be an integer >= 1, got {reuse!r}")
        tr, hr, kr = _f64(), _f64(), _i64()
        status = self._rodas(
            _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
            self.n_switches, float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
            _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(rtol),
            float(atol), float(h), float(max_step), _ptr(t_out, np.float64, "t_out"),
            t_out.shape[0], _ptr(Y_out, np.float64, "Y_out", True), int(k), int(budget),
            int(order), int(reuse), _ptr(stats, np.int64, "stats", True), ctypes.byref(tr),
            ctypes.byref(hr), ctypes.byref(kr))
        return _result(status, tr, hr, kr)

    def rk4(self, fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
            p: np.ndarray, m: np.ndarray, h: float, t_out: np.ndarray, Y_out: np.ndarray,
            k: int, stats: np.ndarray) -> tuple[int, float, float, int]:
        """Fixed-step RK4 with steps of at most ``h`` [s] evenly dividing
        ``[t0, t1]``."""
        if not (math.isfinite(h) and h > 0.0):
            raise ValueError(f"h must be a finite step > 0 s, got {h!r}")
        n = _check(fns, table, y, m, t_out, Y_out, stats, jacobian=False)
        self._sizes(y, p)
        tr, hr, kr = _f64(), _f64(), _i64()
        status = self._rk4(
            _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
            self.n_switches, float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
            _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(h),
            _ptr(t_out, np.float64, "t_out"), t_out.shape[0],
            _ptr(Y_out, np.float64, "Y_out", True), int(k),
            _ptr(stats, np.int64, "stats", True), ctypes.byref(tr), ctypes.byref(hr),
            ctypes.byref(kr))
        return _result(status, tr, hr, kr)

    def modes(self, fns: np.ndarray, table: np.ndarray, t: float, y: np.ndarray,
              p: np.ndarray, m: np.ndarray, *, contact_auto: bool) -> None:
        """The modes a step starting at ``(t, y)`` runs in, into ``m``:
        a nip touching where its switching function is > 0 (``AUTO`` where
        ``contact_auto``), a roll at its core where ``r <= r_c`` and it does not turn
        forwards."""
        y = np.ascontiguousarray(y, dtype=np.float64)
        self._sizes(y, p)
        if m.shape != (table.shape[0],):
            raise ValueError(f"m must hold one mode per slot ({table.shape[0]}), got {m.shape}")
        status = self._modes(_ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"),
                             table.shape[0], self.n_switches, float(t),
                             _ptr(y, np.float64, "y"), y.shape[0],
                             _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True),
                             int(bool(contact_auto)))
        _result(status, _f64(), _f64(), _i64())

    def repeat(self, fns: np.ndarray, which: int, count: int, t: float, y: np.ndarray,
               p: np.ndarray, m: np.ndarray, out: np.ndarray) -> float:
        """``count`` evaluations of the generated function ``fns[which]`` (``F_RHS``, ...)
        at one point, from C as the integrators call it (the benchmarks' cost per
        evaluation); ``out`` holds the last result. Returns the sum of ``out[0]``."""
        if not 0 <= which < 4:
            raise ValueError(f"which must be 0–3 (rhs, jac, out, sw), got {which}")
        if which == 1:
            self.jacobian(fns)
        y = np.ascontiguousarray(y, dtype=np.float64)
        self._sizes(y, p)
        size = (self.n_states, self.n_states ** 2, self.n_channels, self.n_switches)[which]
        if out.shape[0] < size:
            raise ValueError(f"out must hold {size} values, got {out.shape}")
        return float(self._repeat(_ptr(fns, np.int64, "fns"), int(which), int(count),
                                  float(t), _ptr(y, np.float64, "y"),
                                  _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m"),
                                  _ptr(out, np.float64, "out", True)))

    def channels(self, fns: np.ndarray, table: np.ndarray, t: np.ndarray, Y: np.ndarray,
                 p: np.ndarray) -> np.ndarray:
        """The channels (n_channels, len(t)) of the samples ``Y`` (n, len(t)), each in
        the modes of its state with the nips' clamped law."""
        t = np.ascontiguousarray(t, dtype=np.float64)
        Y = np.ascontiguousarray(Y, dtype=np.float64)
        if Y.ndim != 2 or Y.shape != (self.n_states, t.shape[0]):
            raise ValueError(f"Y must be ({self.n_states}, {t.shape[0]}), got {Y.shape}")
        self._sizes(Y[:, 0] if Y.shape[1] else np.empty(self.n_states), p)
        out = np.empty((self.n_channels, t.shape[0]))
        m = np.empty(table.shape[0])
        status = self._channels(_ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"),
                                table.shape[0], self.n_switches, _ptr(t, np.float64, "t"),
                                t.shape[0], _ptr(Y, np.float64, "Y"), Y.shape[0],
                                _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True),
                                _ptr(out, np.float64, "out", True), self.n_channels)
        _result(status, _f64(), _f64(), _i64())
        return out


def _check(fns: np.ndarray, table: np.ndarray, y: np.ndarray, m: np.ndarray,
           t_out: np.ndarray, Y_out: np.ndarray, stats: np.ndarray, *,
           jacobian: bool = True) -> int:
    """The arrays' shapes; ``jacobian``: the kernel calls the Jacobian, whose address must
    be there (:meth:`Kernels.jacobian`)."""
    n = y.shape[0]
    if stats.shape[0] < 4:
        raise ValueError("stats must hold at least 4 counters")
    if Y_out.ndim != 2 or Y_out.shape[0] != n or Y_out.shape[1] != t_out.shape[0]:
        raise ValueError(f"Y_out must be ({n}, {t_out.shape[0]}), got {Y_out.shape}")
    if table.ndim != 2 or table.shape[1] != 5 or m.shape[0] != table.shape[0]:
        raise ValueError("table must be (slots, 5) with one mode per slot")
    if fns.shape[0] < 4:
        raise ValueError("fns must hold the 4 generated functions' addresses")
    if jacobian and fns[1] == 0:
        raise ValueError("fns[F_JAC] is 0: the Jacobian is built on first use; "
                         "Kernels.jacobian(fns) builds it")
    return n


def _result(status: int, tr: Any, hr: Any, kr: Any) -> tuple[int, float, float, int]:
    if status == 6:
        raise MemoryError("the C integrator could not allocate its work buffers")
    return int(status), tr.value, hr.value, int(kr.value)
