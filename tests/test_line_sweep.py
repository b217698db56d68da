"""`winder sweep` reaches a web line's keys (issue #34): an idler's, its dancer's, a span's
by its index (``web.span.1.length``: spans have no names), the unwind's ``dancer_control``
and ``tension_control`` keys. Oracles: one real sweep point through the CLI equals the
direct run of the scene with the same changes (the other path, bit for bit); a bad key
exits 2 naming the key and listing the valid ones."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w
from test_idler_line import _dancer_controlled

import winder
from winder.cli import main
from winder.scene.keys import key_unit

#: one point: a span by its index, the dancer's carriage, an idler's bearing, the unwind's
#: loop, the web's friction on the rollers
POINT = {"web.span.1.length": 2.5, "idler.dancer.dancer.damping": 800.0,
         "idler.dancer.bearing_viscous": 0.02, "roll.parent.drive.bandwidth": 4.0,
         "web.mu": 0.4}


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("line") / "line.toml"
    data = _dancer_controlled(0.02, 5.0)
    data["scene"]["duration"] = 0.3
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    return path


def test_a_sweep_point_is_the_direct_run(scene_file: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "s"
    args = ["sweep", str(scene_file), "--out", str(out), "--workers", "1", "--t-end", "0.3",
            "--output-step", "0.01", "--trajectories", "--no-progress"]
    for key, value in POINT.items():
        args += ["--vary", f"{key}={value}"]
    assert main(args) == 0, capsys.readouterr().err
    table = winder.SweepTable.read(out)
    row = table.frame.iloc[0]
    assert row["status"] == "ok"
    res = winder.load_result(out / "trajectories" / f"{row['run_id']}.npz")
    scene = winder.load_scene(scene_file).replace(
        web={"mu": 0.4, "span": {"1": {"length": 2.5}}},
        idler={"dancer": {"bearing_viscous": 0.02, "dancer": {"damping": 800.0}}},
        roll={"parent": {"drive": {"bandwidth": 4.0}}})
    direct = winder.simulate(scene, t_end=0.3, output_step=0.01)
    for name in ("dancer_position", "span0_tension", "span1_tension", "parent_torque",
                 "dancer_traction"):
        np.testing.assert_array_equal(res[name], direct[name], err_msg=name)
    # the change took: the 2.5 m span is not the base's 3 m
    base = winder.simulate(winder.load_scene(scene_file), t_end=0.3, output_step=0.01)
    assert np.max(np.abs(base["dancer_position"] - direct["dancer_position"])) > 1e-4
    data = winder.load_scene(scene_file).to_dict()
    assert [key_unit(k, data) for k in POINT] == ["m", "N·s/m", "N·m·s/rad", "rad/s", "-"]


BAD = [
    ("web.span.7.length", r"no element named '7' in web.span; valid names: 0, 1"),
    ("web.span.1.lenght", r"\[web.span #2\] lenght: unknown key; valid keys: from, to, "
                          r"length, EA, T_in, initial_tension"),
    ("idler.dancer.dancer.stifness", r"stifness: unknown key; valid keys: stiffness, "
                                     r"damping, load, mass, travel"),
    ("idler.dancer.bearing_viscose", r"valid keys: name, radius, inertia, mass, centre, "
                                     r"sense, initial_speed, wrap, bearing_viscous, "
                                     r"bearing_coulomb, drive, dancer"),
    ("roll.parent.drive.bandwith", r"valid keys: kind, torque, tension, bandwidth, dancer, "
                                   r"span"),
]


@pytest.mark.parametrize("key, message", BAD, ids=[b[0] for b in BAD])
def test_a_bad_line_key_exits_2_naming_it(key: str, message: str, scene_file: Path,
                                          tmp_path: Path, capsys: Any) -> None:
    import re

    out = tmp_path / "s"
    code = main(["sweep", str(scene_file), "--vary", f"{key}=1,2", "--out", str(out),
                 "--workers", "1", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and key in err and "Traceback" not in err
    assert re.search(message, err), err
    assert not out.exists()
