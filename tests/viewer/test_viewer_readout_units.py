"""The viewer's readout prints the units the result carries (:attr:`winder.Result.units`,
on the Motion), and SI where a result has none (an old NPZ, a CSV)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from winder.viewer import motion, readout_text

import winder

MODELS = Path(__file__).resolve().parents[2] / "models"


@pytest.fixture(scope="module")
def run() -> tuple[winder.Scene, winder.Result]:
    scene = winder.load_scene(MODELS / "winder_line.toml")
    return scene, winder.simulate(scene.replace(scene={"duration": 0.2, "output_step": 0.05}))


def _lines(scene: winder.Scene, res: winder.Result) -> dict[str, list[str]]:
    """The readout of the last sample, each line split into words, by its first words."""
    m = motion(scene, res, res.t[-1:])
    out = {}
    for line in readout_text(m, 0).splitlines():
        words = line.split()
        out[" ".join(words[:2])] = words
    return out


def test_readout_units_are_the_results(run) -> None:
    scene, res = run
    assert res.units["set_radius"] == "m" and res.units["span_tension"] == "N"
    words = _lines(scene, res)
    assert words["t 0.20"][-1] == res.units["t"] == "s"
    assert words["set r"] == ["set", "r", f"{res['set_radius'][-1]:.4f}", "m"]
    front = words[f"front {res['front_speed'][-1]:.2f}"]
    assert front[2] == res.units["front_speed"] == "rad/s" and front[-1] == "m/s"
    nip = scene.nips[0].name
    assert words[f"{nip} N"][-1] == "k" + res.units[f"{nip}_normal_force"] == "kN"
    assert words["span T"][-1] == res.units["span_tension"] == "N"


def test_readout_follows_a_changed_unit(run) -> None:
    """A copy of the result with other units: the readout prints those."""
    scene, res = run
    nip = scene.nips[0].name
    units = {**res.units, "front_speed": "rev/s", "set_radius": "mm",
             f"{nip}_normal_force": "lbf", "span_tension": "daN", "t": "min"}
    other = winder.Result({k: res[k] for k in res}, res.meta, units=units)
    words = _lines(scene, other)
    assert words["t 0.20"][-1] == "min"
    assert words["set r"][-1] == "mm"
    assert words[f"front {res['front_speed'][-1]:.2f}"][2] == "rev/s"
    assert words[f"set {res['set_speed'][-1]:.2f}"][2] == "rad/s"  # its own, unchanged
    assert words[f"{nip} N"][-1] == "klbf"
    assert words["span T"][-1] == "daN"


def test_readout_without_units_is_si(run) -> None:
    """A result without units (an NPZ from before units): the same text, SI."""
    scene, res = run
    bare = winder.Result({k: res[k] for k in res}, res.meta)
    assert dict(bare.units) == {}
    m, m0 = (motion(scene, r, res.t) for r in (res, bare))
    assert m0.units == {} and m.units == dict(res.units)
    for k in range(len(res.t)):
        assert readout_text(m0, k) == readout_text(m, k)
    assert np.all([readout_text(m0, k).splitlines()[0].endswith(" s")
                   for k in range(len(res.t))])
