"""The cache of generated machines (:mod:`winder.model.codegen`): one compile per
structure, parameter values at run time, distinct keys for distinct structures, safe
concurrent builds, no leftovers. Every test uses its own cache directory."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import machines as mc
import numpy as np
import pytest

from winder.model import codegen
from winder.model.backends import NumericBackend
from winder.model.locked_modes import AUTO, CORE_AUTO
from winder.model.machine import Machine

pytest.importorskip("casadi")

TESTS = Path(__file__).resolve().parents[1]


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh, empty ``$WINDER_CACHE_DIR`` for one test."""
    d = tmp_path / "cache"
    monkeypatch.setenv("WINDER_CACHE_DIR", str(d))
    return d


def _leftovers(cache: Path) -> list[str]:
    """Everything in the cache that is not a finished object or library."""
    return sorted(str(p.relative_to(cache)) for p in cache.rglob("*")
                  if not (p.is_dir() and p.name == "generated")
                  and not (p.is_file() and p.suffix in (".so", ".o")
                           and p.parent.name == "generated"))


def _state(m: Machine) -> tuple[float, np.ndarray, np.ndarray]:
    x = np.array(m.state_initial, dtype=float)
    x[m.index("set.z")] -= 1e-4
    x[m.index("set.theta_dot")] = -40.0
    x[m.index("set.radius")] = 0.2
    modes = np.array([AUTO if n.endswith(".contact") else CORE_AUTO for n in m.mode_names],
                     dtype=float)
    return 3.0, x, modes


def _numeric_rhs(m: Machine, t: float, x: np.ndarray, p: np.ndarray,
                 modes: np.ndarray) -> np.ndarray:
    ev = m.evaluate(NumericBackend(m.model), t, x, p, modes, outputs=False)
    return np.array([float(ev.rates[n]) for n in m.state_names])


def test_second_build_and_new_values_compile_nothing(cache: Path,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """The first build compiles; the same structure again, and the same structure with
    other parameter values, load the library (no code is generated: the source writer is
    disabled) and the new values act at run time."""
    m1 = Machine(mc.two_drum())
    before = dict(codegen.stats)
    g1 = codegen.generate(m1)
    assert not g1.from_cache and codegen.stats["compiled"] == before["compiled"] + 1

    def no_source(*args: Any, **kw: Any) -> None:
        raise AssertionError("generated code again for a cached structure")

    monkeypatch.setattr(codegen, "_c_source", no_source)
    g2 = codegen.generate(Machine(mc.two_drum()))
    values = {"set.caliper": 3e-4, "front_nip.contact.stiffness": 4e7, "scene.gravity": 3.0,
              "rider.mass": 900.0, "web.tension": 10.0, "rear.drive.web_speed": 20.0}
    m3 = Machine(mc.two_drum(values=values))
    g3 = codegen.generate(m3)
    assert g2.from_cache and g3.from_cache
    assert g1.key == g2.key == g3.key
    assert codegen.stats["compiled"] == before["compiled"] + 1
    assert codegen.stats["cached"] == before["cached"] + 2
    # the new values are inputs of the one library
    t, x, modes = _state(m3)
    p1, p3 = m1.parameters(), m3.parameters()
    assert not np.array_equal(p1, p3)
    for p in (p1, p3):
        got = g3.call("rhs", t, x, p, modes)
        ref = _numeric_rhs(m3, t, x, p, modes)
        # measured: 0 and 8.6e-22 relative (round-off floor: 1e-16)
        assert np.max(np.abs(got - ref)) <= 1e-15 * np.max(np.abs(ref))
    assert np.max(np.abs(g3.call("rhs", t, x, p1, modes) - g3.call("rhs", t, x, p3, modes))) > 1.0
    assert _leftovers(cache) == []


STRUCTURE_CHANGES: dict[str, Any] = {
    "effect off": lambda: mc.two_drum(imbalance=False),
    "contact law": lambda: mc.two_drum(law="hunt_crossley"),
    "one nip's law": lambda: mc.two_drum(values={"rider_nip.contact.law": "hunt_crossley"}),
    "free axis": lambda: mc.two_drum(free=("z",)),
    "drum centre": lambda: mc.two_drum(values={"rear.centre": (0.53, 0.0)}),
    "drive kind": lambda: mc.two_drum(drive="torque"),
    "sense": lambda: mc.two_drum(values={"set.sense": 1}),
    "no rider (a nip fewer)": lambda: mc.two_drum(rider_roll=False),
    "web entry": lambda: mc.two_drum(values={"web.entry_nip": "front_nip"}),
    "load points": lambda: mc.two_drum(values={"rider.load": ((0.05, 1.0),)}),
}


def test_structure_changes_change_the_key(cache: Path) -> None:
    """Every change of structure gives its own key (and its own library); values do not."""
    base = Machine(mc.two_drum()).structure_key()
    assert Machine(mc.two_drum(values={"set.density": 1.0})).structure_key() == base
    keys = {name: Machine(make()).structure_key() for name, make in STRUCTURE_CHANGES.items()}
    same = [name for name, k in keys.items() if k == base]
    assert not same, f"same key as the base machine: {same}"
    assert len(set(keys.values())) == len(keys)


def test_adding_a_nip_compiles_a_new_library(cache: Path) -> None:
    """A third nip (the rider) is another library next to the first one."""
    g1 = codegen.generate(Machine(mc.two_drum(rider_roll=False)))
    g2 = codegen.generate(Machine(mc.two_drum()))
    assert not g1.from_cache and not g2.from_cache and g1.key != g2.key
    assert sorted(p.name for p in (cache / "generated").glob("*.so")) == \
        sorted([g1.path.name, g2.path.name])


_WORKER = textwrap.dedent("""
    import json, os, sys, time
    from pathlib import Path
    sys.path.insert(0, {tests!r})
    import numpy as np
    import machines as mc
    from winder.model import codegen
    from winder.model.machine import Machine
    go = Path({go!r})
    m = Machine(mc.two_drum())
    while not go.exists():  # start both builds at once
        time.sleep(0.005)
    g = codegen.generate(m)
    x = np.array(m.state_initial); x[m.index("set.z")] -= 1e-4
    modes = np.full(len(m.mode_names), -1.0)
    out = g.call("rhs", 2.0, x, m.parameters(), modes)
    print(json.dumps({{"key": g.key, "from_cache": g.from_cache,
                       "rhs": [v.hex() for v in out.tolist()]}}))
""")


def test_concurrent_builds_into_one_empty_cache(cache: Path) -> None:
    """Two processes building the same machine at once into the same empty cache both
    succeed with identical results, and leave only the library behind."""
    go = cache.parent / "go"
    code = _WORKER.format(tests=str(TESTS), go=str(go))
    env = {**os.environ, "WINDER_CACHE_DIR": str(cache)}
    procs = [subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    go.touch()
    results = []
    for p in procs:
        out, err = p.communicate(timeout=300)
        assert p.returncode == 0, err[-2000:]
        results.append(json.loads(out.strip().splitlines()[-1]))
    a, b = results  # measured: both compiled (neither found the other's library)
    assert a["key"] == b["key"] and a["rhs"] == b["rhs"]
    assert _leftovers(cache) == []
    assert sorted(p.name for p in (cache / "generated").iterdir()) == [f"w{a['key']}.o",
                                                                       f"w{a['key']}.so"]
    # and the parent process loads it without compiling
    g = codegen.generate(Machine(mc.two_drum()))
    assert g.from_cache and g.key == a["key"]


def test_failed_compile_leaves_nothing(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A compiler that fails raises with its message and leaves no file in the cache."""
    monkeypatch.setenv("CC", "false")
    with pytest.raises(RuntimeError, match="compiling the generated model failed"):
        codegen.generate(Machine(mc.single_drum()))
    assert _leftovers(cache) == []
    assert not list((cache / "generated").glob("*.so"))
