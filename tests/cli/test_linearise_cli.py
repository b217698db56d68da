"""``winder linearise``: the plant written for MATLAB and NumPy equals
:func:`winder.linearise`'s, the printed poles are its eigenvalues, and bad arguments are
one line naming the option and what is valid (exit 2, nothing written)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.io import loadmat

import winder
from winder.cli import main


def test_writes_the_plant_and_prints_its_poles(tmp_path, models_dir, capsys) -> None:
    scene = models_dir / "winder_line.toml"
    mat, npz = tmp_path / "plant.mat", tmp_path / "plant.npz"
    args = ["linearise", str(scene), "--radius", "0.3", "--input", "parent_tension_setpoint",
            "--output", "span_tension", "--output", "set_z"]
    assert main([*args, "--out", str(mat)]) == 0
    printed = capsys.readouterr().out
    assert main([*args, "--out", str(npz)]) == 0
    plant = winder.linearise(scene, 0.3, inputs=["parent_tension_setpoint"],
                             outputs=["span_tension", "set_z"])
    m, n = loadmat(mat), np.load(npz)
    for key in "ABCD":
        np.testing.assert_array_equal(m[key], np.asarray(getattr(plant, key)))
        np.testing.assert_array_equal(n[key], np.asarray(getattr(plant, key)))
    assert [str(s) for s in n["outputs"]] == ["span_tension", "set_z"]
    assert [str(np.ravel(s)[0]) for s in np.ravel(m["state_units"])][-2:] == ["N", "N·s"]
    assert float(m["radius"][0, 0]) == 0.3
    assert "14 states, 1 inputs (parent_tension_setpoint), 2 outputs" in printed
    # the printed poles (one of each pair) are the plant's eigenvalues, slowest first
    rows = re.findall(r"^  (-?[\d.e+-]+)(?: ± ([\d.e+-]+)j)?\s+([\d.e+-]+) Hz\s+([\d.]+)$",
                      printed, re.M)
    lam = np.linalg.eigvals(np.asarray(plant.A))
    assert len(rows) == np.sum(lam.imag >= 0) > 5
    for re_, im, hz, zeta in rows:
        pole = complex(float(re_), float(im or 0.0))
        assert np.min(np.abs(lam - pole)) <= 1e-5 * abs(pole)  # printed to 6 digits
        assert float(hz) == pytest.approx(abs(pole) / (2 * np.pi), rel=1e-3)
        assert float(zeta) == pytest.approx(-pole.real / abs(pole), abs=1e-4)


@pytest.mark.parametrize(("args", "message"), [
    (["--radius", "0.01"], "winder: error: --radius = 0.01 is out of range; valid: a finite "
                           "radius >= [[roll]] 'set' core_radius = 0.05 m"),
    (["--radius", "0.3", "--input", "nope"],
     "winder: error: --input: 'nope' is not one of this scene's inputs; valid: "
     "parent_tension_setpoint, front_web_speed, rear_web_speed"),
    (["--radius", "0.3", "--out", "plant.txt"], "unknown file type '.txt'; valid: .npz, .mat"),
    (["--radius", "-1"], "argument --radius: '-1' is out of range; valid: a finite number, "
                         "0 < x"),
    ([], "the following arguments are required: --radius"),
])
def test_bad_arguments_are_one_line(tmp_path, models_dir, capsys, monkeypatch, args,
                                    message) -> None:
    monkeypatch.chdir(tmp_path)
    status = main(["linearise", str(models_dir / "winder_line.toml"), *args])
    err = capsys.readouterr().err
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert list(tmp_path.iterdir()) == []
