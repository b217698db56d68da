"""Web lines from parts (machines.md §11, issue #34): idler rollers and several spans.

A small line: an unwinding parent roll (tension control on the first span, its wound-in
tension ``T_in`` equal to the set-point so that the first span starts in equilibrium), one
roller, and the entry drum of a wound roll (contact off: the drum's surface speed is the
web's speed out, prescribed). Oracles: the tension rise over an idler equals its bearing
drag over its radius, ``(c_v ω + τ_c tanh(ω / 0.1)) / R``, and its motion
``J ω̇ = R (T_down − T_up) − drag`` at every sample; with equal tensions its load cell
reads ``2 T sin(β / 2)``; between two driven rollers with a draw the second span's tension
follows the transport equation's closed form ``T_ss + (T(0) − T_ss) exp(−v t / L)``
(steady ``T_ss = (EA (v_B − v_A) + v_A T_0) / v_B``, time constant ``L / v_B``), and the
pull roll's drive holds ``−R (T_1 − T_0)``; every §11 refusal through the API and
``winder run``.
"""

from __future__ import annotations

import copy
import math
from typing import Any

import numpy as np
import pytest
import tomli_w

import winder
from winder.cli import main
from winder.solve.simulate import WebSlipWarning

V = 10.0          # [m/s] web speed
R_IDLER = 0.1     # [m]
J_IDLER = 0.5     # [kg m²]
L, EA = 3.0, 1.4e6  # [m, N] every span
T_SET = 1000.0    # [N] the unwind's set-point and the parent's wound-in tension


def _data(*, rollers: list[dict[str, Any]], spans: list[dict[str, Any]],
          v_entry: float = V) -> dict[str, Any]:
    """The line's scene as a dict: parent → spans over ``rollers`` → entry drum at
    ``v_entry`` [m/s]."""
    return {
        "scene": {"name": "idler_line", "duration": 1.0, "output_step": 0.01},
        "effects": {"contact": False, "gravity": False, "imbalance": False,
                    "slip_relaxation": False},
        "paper": {"density": 650.0, "caliper": 70e-6},
        "drum": [{"name": "entry", "radius": 0.5, "inertia": 600.0, "mass": 3000.0,
                  "centre": [0.0, 0.0],
                  "drive": {"kind": "speed_profile", "web_acceleration": 0.0,
                            "web_speed": v_entry}}],
        "roll": [{"name": "set", "centre": [0.0, 0.6], "free": ["z"], "core_radius": 0.1,
                  "core_mass": 40.0, "core_inertia": 0.2, "width": 5.0,
                  "initial_radius": 0.1, "initial_speed": v_entry / 0.1},
                 {"name": "parent", "kind": "unwinding", "centre": [6.0, 0.0], "free": [],
                  "sense": 1, "core_radius": 0.4, "core_mass": 3000.0,
                  "core_inertia": 300.0, "width": 5.0, "initial_radius": 1.0,
                  "initial_speed": V / 1.0,
                  "drive": {"kind": "tension_control", "tension": T_SET,
                            "bandwidth": 10.0}}],
        "idler": rollers,
        "nip": [{"name": "entry_nip", "a": "entry", "b": "set",
                 "contact": {"law": "linear", "stiffness": 2.5e7, "damping": 1.5e4},
                 "friction": {"mu": 0.35, "slip_velocity": 0.05,
                              "relaxation_length": 0.01, "min_speed": 0.1}}],
        "web": {"entry_nip": "entry_nip", "span": spans},
        "solver": {"rtol": 1e-10, "atol": 1e-9},
    }


def _idler(**kw: Any) -> dict[str, Any]:
    return {"name": "idler", "radius": R_IDLER, "inertia": J_IDLER, "centre": [3.0, -1.0],
            "wrap": math.pi / 2, "initial_speed": V / R_IDLER, **kw}


def _spans(to: str = "idler", t1: float = T_SET) -> list[dict[str, Any]]:
    return [{"from": "parent", "length": L, "EA": EA, "T_in": T_SET,
             "initial_tension": T_SET, "to": to},
            {"length": L, "EA": EA, "initial_tension": t1}]


def _run(data: dict[str, Any], t_end: float) -> winder.Result:
    return winder.simulate(winder.scene_from_dict(data, source="<line>"), t_end=t_end,
                           output_step=0.01)


def test_idler_tension_rise_is_its_bearing_drag() -> None:
    """At steady speed ``T_down − T_up = (c_v ω + τ_c tanh(ω/0.1)) / R``; at every sample
    ``J ω̇ = R (T_down − T_up) − drag`` (the tensions as the rollers feel them,
    ``max(T, 0)``); the traction is the capstan share, and the run warns that it slips."""
    cv, tc = 2.0, 5.0
    with pytest.warns(WebSlipWarning, match=r"idler 'idler': the web would slip on it "
                                            r"from t = "):
        r = _run(_data(rollers=[_idler(bearing_viscous=cv, bearing_coulomb=tc)],
                       spans=_spans()), 4.0)
    t_up, t_down, w = r["span0_tension"], r["span1_tension"], r["idler_speed"]
    drag = cv * w + tc * np.tanh(w / 0.1)
    rise = t_down[-1] - t_up[-1]
    # measured 2.1e-10 (the rise 2047 N)
    assert rise == pytest.approx(drag[-1] / R_IDLER, rel=2e-9)
    pull = R_IDLER * (np.maximum(t_down, 0.0) - np.maximum(t_up, 0.0))
    # measured 0 (bit-exact) for both
    assert np.max(np.abs(J_IDLER * r["idler_accel"] - (pull - drag))) < 1e-12 * np.max(drag)
    assert np.max(np.abs(r["idler_torque"] - pull)) < 1e-12 * np.max(np.abs(pull))
    beta = math.pi / 2
    traction = rise / ((math.exp(0.3 * beta) - 1.0) * t_up[-1])
    assert r["idler_traction"][-1] == pytest.approx(traction, rel=1e-12)
    assert r.meta["slips"] and r["idler_traction"][-1] > 1.0


def test_load_cell_reads_twice_the_tension_over_half_the_wrap() -> None:
    """A drag-free idler at steady speed: equal tensions, load cell ``2 T sin(β/2)``; the
    web holds (traction far below 1: no warning)."""
    beta = 2.0
    r = _run(_data(rollers=[_idler(wrap=beta)], spans=_spans()), 3.0)
    T = r["span1_tension"][-1]
    assert T == pytest.approx(T_SET, rel=6e-9)  # measured 5.9e-10
    # measured 7.2e-10 (the tensions differ by the idler's J ω̇ / R at the end)
    assert r["idler_load_cell"][-1] == pytest.approx(2.0 * T * math.sin(beta / 2), rel=7e-9)
    # measured 4.6e-9 after 0.5 s
    assert "slips" not in r.meta and np.max(r["idler_traction"][50:]) < 5e-8


def test_draw_between_two_driven_rollers() -> None:
    """A pull roll at ``v_A`` and the entry drum at ``v_B``: the second span's tension
    follows ``T_ss + (T(0) − T_ss) exp(−v_B t / L)`` with ``T_ss = (EA (v_B − v_A) +
    v_A T_0) / v_B`` (the transport equation, T_0 held at the set-point); its time
    constant is ``L / v_B``; the pull roll's drive holds ``−R (T_1 − T_0)``."""
    va, vb, rp = V, 1.01 * V, 0.2
    pull = {"name": "pull", "radius": rp, "inertia": 5.0, "centre": [3.0, -1.0],
            "wrap": math.pi / 2,
            "drive": {"kind": "speed_profile", "web_acceleration": 0.0, "web_speed": va}}
    with pytest.warns(WebSlipWarning, match="idler 'pull'"):
        r = _run(_data(rollers=[pull], spans=_spans("pull"), v_entry=vb), 5.0)
    t0, t1 = r["span0_tension"], r["span1_tension"]
    # measured 3.0e-11: the first span stays at its set-point
    assert np.max(np.abs(t0 - T_SET)) < 3e-10 * T_SET
    t_ss = (EA * (vb - va) + va * T_SET) / vb
    closed = t_ss + (T_SET - t_ss) * np.exp(-vb * r.t / L)
    # measured 6.0e-11 of the steady tension (14851 N)
    assert np.max(np.abs(t1 - closed)) < 6e-10 * t_ss
    k = (r.t > 0.1) & (r.t < 1.0)
    tau = -1.0 / np.polyfit(r.t[k], np.log(np.abs(t1[k] - t_ss)), 1)[0]
    # measured 3.7e-11
    assert tau == pytest.approx(L / vb, rel=4e-10)
    # measured 0 (bit-exact): inverse dynamics of the prescribed roller
    assert np.max(np.abs(r["pull_torque"] + rp * (t1 - t0))) < 1e-12 * t_ss * rp
    assert r["pull_speed"][-1] * rp == pytest.approx(va, rel=1e-12)


def test_paper_balance_of_a_line() -> None:
    """What the parent loses equals what leaves the line at the entry drum plus what the
    spans hold, up to strain: summed over the spans the transport equation gives (the
    web does not slip on a roller, so a roller's speed in and out are one)

        ∫(v_out − v_1) dt = Σ L_i ΔT_i / EA_i − ∫(v_1 T_in / EA_0 − v_out T_last / EA) dt,

    and the parent's mass falls by ``ρ W h ∫ v_1 dt``. A free idler with drag between."""
    r = _run(_data(rollers=[_idler(bearing_viscous=2.0, bearing_coulomb=5.0)],
                   spans=_spans(), v_entry=1.005 * V), 3.0)
    t, v1 = r.t, r["parent_radius"] * r["parent_speed"]
    v_out = r["web_speed"]
    tensions = [r["span0_tension"], r["span1_tension"]]
    held = sum(L * (T[-1] - T[0]) / EA for T in tensions)
    flow = np.trapezoid(v1 * T_SET - v_out * tensions[-1], t) / EA
    net = np.trapezoid(v_out - v1, t)
    assert abs(net) > 1e-3  # the spans stretch: a visible difference of lengths
    # measured 1.2e-6 m of a 0.049 m difference, 2.5e-5 (the trapezoid over 0.01 s
    # samples of the ringing start)
    assert abs(net - (held - flow)) < 3e-4 * abs(net)
    lost = r["parent_mass"][0] - r["parent_mass"][-1]
    # measured 4.7e-9 of 6.8 kg (the trapezoid)
    assert lost == pytest.approx(650.0 * 70e-6 * 5.0 * np.trapezoid(v1, t), rel=5e-8)


# ---- refusals (machines.md §11 checks): API and `winder run` -----------------------------
def _two(to: str = "idler") -> list[dict[str, Any]]:
    return _spans(to)


def _second_web(d: dict[str, Any]) -> None:
    """A second station (drum, wound roll, nip, parent) whose web also ends a span at the
    idler."""
    d["drum"].append({**d["drum"][0], "name": "entry2", "centre": [20.0, 0.0]})
    d["roll"].append({**d["roll"][0], "name": "set2", "centre": [20.0, 0.6]})
    d["roll"].append({**d["roll"][1], "name": "parent2", "centre": [26.0, 0.0]})
    d["nip"].append({**d["nip"][0], "name": "entry2_nip", "a": "entry2", "b": "set2"})
    second = {"entry_nip": "entry2_nip", "span": copy.deepcopy(d["web"]["span"])}
    second["span"][0]["from"] = "parent2"
    d["web"] = [d["web"], second]


REFUSALS = [
    ("a roller in two webs", _second_web,
     r"\[web #2.span #1\] to: 'idler': \[web #1.span #1\] already ends at it: a roller "
     r"carries one web, once"),
    ("to on the last span",
     lambda d: d["web"]["span"][1].update(to="idler"),
     r"\[web.span #2\] to: 'idler': the last span ends at the entry nip's drum"),
    ("no to on a span before the last",
     lambda d: d["web"]["span"][0].pop("to"),
     r"\[web.span #1\] to: missing required key .*valid names: idler"),
    ("to names a drum",
     lambda d: d["web"]["span"][0].update(to="entry"),
     r"\[web.span #1\] to: 'entry' is drum 'entry', not a roller; .*valid names: idler"),
    ("to names nothing",
     lambda d: d["web"]["span"][0].update(to="nowhere"),
     r"\[web.span #1\] to: 'nowhere' is not a roller of the scene"),
    ("a roller twice in one web",
     lambda d: d["web"]["span"].insert(1, {"length": L, "EA": EA, "to": "idler"}),
     r"\[web.span #2\] to: 'idler': \[web.span #1\] already ends at it: a roller carries "
     r"one web, once"),
    ("wrap on a roller no web wraps",
     lambda d: d["idler"].append(_idler(name="spare", centre=[3.0, 3.0])),
     r"\[idler 'spare'\] wrap: 1.57.*: no web wraps this roller"),
    ("a web wraps a roller lacking wrap",
     lambda d: d["idler"][0].pop("wrap"),
     r"\[idler 'idler'\] wrap: missing required key \(\[web.span #1\] ends at it"),
    ("from on a later span",
     lambda d: d["web"]["span"][1].update({"from": "parent"}),
     r"\[web.span #2\] from: 'parent': only the first span has from"),
    ("T_in on a later span",
     lambda d: d["web"]["span"][1].update(T_in=5.0),
     r"\[web.span #2\] T_in: 5.0: only the first span has T_in"),
    ("wrap beyond a full turn",
     lambda d: d["idler"][0].update(wrap=7.0),
     r"\[idler 'idler'\] wrap: .*7"),
    ("no from on the first span",
     lambda d: d["web"]["span"][0].pop("from"),
     r"\[web.span #1\] from: missing required key"),
]


@pytest.mark.parametrize("case, change, message", REFUSALS, ids=[c[0] for c in REFUSALS])
def test_line_refusals(case: str, change: Any, message: str, tmp_path, capsys) -> None:
    data = _data(rollers=[_idler()], spans=_two())
    change(data)
    with pytest.raises(winder.SceneError, match=message):
        winder.scene_from_dict(data, source="<line>")
    path = tmp_path / "line.toml"
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    out = tmp_path / "r.csv"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err
    assert message.split(" ", 1)[0].replace("\\", "") in err
    assert not out.exists()


def test_line_scene_round_trips_and_one_span_keeps_its_meaning() -> None:
    """A line scene written as a dict reads back the same; a single ``[[web.span]]``
    element is the single ``[web.span]`` (the same part, the same state names)."""
    s = winder.scene_from_dict(_data(rollers=[_idler()], spans=_two()), source="<line>")
    assert winder.scene_from_dict(s.to_dict(), source="<line>") == s
    assert [sp.to for sp in s.web.spans] == ["idler", None] and s.web.rollers == ("idler",)
    one = _data(rollers=[], spans=[{"from": "parent", "length": L, "EA": EA}])
    del one["idler"]
    as_list = winder.scene_from_dict(one, source="<one>")
    one["web"]["span"] = one["web"]["span"][0]
    assert winder.scene_from_dict(one, source="<one>").web == as_list.web
    assert isinstance(as_list.to_dict()["web"]["span"], dict)


# ---- dancers (machines.md §11) ----------------------------------------------------------
K_D, M_D, M_R = 2e4, 20.0, 5.0  # [N/m, kg, kg] carriage stiffness and mass, roller mass


def _dancer_line(*, travel: tuple[float, float] = (-0.1, 0.1), **dancer: Any
                 ) -> dict[str, Any]:
    """At standstill: parent → span 0 → pull roll (held at rest) → span 1 → dancer →
    span 2 → entry drum (at rest); every span 3 m at 1000 N, the carriage balanced at
    ``d = 0`` (load 2 T)."""
    pull = {"name": "pull", "radius": 0.2, "inertia": 5.0, "centre": [4.0, -1.0],
            "wrap": math.pi / 2,
            "drive": {"kind": "speed_profile", "web_acceleration": 0.0, "web_speed": 0.0}}
    roller = {"name": "dancer", "radius": 0.1, "inertia": 0.5, "mass": M_R,
              "centre": [2.0, -2.0], "wrap": math.pi,
              "dancer": {"stiffness": K_D, "damping": 0.0, "load": 2 * T_SET, "mass": M_D,
                         "travel": list(travel), **dancer}}
    spans = [{"from": "parent", "length": L, "EA": EA, "T_in": T_SET,
              "initial_tension": T_SET, "to": "pull"},
             {"length": L, "EA": EA, "initial_tension": T_SET, "to": "dancer"},
             {"length": L, "EA": EA, "initial_tension": T_SET}]
    data = _data(rollers=[pull, roller], spans=spans, v_entry=0.0)
    data["roll"][1]["initial_speed"] = 0.0
    return data


def _kicked(data: dict[str, Any], speed: float, t_end: float) -> winder.Result:
    """A run from the scene's initial state with the carriage kicked to ``speed`` [m/s]."""
    from winder.solve.system import MachineSystem

    scene = winder.scene_from_dict(data, source="<dancer>")
    system = MachineSystem(scene)
    y0 = np.array(system.initial_state(), dtype=float)
    assert y0[system.index("dancer.position")] == 0.0  # d(0): the carriage's balance
    y0[system.index("dancer.position_dot")] = speed
    return winder.simulate(scene, t_end=t_end, output_step=0.001, initial_state=y0)


def test_dancer_at_standstill_oscillates_at_its_spring_and_spans() -> None:
    """Equal spans either side, the web at rest: ``f = sqrt((k + EA/L_up + EA/L_down) /
    m_d) / 2π`` (the roller's mass rides with the carriage); the roller does not turn."""
    r = _kicked(_dancer_line(), 1e-3, 2.0)
    d = r["dancer_position"]
    j = np.flatnonzero(np.diff(np.sign(d[1:])) != 0) + 1
    crossings = r.t[j] - d[j] * (r.t[j + 1] - r.t[j]) / (d[j + 1] - d[j])
    f = (len(crossings) - 1) / (2.0 * (crossings[-1] - crossings[0]))
    f0 = math.sqrt((K_D + 2.0 * EA / L) / (M_D + M_R)) / (2.0 * math.pi)
    # measured 4.8e-7 (31.08 Hz; the spans' L + d and the crossings' interpolation)
    assert f == pytest.approx(f0, rel=3e-6)
    assert np.max(np.abs(r["dancer_speed"])) < 1e-9
    # the spans stretch with the carriage: T − T0 = EA d / L to first order (measured
    # 8.5e-7 of the amplitude)
    np.testing.assert_allclose(r["span1_tension"] - T_SET, EA * d / L, rtol=0,
                               atol=1e-5 * EA * np.max(np.abs(d)) / L)


def test_dancer_travel_end_ends_the_run() -> None:
    """Kicked past its upper end: the run ends where ``d`` reaches it, at ``asin(hi ω /
    v0) / ω``, with a message naming the dancer and the end; a valid result up to there."""
    v0, hi = 10.0, 0.01
    r = _kicked(_dancer_line(travel=(-0.1, hi)), v0, 1.0)
    w = math.sqrt((K_D + 2.0 * EA / L) / (M_D + M_R))
    assert r.meta["ended"].startswith("the dancer 'dancer' reached the upper end of its "
                                      "travel (d = 0.01 m) at t = ")
    # measured 5.3e-6 (the spans' L + d at 0.3 % strain of the length)
    assert r.t[-1] == pytest.approx(math.asin(hi * w / v0) / w, rel=5e-5)
    assert r["dancer_position"][-1] == hi and np.all(r["dancer_position"] <= hi)


DANCER_REFUSALS = [
    ("wrap not π", lambda d: d["idler"][1].update(wrap=3.0),
     r"\[idler 'dancer'\] wrap: 3.0: a dancer's roller is wrapped by π"),
    ("stiffness not positive", lambda d: d["idler"][1]["dancer"].update(stiffness=0.0),
     r"\[idler 'dancer'.dancer\] stiffness: must be > 0 .*got 0.0"),
    ("travel without d(0)", lambda d: d["idler"][1]["dancer"].update(travel=[0.01, 0.1]),
     r"\[idler 'dancer'.dancer\] travel: \[0.01, 0.1\] does not hold d\(0\) = 0 m "
     r"strictly"),
    ("travel the wrong way", lambda d: d["idler"][1]["dancer"].update(travel=[0.1, -0.1]),
     r"\[idler 'dancer'.dancer\] travel: \[0.1, -0.1\]: valid: \[lo, hi\] with lo < hi"),
]


@pytest.mark.parametrize("case, change, message", DANCER_REFUSALS,
                         ids=[c[0] for c in DANCER_REFUSALS])
def test_dancer_refusals(case: str, change: Any, message: str, tmp_path, capsys) -> None:
    data = _dancer_line()
    change(data)
    with pytest.raises(winder.SceneError, match=message):
        winder.scene_from_dict(data, source="<dancer>")
    path = tmp_path / "dancer.toml"
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    assert main(["run", str(path), "--out", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err and "idler 'dancer'" in err


def _dancer_controlled(offset: float, bandwidth: float) -> dict[str, Any]:
    """Parent → span 0 → dancer → span 1 → entry drum at ``V``, the unwind under dancer
    control; the carriage's load puts ``d(0)`` at ``offset`` [m] under the initial 1000 N."""
    roller = {"name": "dancer", "radius": 0.1, "inertia": 0.5, "mass": M_R,
              "centre": [3.0, -2.0], "wrap": math.pi, "initial_speed": V / 0.1,
              "dancer": {"stiffness": K_D, "damping": 500.0, "mass": M_D,
                         "load": 2 * T_SET + K_D * offset, "travel": [-0.2, 0.2]}}
    spans = [{"from": "parent", "length": L, "EA": EA, "T_in": T_SET,
              "initial_tension": T_SET, "to": "dancer"},
             {"length": L, "EA": EA, "initial_tension": T_SET}]
    data = _data(rollers=[roller], spans=spans)
    data["roll"][1]["drive"] = {"kind": "dancer_control", "dancer": "dancer",
                                "bandwidth": bandwidth}
    return data


def dancer_decay(d0: float = 0.02, bandwidth: float = 5.0) -> tuple[winder.Result, float]:
    """The run of the dancer-controlled line from ``d0`` [m] out (8 s) and the error's
    decay rate [1/s]: the slope of ``log|d| − 2 log t`` over 2–5 s (the design's three
    poles at ``−ω_c`` give ``|d| t⁻² ∝ exp(−ω_c t)``). Also the source of
    docs/guide/idlers-dancers-spans.md's rate (benchmarks/guide_numbers.py)."""
    r = _run(_dancer_controlled(d0, bandwidth), 8.0)
    d = r["dancer_position"]
    k = (r.t > 2.0) & (r.t < 5.0)
    return r, float(np.polyfit(r.t[k], np.log(np.abs(d[k])) - 2.0 * np.log(r.t[k]), 1)[0])


def test_dancer_control_holds_the_dancer_at_its_centre() -> None:
    """Started 20 mm out, the unwind brings the carriage to ``d = 0`` (integral action)
    where it balances its load: both spans at ``F_load / 2``; the error decays at about
    the design's ``ω_c`` (three poles at ``−ω_c`` of the double-integrator model: ``|d|
    t⁻² ∝ exp(−ω_c t)``)."""
    wc, d0 = 5.0, 0.02
    r, rate = dancer_decay(d0, wc)
    d = r["dancer_position"]
    np.testing.assert_array_equal(d, r["dancer_error"])
    assert d[0] == d0
    # measured 7e-12 m at 8 s
    assert abs(d[-1]) < 1e-9 * d0
    balance = (2 * T_SET + K_D * d0) / 2
    for name in ("span0_tension", "span1_tension"):  # measured 4.5e-9
        assert r[name][-1] == pytest.approx(balance, rel=5e-8)
    # measured −4.67: the model leaves out the carriage's spring and the spans' strain
    assert rate == pytest.approx(-wc, rel=0.15)


DRIVE_REFUSALS = [
    ("dancer control of a fixed roller",
     lambda d: d["idler"][0].pop("dancer") and d["idler"][0].update(wrap=1.0),
     r"\[roll 'parent'.drive\] dancer: 'dancer' is idler 'dancer', not a dancer on its "
     r"web; valid names: dancers \[web\] wraps: \(none\)"),
    ("dancer control of nothing",
     lambda d: d["roll"][1]["drive"].update(dancer="nowhere"),
     r"\[roll 'parent'.drive\] dancer: 'nowhere' is not a part of the scene"),
]


@pytest.mark.parametrize("case, change, message", DRIVE_REFUSALS,
                         ids=[c[0] for c in DRIVE_REFUSALS])
def test_unwind_drive_refusals(case: str, change: Any, message: str, tmp_path,
                               capsys) -> None:
    data = _dancer_controlled(0.0, 5.0)
    change(data)
    with pytest.raises(winder.SceneError, match=message):
        winder.scene_from_dict(data, source="<drive>")
    path = tmp_path / "drive.toml"
    path.write_text(tomli_w.dumps(data), encoding="utf-8")
    assert main(["run", str(path), "--out", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err and "drive] " in err


def test_dancer_at_speed_follows_the_linearised_transport_equation() -> None:
    """The same line at 10 m/s (pull roll and entry drum prescribed): the kicked carriage
    follows the linearised model (states ``d, ḋ, T_up, T_down, ω`` of the roller)

        m d̈ = −k d − δT_up − δT_down,      J ω̇ = R (δT_down − δT_up),
        L δṪ_up = EA ḋ + (EA − T) R δω − v δT_up,
        L δṪ_down = EA ḋ − (EA − T) R δω + v δT_up − v δT_down,

    whose carriage mode the web's speed damps (ζ = 4.2e-3 at 31.08 Hz; none at rest)."""
    from scipy.linalg import expm

    v, kick, R, J = 10.0, 1e-3, 0.1, 0.5
    data = _dancer_line()
    data["idler"][0]["drive"]["web_speed"] = v
    data["drum"][0]["drive"]["web_speed"] = v
    data["roll"][0]["initial_speed"] = v / 0.1
    data["roll"][1]["initial_speed"] = v / 1.0
    data["idler"][1]["initial_speed"] = v / R
    r = _kicked(data, kick, 1.0)
    m = M_D + M_R
    A = np.zeros((5, 5))
    A[0, 1] = 1.0
    A[1, 0], A[1, 2], A[1, 3] = -K_D / m, -1.0 / m, -1.0 / m
    A[2, 1], A[2, 2], A[2, 4] = EA / L, -v / L, (EA - T_SET) * R / L
    A[3, 1], A[3, 2], A[3, 3], A[3, 4] = EA / L, v / L, -v / L, -(EA - T_SET) * R / L
    A[4, 2], A[4, 3] = -R / J, R / J
    linear = np.array([(expm(A * t) @ [0.0, kick, 0.0, 0.0, 0.0])[0] for t in r.t])
    d = r["dancer_position"]
    # measured 7.4e-6 of the 5 µm amplitude (the spans' L + d and the products of δs)
    assert np.max(np.abs(d - linear)) < 7e-5 * np.max(np.abs(d))
    carriage = max(np.linalg.eigvals(A), key=lambda s: abs(s.imag))
    assert abs(carriage.imag) / (2 * math.pi) == pytest.approx(31.08, abs=0.01)
    assert -carriage.real / abs(carriage) == pytest.approx(4.2e-3, rel=0.01)


def test_sweeps_reach_the_line_keys() -> None:
    """``Scene.replace`` (the sweeps' path) reaches an idler's keys, its dancer's, the
    web's ``mu`` and a line's span by its index (spans have no names)."""
    s = winder.scene_from_dict(_dancer_line(), source="<dancer>")
    t = s.replace(idler={"dancer": {"bearing_viscous": 0.1, "dancer": {"stiffness": 3e4}}},
                  web={"mu": 0.5, "span": {"1": {"length": 2.0}, 2: {"EA": 2e6}}})
    assert t.idlers[1].bearing_viscous == 0.1 and t.idlers[1].dancer.stiffness == 3e4
    assert t.web.mu == 0.5
    assert [sp.length for sp in t.web.spans] == [L, 2.0, L]
    assert [sp.EA for sp in t.web.spans] == [EA, EA, 2e6]
    with pytest.raises(winder.ArgumentError, match=r"no element named '3'; valid names: "
                                                   r"0, 1, 2"):
        s.replace(web={"span": {"3": {"EA": 1.0}}})


def test_fmu_interface_of_a_line() -> None:
    """The FMU of a line (its interface, nothing compiled): a pull roll's torque is an
    input (beside the unwind's tension set-point); every span's tension, every roller's
    load cell and the dancer's position are outputs, in the machine's units."""
    from winder.fmu.interface import native_interface

    data = _dancer_line()
    data["idler"][0]["drive"] = {"kind": "torque", "torque": 0.0, "web_speed": 0.0}
    ni = native_interface(winder.scene_from_dict(data, source="<dancer>"))
    assert [v.name for v in ni.inputs] == ["pull_torque", "parent_tension_setpoint"]
    units = {v.name: v.unit for v in ni.outputs}
    for name, unit in (("span0_tension", "N"), ("span1_tension", "N"),
                       ("span2_tension", "N"), ("pull_load_cell", "N"),
                       ("dancer_load_cell", "N"), ("dancer_position", "m"),
                       ("dancer_position_dot", "m/s"), ("dancer_traction", None)):
        assert name in units and (unit is None or units[name] == unit), name
