"""Every shipped scene (models/*.toml) against its results saved before the redesign
(tests/data/shipped/NAME.npz; regenerate only on purpose, with
``python tests/test_shipped_references.py``).

The contract of the redesign (issue "parts own their behaviour"): behaviour does not change.
A smooth scene agrees to 1e-12 of each channel's largest value over the whole saved run. A
bouncing scene (a nip opens somewhere) agrees to 1e-12 up to its first lift-off, and after
it opens and closes its nips in the same windows: every window's start and end within one
output step. Round-off changes of the generated code are allowed, changes in physics are
not: a dropped, doubled or sign-flipped force fails at the first samples.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import winder

#: bit-level records of route cpp's code (conftest.route_cpp)
pytestmark = pytest.mark.usefixtures("route_cpp")

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "shipped"
#: Each shipped scene: (simulated time [s], output step [s]): every whole cycle (the
#: bouncing band of the two-drum machines included); the flexible two-drum winder (issue
#: #25, 32 segment bodies) its first second, to keep the suite's time small.
RUNS = {
    "free_spin": (300.0, 1.0),
    "paper_winding": (700.0, 0.5),
    "paper_winding_no_web": (700.0, 0.5),
    "paper_winding_smooth": (700.0, 0.5),
    "two_drum_winder": (414.5, 0.25),
    "two_drum_winder_flexible": (1.0, 0.01),
    "winder_line": (414.5, 0.25),
    "winder_line_fmu": (58.0, 0.05),
    "winder_line_small": (58.0, 0.05),
    "winder_line_dancer": (10.0, 0.05),  # issue #34: the ramp's first 10 s
}
TOL = 1e-12  # of each channel's largest value


def _run(name: str) -> winder.Result:
    t_end, dt = RUNS[name]
    return winder.simulate(ROOT / "models" / f"{name}.toml", t_end=t_end, output_step=dt)


def _forces(res) -> list[str]:  # noqa: ANN001 - a Result or an NpzFile
    names = list(res.files if hasattr(res, "files") else res)
    return [k for k in names if k == "normal_force" or k.endswith("_normal_force")]


def _windows(open_: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) sample of each run of ``True`` in ``open_``."""
    edges = np.diff(np.concatenate([[0], open_.astype(int), [0]]))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1, strict=True))


def test_every_shipped_scene_has_a_reference() -> None:
    assert {p.stem for p in (ROOT / "models").glob("*.toml")} == set(RUNS)
    assert {p.stem for p in DATA.glob("*.npz")} == set(RUNS)


@pytest.mark.parametrize("name", sorted(RUNS))
def test_shipped_scene_matches_its_saved_results(name: str) -> None:
    ref = np.load(DATA / f"{name}.npz")
    res = _run(name)
    assert list(res) == list(ref.files), "the channels changed"
    assert np.array_equal(res.t, ref["t"])
    forces = _forces(ref)
    opened = np.zeros(len(ref["t"]), dtype=bool)
    for k in forces:
        opened |= ref[k] <= 0.0
    first = int(np.argmax(opened)) if opened.any() else len(opened)
    for k in ref.files:
        scale = max(float(np.max(np.abs(ref[k]))), 1e-300)
        err = float(np.max(np.abs(res[k][:first] - ref[k][:first]), initial=0.0)) / scale
        assert err <= TOL, (k, err, f"up to sample {first} of {len(opened)}")
    for k in forces:  # after the first lift-off: the same windows, within one sample
        want, got = _windows(ref[k] <= 0.0), _windows(res[k] <= 0.0)
        assert len(got) == len(want), (k, len(got), len(want))
        for (a0, a1), (b0, b1) in zip(want, got, strict=True):
            assert abs(a0 - b0) <= 1 and abs(a1 - b1) <= 1, (k, (a0, a1), (b0, b1))


def main() -> int:
    """Write the references (only when the behaviour is meant to change)."""
    DATA.mkdir(parents=True, exist_ok=True)
    for name in (sys.argv[1:] or sorted(RUNS)):
        res = _run(name)
        np.savez_compressed(DATA / f"{name}.npz", **{k: res[k] for k in res})
        print(f"{name}: {len(res.t)} samples, {len(res)} channels")
    return 0


if __name__ == "__main__":
    sys.exit(main())
