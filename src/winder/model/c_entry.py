"""The C text around CasADi's generated functions (:mod:`winder.model.codegen`): CasADi's
null checks removed (:func:`unguarded`) and the flat, reentrant entry points
``SYMBOL_K_flat(t, x, p, m, out)`` (:func:`flat_entry`), the Jacobian's with its
nonzeros' entry point and CCS pattern, and that of a function cut into parts
(:func:`parts_entry`, :mod:`winder.model.c_split`)."""

from __future__ import annotations

import re
from typing import Any

__all__ = ["unguarded", "flat_entry", "parts_entry"]


def unguarded(code: str) -> str:
    """CasADi's code without its null checks on each argument read (``arg[i]? arg[i][j] :
    0``) and each result written (``if (res[0]!=0) ...``): the functions are only called
    through their flat entry points, which pass every argument and the result. One branch
    per element made the compiler's register allocation superlinear in the function's size
    (the flexible two-drum winder's Jacobian: 4800 writes, MEASURED)."""
    code = code.replace("if (res[0]!=0) ", "")
    return re.sub(r"arg\[(\d+)\]\? (arg\[\1\]\[\d+\]) : 0", r"\2", code)


def flat_entry(symbol: str, k: str, f: Any, blocks: list[tuple[str, Any, int]] | None,
                sparsity: Any) -> str:
    """The flat, reentrant entry point ``SYMBOL_K_flat(t, x, p, m, out)`` of one generated
    function. The Jacobian's (``blocks``: each column block's function name, function and
    offset of its first nonzero; ``sparsity``: the CCS pattern): each block writes its
    nonzeros to the front of ``out`` at its offset, the rest is set to 0 (one ``memset``)
    and each nonzero moved to its dense column-major place, last first (the place of the
    k-th nonzero is never before k, so none is overwritten before it moves)."""
    head = (f"\n/* flat, reentrant entry point */\n"
            f"int {symbol}_{k}_flat(const double* t, const double* x, const double* p, "
            f"const double* m, double* out) {{\n")
    if blocks is None:
        return (head + f"  const casadi_real* arg[{max(f.sz_arg(), 4)}] = {{t, x, p, m}};\n"
                f"  casadi_real* res[{max(f.sz_res(), 1)}] = {{out}};\n"
                f"  casadi_int iw[{f.sz_iw() + 1}];\n  casadi_real w[{f.sz_w() + 1}];\n"
                f"  return {symbol}_{k}(arg, res, iw, w, 0);\n}}\n")
    n, nnz = sparsity.size1(), sparsity.nnz()
    rows, cols = sparsity.get_triplet()
    place = [int(r) + n * int(c) for r, c in zip(rows, cols, strict=True)]
    ccs = [n, n, *map(int, sparsity.colind()), *map(int, sparsity.row())]

    def table(values: list[int]) -> str:
        lines = [", ".join(str(v) for v in values[i:i + 16]) for i in range(0, len(values), 16)]
        return ",\n  ".join(lines or ["0"])

    decls = "".join(f"int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, "
                    "casadi_real* w, int mem);\n" for name, _, _ in blocks[1:])
    calls = "".join(f"  res[0] = out + {off};\n  flag |= {name}(arg, res, iw, w, 0);\n"
                    for name, _, off in blocks)
    fs = [g for _, g, _ in blocks]
    sig = "(const double* t, const double* x, const double* p, const double* m, double* out)"
    return ("#include <string.h>\n" + decls
            + f"static const casadi_int {symbol}_jac_place[{max(nnz, 1)}] = {{\n  "
            + table(place) + "};\n"
            + f"static const casadi_int {symbol}_jac_ccs[{len(ccs)}] = {{\n  " + table(ccs)
            + "};\n\n/* the Jacobian's structural sparsity in CasADi's compressed column "
            "format:\n * {rows, columns, colind[columns + 1], row[nonzeros]} */\n"
            f"const casadi_int* {symbol}_jac_sparsity(void) {{\n"
            f"  return {symbol}_jac_ccs;\n}}\n"
            "\n/* the Jacobian's nonzeros only, in the order of its sparsity (CCS) */\n"
            f"int {symbol}_jac_nz_flat{sig} {{\n"
            f"  const casadi_real* arg[{max(4, *(g.sz_arg() for g in fs))}] = {{t, x, p, m}};\n"
            f"  casadi_real* res[{max(1, *(g.sz_res() for g in fs))}];\n"
            f"  casadi_int iw[{max(g.sz_iw() for g in fs) + 1}];\n"
            f"  casadi_real w[{max(g.sz_w() for g in fs) + 1}];\n"
            f"  int flag = 0;\n" + calls + "  return flag;\n}\n" + head
            + f"  int flag = {symbol}_jac_nz_flat(t, x, p, m, out);\n  casadi_int k;\n"
            f"  memset(out + {nnz}, 0, sizeof(double) * {n * n - nnz});\n"
            f"  for (k = {nnz} - 1; k >= 0; k--) {{\n"
            f"    double v = out[k];\n"
            f"    out[k] = 0.;\n"
            f"    out[{symbol}_jac_place[k]] = v;\n  }}\n"
            f"  return flag;\n}}\n")


def parts_entry(symbol: str, k: str, parts: list[tuple[str, Any, int | None]],
                n_carried: int) -> str:
    """The flat, reentrant entry point ``SYMBOL_K_flat(t, x, p, m, out)`` of a function cut
    into parts (:func:`winder.model.c_split.split`; ``parts``: each part's C name, function
    and offset into the carried values, ``None`` for the last): the parts called in turn,
    each writing its carried values into one array on the stack (``c``, ``n_carried``
    doubles), the last the output."""
    fs = [g for _, g, _ in parts]
    decls = "".join(f"int {name}(const casadi_real** arg, casadi_real** res, casadi_int* iw, "
                    "casadi_real* w, int mem);\n" for name, _, _ in parts[:-1])
    calls = "".join(f"  res[0] = {'out' if off is None else f'c + {off}'};\n"
                    f"  flag |= {name}(arg, res, iw, w, 0);\n" for name, _, off in parts)
    return (f"\n{decls}/* flat, reentrant entry point: the {len(parts)} parts in turn */\n"
            f"int {symbol}_{k}_flat(const double* t, const double* x, const double* p, "
            f"const double* m, double* out) {{\n"
            f"  casadi_real c[{max(n_carried, 1)}];\n"
            f"  const casadi_real* arg[{max(5, *(g.sz_arg() for g in fs))}] = "
            "{t, x, p, m, c};\n"
            f"  casadi_real* res[{max(1, *(g.sz_res() for g in fs))}];\n"
            f"  casadi_int iw[{max(g.sz_iw() for g in fs) + 1}];\n"
            f"  casadi_real w[{max(g.sz_w() for g in fs) + 1}];\n"
            f"  int flag = 0;\n" + calls + "  return flag;\n}\n")
