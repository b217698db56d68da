"""``winder fit``: FIT.json, the figure and the fitted scene equal :func:`winder.fit`'s
result, written together; bad input is one line naming the option, key or column (exit 2,
nothing written)."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

import winder
from winder.cli import main

NOISE = {"drum_torque": 5.0}


@pytest.fixture(scope="module")
def record(tmp_path_factory, models_dir):
    """A drum-torque record of the paper scene's first 0.1 s, with noise (CSV, units in
    the header)."""
    run = winder.simulate(models_dir / "paper_winding.toml", t_end=0.1, rtol=1e-10,
                          atol=1e-12, output_step=0.002, method="DOP853")
    rng = np.random.default_rng(7)
    keep = run.t > 0
    torque = run["drum_torque"][keep] + rng.normal(0, NOISE["drum_torque"], keep.sum())
    d = tmp_path_factory.mktemp("record")
    path = d / "mill.csv"
    np.savetxt(path, np.column_stack([run.t[keep], torque, run["z"][keep]]), delimiter=",",
               header="t,drum_torque [N·m],z [m]", comments="")
    return path


def test_writes_the_fit_and_the_fitted_scene(tmp_path, models_dir, record, capsys):
    scene = models_dir / "paper_winding.toml"
    out, png, toml = tmp_path / "fit.json", tmp_path / "fit.png", tmp_path / "fitted.toml"
    status = main(["fit", str(scene), "--data", str(record), "--param",
                   "drum.inertia=100:1000", "--channel", "drum_torque:5", "--out", str(out),
                   "--plot", str(png), "--scene-out", str(toml)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "evaluation 1" in captured.err  # progress on stderr
    res = winder.fit(scene, record, ["drum.inertia=100:1000"], channels=["drum_torque"],
                     sigma=NOISE)
    data = json.loads(out.read_text())
    p = data["parameters"]["drum.inertia"]
    assert p["value"] == pytest.approx(res["drum.inertia"], rel=1e-12)
    assert p["std"] == pytest.approx(res.std[0], rel=1e-12)
    assert p["ci95"] == pytest.approx(list(res.ci95[0]), rel=1e-12)
    assert p["initial"] == 400.0 and p["unit"] == "kg·m²"
    assert data["channels"]["drum_torque"]["sigma"] == 5.0
    assert data["converged"] and data["evaluations"] >= 1
    assert set(data) >= {"parameters", "correlation", "channels", "cost", "iterations",
                         "evaluations", "converged", "identifiability"}
    assert f"{res['drum.inertia']:.7g}" in captured.out
    fitted = winder.scene_from_dict(tomllib.loads(toml.read_text()))
    assert fitted.to_dict() == res.fitted_scene().to_dict()
    assert png.stat().st_size > 1000


@pytest.mark.parametrize(("args", "message"), [
    (["--param", "contact.stifness"], "--param: key 'contact.stifness' is not in the scene"),
    (["--param", "nope.stiffness"], "--param: key 'nope.stiffness': the scene has no table"),
    (["--param", "drum.inertia", "--channel", "rider_speed"],
     "--channel: 'rider_speed' is not a channel of this scene"),
    (["--param", "drum.inertia", "--t-end", "900"], "--t-end: 900 s is after the run's end"),
    (["--param", "drum.inertia", "--t-start", "5", "--t-end", "6"],
     "holds no sample of the data"),
    (["--param", "drum.mass", "--channel", "drum_torque"],
     "--param: drum.mass: no fitted channel sees it"),
    (["--param", "drum.inertia=1:2"], "outside the bounds"),
    (["--param", "drum.inertia", "--t-end", "nan"],
     "argument --t-end: 'nan' is out of range; valid: a finite time >= 0 s"),
])
def test_bad_input_is_one_line(tmp_path, models_dir, record, capsys, monkeypatch, args,
                               message):
    monkeypatch.chdir(tmp_path)
    status = main(["fit", str(models_dir / "paper_winding.toml"), "--data", str(record),
                   *args, "--out", "fit.json", "--scene-out", "fitted.toml"])
    err = capsys.readouterr().err
    lines = [ln for ln in err.strip().splitlines() if not ln.startswith("fit: evaluation")]
    assert status == 2 and message in err and len(lines) == 1, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("header", "row", "message"), [
    ("t,drum_torque,z [m]", "0.1,1.0,0.5", "column 'drum_torque' has no unit; give it as "
                                            "'drum_torque [N·m]'"),
    ("t,drum_torque [N],z [m]", "0.1,1.0,0.5", "column 'drum_torque' is in 'N', the channel "
                                               "in 'N·m'"),
    ("t,drum_torque [N·m],z [m]", "0.1,nan,0.5", "column 'drum_torque' row 1 is nan"),
    ("t,drum_torque [N·m],speed [m]", "0.1,1.0,0.5", "column 'speed' is not a channel"),
])
def test_bad_columns_are_named(tmp_path, models_dir, capsys, monkeypatch, header, row,
                               message):
    monkeypatch.chdir(tmp_path)
    data = tmp_path / "d.csv"
    data.write_text(f"{header}\n0.05,1.0,0.5\n{row}\n")
    status = main(["fit", str(models_dir / "paper_winding.toml"), "--data", str(data),
                   "--param", "drum.inertia", "--out", "fit.json"])
    err = capsys.readouterr().err
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.csv"]
