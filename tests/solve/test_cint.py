"""One library per machine (:mod:`winder.solve.cint`, issue #23): the integrators'
objects are compiled once and linked with each machine's generated object; a change of
the integrators relinks and generates nothing; the library's entry points agree with the
generated functions called alone."""

from __future__ import annotations

from pathlib import Path

import machines as mc
import numpy as np
import pytest

from winder.model import codegen
from winder.model.machine import Machine
from winder.solve import cint
from winder.solve import integrators as integ
from winder.solve.system import MachineSystem


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh, empty ``$WINDER_CACHE_DIR`` (and no link of another cache)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("WINDER_CACHE_DIR", str(d))
    monkeypatch.setattr(cint, "_LINKS", {})
    return d


def test_changed_integrators_relink_and_generate_nothing(cache: Path) -> None:
    """The generated object is compiled once; a library with other integrator objects
    (another link key) is linked from it, and computes the same right-hand side."""
    machine = Machine(mc.two_drum())
    link = cint.link()
    assert len(link.objects) == len(cint.SOURCES) and all(o.exists() for o in link.objects)
    before = dict(codegen.stats)
    g1 = codegen.generate(machine, link=link)
    g2 = codegen.generate(machine, link=codegen.Link(link.objects, "another"))
    g3 = codegen.generate(machine, link=link)
    assert codegen.stats["compiled"] == before["compiled"] + 1
    assert codegen.stats["linked"] == before["linked"] + 1
    assert codegen.stats["cached"] == before["cached"] + 1
    assert g1.path != g2.path and g1.path == g3.path
    assert sorted(p.name for p in (cache / "generated").iterdir()) == sorted(
        [f"w{g1.key}.o", g1.path.name, g2.path.name])
    x = np.array(machine.state_initial, dtype=float)
    p, modes = machine.parameters(), np.full(len(machine.mode_names), -1.0)
    np.testing.assert_array_equal(g1.call("rhs", 0.5, x, p, modes),
                                  g2.call("rhs", 0.5, x, p, modes))


def test_kernels_need_the_linked_library(cache: Path) -> None:
    g = codegen.generate(Machine(mc.single_drum()))
    with pytest.raises(TypeError, match="linked with the integrators"):
        cint.Kernels(g)


def test_library_entry_points_agree_with_the_generated_functions(paper_scene) -> None:
    """``repeat`` leaves the generated rhs's value; ``channels`` of one sample equals the
    generated ``out`` in the modes ``modes`` finds (contact AUTO): bit for bit."""
    system = MachineSystem(paper_scene)
    lib = system.kernels
    y = system.initial_state()
    y[system.index("roll.theta_dot")] = -7.0
    m = system.modes.copy()
    lib.modes(system.fns, system.table, 1.5, y, system.params, m, contact_auto=True)
    out = np.empty(system.n_states)
    total = lib.repeat(system.fns, integ.F_RHS, 3, 1.5, y, system.params, m, out)
    ref = system.generated.call("rhs", 1.5, y, system.params, m)
    np.testing.assert_array_equal(out, ref)
    assert total == 3 * ref[0]
    ch = lib.channels(system.fns, system.table, np.array([1.5]), y[:, None], system.params)
    np.testing.assert_array_equal(ch[:, 0], system.generated.call("out", 1.5, y,
                                                                  system.params, m))
    with pytest.raises(ValueError, match="which must be"):
        lib.repeat(system.fns, 4, 1, 0.0, y, system.params, m, out)


def test_arrays_of_the_wrong_size_are_refused(paper_scene) -> None:
    """The generated code reads and writes the machine's sizes: a state, parameter or
    output array of another length is a ValueError, not a write past its end."""
    system = MachineSystem(paper_scene)
    lib, fns, table = system.kernels, system.fns, system.table
    y, p, m = system.initial_state(), system.params, system.modes.copy()
    stats, t_out = np.zeros(5, dtype=np.int64), np.empty(0)
    with pytest.raises(ValueError, match="states"):
        lib.dopri5(fns, table, 0.0, 1.0, y[:-1].copy(), p, m, 1e-6, 1e-8, 0.0, np.inf, t_out,
                   np.empty((len(y) - 1, 0)), 0, 100, stats)
    with pytest.raises(ValueError, match="parameters"):
        lib.modes(fns, table, 0.0, y, p[:-1].copy(), m, contact_auto=False)
    with pytest.raises(ValueError, match="out must hold"):
        lib.repeat(fns, integ.F_JAC, 1, 0.0, y, p, m, np.empty(len(y)))
    with pytest.raises(ValueError, match="h must be"):
        lib.rk4(fns, table, 0.0, 1.0, y, p, m, 0.0, t_out, np.empty((len(y), 0)), 0, stats)
