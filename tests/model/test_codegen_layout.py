"""The layout of the generated code (issue #33, :mod:`winder.model.codegen`): one C file per
function at its optimisation level, the Jacobian generated on its nonzeros and scattered by
its flat entry point, CasADi's null checks removed. Oracle: CasADi's own evaluation of the
same expressions (its virtual machine, no C), which the compiled functions must equal bit
for bit (no fast-math, no FMA: the optimisation level changes no result)."""

from __future__ import annotations

import ctypes
from pathlib import Path

import machines as mc
import numpy as np
import pytest

from winder.model import codegen
from winder.model.backends import SymbolicBackend
from winder.model.locked_modes import AUTO, CORE_AUTO
from winder.model.machine import Machine

ca = pytest.importorskip("casadi")


def _reference(m: Machine, route: str) -> ca.Function:
    """The rhs, the dense Jacobian, the channels and switching functions on CasADi's VM."""
    t, x = ca.SX.sym("t"), ca.SX.sym("x", m.n_states)
    p, modes = ca.SX.sym("p", len(m.param_names)), ca.SX.sym("m", len(m.mode_names))
    ev = m.evaluate(SymbolicBackend(m.model, route), t, x, p, modes)
    xdot = ca.vertcat(*[ev.rates[n] for n in m.state_names])
    outs = [xdot, ca.densify(ca.jacobian(xdot, x)),
            ca.vertcat(*[ev.channels[n] for n in m.channel_names]),
            ca.vertcat(*[ev.switches[n] for n in m.switch_names])]
    return ca.Function("ref", [t, x, p, modes], [ca.densify(o) for o in outs])


@pytest.mark.parametrize("split, part", [(None, None), (10, None), (None, 150)])
def test_functions_equal_casadi_bit_for_bit(split: int | None, part: int | None,
                                            tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """rhs, Jacobian (scattered from its nonzeros into a buffer full of NaN), channels and
    switching functions of the two-drum winder equal CasADi's evaluation exactly at
    perturbed states (measured: 0 difference everywhere), with the Jacobian in one piece
    and (``split``: its 88 nonzeros over :data:`JAC_SPLIT`) in two column blocks, and the
    rhs in one piece at -O3 and (``part``: its 516 instructions over :data:`RHS_PART`) in
    four parts at ``OPTIMISE["part"]``; the Jacobian is sparse (so the scatter is
    exercised: 77 of 196 entries) and every structural zero is written as 0."""
    monkeypatch.setenv("WINDER_CACHE_DIR", str(tmp_path))
    if split is not None:
        monkeypatch.setattr(codegen, "JAC_SPLIT", split)
    if part is not None:
        monkeypatch.setattr(codegen, "RHS_PART", part)
    m = Machine(mc.two_drum())
    g = codegen.generate(m)
    assert [k for k in g.sizes if k.startswith("rhs")] == (
        ["rhs"] if part is None else ["rhs1", "rhs2", "rhs3", "rhs"])
    ref = _reference(m, g.route)
    x0 = np.array(m.state_initial, dtype=float)
    x0[m.index("set.z")] -= 1e-4
    x0[m.index("set.theta_dot")] = -40.0
    modes = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                     dtype=float)
    p = m.parameters()
    rng = np.random.default_rng(7)
    n = m.n_states
    for _ in range(4):
        x = x0 * (1 + 1e-3 * rng.standard_normal(n)) + 1e-4 * rng.standard_normal(n)
        want = [np.array(v, dtype=float) for v in ref(3.0, x, p, modes)]
        for which, w in zip(codegen.FUNCTIONS, want, strict=True):
            size = w.size
            out = np.full(size, np.nan)
            fn = getattr(g.library(which), f"{g.symbol}_{which}_flat")
            dp = np.ctypeslib.ndpointer(dtype=float, flags="C_CONTIGUOUS")
            fn.argtypes = [dp] * 5
            fn(np.array([3.0]), x, p, modes, out)
            np.testing.assert_array_equal(out, w.ravel(order="F"), err_msg=which)
        nz = np.count_nonzero(want[1])
        assert 0 < nz < n * n / 2  # sparse: the scatter moves and zeroes


def test_levels_and_layout_are_in_the_key(monkeypatch: pytest.MonkeyPatch) -> None:
    """Another optimisation level or layout is another cache key (no stale object)."""
    m = Machine(mc.single_drum())
    flags = codegen.compile_flags()
    base = codegen._key(m, "py", flags)
    monkeypatch.setitem(codegen.OPTIMISE, "jac", "-O1")
    assert codegen._key(m, "py", flags) != base
    monkeypatch.undo()
    monkeypatch.setattr(codegen, "LAYOUT", "another")
    assert codegen._key(m, "py", flags) != base
    monkeypatch.undo()
    monkeypatch.setattr(codegen, "LARGE", 1)
    assert codegen._key(m, "py", flags) != base
    monkeypatch.undo()
    monkeypatch.setattr(codegen, "RHS_PART", 1)
    assert codegen._key(m, "py", flags) != base
    monkeypatch.undo()
    monkeypatch.setattr(codegen, "JAC_SPLIT", 1)
    assert codegen._key(m, "py", flags) != base
    monkeypatch.undo()
    assert codegen._key(m, "py", flags) == base


def test_sources_one_file_per_function_without_null_checks(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """write_source: one file per function (the Jacobian over :data:`JAC_SPLIT` nonzeros in
    two), no ``if (res[0]!=0)`` or ``arg[i]?`` left, the Jacobian's function writes only its
    nonzeros, each file's level as generate uses it."""
    m = Machine(mc.two_drum())
    monkeypatch.setattr(codegen, "JAC_SPLIT", 10)
    (tmp_path / "split").mkdir()
    paths, symbol, pattern, levels = codegen.write_source(m, tmp_path / "split")
    assert [p.name for p in paths] == [f"{symbol}_{k}.c" for k in ("rhs", "jac1", "jac", "out",
                                                                    "sw")]
    monkeypatch.undo()
    paths, symbol, pattern, levels = codegen.write_source(m, tmp_path)
    assert [p.name for p in paths] == [f"{symbol}_{k}.c" for k in codegen.FUNCTIONS]
    for path in paths:
        text = path.read_text()
        assert "if (res[0]!=0)" not in text and "]? arg[" not in text, path.name
    jac = paths[1].read_text()
    assert f"{symbol}_jac_place[{len(pattern['x'])}]" in jac
    assert levels == [codegen.OPTIMISE[k] for k in codegen.FUNCTIONS]  # all small


@pytest.mark.parametrize("parts", [2, 3, 7])
def test_rhs_parts_are_the_same_operations(parts: int) -> None:
    """:func:`~winder.model.c_split.split`: the parts, evaluated in turn on CasADi's virtual
    machine (no C) with their carried values, give the whole rhs bit for bit (measured: 0
    difference), and hold each of its operations once (their operations, less the inputs,
    constants and outputs each part reads or writes, add up to the whole's)."""
    from winder.model.c_split import split

    m = Machine(mc.two_drum())
    t, x = ca.SX.sym("t"), ca.SX.sym("x", m.n_states)
    p, modes = ca.SX.sym("p", len(m.param_names)), ca.SX.sym("m", len(m.mode_names))
    ev = m.evaluate(SymbolicBackend(m.model, "py"), t, x, p, modes)
    f = ca.Function("f", [t, x, p, modes], [ca.densify(ca.vertcat(
        *[ev.rates[n] for n in m.state_names]))], {"cse": True})
    cut = split(f, [f"part{j}" for j in range(parts)])

    def operations(g: ca.Function) -> int:
        return sum(g.instruction_id(k) not in (ca.OP_INPUT, ca.OP_OUTPUT, ca.OP_CONST)
                   for k in range(g.n_instructions()))

    assert sum(operations(q.function) for q in cut) == operations(f)
    assert all(operations(q.function) > 0 for q in cut)
    x0 = np.array(m.state_initial, dtype=float)
    x0[m.index("set.z")] -= 1e-4
    x0[m.index("set.theta_dot")] = -40.0
    mv = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                  dtype=float)
    rng = np.random.default_rng(5)
    for k in range(3):
        xs = x0 * (1 + 1e-3 * rng.standard_normal(m.n_states))
        want = np.array(f(1.0 + k, xs, m.parameters(), mv), dtype=float).ravel()
        carried = np.full(cut[0].n_carried, np.nan)
        for q in cut[:-1]:
            out = np.array(q.function(1.0 + k, xs, m.parameters(), mv, carried),
                           dtype=float).ravel()
            carried[q.offset:q.offset + out.size] = out
        got = np.array(cut[-1].function(1.0 + k, xs, m.parameters(), mv, carried),
                       dtype=float).ravel()
        assert not np.isnan(carried).any()  # every carried value written by its part
        np.testing.assert_array_equal(got, want)
        assert np.count_nonzero(want) > m.n_states // 2


def test_sources_with_rhs_parts_compile_as_the_fmu_does(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """write_source (the FMU's path) with the rhs over :data:`RHS_PART`: its parts' files
    before the last (``rhs1``, ``rhs2``, ``rhs3``, then ``rhs`` with the flat entry point),
    each at ``OPTIMISE["part"]`` (several flags: :func:`with_level`); compiled from those
    files and levels, the rhs equals the one-piece rhs of :func:`generate` bit for bit."""
    m = Machine(mc.two_drum())
    monkeypatch.setenv("WINDER_CACHE_DIR", str(tmp_path / "cache"))
    whole = codegen.generate(m)
    monkeypatch.setattr(codegen, "RHS_PART", 150)
    (tmp_path / "src").mkdir()
    paths, symbol, _, levels = codegen.write_source(m, tmp_path / "src")
    assert [p.stem.removeprefix(symbol + "_") for p in paths] == [
        "rhs1", "rhs2", "rhs3", "rhs", "jac", "out", "sw"]
    assert levels[:4] == [codegen.OPTIMISE["part"]] * 4 and levels[4:] == [
        codegen.OPTIMISE[k] for k in ("jac", "out", "sw")]
    objs = []
    for path, lv in zip(paths, levels, strict=True):
        flags = codegen.with_level(codegen.compile_flags(), lv)
        assert len(flags) == len(codegen.compile_flags()) + len(lv.split()) - 1
        codegen.run_compiler([*flags, "-c", str(path), "-o", str(path.with_suffix(".o"))],
                             path.name)
        objs.append(str(path.with_suffix(".o")))
    lib = tmp_path / "parts.so"
    codegen.run_compiler([*codegen.link_flags(), *objs, "-o", str(lib), "-lm"], "parts")
    fn = getattr(ctypes.CDLL(str(lib)), f"{symbol}_rhs_flat")
    dp = np.ctypeslib.ndpointer(dtype=float, flags="C_CONTIGUOUS")
    fn.argtypes = [dp] * 5
    x0 = np.array(m.state_initial, dtype=float)
    modes = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                     dtype=float)
    rng = np.random.default_rng(9)
    for k in range(3):
        x = x0 * (1 + 1e-3 * rng.standard_normal(m.n_states))
        out = np.full(m.n_states, np.nan)
        fn(np.array([1.0 + k]), x, m.parameters(), modes, out)
        np.testing.assert_array_equal(out, whole.call("rhs", 1.0 + k, x, m.parameters(), modes))
