"""Operating point and static balance for every scene ``winder run`` accepts (issue #21,
items 1, 2 and 5): the single-drum bounce mode against its closed form for each nip law
with and without slip relaxation, at every radius of a map; ``winder modes`` on a
Hunt–Crossley scene; the two-drum winder with a Hunt–Crossley rider nip starts in static
balance (the rider's penetration against the law's closed form); the refusals of scenes
that have no balance name the key that decides it, exit 2 and leave nothing on disk."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import without_build_lines

import winder
from winder.analysis.modes import _Linearisation, mode_map
from winder.cli import main
from winder.solve.equilibrium import EquilibriumError, resting_state

MODELS = Path(__file__).resolve().parents[2] / "models"
HC = {"law": "hunt_crossley", "stiffness": 1e9, "exponent": 1.5, "hc_damping": 0.3}


def _roll_mass(scene: winder.Scene, r: np.ndarray) -> np.ndarray:
    """m(r) = m_core + ρπL(r² − r_c²) [kg] (winder-model §2)."""
    ro = scene.roll
    return ro.core_mass + scene.paper.density * math.pi * ro.width * (r**2 - ro.core_radius**2)


def _bounce(scene: winder.Scene, r: np.ndarray, v: float, *, growth: bool
            ) -> tuple[np.ndarray, np.ndarray]:
    """Damped bounce frequency [Hz] and damping ratio of the roll's mass on the nip,
    linearised about the static penetration: ``k_eff = ∂F/∂δ``, ``c_eff = ∂F/∂δ̇`` at
    ``F = m g``. ``growth``: at the operating point the nip closes at ``δ̇ = ṙ = h v/2πr``
    (the radius growth) and the variable-mass term adds the damping ``ṁ = 2πρL r ṙ``;
    without it, the issue's formula (``δ̇ = 0``): Hunt–Crossley ``δ₀ = (m g/k)^(1/p)``,
    ``k_eff = p k δ₀^(p−1)``, ``c_eff = α m g``; linear ``k``, ``c``."""
    m, g, c = _roll_mass(scene, r), scene.scene.gravity, scene.contact
    rd = scene.paper.caliper * v / (2 * math.pi * r) if growth else 0.0 * r
    if c.law == "linear":
        ke, ce = c.stiffness + 0.0 * r, c.damping + 0.0 * r
    else:
        gain = 1.0 + c.hc_damping * rd
        d0 = (m * g / (c.stiffness * gain)) ** (1 / c.exponent)
        ke = c.exponent * c.stiffness * d0 ** (c.exponent - 1) * gain
        ce = c.hc_damping * c.stiffness * d0**c.exponent
    if growth:
        ce = ce + 2 * math.pi * scene.paper.density * scene.roll.width * r * rd
    f = np.sqrt(ke / m - (ce / (2 * m)) ** 2) / (2 * math.pi)
    return f, ce / (2 * np.sqrt(ke * m))


@pytest.mark.parametrize("law", ["hunt_crossley", "linear"])
@pytest.mark.parametrize("relaxation", [True, False])
def test_single_drum_bounce_matches_closed_form(law, relaxation) -> None:
    """At every radius of the default map (core to the end of the run, 60 points), the
    bounce mode of the operating point is the closed form of the law linearised about the
    static penetration. The issue's formula (radius growth ignored) holds to 1e-3
    (measured: Hunt–Crossley 6.8e-4, linear 6.6e-5). With the radius growth in the nip's
    rate and the variable-mass damping, the frequency holds to 1e-5 for Hunt–Crossley
    (measured 8e-7) and 2e-4 for the linear law (measured 1.5e-5: the nip's friction couples
    the slip into the bounce), the damping ratio to 1e-3 (measured 1.2e-4)."""
    base = winder.load_scene(MODELS / "paper_winding.toml")
    scene = base.replace(effects={"slip_relaxation": relaxation},
                         **({"contact": HC} if law == "hunt_crossley" else {}))
    mm = mode_map(scene, n=60)
    r, v = mm.radius, mm.web_speed
    assert r[0] == scene.roll.initial_radius and len(r) == 60
    f_issue, _ = _bounce(scene, r, v, growth=False)
    np.testing.assert_allclose(mm.bounce_frequency, f_issue, rtol=1e-3)
    f, zeta = _bounce(scene, r, v, growth=True)
    np.testing.assert_allclose(mm.bounce_frequency, f,
                               rtol=1e-5 if law == "hunt_crossley" else 2e-4)
    np.testing.assert_allclose(mm.bounce_damping, zeta, rtol=1e-3)


def test_modes_cli_on_hunt_crossley_scene(tmp_path) -> None:
    """The issue's command: ``winder modes`` on the paper scene with a Hunt–Crossley nip
    (1e9 N/m, p = 1.5, α = 0.3) exits 0, prints nothing from LAPACK, and its table over
    ``--radius-min``/``--radius-max`` follows the closed form (1e-5; measured 8e-7 over the
    default range)."""
    text = (MODELS / "paper_winding.toml").read_text()
    text = re.sub(r'(?m)^law = "linear"\nstiffness = .*\ndamping = .*$',
                  'law = "hunt_crossley"\nstiffness = 1e9\nexponent = 1.5\nhc_damping = 0.3',
                  text)
    path = tmp_path / "hc.toml"
    path.write_text(text)
    csv = tmp_path / "m.csv"
    proc = subprocess.run([sys.executable, "-m", "winder", "modes", str(path), "--points", "12",
                           "--radius-min", "0.1", "--radius-max", "1.2", "--csv", str(csv)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "DLASCL" not in proc.stdout + proc.stderr
    table = np.genfromtxt(csv, delimiter=",", names=True)
    r = table["radius"]
    np.testing.assert_allclose(r, np.linspace(0.1, 1.2, 12), rtol=1e-9)
    scene = winder.load_scene(path)
    f, _ = _bounce(scene, r, 20.0, growth=True)
    np.testing.assert_allclose(table["bounce_frequency"], f, rtol=1e-5)


def test_radius_range_arguments(paper_scene) -> None:
    """``radius_min``/``radius_max`` set the map's range; bad values name the argument."""
    mm = mode_map(paper_scene, n=3, radius_min=0.2, radius_max=0.4)
    np.testing.assert_allclose(mm.radius, [0.2, 0.3, 0.4], rtol=1e-15)
    mm = mode_map(paper_scene, n=2, radius_max=0.3)
    assert mm.radius[0] == paper_scene.roll.initial_radius and mm.radius[-1] == 0.3
    for kw, match in (({"radius_min": 0.05}, r"radius_min = 0.05 is out of range; valid: "
                                             r"a finite radius >= \[roll\] core_radius"),
                      ({"radius_max": 0.07}, r"radius_max = 0.07 is out of range; valid: a "
                                             r"finite radius > the roll's initial radius"),
                      ({"radius_min": 0.3, "radius_max": 0.2}, r"radius_max = 0.2 is out of "
                                                               r"range; valid: .*> radius_min"),
                      ({"radius_max": 11.0}, r"radius_max = 11.0 is out of range"),
                      ({"radius_min": 2.0}, r"radius_min = 2 m is not below the wound roll's "
                                            r"radius at the end of the run")):
        with pytest.raises(winder.ArgumentError, match=match):
            mode_map(paper_scene, n=2, **kw)
    with pytest.raises(winder.ArgumentError, match="give radii or radius_min/radius_max"):
        mode_map(paper_scene, [0.1, 0.2], radius_max=0.3)


def _two_drum(tmp_path: Path, name: str, **subs: str) -> Path:
    """models/two_drum_winder.toml with text replaced (``old=new`` pairs, regex)."""
    text = (MODELS / "two_drum_winder.toml").read_text()
    for old, new in subs.values():
        text, k = re.subn(old, new, text, count=1)
        assert k == 1, old
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


RIDER_HC = (r'(name = "rider_nip"\na = "set"\nb = "rider"\n)contact = \{[^}]*\}',
            r'\1contact = { law = "hunt_crossley", stiffness = 1e9, exponent = 1.5, '
            r'hc_damping = 0.3 }')


def test_two_drum_rider_hunt_crossley_starts(tmp_path) -> None:
    """The issue's scene: only the rider nip Hunt–Crossley (1e9 N/m) was refused with "no
    static balance for body 'rider'". It starts: the balance's residual is below 1e-6 of
    its largest force (measured 1e-9 N of 5e4 N), the rider carries its weight and line
    load through the nip (vertical balance to 1e-12, measured 4e-14) compressed by the
    law's static penetration ``(F_n/k)^(1/p)`` (1e-13, measured 3e-16), and the
    closed-form start is within 3e-7 m of the solved positions (measured 2.9e-8 m: the
    web tension and the tilt of the rider nip that it leaves out)."""
    path = _two_drum(tmp_path, "rider_hc", rider=RIDER_HC)
    scene = winder.load_scene(path)
    system = winder.MachineSystem(scene)
    eq = system.equilibrium
    assert eq.residual <= 1e-6 * eq.scale
    y = eq.state
    ch = system.channels(np.array([0.0]), y[:, None])
    fn = ch["rider_nip_normal_force"][0]
    rider = scene.riders[0]
    g = scene.scene.gravity
    load = 5.0 * 3000.0  # width × line load at the core (r = 0.05 m)
    set_x, set_z = y[system.index("set.x")], y[system.index("set.z")]
    rider_z = y[system.index("rider.z")]
    nz = (rider_z - set_z) / math.hypot(rider.x - set_x, rider_z - set_z)
    assert fn * nz == pytest.approx(rider.mass * g + load, rel=1e-12)
    assert ch["rider_nip_penetration"][0] == pytest.approx((fn / 1e9) ** (1 / 1.5), rel=1e-13)
    # the start: each nip at its closed-form penetration under the accumulated loads
    m = system.machine
    start = resting_state(m, np.array(m.state_initial), system.params,
                          {"set", "rider"}).state
    for c in ("set.x", "set.z", "rider.z"):
        assert abs(start[m.index(c)] - y[m.index(c)]) < 3e-7, c
    res = winder.simulate(scene, t_end=0.02, output_step=0.01)
    assert np.all(res["rider_nip_normal_force"] > 0)


@pytest.mark.parametrize("label, subs, key", [
    ("drum centres in mm", {"front": (r"centre = \[-0\.525, 0\.0\]", "centre = [-525.0, 0.0]"),
                            "rear": (r"centre = \[0\.525, 0\.0\]", "centre = [525.0, 0.0]")},
     "[[drum]] 'front' centre and [[drum]] 'rear' centre (in metres)"),
    ("front nip stiffness 1e2", {"k": (r"stiffness = 2\.5e7", "stiffness = 1e2")},
     "[[nip]] 'front_nip' contact stiffness is too soft"),
    ("rider nip stiffness 1e2",
     {"k": (r'(name = "rider_nip"\na = "set"\nb = "rider"\ncontact = \{ law = "linear", )'
            r"stiffness = 2\.5e7", r"\1stiffness = 1e2")},
     "[[nip]] 'rider_nip' contact stiffness is too soft"),
    ("rider x = 2.0", {"x": (r"(?m)^x = 0\.0 ", "x = 2.0 ")},
     "check [[rider]] 'rider' x; valid: x between -0.2 and 0.2 m"),
])
def test_no_balance_names_the_key(tmp_path, capsys, label, subs, key) -> None:
    """Scenes without a static balance are refused before anything runs: the Python API
    raises :class:`EquilibriumError` (a ValueError) and ``winder run`` exits 2 naming the
    file and the key (the generic "check its centre" is gone), without a traceback and
    without writing its output."""
    path = _two_drum(tmp_path, "bad", **subs)
    scene = winder.load_scene(path)
    with pytest.raises(EquilibriumError) as info:
        winder.MachineSystem(scene).initial_state()
    assert key in str(info.value) and isinstance(info.value, ValueError)
    out = tmp_path / "r.csv"
    assert main(["run", str(path), "--out", str(out), "--t-end", "0.01"]) == 2
    err = without_build_lines(capsys.readouterr().err)
    assert err.startswith(f"winder: error: {path}: ") and key in err
    assert "Traceback" not in err and "check its centre" not in err
    assert len(err.splitlines()) <= 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_too_soft_nip_refused_by_modes(tmp_path, capsys) -> None:
    """``winder modes`` on a scene whose rider nip is too soft for its load exits 2
    naming that nip's stiffness key (per nip, as ``[contact] stiffness`` for the
    single-drum format), and writes nothing."""
    path = _two_drum(tmp_path, "soft", k=(
        r'(name = "rider_nip"\na = "set"\nb = "rider"\ncontact = \{ law = "linear", )'
        r"stiffness = 2\.5e7", r"\1stiffness = 1e3"))
    csv = tmp_path / "m.csv"
    assert main(["modes", str(path), "--points", "3", "--csv", str(csv)]) == 2
    err = without_build_lines(capsys.readouterr().err)
    assert "[[nip]] 'rider_nip' contact stiffness is too soft" in err
    assert "Traceback" not in err and not csv.exists()


def test_failed_operating_point_names_the_equation(paper_scene) -> None:
    """Where no operating point exists the message names the equation left over and the
    nip whose friction saturates: web momentum without the variable-mass term near the
    core asks the nip for more tangential force than ``μ F_n``."""
    scene = paper_scene.replace(effects={"variable_mass": False, "slip_relaxation": False})
    lin = _Linearisation(scene, 20.0)
    with pytest.raises(winder.ArgumentError,
                       match=r"at radius = 0.0825 m and web_speed = 20 m/s the nip cannot "
                             r"carry the roll's torque and weight: no operating point .*"
                             r"nip 'nip' slips at v_s = .* m/s, its friction saturated at "
                             r"mu F_n = .* N"):
        lin.solve(0.0825, "operating_point")
    lin.solve(0.1, "operating_point")  # further out the nip carries it


def test_two_drum_modes_break_off_where_overdamped(tmp_path) -> None:
    """Issue #21 item 5: in ``two_drum_modes.png`` the set's modes break off near r = 0.17
    and 0.32 m. Every operating point of the map solves; the breaks are the stretches where
    the mode is overdamped (real eigenvalue): at 41.7 m/s the relaxed friction acts on the
    set's tangential motion as a damper of slope ``μ F_n/v_ref`` beyond critical for the
    light set. Checked independently at r = 0.2 m on the exact Jacobian: no oscillating
    eigenpair carries a quarter of its kinetic energy in ``set.x``, while at web speed 0
    (the friction state relaxes at ``v_min/σ``, too slowly to damp) ``set.x`` oscillates.
    ``winder modes`` prints the ranges and the chart marks them."""
    from winder.analysis.linearise import jacobian
    from winder.analysis.modes import modes_at

    path = MODELS / "two_drum_winder.toml"
    scene = winder.load_scene(path)
    mm = mode_map(scene, n=150)
    for c in mm.coordinates:
        assert np.all(np.isfinite(mm.frequencies[c])), c
    (lo_z, hi_z), = mm.overdamped("set.z")
    (lo_x, hi_x), = mm.overdamped("set.x")
    assert 0.13 < lo_z < hi_z < 0.18 and 0.16 < lo_x < 0.2 and 0.3 < hi_x < 0.33
    assert mm.overdamped("rider.z") == []
    inside = (mm.radius >= lo_x) & (mm.radius <= hi_x)
    np.testing.assert_array_equal(mm.dampings["set.x"][inside], 1.0)
    # independently: eigenpairs and kinetic-energy shares at r = 0.2 m
    lin = _Linearisation(scene, 41.7)
    y = lin.solve(0.2, "test")
    A = jacobian(lin.system, lin.t, y)[np.ix_(lin.fast, lin.fast)]
    lam, vec = np.linalg.eig(A)
    nt = len(lin.positions)
    ev = lin.system.evaluate_numeric(lin.t, y, outputs=False)
    masses = np.array([float(ev.bodies[c.split(".")[0]].mass) for c in lin.coords])
    inertias = np.array([float(ev.bodies[b].inertia) for b in ("set", "rider")])
    for i in np.nonzero(lam.imag > 0)[0]:
        kin = np.concatenate([masses * np.abs(vec[nt:2 * nt, i]) ** 2,
                              inertias * np.abs(vec[2 * nt:2 * nt + 2, i]) ** 2])
        assert kin[lin.coords.index("set.x")] / kin.sum() < 0.25, lam[i]
    still = {m.coordinate: m for m in modes_at(scene, 0.2, web_speed=0.0)[:3]}
    assert still["set.x"].frequency > 10.0 and still["set.x"].damping_ratio < 0.5
    csv = tmp_path / "m.csv"
    png = tmp_path / "m.png"
    proc = subprocess.run([sys.executable, "-m", "winder", "modes", str(path), "--points",
                           "150", "--no-simulate", "--csv", str(csv), "--plot", str(png)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert (f"bounce mode set.x is overdamped (real eigenvalue, no oscillation, no crossing) "
            f"at r = {lo_x:.4f}-{hi_x:.4f} m") in proc.stdout
    assert "bounce mode set.z is overdamped" in proc.stdout and png.exists()


def test_states_without_dynamics_drop_out(paper_scene) -> None:
    """A state whose rate is identically zero (here the friction state of the paper
    scene, frozen by wrapping the system, as an effect that is off would leave it) drops
    out of the operating point's unknowns and of the modes. Drum at rest: the operating
    point keeps the friction at its initial value 0 and the roll at rest on the nip, and
    the bounce mode is the damped closed form ``−c/2m ± i√(k/m − (c/2m)²)`` (1e-9,
    measured 4e-16), with no zero eigenvalue of the frozen state among the modes."""
    lin = _Linearisation(paper_scene, 0.0)
    sys_ = lin.system
    i = sys_.index("nip.friction")
    rhs, jac = sys_.rhs, sys_.jac

    def frozen_rhs(t: float, y: np.ndarray) -> np.ndarray:
        f = rhs(t, y)
        f[i] = 0.0
        return f

    def frozen_jac(t: float, y: np.ndarray) -> np.ndarray:
        J = jac(t, y)
        J[i] = 0.0
        return J

    sys_.rhs, sys_.jac = frozen_rhs, frozen_jac
    r = 0.3
    y = lin.solve(r, "test")
    assert lin.idle == ["nip.friction"] and i not in lin.unknowns and i not in lin.fast
    assert y[i] == 0.0
    res, _ = lin._residual(y)
    assert np.max(np.abs(res)) < 1e-9
    modes = lin.modes(y)
    assert len(modes) == 2 and min(abs(m.eigenvalue) for m in modes) > 0
    m = _roll_mass(paper_scene, np.array(r))
    k, c = paper_scene.contact.stiffness, paper_scene.contact.damping
    lam = modes[0].eigenvalue
    assert lam.real == pytest.approx(-c / (2 * m), rel=1e-9)
    assert abs(lam.imag) == pytest.approx(math.sqrt(k / m - (c / (2 * m)) ** 2), rel=1e-9)
