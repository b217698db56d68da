"""Calling generated C functions from compiled (numba) code through their addresses.

A generated function has the flat signature ``int f(const double* t, const double* x,
const double* p, const double* m, double* out)``. :func:`call` casts an address to that
function type inside the compiled code, so one compiled integrator serves every machine
and numba can cache it (a ctypes function in a global cannot be cached).
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["call"]


@intrinsic
def call(typingctx: Any, addr: Any, t: Any, x: Any, p: Any, m: Any, out: Any) -> Any:
    """``f(t, x, p, m, out)`` for the C function at ``addr``; all arguments are integers
    (addresses: ``arr.ctypes.data``). Returns the function's status."""
    sig = types.int32(addr, t, x, p, m, out)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        dptr = ir.DoubleType().as_pointer()
        fnty = ir.FunctionType(ir.IntType(32), [dptr] * 5)
        fn = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(fn, [builder.inttoptr(a, dptr) for a in args[1:]])

    return sig, codegen
