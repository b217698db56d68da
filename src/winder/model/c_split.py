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

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from winder.model.c_entry import parts_entry, unguarded

__all__ = ["Part", "split", "write_parts"]


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
    code = [f.instruction_id(k) for k in range(n)]
    special = (ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST)
    n_ops = sum(op not in special for op in code)
    # one pass: single-assignment values (CasADi reuses its work variables), where each is
    # defined (its part; -1: inputs and constants, made where used) and used
    work: dict[int, int] = {}  # work variable -> value
    kind: list[Any] = []  # value -> (input, nz) | constant (float) | None (an operation)
    home: list[int] = []  # value -> its part
    steps: list[list[tuple[int, list[int], int]]] = [[] for _ in range(parts)]
    outputs: dict[int, int] = {}  # output nonzero -> value
    later_use: set[int] = set()  # values used in a later part than theirs (or outputs)
    i = 0
    for k, op in enumerate(code):
        ins, out = f.instruction_input(k), f.instruction_output(k)
        if op == ca.OP_OUTPUT:
            if out[0] != 0:
                raise ValueError("split: one output only")
            outputs[out[1]] = work[ins[0]]
            continue
        if op == ca.OP_INPUT:
            kind.append((ins[0], ins[1]))
            home.append(-1)
        elif op == ca.OP_CONST:
            kind.append(f.instruction_constant(k))
            home.append(-1)
        else:
            j = min(i * parts // n_ops, parts - 1)  # parts of about equal operations
            i += 1
            args = [work[w] for w in ins]
            later_use.update(v for v in args if 0 <= home[v] < j)
            kind.append(None)
            home.append(j)
            steps[j].append((op, args, len(kind) - 1))
        work[out[0]] = len(kind) - 1
    later_use.update(v for v in outputs.values() if 0 <= home[v] < parts - 1)
    carried = {v: i for i, v in enumerate(sorted(later_use))}  # in the order of definition
    n_c = len(carried)
    syms = [f.sx_in(i) for i in range(f.n_in())]
    elements = [ca.vertsplit(s) for s in syms]  # inputs: dense vectors
    c = ca.SX.sym("c", n_c)
    c_el = ca.vertsplit(c)
    result: list[Part] = []
    was = ca.GlobalOptions.getSimplificationOnTheFly()
    ca.GlobalOptions.setSimplificationOnTheFly(False)  # every operation as it is in f
    try:
        for j in range(parts):
            made: dict[int, Any] = {}

            def get(v: int, j: int = j, made: dict[int, Any] = made) -> Any:
                what = kind[v]
                if what is None:
                    return made[v] if home[v] == j else c_el[carried[v]]
                if isinstance(what, tuple):
                    return elements[what[0]][what[1]]
                return ca.SX(what)

            for op, args, v in steps[j]:
                a = [get(u) for u in args]
                if len(a) not in (1, 2):  # a call node, say: not an operation replayed here
                    raise NotImplementedError(f"c_split: operation {op} of {len(a)} operands "
                                              "(only unary and binary operations are split)")
                made[v] = ca.SX.unary(op, a[0]) if len(a) == 1 else \
                    ca.SX.binary(op, a[0], a[1])
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


def write_parts(f: Any, symbol: str, directory: Path, size: int,
                ready: Callable[[str, Path, int], None] | None
                ) -> list[tuple[str, Path, int]]:
    """The right-hand side ``f`` cut (:func:`split`) into about ``f.n_instructions() /
    size`` parts, one C file each in ``directory``: ``SYMBOL_rhs1.c``, ... and last
    ``SYMBOL_rhs.c`` with the flat entry point that calls them in turn
    (:func:`~winder.model.c_entry.parts_entry`); ``ready("part", path, instructions)``
    called on each file as soon as it is written. Returns those triples."""
    import casadi as ca

    k = -(-f.n_instructions() // size)
    names = [f"{symbol}_rhs{j}" for j in range(1, k)] + [f"{symbol}_rhs"]
    parts = split(f, names)
    calls = [(n, q.function, q.offset) for n, q in zip(names, parts, strict=True)]
    files: list[tuple[str, Path, int]] = []
    for j, (name, part) in enumerate(zip(names, parts, strict=True)):
        cg = ca.CodeGenerator(f"{name}.c", {"with_header": False})
        cg.add(part.function)
        entry = "" if j < k - 1 else parts_entry(symbol, "rhs", calls, part.n_carried)
        path = directory / f"{name}.c"
        path.write_text(f"/* {name}: part {j + 1} of {k} of {symbol}_rhs, generated by CasADi "
                        f"{ca.__version__} for winder */\n" + unguarded(cg.dump()) + entry)
        files.append(("part", path, part.function.n_instructions()))
        if ready is not None:
            ready(*files[-1])
    return files
