"""Several webs (machines spec §3, §8, §9): every wound roll is fed by exactly one web, a
scene has one ``[[web]]`` per wound roll (a single ``[web]`` stays valid), and each
winding station of a scene behaves exactly as it does alone where the parts do not touch.

The oracle: two stations in one scene give, channel for channel, what each gives alone, to
round-off. The stations are decoupled (far apart, no shared part), so on a fixed-step RK4
without events the combined integration does the same arithmetic per station; what differs
is the order of the static solve's Newton updates (round-off in the initial state), which
the stiff contacts amplify in the acceleration channels to ~1e-10 of their scale.

The refusals (a wound roll no web feeds, two webs into one roll, bad ``[[web]]`` keys and
references, circles overlapping without a nip) name the file, the table and the key, through
the API and the command line (exit 2, nothing left on disk)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomli_w
from cli_corpus import Case, run_case

import winder
from winder.analysis.sweep_grid import build_grid
from winder.cli import main
from winder.scene.load import scene_from_dict
from winder.scene.schema import ARRAYS

MODELS = Path(__file__).resolve().parents[2] / "models"
V = 5.0  # [m/s] the web speed of every station, from t = 0
T_END = 0.1  # [s]
STEP = 2e-4  # [s] RK4 step (1 ms makes the stiff nips of the line ring and amplify round-off)
#: Largest difference of a channel between a station alone and in the two-station scene,
#: relative to the channel's largest magnitude (at least 1): measured 6e-11 (set_z_accel).
ROUND_OFF = 1e-9


def _model(name: str) -> dict[str, Any]:
    return tomllib.loads((MODELS / f"{name}.toml").read_text(encoding="utf-8"))


def _station(data: dict[str, Any], suffix: str, dx: float, web: str | None = None
             ) -> dict[str, Any]:
    """A scene of parts with every part renamed ``NAME + suffix`` and moved by ``dx`` [m]
    along x; its web named ``web``; drums at the web speed ``V`` from t = 0 and every roll
    turning with them (so that no core event splits a step of the fixed-step run)."""
    d = copy.deepcopy(data)
    for array in ARRAYS:
        for p in d.get(array, []):
            p["name"] += suffix
            if "centre" in p:
                p["centre"] = [p["centre"][0] + dx, p["centre"][1]]
    for r in d.get("rider", []):
        r["rides"] += suffix
        r["x"] += dx
    for n in d["nip"]:
        n["a"] += suffix
        n["b"] += suffix
    d["web"]["entry_nip"] += suffix
    if "span" in d["web"]:
        d["web"]["span"]["from"] += suffix
    if web is not None:
        d["web"]["name"] = web
    for drum in d["drum"]:
        drum["drive"] = {"kind": "speed_profile", "web_acceleration": 0.0, "web_speed": V}
    for roll in d["roll"]:
        roll["initial_speed"] = V / roll["initial_radius"]
    return d


def _together(*stations: dict[str, Any]) -> dict[str, Any]:
    """One scene of the stations' parts, one ``[[web]]`` per station."""
    out = copy.deepcopy(stations[0])
    for array in ARRAYS:
        out[array] = [p for s in stations for p in copy.deepcopy(s.get(array, []))]
    out["web"] = [copy.deepcopy(s["web"]) for s in stations]
    out["scene"]["name"] = "stations"
    return out


def _run(data: dict[str, Any]) -> winder.Result:
    return winder.simulate(scene_from_dict(copy.deepcopy(data)), t_end=T_END, method="RK4",
                           max_step=STEP, backend="pinocchio", events=False)


def _compare(alone: winder.Result, together: winder.Result, web: str,
             span: str | None = None) -> float:
    """The largest relative difference of ``alone``'s channels against ``together``'s:
    ``web_speed``/``web_force`` are ``WEB_...`` there, ``span_tension``/``tension_error``
    ``SPAN_...`` when ``span`` (several spans), every other channel has the same name."""
    assert alone.t.shape == together.t.shape and np.array_equal(alone.t, together.t)
    worst = 0.0
    for ch in alone:
        name = ch
        if ch in ("web_speed", "web_force"):
            name = f"{web}_{ch}"
        elif span is not None and ch in ("span_tension", "tension_error"):
            name = f"{span}_{ch}"
        assert name in together, (ch, name, sorted(together))
        x, y = np.asarray(alone[ch]), np.asarray(together[name])
        err = float(np.max(np.abs(x - y))) / max(1.0, float(np.max(np.abs(x))))
        assert err <= ROUND_OFF, (ch, name, err)
        worst = max(worst, err)
    return worst


@pytest.fixture(scope="module")
def winder_and_line() -> dict[str, Any]:
    """The two-drum winder (constant tension 1000 N) and, 10 m away, the small winder line
    (its own unwind, span and tension controller): alone and in one scene."""
    a = _station(_model("two_drum_winder"), "", 0.0)
    b = _station(_model("winder_line_small"), "_b", 10.0, web="line")
    b["scene"] = dict(a["scene"])
    return {"a": a, "b": b, "ab": _together(a, b)}


def test_two_stations_give_what_each_gives_alone(winder_and_line) -> None:
    """Oracle: each station's channels in the two-station scene equal its run alone, to
    round-off; the web channels carry the web's name (two webs, one span: ``span_tension``
    keeps its name, spec §9), and there is no other channel."""
    runs = {k: _run(v) for k, v in winder_and_line.items()}
    assert runs["a"].meta["events"] == runs["b"].meta["events"] == 0
    _compare(runs["a"], runs["ab"], "rear_nip")
    _compare(runs["b"], runs["ab"], "line")
    named = {f"{w}_{c}" if c in ("web_speed", "web_force") else c
             for k, w in (("a", "rear_nip"), ("b", "line")) for c in runs[k]}
    assert set(runs["ab"]) == named
    # each wound roll grows with its own web only: paper length ≈ V t (no slip), and the
    # roll of station a does not grow twice as fast (the old second-web-from-nowhere)
    for roll in ("set", "set_b"):
        r = runs["ab"][f"{roll}_radius"]
        h = 70e-6
        wound = np.pi * (r[-1] ** 2 - r[0] ** 2) / h  # [m] paper on the roll
        assert wound == pytest.approx(V * T_END, rel=0.02)


def test_two_spans_each_as_alone() -> None:
    """Two winder lines in one scene (two spans, two controllers): ``WEB_span_tension``,
    ``WEB_tension_error``, ``WEB_web_speed`` per web, each equal to the line alone."""
    line = _model("winder_line_small")
    b = _station(line, "_b", 10.0, web="line")
    c = _station(line, "_c", 20.0, web="line2")
    runs = {"b": _run(b), "bc": _run(_together(b, c))}
    _compare(runs["b"], runs["bc"], "line", span="line")
    assert "span_tension" not in runs["bc"] and "tension_error" not in runs["bc"]
    # the second line is the first one moved: its channels are the first's, renamed
    for ch in ("span_tension", "tension_error", "web_speed"):
        x, y = runs["bc"][f"line_{ch}"], runs["bc"][f"line2_{ch}"]
        assert np.max(np.abs(x - y)) <= ROUND_OFF * max(1.0, np.max(np.abs(x)))
    assert np.max(np.abs(runs["bc"]["parent_c_torque"] - runs["bc"]["parent_b_torque"])) <= \
        ROUND_OFF * np.max(np.abs(runs["bc"]["parent_b_torque"]))


# ---- the scene: [[web]] and a single [web] ------------------------------------------------

def test_web_array_of_one_is_the_single_web_table(tmp_path) -> None:
    """``[[web]]`` with one table is the same scene as ``[web]``; Scene.web is the first
    web, Scene.webs all; the name defaults to the entry nip's."""
    data = _model("two_drum_winder")
    single = scene_from_dict(copy.deepcopy(data))
    data["web"] = [data["web"]]
    array = scene_from_dict(data)
    assert array == single
    assert single.webs == (single.web,) and single.web.name == "rear_nip"


def test_several_webs_round_trip_and_replace(winder_and_line) -> None:
    """A scene of two webs writes ``[[web]]`` (each with its name), reads back equal, and
    ``replace`` reaches one web by its name."""
    s = scene_from_dict(copy.deepcopy(winder_and_line["ab"]))
    assert [w.name for w in s.webs] == ["rear_nip", "line"] and s.web is s.webs[0]
    d = s.to_dict()
    assert [w["name"] for w in d["web"]] == ["rear_nip", "line"]
    assert scene_from_dict(tomllib.loads(tomli_w.dumps(d))) == s
    r = s.replace(web={"rear_nip": {"tension": 250.0}, "line": {"span": {"EA": 2e6}}})
    assert (r.webs[0].tension, r.webs[1].span.EA) == (250.0, 2e6)
    assert (s.webs[0].tension, s.webs[1].span.EA) == (1000.0, 1.4e6)
    grid = build_grid(s, {"web.line.span.EA": [1e6, 2e6], "web.rear_nip.tension": [10.0]})
    assert [(g.webs[0].tension, g.webs[1].span.EA) for g in grid.scenes] == \
        [(10.0, 1e6), (10.0, 2e6)]


def _second_station(d: dict[str, Any]) -> None:
    """The issue's case: a second drum and wound roll (with their nip), no web for it."""
    d["drum"].append({**copy.deepcopy(d["drum"][1]), "name": "far", "centre": [5.0, 0.0]})
    d["roll"].append({**copy.deepcopy(d["roll"][0]), "name": "set2", "centre": [5.0, 0.55],
                      "free": ["z"]})
    d["nip"].append({**copy.deepcopy(d["nip"][1]), "name": "far_nip", "a": "far",
                     "b": "set2"})


def _webs(d: dict[str, Any], *more: dict[str, Any]) -> None:
    _second_station(d)
    d["web"] = [d["web"], *more]


BAD = [
    ("wound roll without web", _second_station,
     r"\[roll 'set2'\] kind: 'wound': no web feeds this wound roll, so its paper would come "
     r"from nowhere \(every wound roll is fed by exactly one web\); add a \[\[web\]\] "
     r"with entry_nip = .*valid names: far_nip"),
    ("two webs into one roll", lambda d: _webs(d, {"entry_nip": "front_nip", "name": "w2"}),
     r"\[web 'w2'\] entry_nip: 'front_nip' enters wound roll 'set', which \[web #1\] already "
     r"feeds: two webs into one roll; .*valid names: nips into the other wound rolls: "
     r"far_nip"),
    ("missing entry_nip", lambda d: _webs(d, {"tension": 5.0}),
     r"\[web #2\] entry_nip: missing required key"),
    ("entry_nip unknown", lambda d: _webs(d, {"entry_nip": "nope"}),
     r"\[web #2\] entry_nip: 'nope' is not a nip of the scene; valid names: front_nip, "
     r"rear_nip, far_nip"),
    ("entry_nip a rider's nip", lambda d: _webs(d, {"entry_nip": "rider_nip", "name": "w"}),
     r"\[web 'w'\] entry_nip: 'rider_nip' is nip 'rider_nip' joining roll 'set' \(a\) and "
     r"rider 'rider' \(b\); the web enters a wound roll \(b\) from the drum it wraps"),
    ("entry_nip a drum", lambda d: _webs(d, {"entry_nip": "far"}),
     r"\[web #2\] entry_nip: 'far' is drum 'far', not a nip"),
    ("tension with span", lambda d: _webs(d, {"entry_nip": "far_nip", "tension": 9.0,
                                              "span": {"from": "set", "length": 1.0,
                                                       "EA": 1e6}}),
     r"\[web #2\] tension: 9.0: with \[web.span\] the tension is the span's state"),
    ("span from a wound roll", lambda d: _webs(d, {"entry_nip": "far_nip", "span": {
        "from": "set", "length": 1.0, "EA": 1e6}}),
     r"\[web #2.span\] from: 'set' is roll 'set' of kind 'wound', not an unwinding roll"),
    ("span without length", lambda d: _webs(d, {"entry_nip": "far_nip", "span": {
        "from": "set", "EA": 1e6}}),
     r"\[web #2.span\] length: missing required key"),
    ("duplicate web name", lambda d: _webs(d, {"entry_nip": "far_nip", "name": "rear_nip"}),
     r"\[web 'rear_nip'\] name: 'rear_nip' is already the name of \[web #1\]; every web "
     r"needs its own name"),
    ("web name of a part", lambda d: _webs(d, {"entry_nip": "far_nip", "name": "set"}),
     r"\[web 'set'\] name: 'set' is already the name of roll 'set'"),
    ("bad web name", lambda d: _webs(d, {"entry_nip": "far_nip", "name": "a web"}),
     r"\[web #2\] name: 'a web' is not a part name"),
    ("unknown web key", lambda d: _webs(d, {"entry_nip": "far_nip", "speed": 3.0}),
     r"\[web #2\] speed: unknown key; valid keys: name, entry_nip, tension, span, mu"),
    ("web tension negative", lambda d: _webs(d, {"entry_nip": "far_nip", "tension": -1.0}),
     r"\[web #2\] tension: must be >= 0"),
    ("web not a table", lambda d: _webs(d, 5),
     r"\[web #2\] must be a table of keys, got 5"),
    ("empty web array", lambda d: d.update(web=[]),
     r"\[\[web\]\]: an empty array of webs"),
    # circles overlapping at the start without a nip (spec §8)
    ("rear drum into the front drum", lambda d: d["drum"][1].update(centre=[0.2, 0.0]),
     r"\[drum 'rear'\] centre: drum 'rear' \(radius 0.5 m at \(0.2, 0\) m\) overlaps drum "
     r"'front' \(radius 0.5 m at \(-0.525, 0\) m\) by 0.275 m at the start, and no "
     r"\[\[nip\]\] joins them"),
    ("roll into another station's drum", lambda d: [_webs(d, {"entry_nip": "far_nip"}),
                                                    d["roll"][1].update(centre=[0.525, 0.4])],
     r"\[roll 'set2'\] centre: roll 'set2' .* overlaps drum 'rear' .* and no \[\[nip\]\] "
     r"joins them.*valid: centres at least the sum of the radii apart, or a \[\[nip\]\] "
     r"with a = 'rear', b = 'set2'"),
]


@pytest.mark.parametrize("case, edit, pattern", BAD, ids=[b[0] for b in BAD])
def test_bad_webs_name_key_value_and_valid(tmp_path, case, edit, pattern) -> None:
    data = _model("two_drum_winder")
    edit(data)
    p = tmp_path / "scene.toml"
    p.write_text(tomli_w.dumps(data), encoding="utf-8")
    with pytest.raises(winder.SceneError, match=pattern) as info:
        winder.load_scene(p)
    assert str(info.value).startswith(f"{p}: ") and len(str(info.value)) < 600


def test_second_station_with_its_web_loads() -> None:
    """The fix of the first case: the second wound roll with its own web loads, and the
    circles that touch through a nip (drum and roll at distance R + r) are accepted."""
    data = _model("two_drum_winder")
    _webs(data, {"entry_nip": "far_nip", "tension": 200.0})
    s = scene_from_dict(data)
    assert [(w.name, w.entry_nip, w.tension) for w in s.webs] == \
        [("rear_nip", "rear_nip", 1000.0), ("far_nip", "far_nip", 200.0)]


def _cli_case(label: str, edit: Any, names: tuple[str, ...]) -> Case:
    def build(d: Path) -> list[str]:
        data = _model("two_drum_winder")
        edit(data)
        p = d / "scene.toml"
        p.write_text(tomli_w.dumps(data), encoding="utf-8")
        return ["run", str(p), "--out", str(d / "out" / "r.npz"), "--t-end", "0.01"]
    return Case("webs", label, build, names=names)


CLI = [_cli_case(label, edit, names) for label, edit, names in (
    ("wound roll without web", _second_station, ("scene.toml", "[roll 'set2'] kind", "web")),
    ("two webs into one roll", BAD[1][1], ("scene.toml", "[web 'w2'] entry_nip", "'set'")),
    ("missing entry_nip", BAD[2][1], ("scene.toml", "[web #2] entry_nip")),
    ("overlapping drums", BAD[-2][1], ("scene.toml", "[drum 'rear'] centre", "0.2")),
)]


def _fmu_of_two_webs(d: Path) -> list[str]:
    data = _model("two_drum_winder")
    _webs(data, {"entry_nip": "far_nip"})
    p = d / "scene.toml"
    p.write_text(tomli_w.dumps(data), encoding="utf-8")
    return ["fmu", str(p), "--out", str(d / "w.fmu")]


#: The FMU takes one web: a scene of several is refused before anything is built.
CLI.append(Case("webs", "fmu of two webs", _fmu_of_two_webs,
                names=("scene.toml", "[[web]]", "2 webs", "rear_nip, far_nip")))


@pytest.mark.parametrize("case", CLI, ids=[c.label for c in CLI])
def test_cli_refuses_bad_webs(case: Case, tmp_path: Path) -> None:
    """``winder run`` exits 2 with a few lines naming the file and the key, no traceback,
    nothing left on disk."""
    outcome = run_case(main, case, tmp_path / "case")
    assert outcome.status == 2 and outcome.clean, (outcome.problems, outcome.stderr)


def test_cli_runs_two_stations(winder_and_line, tmp_path: Path) -> None:
    """``winder run`` on a two-station scene writes the channels of both webs, equal to
    :func:`winder.simulate` of the same scene (another path)."""
    p = tmp_path / "stations.toml"
    p.write_text(tomli_w.dumps(winder_and_line["ab"]), encoding="utf-8")
    out = tmp_path / "r.npz"
    args = ["run", str(p), "--out", str(out), "--t-end", "0.004", "--method", "RK4",
            "--backend", "pinocchio"]
    assert main(args) == 0
    got = winder.load_result(out)
    ref = winder.simulate(winder.load_scene(p), t_end=0.004, method="RK4",
                          backend="pinocchio")
    for ch in ("rear_nip_web_speed", "line_web_speed", "rear_nip_web_force",
               "line_web_force", "span_tension", "set_radius", "set_b_radius"):
        np.testing.assert_array_equal(got[ch], ref[ch])


def test_viewer_draws_each_web(winder_and_line) -> None:
    """The viewer draws one web per ``[[web]]``: the first under ``web``, the others under
    ``web-NAME``; each path equals the one drawn for its station alone (identity), and
    ends at the wound roll's contact point ``p_b = c_b − r_b n`` (machines spec §2)."""
    from winder.viewer import WinderGraph, motion

    scenes = {k: scene_from_dict(copy.deepcopy(winder_and_line[k])) for k in ("b", "ab")}
    runs = {k: winder.simulate(s, t_end=0.004, method="RK4", backend="pinocchio",
                               output_step=0.001) for k, s in scenes.items()}
    times = runs["ab"].t
    drawn = {k: motion(scenes[k], runs[k], times) for k in scenes}
    assert [w.name for w in drawn["ab"].webs] == ["rear_nip", "line"]
    graph = WinderGraph(scenes["ab"])
    assert [n for n, _ in graph.web_nodes] == ["web", "web-line"]
    for k in range(len(times)):
        alone, (first, line) = drawn["b"].web_paths(k)[0], drawn["ab"].web_paths(k)
        np.testing.assert_allclose(line, alone, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(first, drawn["ab"].web(k))
        for path, (a, b) in ((first, ("rear", "set")), (line, ("rear_b", "set_b"))):
            ca, cb = (np.array([drawn["ab"].bodies[n].x[k], drawn["ab"].bodies[n].z[k]])
                      for n in (a, b))
            n = (cb - ca) / np.hypot(*(cb - ca))
            np.testing.assert_allclose(path[-1], cb - drawn["ab"].bodies[b].radius[k] * n,
                                       rtol=0, atol=1e-12)
        poses = {p[1] for p in graph.pose_commands(drawn["ab"], k) if p[0] == "transform"}
        assert ("web", "s00") in poses and ("web-line", "s00") in poses


def test_two_stations_compiled_equals_numeric(winder_and_line) -> None:
    """The generated code of the two-station machine (the default backend) and the numeric
    Pinocchio path give the same run (RK4, same steps), channel for channel, to 1e-9 of each
    channel's scale (another path)."""
    s = scene_from_dict(copy.deepcopy(winder_and_line["ab"]))
    kw = {"t_end": 0.02, "method": "RK4", "max_step": STEP, "events": False,
          "output_step": 0.002}
    fast, slow = (winder.simulate(s, backend=b, **kw) for b in ("compiled", "pinocchio"))
    assert set(fast) == set(slow)
    for ch in slow:
        x, y = np.asarray(slow[ch]), np.asarray(fast[ch])
        assert np.max(np.abs(x - y)) <= ROUND_OFF * max(1.0, float(np.max(np.abs(x)))), ch
