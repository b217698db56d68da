"""Parameter sweeps on Dask: grid and key paths, summaries against full results, a
2-worker cluster against serial runs, a killed worker, interrupt and resume, bad specs."""

from __future__ import annotations

import io
import math
import os
import signal
from pathlib import Path

import numpy as np
import pytest

import winder
import winder.io.progress as _progress
from winder.analysis.sweep import run_id, run_one, run_settings
from winder.analysis.sweep_grid import (
    build_grid,
    get_path,
    parse_spec,
    parse_vary,
    resolve,
    set_path,
    split_keys,
)
from winder.analysis.sweep_summary import BAND_COLUMNS, SCALAR_COLUMNS, default_band_edges
from winder.analysis.sweep_table import SweepTable
from winder.cli import main
from winder.plots.sweep import axis_label
from winder.scene import key_unit

# Short runs of the paper scene (web speed reached after 6-12 s, 30 s each, ~0.1 s of
# integration): bouncing at the higher speeds and the larger imbalance, none at 12 m/s
# with 0.5 mm.
VARY = {"drum.drive.web_speed": "12:24:4", "roll.com_offset": [0.5e-3, 1e-3]}
RUN = {"t_end": 30.0, "output_step": 2e-3, "bands": 6}
MODELS = Path(__file__).resolve().parents[2] / "models"
# Per-run columns that depend on the machine, not on the physics.
MACHINE = ("wall_time", "task_time", "worker")


@pytest.fixture(scope="module")
def base(paper_scene) -> winder.Scene:
    # max_rhs given: the CLI test's runs that vary it to 50 M are the grid's runs
    return paper_scene.replace(drum={"drive": {"web_acceleration": 2.0}},
                               solver={"max_rhs": 50_000_000})


@pytest.fixture(scope="module")
def two_drum() -> winder.Scene:
    return winder.load_scene(MODELS / "two_drum_winder.toml")


@pytest.fixture(scope="module")
def cluster(base):
    """A 2-worker LocalCluster (one single-threaded process each) and its client."""
    from distributed import Client, LocalCluster

    lc = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0")
    client = Client(lc)
    settings = run_settings(t_end=0.5)
    client.run(run_one, base, settings, [0.07, 0.1])  # import winder, load compiled code
    yield client, lc
    client.close()
    lc.close()


@pytest.fixture(scope="module")
def reference(base):
    """The grid's runs done serially in this process: ``{run_id: row}``."""
    grid = build_grid(base, {k: parse_spec(k, v) if isinstance(v, str) else v
                             for k, v in VARY.items()})
    settings = run_settings(t_end=RUN["t_end"], output_step=RUN["output_step"])
    edges = default_band_edges(grid.scenes, RUN["t_end"], RUN["bands"])
    out = {}
    for scene in grid.scenes:
        row, _ = run_one(scene, settings, edges)
        out[run_id(scene, settings, edges)] = row
    return out


def _assert_rows_equal(row: dict, ref: dict) -> None:
    for k in ("status", "message", *SCALAR_COLUMNS):
        a, b = row[k], ref[k]
        assert a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b)), k
    for k in BAND_COLUMNS:
        np.testing.assert_array_equal(np.asarray(row[k], float), np.asarray(ref[k], float))


def _assert_table_is_reference(table: SweepTable, reference: dict) -> None:
    assert sorted(table.frame["run_id"]) == sorted(reference)
    assert list(table.frame["run"]) == list(range(len(reference)))
    for row in table.frame.to_dict("records"):
        _assert_rows_equal(row, reference[row["run_id"]])


def _worker_pids(client) -> dict[str, int]:
    return client.run(os.getpid)


# ---- key paths and specs ---------------------------------------------------------------

def test_key_paths_select_array_elements_by_name() -> None:
    """Arrays of tables (TOML [[nip]]) are entered by the element's name."""
    data = {"drum": {"radius": 0.5, "drive": {"web_speed": 20.0}},
            "nip": [{"name": "front", "contact": {"stiffness": 1e7}},
                    {"name": "rear", "contact": {"stiffness": 2e7, "damping": 1e3}}]}
    set_path(data, "nip.rear.contact.stiffness", 5e7)
    assert get_path(data, "nip.rear.contact.stiffness") == 5e7
    assert get_path(data, "nip.front.contact.stiffness") == 1e7  # the other one untouched
    set_path(data, "drum.drive.web_speed", 25.0)
    assert data["drum"]["drive"]["web_speed"] == 25.0
    container, slot = resolve(data, "nip.front.contact.damping")  # a leaf not set yet
    assert container is data["nip"][0]["contact"] and slot == "damping"
    with pytest.raises(winder.ArgumentError, match="no element named 'middle'.*front, rear"):
        set_path(data, "nip.middle.contact.stiffness", 1.0)
    with pytest.raises(winder.ArgumentError, match="selects a whole table"):
        set_path(data, "nip.rear", 1.0)
    with pytest.raises(winder.ArgumentError, match="is a table, not a value"):
        set_path(data, "nip.rear.contact", 1.0)
    with pytest.raises(winder.ArgumentError, match="drum.radius is a value"):
        set_path(data, "drum.radius.x", 1.0)
    with pytest.raises(winder.ArgumentError, match="no table 'rol'"):
        set_path(data, "rol.com_offset", 1.0)


def test_specs_ranges_and_lists() -> None:
    values = parse_spec("k", "15:45:16")
    assert len(values) == 16 and values[0] == 15.0 and values[-1] == 45.0
    np.testing.assert_allclose(np.diff(values), 2.0, rtol=0, atol=1e-12)
    assert parse_spec("k", "1e7,2e7, 4e7") == [1e7, 2e7, 4e7]
    assert parse_spec("k", "linear,hunt_crossley") == ["linear", "hunt_crossley"]
    assert parse_spec("k", "true,false") == [True, False]
    assert parse_spec("k", "3:3:1") == [3.0]
    for bad, match in (("15:45:0", "empty range"), ("5:5:3", "empty range"),
                       ("", "empty value list"), ("1,,2", "empty value list"),
                       ("1:2", "START:STOP:COUNT"), ("a:2:3", "START:STOP:COUNT"),
                       ("1,2,1", "listed twice")):
        with pytest.raises(winder.ArgumentError, match=match):
            parse_spec("drum.drive.web_speed", bad)


def test_bad_specs_rejected_before_anything_is_submitted(base, tmp_path, monkeypatch,
                                                         models_dir, capsys) -> None:
    import winder.analysis.sweep as sw

    def no_cluster(*args, **kwargs):
        raise AssertionError("a cluster was contacted")

    monkeypatch.setattr(sw, "_client", no_cluster)
    out = tmp_path / "sweep"
    for vary, key, what in (
            ({"roll.com_ofset": [1e-3]}, "roll.com_ofset", "unknown key"),
            ({"drum.drive.web_speed": "10:20:0"}, "drum.drive.web_speed", "empty range"),
            ({"roll.com_offset": [1e-3], "paper.caliper": [1e-4, -1.0]}, "paper.caliper",
             "-1"),
            ({"contact.law": ["linear", "cubic"]}, "contact.law", "cubic"),
            ({"roll.initial_radius": [0.05]}, "roll.initial_radius", "below core_radius")):
        with pytest.raises(winder.ArgumentError) as err:
            winder.sweep(base, vary, out, **RUN)
        assert key in str(err.value) and what in str(err.value)
    assert not out.exists()
    # the command line: exit 2, one line naming the key and the value, nothing on disk
    code = main(["sweep", str(models_dir / "paper_winding.toml"), "--vary",
                 "roll.com_offset=1e-3,-2e-3", "--out", str(out)])
    assert code == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "roll.com_offset" in lines[0] and "-0.002" in lines[0]
    assert not out.exists()
    # a map that cannot be drawn (words on its vertical axis) is refused before the runs
    code = main(["sweep", str(models_dir / "paper_winding.toml"), "--vary",
                 "contact.law=linear,hunt_crossley", "--out", str(out), "--plot"])
    assert code == 2
    err = capsys.readouterr().err
    assert "--plot" in err and "contact.law" in err and "'hunt_crossley'" in err
    assert not out.exists()


# ---- summaries -------------------------------------------------------------------------

def test_summary_against_the_full_result(base) -> None:
    """Every summary quantity recomputed sample by sample from the run's full result."""
    scene = base.replace(drum={"drive": {"web_speed": 18.0}})
    settings = run_settings(t_end=30.0, output_step=2e-3, window=0.5, threshold=0.5)
    edges = default_band_edges([scene], 30.0, 5)
    row, res = run_one(scene, settings, edges, trajectory=True)
    assert row["status"] == "ok" and res is not None
    again = winder.simulate(scene, t_end=30.0, output_step=2e-3)  # the run is reproducible
    np.testing.assert_array_equal(again["normal_force"], res["normal_force"])
    r, fn, pen, t = res["radius"], res["normal_force"], res["penetration"], res.t
    nb = len(edges) - 1

    def band(x: float) -> int:
        for b in range(nb - 1, -1, -1):
            if x >= edges[b]:
                return b
        return 0

    peak, sq, n_air, count = [-math.inf] * nb, [0.0] * nb, [0] * nb, [0] * nb
    for ri, fi in zip(r, fn, strict=True):
        b = band(ri)
        peak[b] = max(peak[b], fi)
        sq[b] += fi * fi
        n_air[b] += fi <= 0.0
        count[b] += 1
    # the radius grows by ~0.1 m in 30 s; every band holds samples
    assert min(count) > 100
    np.testing.assert_allclose(row["nip_force_peak"], peak, rtol=1e-15)
    np.testing.assert_allclose(row["nip_force_rms"],
                               [math.sqrt(s / c) for s, c in zip(sq, count, strict=True)],
                               rtol=1e-12)  # summation order only (measured 2e-16)
    np.testing.assert_allclose(row["liftoff_share_band"],
                               [a / c for a, c in zip(n_air, count, strict=True)], rtol=1e-14)
    air = [i for i, f in enumerate(fn) if f <= 0.0]
    assert row["liftoff_share"] == pytest.approx(len(air) / len(fn), rel=1e-14)
    assert 0.05 < row["liftoff_share"] < 0.95  # this run bounces: a real test of the radii
    assert row["liftoff_radius_first"] == r[air[0]]
    assert row["liftoff_radius_last"] == r[air[-1]]
    # windows of 0.5 s = 250 samples
    w = int(round(0.5 / 2e-3))
    amp, level, start = [-math.inf] * nb, [-math.inf] * nb, math.nan
    for k in range(len(t) // w):
        sl = slice(k * w, (k + 1) * w)
        rm = float(np.mean(r[sl]))
        b = band(rm)
        amp[b] = max(amp[b], (max(pen[sl]) - min(pen[sl])) / 2)
        lv = (max(fn[sl]) - min(fn[sl])) / 2 / np.mean(fn[sl])
        level[b] = max(level[b], lv)
        if math.isnan(start) and lv >= 0.5:
            start = rm
    np.testing.assert_allclose(row["bounce_amplitude"], amp, rtol=1e-15)
    np.testing.assert_allclose(row["vibration_level"], level, rtol=1e-12)
    assert row["vibration_start_radius"] == pytest.approx(start, rel=1e-14)
    assert row["contact_events"] == res.meta["events"] > 0
    assert row["final_radius"] == r[-1] and row["t_reached"] == 30.0


def test_failed_run_is_recorded_and_the_sweep_goes_on(base) -> None:
    scene = base.replace(solver={"max_rhs": 3000})
    settings = run_settings(t_end=30.0, output_step=2e-3)
    row, _ = run_one(scene, settings, [0.07, 0.2])
    assert row["status"] == "budget" and "max_rhs" in row["message"]
    # the summary covers the partial result up to where the budget stopped the run
    assert 0.0 < row["t_reached"] < 30.0


# ---- on the cluster --------------------------------------------------------------------

def test_cluster_sweep_equals_serial_runs(cluster, base, reference, tmp_path) -> None:
    client, _ = cluster
    table = winder.sweep(base, VARY, tmp_path / "s", scheduler=client, trajectories=True,
                         **RUN)
    _assert_table_is_reference(table, reference)
    assert len(table.computed) == 8 and table.skipped == () and table.missing == []
    assert table.bands("vibration_level").shape == (8, 6)
    # the stored table reads back the same, swept values and scene hash included
    back = SweepTable.read(tmp_path / "s")
    assert back.keys == ("drum.drive.web_speed", "roll.com_offset")
    assert list(back.frame["drum.drive.web_speed"]) == [12.0] * 2 + [16.0] * 2 + \
        [20.0] * 2 + [24.0] * 2
    h = winder.analysis.sweep_grid.scene_hash(base.replace(drum={"drive": {"web_speed": 24.0}},
                                                   roll={"com_offset": 1e-3}).to_dict())
    assert back.frame["scene_hash"].iloc[7] == h
    # trajectories on request: the stored result is the full run of that grid point
    rid = back.frame["run_id"].iloc[5]
    res = winder.load_result(tmp_path / "s" / "trajectories" / f"{rid}.npz")
    direct = winder.simulate(base.replace(drum={"drive": {"web_speed": 20.0}},
                                          roll={"com_offset": 1e-3}), t_end=30.0,
                             output_step=2e-3)
    np.testing.assert_array_equal(res["normal_force"], direct["normal_force"])


def test_killed_worker_is_replaced_and_the_sweep_completes(cluster, base, reference,
                                                           tmp_path) -> None:
    client, _ = cluster
    killed = []

    def kill_one(row: dict) -> None:
        if killed:
            return
        busy = [a for a, keys in client.processing().items() if keys]
        pids = _worker_pids(client)
        victim = busy[0] if busy else next(iter(pids))
        os.kill(pids[victim], signal.SIGKILL)
        killed.append(victim)

    table = winder.sweep(base, VARY, tmp_path / "k", scheduler=client, callback=kill_one,
                         **RUN)
    assert killed
    _assert_table_is_reference(table, reference)
    assert table.missing == []
    client.wait_for_workers(2, timeout=60)


def test_runs_whose_worker_died_are_reported_missing(cluster, base, reference,
                                                     tmp_path) -> None:
    """With no retries allowed, the runs on a killed worker are reported by index and
    values; the table holds exactly the others; a re-run does exactly the missing ones."""
    client, lc = cluster
    lc.scheduler.allowed_failures = 0
    victim: list[str] = []

    def kill_one(row: dict) -> None:
        if victim:
            return
        pids = _worker_pids(client)
        # a worker with a run in progress (more runs wait in the queue: whichever run the
        # victim holds when the signal lands is lost)
        victim.append(next(a for a, keys in client.processing().items() if keys))
        os.kill(pids[victim[0]], signal.SIGKILL)

    try:
        table = winder.sweep(base, VARY, tmp_path / "m", scheduler=client,
                             callback=kill_one, **RUN)
    finally:
        lc.scheduler.allowed_failures = 3
    missing = {m["run_id"] for m in table.missing}
    assert missing
    # each missing run names the worker that died while running it: the one killed
    assert all("KilledWorker" in m["reason"] and victim[0] in m["reason"]
               for m in table.missing)
    assert {m["drum.drive.web_speed"] for m in table.missing} <= {12.0, 16.0, 20.0, 24.0}
    assert missing.isdisjoint(table.frame["run_id"])
    assert missing | set(table.frame["run_id"]) == set(reference)
    client.wait_for_workers(2, timeout=60)
    again = winder.sweep(base, VARY, tmp_path / "m", scheduler=client, **RUN)
    assert set(again.computed) == missing
    _assert_table_is_reference(again, reference)


def test_interrupt_and_resume(cluster, base, reference, tmp_path) -> None:
    client, _ = cluster
    out = tmp_path / "r"
    first: list[str] = []

    def stop_after_three(row: dict) -> None:
        first.append(row["run_id"])
        if len(first) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        winder.sweep(base, VARY, out, scheduler=client, callback=stop_after_three, **RUN)
    assert not (out / "summary.parquet").exists()
    done = {p.stem: p.stat().st_mtime_ns for p in (out / "runs").glob("*.parquet")}
    assert set(done) == set(first)
    table = winder.sweep(base, VARY, out, scheduler=client, **RUN)
    assert set(table.skipped) == set(first)
    assert set(table.computed) == set(reference) - set(first)  # no run done twice
    assert {p.stem: p.stat().st_mtime_ns for p in (out / "runs").glob("*.parquet")
            if p.stem in done} == done
    _assert_table_is_reference(table, reference)
    # a third call finds everything done and starts no cluster at all
    again = winder.sweep(base, VARY, out, scheduler="tcp://127.0.0.1:9", **RUN)
    assert again.computed == () and len(again.skipped) == 8


def test_cli_sweep_with_failures_and_map(cluster, reference, tmp_path, capsys,
                                         models_dir) -> None:
    """`winder sweep` on the test cluster: a failing value is recorded, the map drawn."""
    _, lc = cluster
    scene = tmp_path / "scene.toml"
    text = (models_dir / "paper_winding.toml").read_text()
    scene.write_text(text.replace("web_acceleration = 0.5", "web_acceleration = 2.0")
                     .replace("[solver]\n", "[solver]\nmax_rhs = 50000000\n"))
    png = tmp_path / "map.png"
    code = main(["sweep", str(scene), "--vary", "drum.drive.web_speed=12:24:4",
                 "--vary", "solver.max_rhs=3000,50000000", "--out", str(tmp_path / "c"),
                 "--scheduler", lc.scheduler_address, "--t-end", "30", "--output-step",
                 "2e-3", "--bands", "6", "--plot", str(png), "--no-progress"])
    assert code == 0
    out, err = capsys.readouterr()
    assert "8 runs" in out and "4 failed" in out
    table = SweepTable.read(tmp_path / "c")
    bad = table.frame[table.frame["solver.max_rhs"] == 3000]
    assert list(bad["status"]) == ["budget"] * 4
    # each failed run listed on stderr with its values, status and message; no traceback
    lines = err.strip().splitlines()
    assert lines[0] == "winder: 4 of 8 runs failed:" and "Traceback" not in err
    for line, row in zip(lines[1:], bad.to_dict("records"), strict=True):
        assert line.startswith(f"  run {row['run']} (drum.drive.web_speed = "
                               f"{row['drum.drive.web_speed']!r}, solver.max_rhs = 3000): "
                               "budget: ")
        assert row["message"].split()[0] in line and "max_rhs" in line
    ok = table.frame[table.frame["status"] == "ok"]
    assert len(ok) == 4
    for row in ok.to_dict("records"):  # the same runs as the grid's 1 mm column
        _assert_rows_equal(row, reference[row["run_id"]])
    assert png.stat().st_size > 20_000


def test_cli_sweep_where_every_run_fails_exits_2(cluster, tmp_path, capsys,
                                                models_dir) -> None:
    """Every run stopped by its budget: each is listed, exit 2, no map; the table stays."""
    _, lc = cluster
    png = tmp_path / "map.png"
    code = main(["sweep", str(models_dir / "paper_winding.toml"), "--vary",
                 "solver.max_rhs=2000,3000", "--out", str(tmp_path / "f"), "--scheduler",
                 lc.scheduler_address, "--t-end", "30", "--plot", str(png), "--no-progress"])
    assert code == 2
    out, err = capsys.readouterr()
    assert "2 runs" in out and "2 failed" in out
    lines = err.strip().splitlines()
    assert lines[0] == "winder: every run failed (2):"
    assert lines[1].startswith("  run 0 (solver.max_rhs = 2000): budget: ")
    assert lines[2].startswith("  run 1 (solver.max_rhs = 3000): budget: ")
    assert all("max_rhs" in ln for ln in lines[1:3]) and "no runnability map" in lines[3]
    assert not png.exists()
    assert list(SweepTable.read(tmp_path / "f").frame["status"]) == ["budget"] * 2


# ---- tied keys and units -----------------------------------------------------------------

TIED = "drum.front.drive.web_speed,drum.rear.drive.web_speed"


def test_tied_keys_parse_and_refuse() -> None:
    """Tied keys share one axis; a key named twice (in a tie or across axes), an empty key
    or a key with no spec is refused naming it."""
    vary = parse_vary([TIED + "=10:30:5", "roll.set.com_offset=1e-3,2e-3"])
    assert list(vary) == [TIED, "roll.set.com_offset"]
    assert vary[TIED] == [10.0, 15.0, 20.0, 25.0, 30.0]
    assert parse_vary([" a.b , c.d =1,2"]) == {"a.b,c.d": [1, 2]}  # spaces around keys
    assert split_keys(("a.b", "c.d")) == split_keys("a.b,c.d") == ("a.b", "c.d")
    for items, match in (([TIED + "=1:2:2", "drum.rear.drive.web_speed=3"], "given twice"),
                         (["a.b,a.b=1"], "listed twice"), (["a.b,,c.d=1"], "empty key"),
                         (["a.b,=1"], "empty key"), ([TIED], "KEY=SPEC"),
                         ([TIED + "=1:2"], "START:STOP:COUNT")):
        with pytest.raises(winder.ArgumentError, match=match):
            parse_vary(items)


def test_tied_keys_in_the_grid(two_drum) -> None:
    """Every run sets all tied keys to the axis's value, and its scene is the scene edited
    by hand to those values; bounds are checked with the keys set together."""
    grid = build_grid(two_drum, {TIED: [10.0, 20.0], "roll.set.com_offset": [1e-3, 2e-3]})
    assert [a.keys for a in grid.axes] == [tuple(TIED.split(",")), ("roll.set.com_offset",)]
    assert grid.keys == (*TIED.split(","), "roll.set.com_offset")
    for point, scene in zip(grid.points, grid.scenes, strict=True):
        v, e = point["drum.front.drive.web_speed"], point["roll.set.com_offset"]
        assert point["drum.rear.drive.web_speed"] == v
        hand = two_drum.replace(drum={"front": {"drive": {"web_speed": v}},
                                      "rear": {"drive": {"web_speed": v}}},
                                roll={"set": {"com_offset": e}})
        assert scene.to_dict() == hand.to_dict()
    with pytest.raises(winder.ArgumentError, match=r"drum.middle.*front, rear"):
        build_grid(two_drum, {"drum.front.drive.web_speed,drum.middle.drive.web_speed": [1]})
    with pytest.raises(winder.ArgumentError, match=r"value 2000.0 fails.*web_speed"):
        build_grid(two_drum, {(TIED.split(",")[0], TIED.split(",")[1]): [10.0, 2000.0]})
    with pytest.raises(winder.ArgumentError, match=r"com_offset"):  # metres, not m/s
        build_grid(two_drum, {"drum.front.drive.web_speed,roll.set.com_offset": [10.0]})
    with pytest.raises(winder.ArgumentError, match="given twice"):
        build_grid(two_drum, {TIED: [1.0], "drum.front.drive.web_speed": [2.0]})


def test_units_come_from_the_key_declarations() -> None:
    """Every numeric key of both scene formats has a unit; paths of both formats map to
    the same unit; words and unknown paths have none."""
    from winder.scene.keys import ALL_TABLES

    for table, keys in ALL_TABLES.items():
        for key in keys:
            if key.kind == "num":
                assert key.unit or (table, key.name) == ("solver", "atol"), (table, key)
    for path, unit in (("drum.drive.web_speed", "m/s"), ("drum.front.drive.web_speed", "m/s"),
                       ("roll.com_offset", "m"), ("roll.set.com_offset", "m"),
                       ("roll.set.density", "kg/m³"), ("contact.stiffness", "N/m"),
                       ("nip.rear.contact.stiffness", "N/m"), ("friction.mu", "-"),
                       ("rider.rider.mass", "kg"), ("web.tension", "N"),
                       ("roll.parent.drive.bandwidth", "rad/s"), ("scene.duration", "s"),
                       ("contact.law", ""), ("drum.front.name", ""), ("no.such.key", ""),
                       ("drum", "")):
        assert key_unit(path) == unit, path
    # a Hunt–Crossley nip's stiffness is N/m^p (F = k δ^p), a linear one's N/m
    assert key_unit("contact.stiffness", {"contact": {"law": "hunt_crossley"}}) == "N/m^p"
    assert key_unit("contact.stiffness", {"contact": {"law": "linear"}}) == "N/m"
    nips = {"nip": [{"name": "rear", "contact": {"law": "hunt_crossley"}},
                    {"name": "front", "contact": {"law": "linear"}}]}
    assert key_unit("nip.rear.contact.stiffness", nips) == "N/m^p"
    assert key_unit("nip.front.contact.stiffness", nips) == "N/m"
    # a part named like a sub-table: the scene's tables decide
    assert key_unit("drum.drive.radius", {"drum": [{"name": "drive"}]}) == "m"
    assert key_unit("drum.drive.web_speed", {"drum": {"drive": {}}}) == "m/s"
    assert axis_label(TIED, {"drum": []}) == \
        "drum front drive: web speed,\ndrum rear drive: web speed [m/s]"
    assert axis_label("drum.front.radius,roll.set.core_mass", {"drum": [], "roll": []}) == \
        "drum front: drum radius R [m],\nroll set: mass of the core [kg]"
    # in words, from the keys' declarations (#36): no raw key path on an axis
    assert axis_label("drum.drive.web_speed", {"drum": {"drive": {}}}) == \
        "drum drive: web speed [m/s]"
    assert axis_label("roll.com_offset", {"roll": {}}) == "roll: centre-of-mass offset [m]"


def test_tied_sweep_runs_are_the_hand_edited_scenes(cluster, two_drum, tmp_path, capsys,
                                                    monkeypatch) -> None:
    """Oracle: `winder sweep --vary KEY1,KEY2=SPEC` gives, run for run, the rows of the
    scene edited by hand to the same values (run in this process); the Python API with a
    tuple of keys names the same runs; the map labels the tied axis with both keys and its
    unit."""
    import winder.plots.sweep as _sweep_plot

    _, lc = cluster
    fast = (MODELS / "two_drum_winder.toml").read_text().replace(
        "web_acceleration = 0.7", "web_acceleration = 20.0")
    assert fast.count("web_acceleration = 20.0") == 2
    scene_file = tmp_path / "fast.toml"
    scene_file.write_text(fast)
    figures = []
    monkeypatch.setattr(_sweep_plot.plt, "close", figures.append)
    png = tmp_path / "map.png"
    code = main(["sweep", str(scene_file), "--vary", TIED + "=5:15:3", "--out",
                 str(tmp_path / "t"), "--scheduler", lc.scheduler_address, "--t-end", "1.0",
                 "--output-step", "2e-3", "--bands", "3", "--plot", str(png),
                 "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "3 runs" in out and "0 failed" in out
    table = SweepTable.read(tmp_path / "t")
    assert table.axes == (tuple(TIED.split(",")),)
    assert table.keys == tuple(TIED.split(","))
    base = winder.load_scene(scene_file)
    settings = run_settings(t_end=1.0, output_step=2e-3)
    for row, v in zip(table.frame.to_dict("records"), (5.0, 10.0, 15.0), strict=True):
        assert row["drum.front.drive.web_speed"] == row["drum.rear.drive.web_speed"] == v
        hand = base.replace(drum={"front": {"drive": {"web_speed": v}},
                                  "rear": {"drive": {"web_speed": v}}})
        assert row["run_id"] == run_id(hand, settings, table.band_edges)
        ref, _ = run_one(hand, settings, table.band_edges)
        assert ref["status"] == "ok"
        _assert_rows_equal(row, ref)
    # the runs differ: the tie reaches the physics (both drums at the new speed)
    assert len({row["final_radius"] for row in table.frame.to_dict("records")}) == 3
    again = winder.sweep(base, {tuple(TIED.split(",")): [5.0, 10.0, 15.0]}, tmp_path / "t",
                         scheduler="tcp://127.0.0.1:9", t_end=1.0, output_step=2e-3, bands=3)
    assert again.computed == () and len(again.skipped) == 3  # the same runs: all done
    (fig,) = figures
    labels = [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel()]
    assert "drum front drive: web speed,\ndrum rear drive: web speed [m/s]" in labels
    assert any(ax.get_xlabel() == "roll diameter [m]" for ax in fig.axes)


# ---- progress --------------------------------------------------------------------------

def test_progress_on_a_pipe_is_whole_lines(monkeypatch) -> None:
    monkeypatch.setattr(_progress, "_LOG_INTERVAL", 0.0)
    stream = io.StringIO()
    bar = _progress.Progress(10.0, "scene", stream=stream)
    for t in (2.5, 5.0, 7.5, 10.0):
        bar.update(t)
    bar.close()
    sweep = _progress.SweepProgress(4, done=1, stream=stream)
    for failed in (False, True, False):
        sweep.update(failed=failed)
    sweep.close()
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert [ln.split("%")[0].split()[-1] for ln in lines[:5]] == \
        ["0.0", "25.0", "50.0", "75.0", "100.0"]
    assert lines[-1].startswith("sweep: 4/4 runs") and "1 failed" in lines[-1]
    assert any("ETA" in ln for ln in lines)


def test_scene_files_of_the_repository_sweep_by_path(models_dir) -> None:
    """A grid over a file path builds every scene (the demo's sweep, without running)."""
    grid = build_grid(winder.load_scene(Path(models_dir / "paper_winding.toml")),
                      {"drum.drive.web_speed": parse_spec("w", "10:30:11")})
    assert [s.drum.drive.web_speed for s in grid.scenes] == [10.0 + 2 * i for i in range(11)]
    assert len({s.to_dict()["drum"]["drive"]["web_speed"] for s in grid.scenes}) == 11


def test_unreachable_scheduler_is_an_argument_error(base, tmp_path) -> None:
    with pytest.raises(winder.ArgumentError, match="scheduler 'nonsense::': cannot connect"):
        winder.sweep(base, {"roll.com_offset": [1e-3]}, tmp_path / "x",
                     scheduler="nonsense::", **RUN)
    assert not (tmp_path / "x").exists()


def test_sweep_output_locations_are_checked_before_anything_runs(tmp_path, models_dir,
                                                                 capsys) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    for argv, named in (([ "--out", str(blocker / "sweep")], "--out"),
                        (["--out", str(tmp_path / "s"), "--plot", str(tmp_path / "m.txt")],
                         "--plot")):
        code = main(["sweep", str(models_dir / "paper_winding.toml"), "--vary",
                     "drum.drive.web_speed=10:20:2", *argv])
        err = capsys.readouterr().err
        assert code == 2 and named in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
