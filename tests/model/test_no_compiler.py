"""Without a C compiler the numeric Pinocchio path runs the same dynamics, with a warning
that names the reason."""

from __future__ import annotations

import numpy as np
import pytest

import winder
from winder.solve.system import MachineSystem, NoCompilerWarning


def test_missing_compiler_falls_back_to_pinocchio(paper_scene, tmp_path, monkeypatch) -> None:
    compiled = winder.simulate(paper_scene, t_end=0.2, output_step=0.05, method="LSODA",
                               rtol=1e-9, atol=1e-11)
    monkeypatch.setenv("WINDER_CACHE_DIR", str(tmp_path))  # nothing cached: must compile
    monkeypatch.setenv("CC", "no-such-compiler-anywhere")
    with pytest.warns(NoCompilerWarning, match="CC='no-such-compiler-anywhere'"):
        system = MachineSystem(paper_scene)
    assert system.backend == "pinocchio" and system.generated is None
    with pytest.warns(NoCompilerWarning):
        fallback = winder.simulate(paper_scene, t_end=0.2, output_step=0.05,
                                   method="LSODA", rtol=1e-9, atol=1e-11)
    assert fallback.meta["backend"] == "pinocchio"
    # the same dynamics by the other path: measured 1.8e-9 of the largest value (roll_speed;
    # LSODA's own tolerance, the right-hand sides agree to round-off), z 3e-15
    for k in ("z", "roll_speed", "normal_force", "drum_torque"):
        scale = np.max(np.abs(compiled[k]))
        np.testing.assert_allclose(fallback[k], compiled[k], rtol=0, atol=2e-8 * scale)
    assert not list(tmp_path.rglob("*.so"))
