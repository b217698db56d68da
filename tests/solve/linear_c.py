"""A linear test machine ``x' = A x + b sin(w t)`` written in C and linked with the C
integrators' objects as a generated machine's library is (the oracle machines of
``test_dop853.py`` and ``test_rosenbrock_sparse.py``), and its closed form."""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
from scipy.linalg import expm

from winder.model.codegen import Generated, compile_flags, run_compiler
from winder.solve.cint import EXTRA_CFLAGS, Kernels, link


def rhs_source(A: np.ndarray, B: np.ndarray, W: float) -> str:
    """The C of ``lin_rhs``: ``out = A x + B sin(W t)``, each coefficient printed exactly
    (``repr``), the structural zeros left out."""
    rows = []
    for i in range(len(B)):
        terms = " + ".join(f"({float(A[i, j])!r}) * x[{j}]" for j in range(len(B))
                           if A[i, j] != 0.0)
        rows.append(f"  out[{i}] = {terms} + ({float(B[i])!r}) * sin({W!r} * t[0]);")
    return ("int lin_rhs(const double* t, const double* x, const double* p, const double* m,"
            " double* out) {\n" + "\n".join(rows) + "\n  return 0;\n}\n")


def build(directory: Path, source: str, functions: tuple[str, str, str, str],
          n: int) -> tuple[Kernels, np.ndarray]:
    """``source`` compiled in ``directory`` and linked with the integrators (the flags of a
    machine's library: sanitized builds link the runtime); ``functions``: the C names of the
    rhs, Jacobian, channels and switching functions. The kernels and the addresses."""
    (directory / "lin.c").write_text(source)
    flags = (*compile_flags(), *EXTRA_CFLAGS)
    run_compiler([*flags, "-c", str(directory / "lin.c"), "-o", str(directory / "lin.o")],
                 "the test machine")
    objects = [str(o) for o in link().objects]
    run_compiler([*flags, "-shared", "-o", str(directory / "lin.so"),
                  str(directory / "lin.o"), *objects, "-lm"], "the test library")
    lib = ctypes.CDLL(str(directory / "lin.so"))
    fns = np.array([ctypes.cast(getattr(lib, f), ctypes.c_void_p).value for f in functions],
                   dtype=np.int64)
    gen = Generated("lin", directory / "lin.so", n, 1, 0, 1, 1, fns, _lib=lib)
    return Kernels(gen), fns


def closed_form(A: np.ndarray, B: np.ndarray, W: float, x0: np.ndarray,
                t: float) -> np.ndarray:
    """x(t) from ``x0``: ``expm`` of the system augmented by s = sin(W t), c = cos(W t)."""
    n = len(B)
    big = np.zeros((n + 2, n + 2))
    big[:n, :n], big[:n, n] = A, B
    big[n, n + 1], big[n + 1, n] = W, -W
    return (expm(big * t) @ np.concatenate((x0, [0.0, 1.0])))[:n]
