"""The Jacobian built on first use (issue #33, :mod:`winder.model.codegen`): the machine's
library holds the right-hand side, channels and switching functions (all an explicit run
needs); the Jacobian is generated and compiled into its own library beside it when first
asked for, under the same key. Oracles: the eager path (every function generated at once,
as the FMU compiles them, :func:`~winder.model.codegen.write_source`), which the lazy
Jacobian must equal bit for bit, whether built from the symbols of the first build or from
the machine made on symbols again; its nonzeros and CCS pattern scattered by hand; and the
counters and files of the cache (an explicit run builds no Jacobian, an implicit one
after it builds it once)."""

from __future__ import annotations

import ctypes
from pathlib import Path

import machines as mc
import numpy as np
import pytest

import winder
from winder.model import codegen
from winder.model.locked_modes import AUTO, CORE_AUTO
from winder.model.machine import Machine
from winder.solve.system import MachineSystem

pytest.importorskip("casadi")

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh, empty ``$WINDER_CACHE_DIR`` for one test."""
    d = tmp_path / "cache"
    monkeypatch.setenv("WINDER_CACHE_DIR", str(d))
    return d


def _states(m: Machine, count: int = 3) -> list[tuple[float, np.ndarray, np.ndarray]]:
    x0 = np.array(m.state_initial, dtype=float)
    x0[m.index("set.z")] -= 1e-4
    x0[m.index("set.theta_dot")] = -40.0
    modes = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                     dtype=float)
    rng = np.random.default_rng(11)
    n = m.n_states
    return [(2.0 + k, x0 * (1 + 1e-3 * rng.standard_normal(n)) + 1e-4 * rng.standard_normal(n),
             modes) for k in range(count)]


def _eager_jacobian(m: Machine, directory: Path) -> ctypes.CDLL:
    """Every function of ``m`` generated at once (:func:`write_source`, the FMU's path) and
    compiled into one library, each file at its level."""
    paths, symbol, _, levels = codegen.write_source(m, directory)
    objs = []
    for path, lv in zip(paths, levels, strict=True):
        flags = codegen.with_level(codegen.compile_flags(), lv)
        codegen.run_compiler([*flags, "-c", str(path), "-o", str(path.with_suffix(".o"))],
                             path.name)
        objs.append(str(path.with_suffix(".o")))
    lib = directory / f"{symbol}_eager.so"
    codegen.run_compiler([*codegen.link_flags(), *objs, "-o", str(lib), "-lm"], "eager")
    return ctypes.CDLL(str(lib))


def _dense(lib: ctypes.CDLL, symbol: str, t: float, x: np.ndarray, p: np.ndarray,
           modes: np.ndarray, n: int) -> np.ndarray:
    fn = getattr(lib, f"{symbol}_jac_flat")
    dp = np.ctypeslib.ndpointer(dtype=float, flags="C_CONTIGUOUS")
    fn.argtypes = [dp] * 5
    out = np.full(n * n, np.nan)
    fn(np.array([t]), x, p, modes, out)
    return out


@pytest.mark.parametrize("split", [None, 10])
def test_lazy_jacobian_equals_the_eager_one_bit_for_bit(split: int | None, cache: Path,
                                                        tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    """The two-drum winder (88 nonzeros; ``split``: in two column blocks): its library
    holds no Jacobian (address 0, no ``_jac.so``, no symbol); built on first use from the
    first build's symbols, and again (its library removed) from a machine loaded from the
    cache (the symbols made again), it equals the eager one exactly at perturbed states
    (measured: 0 difference, every entry); its nonzeros scattered by its CCS pattern give
    the dense matrix; the other functions are untouched by it."""
    if split is not None:
        monkeypatch.setattr(codegen, "JAC_SPLIT", split)
    m = Machine(mc.two_drum())
    n = m.n_states
    before = dict(codegen.stats)
    g = codegen.generate(m)
    jac_lib = g.path.parent / f"{g.symbol}_jac.so"
    assert g.addresses[1] == 0 and not jac_lib.exists()
    assert not hasattr(g._lib, f"{g.symbol}_jac_flat")  # not in the first library
    assert all(g.addresses[[0, 2, 3]] != 0)
    (tmp_path / "eager").mkdir()
    eager = _eager_jacobian(m, tmp_path / "eager")
    p = m.parameters()
    rhs_before = [g.call("rhs", t, x, p, mo) for t, x, mo in _states(m)]
    lazy = [g.call("jac", t, x, p, mo) for t, x, mo in _states(m)]  # built here
    assert codegen.stats["jacobians"] == before["jacobians"] + 1 and jac_lib.exists()
    assert g.addresses[1] != 0
    colind, row = g.jac_sparsity()
    assert colind.shape == (n + 1,) and row.shape == (colind[-1],) == (88,)
    for (t, x, mo), J, r0 in zip(_states(m), lazy, rhs_before, strict=True):
        want = _dense(eager, g.symbol, t, x, p, mo, n)
        np.testing.assert_array_equal(J.ravel(order="F"), want)
        nz = g.call("jac_nz", t, x, p, mo)
        scattered = np.zeros((n, n))
        for c in range(n):
            scattered[row[colind[c]:colind[c + 1]], c] = nz[colind[c]:colind[c + 1]]
        np.testing.assert_array_equal(scattered, J)
        np.testing.assert_array_equal(g.call("rhs", t, x, p, mo), r0)
        assert 0 < np.count_nonzero(J) < n * n / 2
    # the Jacobian made again from symbols made again (the first library from the cache)
    jac_lib.unlink()
    g2 = codegen.generate(Machine(mc.two_drum()))
    assert g2.from_cache and g2.addresses[1] == 0
    for t, x, mo in _states(m):
        np.testing.assert_array_equal(g2.call("jac", t, x, p, mo).ravel(order="F"),
                                      _dense(eager, g.symbol, t, x, p, mo, n))
    assert codegen.stats["jacobians"] == before["jacobians"] + 2
    # a machine whose Jacobian is in the cache loads it at once (nothing built)
    g3 = codegen.generate(Machine(mc.two_drum()))
    assert g3.addresses[1] != 0 and codegen.stats["jacobians"] == before["jacobians"] + 2


def test_the_cache_key_separates_the_jacobian(cache: Path) -> None:
    """The Jacobian's library is named by its machine's key beside that machine's object
    and library; another structure has another key and builds its own."""
    g1 = codegen.generate(Machine(mc.two_drum(rider_roll=False)))
    g2 = codegen.generate(Machine(mc.two_drum()))
    assert g1.key != g2.key
    g1.jacobian()
    root = cache / "generated"
    assert sorted(p.name for p in root.iterdir()) == sorted(
        [f"w{g1.key}.o", f"w{g1.key}.so", f"w{g1.key}_jac.so", f"w{g2.key}.o",
         f"w{g2.key}.so"])
    assert g2.addresses[1] == 0  # the other machine's Jacobian is not its own
    g2.jacobian()
    assert (root / f"w{g2.key}_jac.so").exists()
    m1 = Machine(mc.two_drum(rider_roll=False))
    t, x, mo = _states(m1)[0]
    assert g1.call("jac", t, x, m1.parameters(), mo).shape == (g1.n_states, g1.n_states)


def test_an_implicit_run_after_an_explicit_one_builds_the_jacobian_once(
        cache: Path) -> None:
    """The two-drum winder run with DOPRI5 builds no Jacobian; ROS2 after it builds it
    once (first use), a second ROS2 run, ``MachineSystem.jac`` and a new system of the same
    scene build nothing more; the ROS2 run agrees with the DOPRI5 run (the other method:
    ROS2 at rtol 1e-8: every channel's end value within 8e-4 of its scale; measured 8.0e-5,
    the nips' slip velocities)."""
    scene = winder.load_scene(MODELS / "two_drum_winder.toml")
    before = codegen.stats["jacobians"]
    a = winder.simulate(scene, t_end=0.3, method="DOPRI5", rtol=1e-8, atol=1e-10)
    assert codegen.stats["jacobians"] == before
    assert not list((cache / "generated").glob("*_jac.so"))
    b = winder.simulate(scene, t_end=0.3, method="ROS2", rtol=1e-8, atol=1e-10)
    assert codegen.stats["jacobians"] == before + 1
    winder.simulate(scene, t_end=0.1, method="ROS2")
    sy = MachineSystem(scene)
    assert sy.fns[1] != 0  # loaded with the machine: it is in the cache
    J = sy.jac(0.0, sy.initial_state())
    assert J.shape == (sy.n_states, sy.n_states) and np.count_nonzero(J) > 0
    assert codegen.stats["jacobians"] == before + 1
    # the two methods agree (each channel's end value against its scale over the run)
    errs = {k: abs(a[k][-1] - b[k][-1]) / max(np.max(np.abs(a[k])), 1e-30) for k in a}
    worst = max(errs.values())
    assert worst < 8e-4, worst


def test_a_kernel_refuses_a_missing_jacobian(cache: Path) -> None:
    """ROS2 through the kernels builds the Jacobian itself; a kernel handed ``fns`` with
    no Jacobian that does not ask for it is refused (no call through address 0)."""
    from winder.solve import cint

    sy = MachineSystem(winder.load_scene(MODELS / "two_drum_winder.toml"))
    fns = sy.fns.copy()
    assert fns[1] == 0
    y = sy.initial_state()
    t_out = np.array([0.0, 0.01])
    Y = np.empty((sy.n_states, 2))
    stats = np.zeros(5, dtype=np.int64)
    with pytest.raises(ValueError, match="built on first use"):
        cint._check(fns, sy.table, y, sy.modes.copy(), t_out, Y, stats)
    status, t, _, _ = sy.kernels.ros2(fns, sy.table, 0.0, 0.01, y, sy.params,
                                      sy.modes.copy(), 1e-6, 1e-8, 0.0, np.inf, t_out, Y, 0,
                                      100_000, stats)
    assert fns[1] != 0 and status == 0 and t == 0.01 and stats[4] > 0
