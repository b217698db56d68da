"""The static balance kept on disk (:func:`winder.solve.equilibrium.cached_static_state`):
a second run of the same scene and parameters reads exactly the state the solve found;
another parameter value is another entry; a damaged entry is solved again."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import winder
from winder.solve import equilibrium
from winder.solve.system import MachineSystem


@pytest.fixture(scope="module")
def two_drum_scene(models_dir: Path) -> winder.Scene:
    return winder.load_scene(models_dir / "two_drum_winder.toml")


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("WINDER_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache" / "balance"


def test_the_cached_balance_is_the_solved_one(cache: Path, two_drum_scene,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    first = MachineSystem(two_drum_scene).equilibrium
    assert len(list(cache.glob("*.json"))) == 1
    solved = equilibrium.static_state(MachineSystem(two_drum_scene).machine)
    np.testing.assert_array_equal(first.state, solved.state)  # oracle: the solve itself

    def no_solve(*args, **kwargs):  # a second run must not solve
        raise AssertionError("solved again")

    monkeypatch.setattr(equilibrium, "static_state", no_solve)
    again = MachineSystem(two_drum_scene).equilibrium
    np.testing.assert_array_equal(again.state, first.state)
    assert (again.residual, again.scale) == (first.residual, first.scale)


def test_another_parameter_is_another_balance(cache: Path, two_drum_scene) -> None:
    a = MachineSystem(two_drum_scene)
    b = MachineSystem(two_drum_scene)
    b.set_input("rider.line_load_0",
                2.0 * float(b.params[b.machine.param_index("rider.line_load_0")]))
    za, zb = (s.equilibrium.state[s.index("set.z")] for s in (a, b))
    assert len(list(cache.glob("*.json"))) == 2 and za != zb
    fresh = equilibrium.static_state(b.machine, b.params)
    assert zb == fresh.state[b.index("set.z")]


def test_a_damaged_entry_is_solved_again(cache: Path, two_drum_scene) -> None:
    first = MachineSystem(two_drum_scene).equilibrium
    (entry,) = cache.glob("*.json")
    entry.write_text("{not json")
    again = MachineSystem(two_drum_scene).equilibrium
    np.testing.assert_array_equal(again.state, first.state)
    assert entry.read_text().startswith("{\"state\"")
