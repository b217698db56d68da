"""The integrators in C (``solve/c/``: ``events.h`` the shared mode table, event location
and guard; ``dopri5.c``, ``rk4.c``, ``ros2.c``), next to the generated functions, with the
contract of the numba kernels (:func:`winder.solve.dopri5.dopri5`,
:func:`winder.solve.rk4.rk4`, :func:`winder.solve.rosenbrock.ros2`): the same arguments,
statuses, counters and results, bit for bit (issue #23, item 1; ``docs/c-integrators.md``).

For now a separate small shared library, compiled with the flags of the generated code
(:data:`winder.model.codegen.CFLAGS`, plus ``-ffp-contract=off`` so that no fused
multiply–add changes a rounding), cached under :func:`~winder.model.codegen.cache_dir`
keyed by its source and the flags, loaded with ctypes; it takes the generated functions'
addresses (``MachineSystem.fns``). The one library per machine comes later.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import subprocess
import tempfile
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from winder.model.codegen import CFLAGS, CompileError, _compiler, cache_dir

__all__ = ["dopri5", "rk4", "ros2", "library", "kernels", "SOURCES", "EXTRA_CFLAGS", "ENV"]

#: ``WINDER_INTEGRATORS=c`` runs simulate and the Stepper on these kernels (opt-in while
#: they are compared with the numba ones; the default stays numba).
ENV = "WINDER_INTEGRATORS"

_DIR = Path(__file__).resolve().parent / "c"
#: The translation units of the library (each includes ``events.h``).
SOURCES = (_DIR / "dopri5.c", _DIR / "rk4.c", _DIR / "ros2.c")
#: Flags beyond the generated code's: no contraction into FMA (bit-equality with numba).
EXTRA_CFLAGS = ("-ffp-contract=off", "-std=c99")

_LIB: Any = None

_dp = ctypes.POINTER(ctypes.c_double)
_ip = ctypes.POINTER(ctypes.c_int64)
_i64, _f64 = ctypes.c_int64, ctypes.c_double


#: ``WINDER_SANITIZE=1``: build with AddressSanitizer and UBSan (``make test-asan``: Python
#: runs with libasan and libstdc++ preloaded and ``ASAN_OPTIONS=detect_leaks=0``).
SANITIZE_CFLAGS = ("-fsanitize=address,undefined", "-fno-sanitize-recover=undefined",
                   "-fno-omit-frame-pointer", "-g")


def _build(directory: Path | None = None) -> Path:
    flags = (*CFLAGS, *EXTRA_CFLAGS)
    if os.environ.get("WINDER_SANITIZE", "") not in ("", "0"):
        flags = (*flags, *SANITIZE_CFLAGS)
    h = hashlib.sha256(" ".join(flags).encode())
    for f in sorted(_DIR.glob("*.[ch]")):  # every source and header: the key
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    key = h.hexdigest()[:20]
    root = Path(directory) if directory is not None else cache_dir() / "integrators"
    lib = root / f"integrators-{key}.so"
    if lib.exists():
        return lib
    cc = _compiler()
    root.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=root, prefix=".build-") as tmp:
        tmp_lib = Path(tmp) / lib.name
        proc = subprocess.run([cc, *flags, *map(str, SOURCES), "-o", str(tmp_lib), "-lm"],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            raise CompileError(f"compiling the C integrators failed ({cc}):\n"
                               + proc.stderr[-2000:])
        os.replace(tmp_lib, lib)
    return lib


def library() -> Any:
    """The loaded C integrators (built and cached on first use)."""
    global _LIB
    if _LIB is None:
        handle = ctypes.CDLL(str(_build()))
        fn = handle.winder_dopri5
        fn.restype = ctypes.c_int
        fn.argtypes = [_ip, _ip, _i64, _i64, _f64, _f64, _dp, _i64, _dp, _dp, _f64, _f64, _f64,
                       _f64, _dp, _i64, _dp, _i64, _i64, _ip, _i64, _dp, _dp, _ip]
        fn = handle.winder_ros2
        fn.restype = ctypes.c_int
        fn.argtypes = [_ip, _ip, _i64, _i64, _f64, _f64, _dp, _i64, _dp, _dp, _f64, _f64, _f64,
                       _f64, _dp, _i64, _dp, _i64, _i64, _ip, _dp, _dp, _ip]
        fn = handle.winder_rk4
        fn.restype = ctypes.c_int
        fn.argtypes = [_ip, _ip, _i64, _i64, _f64, _f64, _dp, _i64, _dp, _dp, _f64, _dp, _i64,
                       _dp, _i64, _ip, _dp, _dp, _ip]
        _LIB = handle
    return _LIB


def kernels(n_switches: int = 0) -> tuple[Any, Any, Any]:
    """``(dopri5, rk4, ros2)``: the C kernels (for a machine whose ``sw`` writes
    ``n_switches`` values) where ``$WINDER_INTEGRATORS`` is ``c``, else the numba ones
    (the default until the numba code is deleted)."""
    if os.environ.get(ENV, "numba") == "c":
        return (partial(dopri5, n_switches=n_switches), partial(rk4, n_switches=n_switches),
                partial(ros2, n_switches=n_switches))
    from winder.solve.dopri5 import dopri5 as dopri5_numba
    from winder.solve.rk4 import rk4 as rk4_numba
    from winder.solve.rosenbrock import ros2 as ros2_numba

    return dopri5_numba, rk4_numba, ros2_numba


def _ptr(a: np.ndarray, dtype: Any, name: str, writable: bool = False) -> Any:
    if a.dtype != dtype or not a.flags.c_contiguous or (writable and not a.flags.writeable):
        raise TypeError(f"{name}: a C-contiguous{' writable' if writable else ''} {dtype} "
                        f"array is needed, got {a.dtype} {a.shape}")
    return a.ctypes.data_as(_ip if dtype == np.int64 else _dp)


def dopri5(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
           p: np.ndarray, m: np.ndarray, rtol: float, atol: float, h: float,
           max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int, budget: int,
           stats: np.ndarray, n_switches: int = 0) -> tuple[int, float, float, int]:
    """:func:`winder.solve.dopri5.dopri5` in C: the same arguments and results
    (``(status, t, h, k)``; ``y``, ``m``, ``Y_out`` and ``stats`` updated in place).
    ``n_switches``: how many values the generated ``sw`` writes
    (``Generated.n_switches``); the switch buffers hold at least those the ``table``
    refers to (all the numba kernels allocate)."""
    lib = library()
    n = _check(fns, table, y, m, t_out, Y_out, stats)
    tr, hr, kr = _f64(), _f64(), _i64()
    status = lib.winder_dopri5(
        _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
        int(n_switches),
        float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
        _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(rtol), float(atol),
        float(h), float(max_step), _ptr(t_out, np.float64, "t_out"), t_out.shape[0],
        _ptr(Y_out, np.float64, "Y_out", True), int(k), int(budget),
        _ptr(stats, np.int64, "stats", True), stats.shape[0], ctypes.byref(tr),
        ctypes.byref(hr), ctypes.byref(kr))
    return _result(status, tr, hr, kr)


def ros2(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
         p: np.ndarray, m: np.ndarray, rtol: float, atol: float, h: float,
         max_step: float, t_out: np.ndarray, Y_out: np.ndarray, k: int, budget: int,
         stats: np.ndarray, n_switches: int = 0) -> tuple[int, float, float, int]:
    """:func:`winder.solve.rosenbrock.ros2` in C: the same arguments and results
    (``stats`` needs all 5 counters: ``stats[4]`` counts Jacobians; ``n_switches`` as
    :func:`dopri5`)."""
    lib = library()
    n = _check(fns, table, y, m, t_out, Y_out, stats)
    if stats.shape[0] < 5:
        raise ValueError("stats must hold 5 counters")
    tr, hr, kr = _f64(), _f64(), _i64()
    status = lib.winder_ros2(
        _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
        int(n_switches),
        float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
        _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(rtol), float(atol),
        float(h), float(max_step), _ptr(t_out, np.float64, "t_out"), t_out.shape[0],
        _ptr(Y_out, np.float64, "Y_out", True), int(k), int(budget),
        _ptr(stats, np.int64, "stats", True), ctypes.byref(tr), ctypes.byref(hr),
        ctypes.byref(kr))
    return _result(status, tr, hr, kr)


def rk4(fns: np.ndarray, table: np.ndarray, t0: float, t1: float, y: np.ndarray,
        p: np.ndarray, m: np.ndarray, h: float, t_out: np.ndarray, Y_out: np.ndarray, k: int,
        stats: np.ndarray, n_switches: int = 0) -> tuple[int, float, float, int]:
    """:func:`winder.solve.rk4.rk4` in C: the same arguments and results (``n_switches``
    as :func:`dopri5`)."""
    lib = library()
    n = _check(fns, table, y, m, t_out, Y_out, stats)
    tr, hr, kr = _f64(), _f64(), _i64()
    status = lib.winder_rk4(
        _ptr(fns, np.int64, "fns"), _ptr(table, np.int64, "table"), table.shape[0],
        int(n_switches),
        float(t0), float(t1), _ptr(y, np.float64, "y", True), n,
        _ptr(p, np.float64, "p"), _ptr(m, np.float64, "m", True), float(h),
        _ptr(t_out, np.float64, "t_out"), t_out.shape[0],
        _ptr(Y_out, np.float64, "Y_out", True), int(k),
        _ptr(stats, np.int64, "stats", True), ctypes.byref(tr), ctypes.byref(hr),
        ctypes.byref(kr))
    return _result(status, tr, hr, kr)


def _check(fns: np.ndarray, table: np.ndarray, y: np.ndarray, m: np.ndarray,
           t_out: np.ndarray, Y_out: np.ndarray, stats: np.ndarray) -> int:
    n = y.shape[0]
    if stats.shape[0] < 4:
        raise ValueError("stats must hold at least 4 counters")
    if Y_out.ndim != 2 or Y_out.shape[0] != n or Y_out.shape[1] != t_out.shape[0]:
        raise ValueError(f"Y_out must be ({n}, {t_out.shape[0]}), got {Y_out.shape}")
    if table.ndim != 2 or table.shape[1] != 5 or m.shape[0] != table.shape[0]:
        raise ValueError("table must be (slots, 5) with one mode per slot")
    if fns.shape[0] < 4:
        raise ValueError("fns must hold the 4 generated functions' addresses")
    return n


def _result(status: int, tr: Any, hr: Any, kr: Any) -> tuple[int, float, float, int]:
    if status == 6:
        raise MemoryError("the C integrator could not allocate its work buffers")
    return int(status), tr.value, hr.value, int(kr.value)
