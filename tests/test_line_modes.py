"""A web line's modes (machines.md §11, issue #34): ``winder modes --roll PARENT`` maps the
line's tension and dancer modes against the unwinding roll's radius, labelled by shape
(:mod:`winder.analysis.line_modes`).

Oracles: a dancer at standstill between equal held spans oscillates at
``sqrt((k + EA/L_up + EA/L_down) / m_d) / 2π``; at web speed its eigenvalue is the one of
the linearised transport equation (a 5-state closed form); on the shipped line the map's
line modes at a full and an empty parent are the eigenvalues of an independent
small-signal model of the line written here from §11's equations (the steady tensions
from the rollers' drag, the speeds from the paper's flux), under the unwind's
``dancer_control`` and under a constant brake torque (where the parent's ``J(r)/r²``
rides on the first span and moves the modes).
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_idler_line import EA, K_D, M_D, M_R, T_SET, L, _dancer_line

import winder
from winder.cli import main

MODEL = Path(__file__).resolve().parents[1] / "models" / "winder_line_dancer.toml"


def _carriage(modes: list[winder.Mode], name: str = "dancer") -> winder.Mode:
    out = [m for m in modes if m.kind == "line" and m.coordinate == f"{name}.carriage"]
    assert len(out) == 1, [(m.kind, m.coordinate) for m in modes]
    return out[0]


def test_dancer_at_standstill_is_its_spring_and_spans() -> None:
    """Held spans either side, the web at rest: the mode labelled ``dancer.carriage`` is
    undamped at ``sqrt((k + 2 EA/L) / m_d) / 2π`` (31.08 Hz; measured 0 relative error,
    the roller 2.2e-16: the Jacobian exact at d = 0); the roller's own mode
    ``dancer.roller`` at ``sqrt(2 (EA − T) R² / (L J)) / 2π``."""
    scene = winder.scene_from_dict(_dancer_line(), source="<dancer>")
    modes = winder.modes_at(scene)
    m = _carriage(modes)
    f0 = math.sqrt((K_D + 2.0 * EA / L) / (M_D + M_R)) / (2.0 * math.pi)
    assert m.frequency == pytest.approx(f0, rel=1e-12)
    assert abs(m.eigenvalue.real) < 1e-9 * abs(m.eigenvalue)
    # the roller between two held spans: sqrt(2 (EA − T) R² / (L J)) / 2π (R 0.1 m,
    # J 0.5 kg m²; the transport equation's ∂Ṫ/∂v = (EA − T)/L)
    roller = next(x for x in modes if x.coordinate == "dancer.roller")
    assert roller.frequency == pytest.approx(
        math.sqrt(2.0 * (EA - T_SET) * 0.01 / (L * 0.5)) / (2.0 * math.pi), rel=1e-12)


def _at_speed(v: float) -> dict[str, Any]:
    data = _dancer_line()
    data["idler"][0]["drive"]["web_speed"] = v
    data["drum"][0]["drive"]["web_speed"] = v
    data["roll"][0]["initial_speed"] = v / 0.1
    data["roll"][1]["initial_speed"] = v / 1.0
    data["idler"][1]["initial_speed"] = v / 0.1
    return data


def test_dancer_at_speed_against_the_linearised_transport_equation() -> None:
    """At 10 m/s (pull roll and entry drum prescribed) ``dancer.carriage`` is the carriage
    eigenvalue of the linearised line (states ``d, ḋ, T_up, T_down, ω``):

        m d̈ = −k d − δT_up − δT_down,      J ω̇ = R (δT_down − δT_up),
        L δṪ_up = EA ḋ + (EA − T) R δω − v δT_up,
        L δṪ_down = EA ḋ − (EA − T) R δω + v δT_up − v δT_down,

    frequency 31.08 Hz, damping ratio 4.2e-3 from the transport alone (measured 2.2e-16
    and 2.2e-14 relative)."""
    v, R, J = 10.0, 0.1, 0.5
    scene = winder.scene_from_dict(_at_speed(v), source="<dancer>")
    m = _carriage(winder.modes_at(scene))
    mass = M_D + M_R
    A = np.zeros((5, 5))
    A[0, 1] = 1.0
    A[1, 0], A[1, 2], A[1, 3] = -K_D / mass, -1.0 / mass, -1.0 / mass
    A[2, 1], A[2, 2], A[2, 4] = EA / L, -v / L, (EA - T_SET) * R / L
    A[3, 1], A[3, 2], A[3, 3], A[3, 4] = EA / L, v / L, -v / L, -(EA - T_SET) * R / L
    A[4, 2], A[4, 3] = -R / J, R / J
    lam = np.linalg.eig(A)[0]
    # the carriage's eigenvalue: the pair whose eigenvector moves the carriage most
    w, V = np.linalg.eig(A)
    share = mass * np.abs(V[1]) ** 2 / (mass * np.abs(V[1]) ** 2 + J * np.abs(V[4]) ** 2)
    ref = lam[int(np.argmax(np.where(w.imag > 0, share, -1.0)))]
    assert m.frequency == pytest.approx(ref.imag / (2 * math.pi), rel=1e-14)
    assert m.damping_ratio == pytest.approx(-ref.real / abs(ref), rel=3e-13)
    assert m.damping_ratio == pytest.approx(4.2e-3, rel=0.01)


# ---- the shipped line against an independent small-signal model -----------------------
def _line_model(data: dict[str, Any], r: float, brake: float | None
                ) -> tuple[np.ndarray, list[str]]:
    """The linearised line of ``data`` (the shipped scene's dict) with the parent at
    radius ``r`` [m]: states ``ω_parent, ω_roller…, d, ḋ, T_0…T_4`` and, under
    ``dancer_control``, its integral ``I`` (``brake`` None), else a constant drive torque
    ``brake`` [N m]. Written from machines.md §11 and forces/dancer_control.py's law,
    nothing of winder's but the numbers of the scene."""
    rolls = {x["name"]: x for x in data["roll"]}
    p = rolls["parent"]
    rollers = data["idler"]
    spans = data["web"]["span"]
    v_end = next(d for d in data["drum"] if d["name"] == "rear")["drive"]["web_speed"]
    k_paper = math.pi * data["paper"]["density"] * p["width"]
    h = data["paper"]["caliper"]
    Jp = p["core_inertia"] + 0.5 * k_paper * (r**4 - p["core_radius"] ** 4)
    dancer = next(x for x in rollers if "dancer" in x)
    car = dancer["dancer"]
    m_d, k_d, c_d, F = car["mass"] + dancer["mass"], car["stiffness"], car["damping"], \
        car["load"]
    ea = [s["EA"] for s in spans]
    t_in = spans[0]["T_in"]
    n, nr = len(spans), len(rollers)
    # the steady line: u_i (1 − ε_i) = Q (u_i the speed at span i's downstream end), each
    # roller's tension rise its drag / R; the carriage at d = 0 (dancer_control:
    # T_up + T_down = F) or in balance under the brake (J ω̇ = τ + r T_0 with the constant
    # surface speed's ω̇ = h ω² / (2π r))
    T = np.full(n, 1000.0)
    d = 0.0
    for _ in range(200):
        Q = v_end * (1.0 - T[-1] / ea[-1])
        u = Q / (1.0 - T / np.array(ea))
        w = [u[i] / rollers[i]["radius"] for i in range(nr)]
        drag = [(x["bearing_viscous"] * w[i] + x["bearing_coulomb"] * math.tanh(w[i] / 0.1))
                / x["radius"] for i, x in enumerate(rollers)]
        j = rollers.index(dancer)
        if brake is None:
            T[j] = (F - drag[j]) / 2.0
        else:
            u_p = Q / (1.0 - t_in / ea[0])
            T[0] = (Jp * h * (u_p / r) ** 2 / (2.0 * math.pi * r) - brake) / r
            for i in range(j):
                T[i + 1] = T[i] + drag[i]
        for i in range(j, n - 1):
            T[i + 1] = T[i] + drag[i]
        for i in range(j - 1, -1, -1):
            T[i] = T[i + 1] - drag[i]
        if brake is not None:
            d = (F - T[j] - T[j + 1]) / k_d
    u_p = Q / (1.0 - t_in / ea[0])
    names = ["w_p", *[f"w_{x['name']}" for x in rollers], "d", "d_dot",
             *[f"T{i}" for i in range(n)]] + ([] if brake is not None else ["I"])
    ix = {s: i for i, s in enumerate(names)}
    A = np.zeros((len(names), len(names)))
    for i, x in enumerate(rollers):  # J ω̇ = R (T_down − T_up) − c_v ω − τ_c tanh(ω/0.1)
        row, R, J = ix[f"w_{x['name']}"], x["radius"], x["inertia"]
        A[row, ix[f"T{i + 1}"]] += R / J
        A[row, ix[f"T{i}"]] -= R / J
        A[row, row] -= (x["bearing_viscous"] + x["bearing_coulomb"] / 0.1
                        * (1.0 - math.tanh(w[i] / 0.1) ** 2)) / J
    A[ix["d"], ix["d_dot"]] = 1.0  # m d̈ = F − k d − c ḋ − (T_up + T_down)
    A[ix["d_dot"], [ix["d"], ix["d_dot"]]] = -k_d / m_d, -c_d / m_d
    A[ix["d_dot"], [ix[f"T{j}"], ix[f"T{j + 1}"]]] = -1.0 / m_d
    for i, s in enumerate(spans):  # L Ṫ = EA (v2 − v1 + L̇) + v1 T_{i−1} − v2 T_i
        row, length = ix[f"T{i}"], s["length"] + (d if i in (j, j + 1) else 0.0)
        v1 = u_p if i == 0 else u[i - 1]
        t_up = t_in if i == 0 else T[i - 1]
        if i < n - 1:  # ∂/∂v2 (a roller's surface R ω)
            A[row, ix[f"w_{rollers[i]['name']}"]] += (ea[i] - T[i]) * rollers[i]["radius"] \
                / length
        up = ("w_p", r) if i == 0 else (f"w_{rollers[i - 1]['name']}", rollers[i - 1]["radius"])
        A[row, ix[up[0]]] += -(ea[i] - t_up) * up[1] / length
        if i > 0:
            A[row, ix[f"T{i - 1}"]] += v1 / length
        A[row, row] -= u[i] / length
        if i in (j, j + 1):
            A[row, ix["d_dot"]] += ea[i] / length
    wp = ix["w_p"]
    if brake is None:  # J ω̇ = J ω̇_ref − r T_0 − k_p d − k_i I − k_d ḋ + r T_0
        wc = p["drive"]["bandwidth"]
        g = r / (2.0 * Jp)
        A[wp, ix["d"]], A[wp, ix["I"]], A[wp, ix["d_dot"]] = \
            -3 * wc**2 / g / Jp, -wc**3 / g / Jp, -3 * wc / g / Jp
        # ω̇_ref = −v ṙ / r², v = R ω_guide1, ṙ = −h ω / (2π)
        R1 = rollers[0]["radius"]
        A[wp, ix[f"w_{rollers[0]['name']}"]] += R1 * h * (u_p / r) / (2 * math.pi * r * r)
        A[wp, wp] += u[0] * h / (2 * math.pi * r * r)
        A[ix["I"], ix["d"]] = 1.0
    else:  # J ω̇ = τ + r T_0
        A[wp, ix["T0"]] = r / Jp
    return A, names


def _shipped(brake: bool) -> tuple[dict[str, Any], winder.Scene]:
    data = winder.load_scene(MODEL).to_dict()
    if brake:  # a constant brake holding the first span near 1000 N at r = 1 m
        parent = next(x for x in data["roll"] if x["name"] == "parent")
        parent["drive"] = {"kind": "torque", "torque": -1000.0}
    return data, winder.scene_from_dict(copy.deepcopy(data), source=str(MODEL))


@pytest.mark.parametrize("brake", [False, True], ids=["dancer_control", "brake"])
def test_line_modes_against_the_parent_radius(brake: bool) -> None:
    """The map over the parent's radius (the set at its initial radius) at a full
    (1.25 m) and an empty (0.45 m) parent: every line mode that oscillates is an
    eigenvalue of the independent model, and ``dancer.carriage`` is its oscillating mode
    in which the carriage has the largest share of the kinetic energy. Under
    ``dancer_control`` the tension's torque on the parent and its feed-forward cancel and
    the gains follow ``J(r)``: the modes stay put as the parent empties; under a brake
    the parent's ``J/r²`` rides on the first span: its mode on the dancer's spring (0.12 Hz
    full, 0.25 Hz empty) moves with the diameter. Measured: 3.7e-13 relative at most (the
    slow loop mode; the others 4e-16 … 6e-15)."""
    data, scene = _shipped(brake)
    radii = np.array([0.45, 1.25])
    mm = winder.mode_map(scene, radii, roll="parent")
    assert mm.unwinding and mm.roll == "parent"
    worst = 0.0
    for i, r in enumerate(radii):
        A, names = _line_model(data, float(r), -1000.0 if brake else None)
        w, V = np.linalg.eig(A)
        for c in mm.line_shown:
            f, z = mm.line[c][i], mm.line_damping[c][i]
            if not f > 0:
                continue
            lam = complex(-z * 2 * math.pi * f / math.sqrt(1 - z * z), 2 * math.pi * f)
            err = float(np.min(np.abs(w - lam)) / abs(lam))
            worst = max(worst, err)
            assert err < 5e-12, (c, r, lam, w)
        kin = np.vstack([m_ * np.abs(V[names.index(s)]) ** 2
                         for s, m_ in _masses(data, float(r))])
        share = kin[-1] / kin.sum(axis=0)  # the carriage's share of the kinetic energy
        car = w[int(np.argmax(np.where(w.imag > 1e-6, share, -1.0)))]
        assert mm.line["dancer.carriage"][i] == pytest.approx(car.imag / (2 * math.pi),
                                                               rel=1e-12)
    assert worst < 5e-12
    f = mm.line["dancer.carriage"]
    if not brake:  # the scheduled loop: the same modes at every radius
        assert f[0] == pytest.approx(f[1], rel=1e-4)


def _masses(data: dict[str, Any], r: float) -> list[tuple[str, float]]:
    """The kinetic weights ``(state, J or m)``: the parent, the rollers, the carriage last."""
    p = next(x for x in data["roll"] if x["name"] == "parent")
    k_paper = math.pi * data["paper"]["density"] * p["width"]
    Jp = p["core_inertia"] + 0.5 * k_paper * (r**4 - p["core_radius"] ** 4)
    out = [("w_p", Jp)] + [(f"w_{x['name']}", x["inertia"]) for x in data["idler"]]
    car = next(x for x in data["idler"] if "dancer" in x)
    return out + [("d_dot", car["dancer"]["mass"] + car["mass"])]


def test_modes_cli_over_the_parent(tmp_path) -> None:
    """``winder modes --roll parent``: the table's dancer column is the map's; a roll that
    is neither the wound nor an unwinding roll is refused (exit 2, naming it)."""
    csv = tmp_path / "line.csv"
    assert main(["modes", str(MODEL), "--roll", "parent", "--points", "3", "--csv",
                 str(csv)]) == 0
    table = np.genfromtxt(csv, delimiter=",", names=True)
    mm = winder.mode_map(winder.load_scene(MODEL), roll="parent", n=3)
    np.testing.assert_allclose(table["radius"], mm.radius, rtol=1e-9)
    np.testing.assert_allclose(table["dancer_carriage_frequency"],
                               mm.line["dancer.carriage"], rtol=1e-9)
    assert mm.radius[0] == pytest.approx(0.4) and mm.radius[-1] == pytest.approx(1.25)
    with pytest.raises(winder.ArgumentError, match="roll = 'guide1'.*'parent'"):
        winder.mode_map(winder.load_scene(MODEL), roll="guide1", n=3)
    assert main(["modes", str(MODEL), "--roll", "rider", "--points", "3"]) == 2


def test_line_map_figure_draws_the_map(tmp_path, monkeypatch) -> None:
    """The line map's figure draws each oscillating line mode's frequencies over the
    parent's radius and the parent's rotation ``k v / (2π r)``, legend beside the chart."""
    import winder.plots.figures as _plots
    from winder.plots.campbell import campbell_figure

    mm = winder.mode_map(winder.load_scene(MODEL), roll="parent", n=4)
    drawn: dict[str, np.ndarray] = {}
    save = _plots._save

    def capture(fig, path: Path) -> Path:
        drawn.update({ln.get_label(): np.asarray(ln.get_ydata(), float)
                      for ln in fig.axes[0].get_lines()})
        drawn["legends"] = np.array([len(fig.legends)])
        return save(fig, path)

    monkeypatch.setattr(_plots, "_save", capture)
    campbell_figure(mm, tmp_path / "line.png", title="line")
    for c in mm.line_shown:
        np.testing.assert_array_equal(drawn[f"line mode {c} (damped)"], mm.line[c])
    for k in (1, 2, 3):
        label = f"{k}× rotation of parent (unwinding) at 41.7 m/s"
        np.testing.assert_allclose(drawn[label], k * 41.7 / (2 * np.pi * mm.radius),
                                   rtol=1e-12)
    assert drawn["legends"][0] == 1  # the figure's legend, beside the chart
