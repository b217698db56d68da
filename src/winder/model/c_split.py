"""A large generated function cut into parts, each its own C file (issue #33,
:mod:`winder.model.codegen`): the compiler's time on one function grows faster than the
function (register allocation over thousands of values), so a right-hand side of many
CasADi instructions is compiled as several functions of bounded size, in parallel, called
in turn by its flat entry point.

The cut is made on the function's own algorithm (:func:`split`): its instructions, in
CasADi's order, are replayed on fresh symbols with CasADi's simplification on the fly
turned off, so every part holds exactly the operations of the whole, each once, with the
same operands (the results are bitwise those of the one function). The values a part
computes and a later part uses (and the outputs computed before the last part) are the
cut's *carried* values: part ``j`` writes its own into one array of doubles, ``c``, at its
offset; every part reads the earlier ones from it (a fifth argument); the last part writes
the function's output."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Part", "split"]


@dataclass(frozen=True)
class Part:
    """One part of a cut function: ``function`` of ``(t, x, p, m, c)`` (``c``: the carried
    values, :attr:`n_carried` of the whole cut) whose one output is written at ``offset``
    into ``c`` (``None``: the last part, whose output is the function's)."""

    function: Any  # casadi.Function
    offset: int | None
    n_carried: int


def split(f: Any, names: list[str]) -> list[Part]:
    """``f`` (a CasADi SX function of inputs ``(t, x, p, m)`` and one dense output) cut into
    ``len(names)`` functions of those names, of about the same number of operations each
    (in the order of ``f``'s algorithm); see the module's docstring. The parts called in
    turn (:class:`Part`) compute ``f``'s output with the same operations."""
    import casadi as ca

    parts = len(names)
    n = f.n_instructions()
    special = (ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST)
    ops = [k for k in range(n) if f.instruction_id(k) not in special]
    part_of_op = {k: min(i * parts // max(len(ops), 1), parts - 1) for i, k in enumerate(ops)}
    # first pass: single-assignment values (CasADi reuses its work variables), where each
    # is defined and where it is used
    work: dict[int, int] = {}  # work variable -> value
    kind: list[tuple[str, Any]] = []  # value -> ("in", (input, nz)) | ("const", v) | ("op", k)
    home: list[int] = []  # value -> part (-1: inputs and constants, made where used)
    args: dict[int, list[int]] = {}  # instruction -> its operands' values
    outputs: dict[int, int] = {}  # output nonzero -> value
    carried: dict[int, int] = {}  # value -> index in c, in the order of definition
    later_use: set[int] = set()
    value_of: dict[int, int] = {}  # instruction -> the value it defines
    for k in range(n):
        op, ins, out = f.instruction_id(k), f.instruction_input(k), f.instruction_output(k)
        if op == ca.OP_OUTPUT:
            if out[0] != 0:
                raise ValueError("split: one output only")
            outputs[out[1]] = work[ins[0]]
            continue
        if op == ca.OP_INPUT:
            kind.append(("in", (ins[0], ins[1])))
            home.append(-1)
        elif op == ca.OP_CONST:
            kind.append(("const", f.instruction_constant(k)))
            home.append(-1)
        else:
            args[k] = [work[i] for i in ins]
            for v in args[k]:
                if 0 <= home[v] < part_of_op[k]:
                    later_use.add(v)
            kind.append(("op", k))
            home.append(part_of_op[k])
            value_of[k] = len(kind) - 1
        work[out[0]] = len(kind) - 1
    for v in outputs.values():
        if 0 <= home[v] < parts - 1:
            later_use.add(v)
    for v in sorted(later_use):  # values are numbered in the order of definition
        carried[v] = len(carried)
    n_c = len(carried)
    syms = [f.sx_in(i) for i in range(f.n_in())]
    c = ca.SX.sym("c", n_c)
    result: list[Part] = []
    was = ca.GlobalOptions.getSimplificationOnTheFly()
    ca.GlobalOptions.setSimplificationOnTheFly(False)  # every operation as it is in f
    try:
        for j in range(parts):
            made: dict[int, Any] = {}

            def get(v: int, j: int = j, made: dict[int, Any] = made) -> Any:
                what, data = kind[v]
                if what == "in":
                    return syms[data[0]].nz[data[1]]
                if what == "const":
                    return ca.SX(data)
                if home[v] == j:
                    return made[v]
                return c[carried[v]]

            for k in ops:
                if part_of_op[k] != j:
                    continue
                a = [get(v) for v in args[k]]
                val = ca.SX.unary(f.instruction_id(k), a[0]) if len(a) == 1 else \
                    ca.SX.binary(f.instruction_id(k), a[0], a[1])
                made[value_of[k]] = val
            if j < parts - 1:
                mine = [v for v in carried if home[v] == j]
                expr = ca.vertcat(*[made[v] for v in mine]) if mine else ca.SX(0, 1)
                offset: int | None = carried[mine[0]] if mine else n_c
            else:
                expr = ca.vertcat(*[get(outputs[i]) for i in range(len(outputs))])
                offset = None
            fn = ca.Function(names[j], [*syms, c], [ca.densify(expr)])
            result.append(Part(fn, offset, n_c))
    finally:
        ca.GlobalOptions.setSimplificationOnTheFly(was)
    return result
