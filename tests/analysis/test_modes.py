"""Linearisation (the exact Jacobian against finite differences), the bounce modes against
closed forms (√(k/m) on one drum, the valley stiffnesses of a set on two drums), the
crossing radii against independently computed roots, and the resonance map against a
simulation through a crossing."""

from __future__ import annotations

import math
import re
import subprocess
import sys

import matplotlib.pyplot as plt
import numpy as np
import pytest
from scipy.optimize import brentq

import winder
from winder.analysis.linearise import jacobian
from winder.analysis.modes import mode_map, modes_at, operating_point
from winder.model.mass_law import paper_roll_mass
from winder.solve.system import MachineSystem

# central-difference steps by the kind of state (its name's ending)
STEPS = {".x": 1e-8, ".z": 1e-8, ".theta": 1e-6, "_dot": 1e-6, "theta_dot": 1e-5,
         ".radius": 1e-7, ".friction": 1e-2}


def _step(name: str) -> float:
    return max((len(k), h) for k, h in STEPS.items() if name.endswith(k))[1]


def _variants(paper_scene, models_dir):
    return {
        "paper": paper_scene,
        "no_variable_mass": paper_scene.replace(effects={"variable_mass": False}),
        "steady_friction": paper_scene.replace(effects={"slip_relaxation": False}),
        "no_web": paper_scene.replace(effects={"web_momentum": False}),
        "torque_drive": paper_scene.replace(drum={"drive": {"kind": "torque",
                                                            "web_speed": 5.0}}),
        "hunt_crossley": paper_scene.replace(contact={"law": "hunt_crossley",
                                                      "stiffness": 5e9, "exponent": 1.5,
                                                      "hc_damping": 0.3}),
        "two_drum": winder.load_scene(models_dir / "two_drum_winder.toml"),
    }


@pytest.mark.parametrize("name", ["paper", "no_variable_mass", "steady_friction", "no_web",
                                  "torque_drive", "hunt_crossley", "two_drum"])
def test_jacobian_matches_finite_differences(paper_scene, models_dir, name) -> None:
    """``winder.jacobian`` (the generated exact Jacobian) against central differences of
    ``MachineSystem.rhs`` at random states in contact (measured: ≤ 3e-7 of each row's
    largest entry, beyond the difference quotient's round-off)."""
    scene = _variants(paper_scene, models_dir)[name]
    system = MachineSystem(scene)
    if name == "torque_drive":
        system.set_input("drum.torque", 150.0)
    rng = np.random.default_rng(5)
    y0 = system.initial_state()
    names = system.state_names
    for _ in range(6):
        y = y0.copy()
        for k, s in enumerate(names):
            if s.endswith((".x", ".z")):
                y[k] += rng.uniform(-1e-6, 1e-6) - (3e-6 if s.endswith(".z") else 0.0)
            elif s.endswith("theta"):
                y[k] = rng.uniform(-3, 3)
            elif s.endswith(("x_dot", "z_dot")):
                y[k] = rng.normal(0, 0.01)
            elif s.endswith("theta_dot"):
                y[k] = rng.uniform(5, 100) * (-1 if "roll" in s or "set" in s else 1)
            elif s.endswith(".radius"):
                y[k] = rng.uniform(max(y0[k], 0.08), 0.3)  # deeper in contact
            elif s.endswith(".friction"):
                y[k] += rng.normal(0, 10)
        t = rng.uniform(0, 60)
        J = jacobian(system, t, y)
        fd = np.empty_like(J)
        for k, state in enumerate(names):
            h = _step(state)
            yp, ym = y.copy(), y.copy()
            yp[k] += h
            ym[k] -= h
            fd[:, k] = (system.rhs(t, yp) - system.rhs(t, ym)) / (2 * h)
        # relative to each row's largest entry, plus the round-off of the difference
        # quotient (64 ε |f_i| / h_k)
        scale = np.max(np.abs(fd), axis=1, keepdims=True) + 1e-12
        f = np.abs(system.rhs(t, y))[:, None]
        h = np.array([_step(s) for s in names])[None, :]
        bound = 3e-6 * scale + 64 * np.finfo(float).eps * np.maximum(f, 1.0) / h
        worst = np.max(np.abs(J - fd) / bound)
        assert worst <= 1.0, (worst, np.unravel_index(np.argmax(np.abs(J - fd) / bound),
                                                      J.shape))


def test_single_dof_frequency_is_sqrt_k_over_m(paper_scene) -> None:
    """Undamped linear nip, drum at rest: the bounce mode is ±i√(k/m) (measured 2e-16)."""
    k = 3.7e6
    scene = paper_scene.replace(contact={"stiffness": k, "damping": 0.0},
                                drum={"drive": {"web_speed": 0.0}})
    ro = scene.roll
    for r in (0.075, 0.3, 0.7):
        m = paper_roll_mass(r, ro.core_radius, ro.core_mass, ro.core_inertia,
                            math.pi * scene.paper.density * ro.width)[0]
        bounce = modes_at(scene, r, web_speed=0.0)[0]
        assert (bounce.kind, bounce.coordinate) == ("bounce", "roll.z")
        assert bounce.frequency == pytest.approx(math.sqrt(k / m) / (2 * math.pi), rel=1e-12)
        assert abs(bounce.damping_ratio) < 1e-12


def test_damped_bounce_mode(paper_scene) -> None:
    """Linear nip with damping, drum at rest: λ = −c/2m ± i√(k/m − (c/2m)²) (measured
    4e-16)."""
    k, c = 2e7, 2e4
    scene = paper_scene.replace(drum={"drive": {"web_speed": 0.0}})
    ro = scene.roll
    m = paper_roll_mass(0.3, ro.core_radius, ro.core_mass, ro.core_inertia,
                        math.pi * scene.paper.density * ro.width)[0]
    lam = modes_at(scene, 0.3, web_speed=0.0)[0].eigenvalue
    assert lam.real == pytest.approx(-c / (2 * m), rel=1e-9)
    assert abs(lam.imag) == pytest.approx(math.sqrt(k / m - (c / (2 * m)) ** 2), rel=1e-9)


def _valley_scene(models_dir, tmp_path, *, rider: bool = False, mu: float = 1e-12,
                  damping: float = 0.0) -> winder.Scene:
    """The two-drum winder (optionally without its rider), undamped nips, (almost) no
    friction, no web tension."""
    text = (models_dir / "two_drum_winder.toml").read_text()
    if not rider:
        text = re.sub(r"(?s)\[\[rider\]\].*?(?=\[\[nip\]\])", "", text)
        text = re.sub(r'(?s)\[\[nip\]\]\nname = "rider_nip".*?(?=\[web\])', "", text)
    text = re.sub(r"damping = 1\.5e4", f"damping = {damping!r}", text)
    text = re.sub(r"mu = 0\.35", f"mu = {mu!r}", text)
    text = re.sub(r"(?m)^tension = .*$", "tension = 0.0", text)
    path = tmp_path / "valley.toml"
    path.write_text(text)
    return winder.load_scene(path)


def test_two_drum_valley_stiffness(models_dir, tmp_path) -> None:
    """The set alone in the valley of two drums at rest, undamped linear nips: its ``x``
    and ``z`` modes are √(k_x/m), √(k_z/m) with the valley stiffnesses of the geometry,
    ``k_z = 2 (k cos²α − (F_n/d) sin²α)``, ``k_x = 2 (k sin²α − (F_n/d) cos²α)``
    (``α`` the angle of the nip normal from the vertical, ``d`` the centre distance,
    ``F_n = m g / (2 cos α)`` the preload turning with the normal). Measured 3e-13
    (without the preload term the frequencies are 1e-4 … 2.5e-4 lower)."""
    scene = _valley_scene(models_dir, tmp_path)
    k, g = 2.5e7, scene.scene.gravity
    ro = scene.rolls[0]
    for r in (0.05, 0.2, 0.6):
        m = paper_roll_mass(r, ro.core_radius, ro.core_mass, ro.core_inertia,
                            math.pi * ro.density * ro.width)[0]
        system, t, y = operating_point(scene, r, web_speed=0.0)
        x, z = y[system.index("set.x")], y[system.index("set.z")]
        assert abs(x) < 1e-12  # symmetric
        d = math.hypot(0.525, z)
        ca, sa = z / d, 0.525 / d
        fn = m * g / (2 * ca)
        assert 0.5 + r - d == pytest.approx(fn / k, rel=1e-11)  # the balance: 9e-13
        kz = 2 * (k * ca**2 - fn / d * sa**2)
        kx = 2 * (k * sa**2 - fn / d * ca**2)
        modes = {mo.coordinate: mo for mo in modes_at(scene, r, web_speed=0.0)
                 if mo.kind == "bounce"}
        assert set(modes) == {"set.x", "set.z"}
        assert modes["set.z"].frequency == pytest.approx(math.sqrt(kz / m) / (2 * math.pi),
                                                         rel=3e-12)
        assert modes["set.x"].frequency == pytest.approx(math.sqrt(kx / m) / (2 * math.pi),
                                                         rel=3e-12)


def test_two_drum_rider_modes_are_the_two_mass_chain(models_dir, tmp_path) -> None:
    """Set and rider stacked in the valley at rest (undamped, frictionless): the vertical
    modes are those of the chain ground–k_z–set–k–rider, ``det(K − ω² M) = 0`` with the
    set's valley stiffness ``k_z`` and the rider nip's ``k`` less its preload over the
    distance (it stands vertically above: no such term). Measured 3e-14."""
    scene = _valley_scene(models_dir, tmp_path, rider=True)
    k, g = 2.5e7, scene.scene.gravity
    ro, rider = scene.rolls[0], scene.riders[0]
    r = 0.4
    m = paper_roll_mass(r, ro.core_radius, ro.core_mass, ro.core_inertia,
                        math.pi * ro.density * ro.width)[0]
    system, t, y = operating_point(scene, r, web_speed=0.0)
    ch = system.channels(np.array([t]), y[:, None])
    load = ch["rider_nip_normal_force"][0]  # rider weight + its line load
    z = y[system.index("set.z")]
    d = math.hypot(0.525, z)
    ca, sa = z / d, 0.525 / d
    fn = (m * g + load) / (2 * ca)
    kz = 2 * (k * ca**2 - fn / d * sa**2)
    M = np.diag([m, rider.mass])
    K = np.array([[kz + k, -k], [-k, k]])
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    modes = {mo.coordinate: mo.frequency for mo in modes_at(scene, r, web_speed=0.0)
             if mo.kind == "bounce"}
    got = np.sort([modes["set.z"], modes["rider.z"]])
    np.testing.assert_allclose(got, np.sqrt(w2) / (2 * math.pi), rtol=1e-12)


def test_two_drum_crossings_are_roots(models_dir) -> None:
    """``winder modes`` on the two-drum winder: the printed crossings of the rotation
    harmonics with the bounce modes are the roots (brentq on :func:`modes_at`, radius by
    radius) of ``f_mode(r) − k v/(2π r)``; the CSV holds every mode and the drums'
    rotation. Measured: within 7.5e-6 m of the roots (150 radii, linear interpolation),
    printed to 0.1 mm."""
    import tempfile
    from pathlib import Path

    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "m.csv"
        proc = subprocess.run([sys.executable, "-m", "winder", "modes",
                               str(models_dir / "two_drum_winder.toml"), "--csv", str(csv)],
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr
        table = np.genfromtxt(csv, delimiter=",", names=True)
    v = 41.7
    r = table["radius"]
    # wound from the core to the end of the run: ramp 0 → v at 0.7 m/s², then full speed
    length = v * scene.scene.duration - v * v / (2 * 0.7)
    # (the CSV holds 10 significant digits)
    assert r[-1] == pytest.approx(math.sqrt(0.05**2 + 70e-6 * length / math.pi), rel=1e-9)
    np.testing.assert_allclose(table["front_rotation"], v / (2 * math.pi * 0.5), rtol=1e-9)
    np.testing.assert_allclose(table["rotation_1x"], v / (2 * math.pi * r), rtol=1e-9)
    np.testing.assert_array_equal(table["bounce_frequency"], table["set_z_frequency"])
    checked = 0
    for coord, order in (("set.z", 2), ("rider.z", 1), ("rider.z", 0)):
        h = f"{order}x" if order else "drum front/rear"
        line = re.search(rf"{h} rotation meets the bounce mode {coord} at r = (.*)",
                         proc.stdout)
        assert line, proc.stdout
        printed = [float(x) for x in re.findall(r"([0-9.]+) m", line.group(1))]
        key = coord.replace(".", "_") + "_frequency"

        def g(x: float, coord: str = coord, order: int = order) -> float:
            f = next(mo.frequency for mo in modes_at(scene, x) if mo.coordinate == coord)
            return f - (order * v / (2 * math.pi * x) if order else v / (2 * math.pi * 0.5))

        for p in printed:
            i = int(np.searchsorted(r, p))
            root = brentq(g, r[i - 1], r[i], xtol=1e-12)
            assert p == pytest.approx(root, abs=2e-4), (coord, order, p, root)
            checked += 1
        assert np.all(np.isfinite(table[key]))
    assert checked == 3


# rows of docs/modes.csv as the old engine (WinderSystem, Pinocchio ABA derivatives and the
# chain rule) computed them: radius, bounce frequency, bounce damping, slip frequency
OLD_ENGINE = [(0.075, 118.6207248, 0.4083809894, 11.08219036),
              (0.3083735839, 32.32690786, 0.1021179, 20.01979164),
              (0.8477258667, 11.83151253, 0.03720506771, 19.99404028)]


def test_single_drum_scene_keeps_the_old_numbers(models_dir) -> None:
    """The paper scene on the new engine gives the old engine's resonance map: bounce
    frequency and damping to 1.5e-9 and 7.8e-8 (measured over all 150 rows), the slip mode
    to 5.7e-4 at the core (the old operating point iterated the slip 4 times; 3e-9 beyond
    r = 0.1 m)."""
    scene = winder.load_scene(models_dir / "paper_winding.toml")
    r, f, z, slip = np.array(OLD_ENGINE).T
    mm = mode_map(scene, r)
    np.testing.assert_allclose(mm.bounce_frequency, f, rtol=2e-8)
    np.testing.assert_allclose(mm.bounce_damping, z, rtol=1e-6)
    np.testing.assert_allclose(mm.slip_frequency[0], slip[0], rtol=6e-3)
    np.testing.assert_allclose(mm.slip_frequency[1:], slip[1:], rtol=3e-7)
    np.testing.assert_array_equal(mm.slip_damping, 1.0)



def test_mode_map_reports_each_radius_and_the_same_map(paper_scene) -> None:
    """``progress`` (the CLI's bar over a map's radii) is called before the first radius and
    once after each, in order, with the total, and changes nothing of the map (the oracle:
    the map without it)."""
    calls: list[tuple[int, int]] = []
    mm = mode_map(paper_scene, n=6, progress=lambda done, total: calls.append((done, total)))
    assert calls == [(k, 6) for k in range(7)]
    ref = mode_map(paper_scene, n=6)
    np.testing.assert_array_equal(mm.bounce_frequency, ref.bounce_frequency)
    np.testing.assert_array_equal(mm.radius, ref.radius)

def _crossing_scene(paper_scene) -> winder.Scene:
    """A heavy core on a soft nip at a constant 15 m/s: the roll's once-per-revolution
    excitation crosses the bounce mode near r = 0.27 m."""
    return paper_scene.replace(
        roll={"core_mass": 300.0, "com_offset": 2e-5, "initial_speed": 200.0},
        contact={"stiffness": 2e6, "damping": 2000.0},
        drum={"drive": {"web_acceleration": 0.0, "web_speed": 15.0}})


def test_simulated_vibration_peaks_at_predicted_critical_radius(paper_scene) -> None:
    scene = _crossing_scene(paper_scene)
    crit = mode_map(scene, np.linspace(0.075, 0.4, 120)).critical_radii(1)
    assert len(crit) == 1
    res = winder.simulate(scene, t_end=200.0, output_step=2e-3)
    from winder.plots.figures import normal_force_envelope

    r, lo, hi, amp = normal_force_envelope(res, window=0.5)
    assert np.all(lo > 0)  # stays in contact: the linear picture applies
    r_peak = r[np.argmax(amp[2:]) + 2]
    assert r_peak == pytest.approx(crit[0], rel=0.02)
    assert np.max(amp) > 3 * np.median(amp)  # a real resonance peak


def _bounce_closed_form(scene: winder.Scene, r: np.ndarray) -> np.ndarray:
    """Damped bounce frequency [Hz] of the roll's mass on the linear nip, from the scene's
    numbers alone: √(k/m − (c/2m)²)/2π with m(r) = m_core + ρπL(r² − r_c²) (spec §2, §4)."""
    ro, k, c = scene.roll, scene.contact.stiffness, scene.contact.damping
    m = ro.core_mass + scene.paper.density * math.pi * ro.width * (r**2 - ro.core_radius**2)
    return np.sqrt(k / m - (c / (2 * m)) ** 2) / (2 * math.pi)


def test_modes_cli_against_closed_forms(models_dir, tmp_path) -> None:
    """``winder modes`` on the paper scene: the table's radii span core to the no-slip
    radius at the end of the run (the drive's ramp included), its bounce frequencies and
    critical web speeds follow the roll's mass on the nip spring, a critical web speed is
    the speed at which the 1× line meets the bounce mode there, and the printed crossing
    radii are the roots of ``k v/(2π r) = f_bounce(r)``."""
    scene = winder.load_scene(models_dir / "paper_winding.toml")
    png, csv = tmp_path / "campbell.png", tmp_path / "modes.csv"
    proc = subprocess.run([sys.executable, "-m", "winder", "modes",
                           str(models_dir / "paper_winding.toml"), "--plot", str(png),
                           "--no-simulate", "--csv", str(csv), "--points", "150"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    table = np.genfromtxt(csv, delimiter=",", names=True)
    assert table.dtype.names == ("radius", "bounce_frequency", "bounce_damping",
                                 "slip_frequency", "slip_damping", "rotation_1x",
                                 "rotation_2x", "critical_web_speed")
    r, v = table["radius"], scene.drum.drive.web_speed
    assert len(r) == 150 and r[0] == scene.roll.core_radius
    # r² − r_c² = h L/π: one caliper per revolution at no slip; L = v T − v²/2a (ramp)
    a = scene.drum.drive.web_acceleration
    length = v * scene.scene.duration - v * v / (2 * a)
    r_end = math.sqrt(r[0] ** 2 + scene.paper.caliper * length / math.pi)
    assert r[-1] == pytest.approx(r_end, rel=1e-9)
    # the coupling with slip and web momentum shifts the bounce mode by 5.4e-5 (measured)
    f = _bounce_closed_form(scene, r)
    np.testing.assert_allclose(table["bounce_frequency"], f, rtol=5e-4)
    np.testing.assert_allclose(table["critical_web_speed"], 2 * np.pi * r * f, rtol=5e-4)
    for i in (20, 60, 149):  # at v_crit the roll turns at the bounce frequency: 2.1e-5
        v_crit = table["critical_web_speed"][i]
        bounce = modes_at(scene, float(r[i]), web_speed=float(v_crit))[0].frequency
        assert v_crit / (2 * np.pi * r[i]) == pytest.approx(bounce, rel=2e-4)
    for k in (1, 2, 3):
        line = re.search(rf"{k}x rotation meets the bounce mode at r = (.*)", proc.stdout)
        assert line, proc.stdout
        printed = [float(x) for x in re.findall(r"([0-9.]+) m", line.group(1))]
        g = lambda x, k=k: k * v / (2 * math.pi * x) - _bounce_closed_form(scene, x)  # noqa: E731
        grid = np.linspace(r[0], r[-1], 4000)
        s = np.sign(g(grid))
        roots = [brentq(g, grid[j], grid[j + 1], xtol=1e-14)
                 for j in np.nonzero(s[:-1] * s[1:] < 0)[0]]
        assert len(printed) == len(roots), (k, printed, roots)
        # printed to 0.1 mm; measured 3.3e-5 m from the root (3x: 0.1160 against 0.11597)
        np.testing.assert_allclose(printed, roots, rtol=0, atol=3e-4)
    # the drum turns at v/2πR = 6.4 Hz, below the bounce mode's 12 Hz at the end
    assert [len(re.findall(r"[0-9.]+ m", ln)) for ln in proc.stdout.splitlines()
            if "rotation meets" in ln] == [0, 0, 1, 0]
    assert "drum rotation meets the bounce mode at r = (no crossing)" in proc.stdout
    image = plt.imread(png)
    assert image.shape[0] > 300 and image.shape[1] > 400 and np.ptp(image[..., :3]) > 0.5


@pytest.mark.parametrize("call, match", [
    (lambda s: modes_at(s, -1.0), r"operating_point: radius = -1.0 is out of range; valid: "
                                  r"a finite radius >= \[roll\] core_radius = 0.075 m"),
    (lambda s: modes_at(s, math.nan), r"radius = nan is out of range"),
    (lambda s: modes_at(s, 0.07), r"radius = 0.07 is out of range"),
    (lambda s: modes_at(s, 0.3, web_speed=-1.0), r"web_speed must be >= 0 m/s and <= 1000 "
                                                 r"m/s, got -1.0"),
    (lambda s: modes_at(s, 0.3, web_speed=math.nan), r"web_speed must be finite, got nan"),
    (lambda s: mode_map(s, n=0), r"mode_map: n = 0 is out of range; valid: an integer 2 … "
                                 r"10000"),
    (lambda s: mode_map(s, n=-5), r"n = -5 is out of range"),
    (lambda s: mode_map(s, web_speed=0.0), r"mode_map: web_speed must be > 0 m/s"),
    (lambda s: mode_map(s, web_speed=math.inf), r"web_speed must be finite, got inf"),
    (lambda s: mode_map(s, [0.1, 0.05]), r"radii\[1\] = 0.05 is out of range; valid: finite "
                                         r"radii >= \[roll\] core_radius = 0.075 m"),
    (lambda s: mode_map(s, np.zeros((2, 2))), r"radii must be a 1-D array"),
    (lambda s: mode_map(s, []), r"radii must be a 1-D array of 1 … 10000 radii"),
    (lambda s: mode_map(s.replace(drum={"drive": {"web_speed": 0.0}})),
     r"web_speed is not given and the scene's \[drum.drive\] web_speed is 0.0"),
    (lambda s: operating_point(s.replace(effects={"contact": False,
                                                  "slip_relaxation": False}), 0.3),
     r"needs the nip: \[effects\] contact = false"),
    (lambda s: modes_at(s.replace(effects={"contact": False, "slip_relaxation": False}),
                        0.3), r"modes_at: radius = 0.3 m: .*\[effects\] contact = false.*"
                              r"initial state; valid: no radius"),
    (lambda s: modes_at(s), r"modes_at: radius is required"),
    (lambda s: modes_at(s.replace(effects={"gravity": False}), 0.3),
     r"needs the roll's weight on the nip, but \[effects\] gravity = false"),
    (lambda s: modes_at(s.replace(drum={"drive": {"kind": "torque"}}), 0.3),
     r"needs \[drum.drive\] kind = 'speed_profile'"),
    (lambda s: modes_at(s, 0.075, web_speed=60.0), r"at radius = 0.075 m and web_speed = 60 "
                                                   r"m/s the nip cannot carry the roll's "
                                                   r"torque"),
])
def test_bad_mode_arguments_name_the_argument(paper_scene, call, match) -> None:
    with pytest.raises(winder.ArgumentError, match=match):
        call(paper_scene)


def test_parts_scene_errors_name_the_part(models_dir, tmp_path) -> None:
    scene = winder.load_scene(models_dir / "two_drum_winder.toml")
    with pytest.raises(winder.ArgumentError, match=r"radius = 0.04 is out of range; valid: a "
                       r"finite radius >= \[\[roll\]\] 'set' core_radius = 0.05 m"):
        modes_at(scene, 0.04)
    text = (models_dir / "two_drum_winder.toml").read_text()
    path = tmp_path / "torque.toml"
    path.write_text(text.replace('drive = { kind = "speed_profile", web_acceleration = 0.7, '
                                 'web_speed = 41.7 }  # [m/s², m/s]',
                                 'drive = { kind = "torque", web_speed = 41.7 }', 1))
    torque = winder.load_scene(path)
    with pytest.raises(winder.ArgumentError, match=r"needs \[\[drum\]\] 'front' drive kind = "
                       r"'speed_profile'.*got 'torque'"):
        mode_map(torque)


def test_wrong_argument_types(paper_scene) -> None:
    with pytest.raises(winder.ArgumentTypeError, match="scene must be a winder.Scene"):
        modes_at("models/paper_winding.toml", 0.3)
    with pytest.raises(winder.ArgumentTypeError, match="n must be an integer, got 2.5"):
        mode_map(paper_scene, n=2.5)
    with pytest.raises(winder.ArgumentTypeError, match="web_speed expected a number"):
        mode_map(paper_scene, web_speed="fast")
    system = MachineSystem(paper_scene)
    with pytest.raises(winder.ArgumentTypeError, match="jacobian: system must be a "
                       "MachineSystem"):
        jacobian(paper_scene, 0.0, np.zeros(6))
    with pytest.raises(winder.ArgumentError, match=r"jacobian: y must be 6 finite values "
                       r"\(roll.z, roll.theta, "):
        jacobian(system, 0.0, np.zeros(5))
    with pytest.raises(winder.ArgumentError, match="jacobian: y must be 6 finite values"):
        jacobian(system, 0.0, np.full(6, np.nan))
    with pytest.raises(winder.ArgumentTypeError, match="jacobian: y must be an array of 6 "):
        jacobian(system, 0.0, ["a"] * 6)
    with pytest.raises(winder.ArgumentError, match="jacobian: t must be finite, got nan"):
        jacobian(system, math.nan, system.initial_state())


def test_frictionless_nip_has_no_mode_map(models_dir, tmp_path) -> None:
    """μ = 0: the drum cannot drive the roll, so there is no winding operating point (and no
    slip mode): ``winder modes`` exits 2 naming [friction] mu, and writes nothing."""
    text = (models_dir / "paper_winding.toml").read_text()
    scene_file = tmp_path / "frictionless.toml"
    scene_file.write_text(re.sub(r"(?m)^mu = .*$", "mu = 0.0", text))
    scene = winder.load_scene(scene_file)
    assert scene.friction.mu == 0.0
    with pytest.raises(winder.ArgumentError, match=r"\[friction\] mu = 0: without friction"):
        modes_at(scene, 0.3)
    proc = subprocess.run([sys.executable, "-m", "winder", "modes", str(scene_file), "--csv",
                           str(tmp_path / "m.csv"), "--points", "5"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert str(scene_file) in proc.stderr and "[friction] mu = 0" in proc.stderr
    assert not (tmp_path / "m.csv").exists()


def test_exact_jacobian_in_implicit_methods(models_dir) -> None:
    """BDF with the generated exact Jacobian solves the same problem as with finite
    differences (to the tolerance)."""
    scene = winder.load_scene(models_dir / "paper_winding_smooth.toml")
    kw = {"t_end": 5.0, "output_step": 0.5, "method": "BDF", "rtol": 1e-8, "atol": 1e-10}
    a = winder.simulate(scene, jacobian="exact", **kw)
    b = winder.simulate(scene, jacobian="fd", **kw)
    for k in ("radius", "roll_speed", "z", "normal_force"):
        np.testing.assert_allclose(a[k], b[k], rtol=1e-5, atol=1e-6 * np.max(np.abs(b[k])))
    with pytest.raises(winder.ArgumentError, match="valid: exact, fd, pinocchio"):
        winder.simulate(scene, t_end=0.1, jacobian="analytic")


def test_contact_off_two_drum_modes_are_free_masses(models_dir, tmp_path) -> None:
    """Issue #32 item 5: the two-drum winder with ``[effects] contact = false`` (``winder
    run`` accepts it): one row at its initial state. Nothing holds the set (free in x, z)
    or the rider (free in z): the rider's rows of the Jacobian vanish (gravity and its load
    are constant: a zero eigenvalue, measured exactly 0); the set's only stiffness is the
    web's pull ``T`` at the nip turning with the line of centres, ``K = T/(m d) · n tᵀ``
    (``n`` along the line of centres to the rear drum, ``d`` = 0.55 m, ``t ⊥ n``):
    ``|K|_F = T/(m d)`` (measured exact), nilpotent (trace and determinant 0: measured 8e-17
    and 9e-17 of ``|K|``, ``|K|²``), so its modes are zero eigenvalues too (round-off splits
    the fourfold root to ``(ε |K|²)^¼``: |λ|/2π = 1.1e-4 Hz, below ``FREE_BELOW`` = 1e-3).
    ``set.x``, ``set.z``, ``rider.z`` are reported free (0 Hz), neither oscillating nor
    overdamped. ``winder modes`` exits 0 with the one row and the map's columns; radii are
    refused."""
    from winder.analysis.modes import FREE_BELOW, _at_rest

    text = (models_dir / "two_drum_winder.toml").read_text()
    text = re.sub(r"(?m)^(contact|slip_relaxation) = true", r"\1 = false", text)
    path = tmp_path / "apart.toml"
    path.write_text(text)
    scene = winder.load_scene(path)
    assert not scene.effects.contact
    lin = _at_rest(scene, "test", None)
    y = lin.initial()
    A = lin.fast_jacobian(y)
    names = [lin.machine.state_names[i] for i in lin.fast]
    acc = [names.index(f"set.{c}_dot") for c in "xz"]
    K = A[np.ix_(acc, [names.index("set.x"), names.index("set.z")])]
    d = math.hypot(y[lin.system.index("set.x")] - 0.525, y[lin.system.index("set.z")])
    norm = 1000.0 / (40.0 * d)  # T / (m d): the core alone at r = r_c
    assert np.linalg.norm(K) == pytest.approx(norm, rel=1e-13)
    assert abs(np.trace(K)) < 1e-15 * norm and abs(np.linalg.det(K)) < 1e-15 * norm ** 2
    assert not np.any(A[names.index("rider.z_dot")])
    ms = modes_at(scene)
    assert ms and all(m.natural_frequency < FREE_BELOW for m in ms)
    bounce = {m.coordinate: m for m in ms if m.kind == "bounce"}
    assert set(bounce) == {"set.x", "set.z", "rider.z"}
    assert bounce["rider.z"].eigenvalue == 0
    mm = mode_map(scene)
    assert mm.initial_state and len(mm.radius) == 1 and mm.radius[0] == 0.05
    for c in ("set.x", "set.z", "rider.z"):
        assert mm.natural[c][0] < FREE_BELOW and mm.overdamped(c) == []
    np.testing.assert_allclose(mm.rotation_1x, 41.7 / (2 * math.pi * 0.05), rtol=1e-12)
    with pytest.raises(winder.ArgumentError, match=r"radii given: .*contact = false"):
        mode_map(scene, [0.1, 0.2])
    csv = tmp_path / "m.csv"
    proc = subprocess.run([sys.executable, "-m", "winder", "modes", str(path), "--csv",
                           str(csv), "--plot", str(tmp_path / "m.png")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "initial state" in proc.stdout and "contact = false" in proc.stdout
    assert "bounce mode set.z 0 Hz: free" in proc.stdout
    table = np.genfromtxt(csv, delimiter=",", names=True)
    assert table.shape == () and table.dtype.names == tuple(mm.as_columns())
    assert table["rider_z_frequency"] == 0.0 and table["radius"] == 0.05
    assert (tmp_path / "m.png").exists()
