"""The README's numbers script (benchmarks/readme_numbers.py) against made-up results whose
answers are known by construction: band, open shares inside it and over the whole run,
peaks, the tension error at the ramp's ends."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import winder

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def rn():
    spec = importlib.util.spec_from_file_location("readme_numbers",
                                                  ROOT / "benchmarks" / "readme_numbers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _two_drum() -> winder.Result:
    """200 s at 0.01 s. The band is t = 100.00–139.99 s: inside it the front nip is open
    every 4th sample (25 %), the rear every 5th (20 %) from t = 101 s, the rider every 2nd
    (50 %) from t = 100 s; whole run: 4000 of 20 001 samples are in the band."""
    t = np.round(np.arange(20_001) * 0.01, 10)
    n = t.size
    i = np.arange(n)
    radius = 0.05 + 0.55 * t / 200.0
    front = np.full(n, 20e3)
    rear = np.full(n, 20e3)
    rider = np.full(n, 15e3)
    band = (i >= 10_000) & (i < 14_000)
    front[band & (i % 4 == 0)] = 0.0
    rear[band & (i % 5 == 0) & (i >= 10_100)] = 0.0
    rider[band & (i % 2 == 0)] = 0.0
    front[12_001] = 79.2e3  # the peaks, inside the band
    rear[12_003] = 66.5e3
    rider[12_005] = 64.4e3
    rider[13_998] = 0.0  # the last opening of any nip: t = 139.98 s
    zeros = np.zeros(n)
    return winder.Result({"t": t, "front_nip_normal_force": front,
                          "rear_nip_normal_force": rear, "rider_nip_normal_force": rider,
                          "set_radius": radius, "set_z": 0.4 + zeros, "rider_z": 1.0 + zeros,
                          "set_x": zeros})


def test_two_drum_numbers_known_by_construction(rn):
    rows = dict(rn.two_drum_numbers(_two_drum()))
    r = lambda tt: 0.05 + 0.55 * tt / 200.0  # noqa: E731
    assert rows["bounce band: first to last opening of any nip"] == \
        f"t = 100.0–140.0 s, r = {r(100.0):.3f}–{r(139.98):.3f} m"
    assert rows["first opening per nip (set radius) [m]"] == \
        f"front_nip {r(100.0):.3f}, rider_nip {r(100.0):.3f}, rear_nip {r(101.0):.3f}"
    n_band = 13_998 - 10_000 + 1
    front = len(range(10_000, 13_999, 4))
    rear = len(range(10_100, 13_999, 5))
    rider = len(range(10_000, 13_999, 2))  # 13 998 is even: already counted
    assert rows["share of samples open, inside the band [%]"] == (
        f"front_nip {100 * front / n_band:.1f}, rear_nip {100 * rear / n_band:.1f}, "
        f"rider_nip {100 * rider / n_band:.1f}")
    assert rows["share of samples open, whole run [%]"] == (
        f"front_nip {100 * front / 20_001:.1f}, rear_nip {100 * rear / 20_001:.1f}, "
        f"rider_nip {100 * rider / 20_001:.1f}")
    assert rows["force peak inside the band [kN]"] == \
        "front_nip 79.2, rear_nip 66.5, rider_nip 64.4"


def test_line_numbers_known_by_construction(rn):
    t = np.round(np.arange(40_001) * 0.01, 10)
    e = 1e-3 * np.sin(t)
    e[20] = 0.631  # t = 0.20 s
    e[5977] = -0.558  # t = 59.77 s
    e[5990] = 0.4
    tau = np.where(t <= 59.57, 5.82e3 * t / 59.57, -1.05e3)
    tau[7000] = -1.11e3
    res = winder.Result({"t": t, "tension_error": e, "parent_torque": tau,
                         **{f"{n}_normal_force": np.full(t.size, 1e4)
                            for n in ("front_nip", "rear_nip", "rider_nip")}})
    rows = dict(rn.line_numbers(res, 59.57))
    assert rows["tension error peak at the ramp's start (t < 5 s) [N]"] == \
        "+0.631 at t = 0.20 s"
    assert rows["tension error peak at the ramp's end (59.57 ± 5 s) [N]"] == \
        "-0.558 at t = 59.77 s"
    rms = np.sqrt(np.mean(e ** 2))
    assert rows["tension error RMS over the run [N]"] == f"{rms:.3g}"
    assert rows["unwind torque: peak during the ramp; range after it [kN m]"] == \
        "+5.82; -1.11 to -1.05"


def test_flex_numbers_known_by_construction(rn):
    """The flexible winder's rows: four slices of a 4 m nip whose line loads at the end are
    10, 9, 9.5, 11 kN/m (least at y = 1.5 m, largest at y = 3.5 m); a map whose order-1
    bending mode stays at 50 Hz meets k × v/(2π r) at r = k v/(2π · 50) (the map's linear
    interpolation of f − k f₁ between radii 0.25 mm apart: measured 8e-7 relative, far
    below the three decimals printed); its order-3 mode at 20 Hz is not quoted."""
    from winder.analysis.modes import ModeMap

    t = np.linspace(0.0, 5.0, 11)
    q = {"front_nip": [10e3, 9e3, 9.5e3, 11e3], "rear_nip": [10e3] * 4,
         "rider_nip": [5e3, 5.1e3, 5e3, 5e3]}
    ch = {"t": t}
    for nip, loads in q.items():
        for i, qi in enumerate(loads):
            ch[f"{nip}_s{i}_normal_force"] = np.full(t.size, qi * 1.0)  # L/N = 1 m
        ch[f"{nip}_line_load_mean"] = np.full(t.size, np.mean(loads))
    rows = dict(rn.flex_numbers(winder.Result(ch), _flat_map(ModeMap)))
    assert rows["front_nip line load at t = 5 s: least, largest, mean [kN/m]"] == \
        "9.000 at y = 1.50 m, 11.000 at y = 3.50 m, 9.875; (max − min)/mean 20.25 %"
    assert rows["rear_nip line load at t = 5 s: least, largest, mean [kN/m]"].endswith(
        "(max − min)/mean 0.00 %")
    assert rows["least uniform line load"] == "front_nip (20.25 %)"
    v, f = 40.0, 50.0
    want = "; ".join(f"{k}x meets drum.bend.z1 at r = {k * v / (2 * np.pi * f):.3f}"
                     for k in (1, 2, 3))
    assert rows["harmonics meeting an order-1 bending mode at 40 m/s [m]"] == want


def _flat_map(ModeMap):  # noqa: N803 - the class
    r = np.arange(0.05, 0.6, 2.5e-4)
    flat = {"drum.bend.z1": np.full(r.size, 50.0), "drum.bend.z2": np.full(r.size, 500.0),
            "set.bend.z3": np.full(r.size, 20.0)}
    zeros = {k: np.zeros(r.size) for k in flat}
    return ModeMap(r, flat, zeros, np.zeros(r.size), np.zeros(r.size),
                   40.0 / (2 * np.pi * r), 40.0, "set")


def test_bounce_has_no_edge_artefact(rn):
    """A body rising at a steady rate with a 2 mm bounce, the band running to the run's
    last sample: less its centred 0.5 s mean (501 samples of 1 ms, two whole periods: the
    mean of the sampled sine is 0, of the ramp the ramp) the bounce is the sine exactly, to
    the end. The old measure,
    less the interpolated means of consecutive windows, held the last mean over the last
    half window: there the ramp's own rise showed as bounce (the spike of every bounce
    panel)."""
    t = np.round(np.arange(10_001) * 0.001, 12)  # 10 s at 1 ms
    amp, rate = 2e-3, 0.05  # [m], [m/s]
    f = 2 / 0.501  # [Hz]
    z = 0.4 + rate * t + amp * np.sin(2 * np.pi * f * t + 0.3)
    band = slice(5_000, t.size)
    lo, hi = rn.bounce_range(t, z, band)
    # the samples with a whole window: the sine's extremes among them to 1e-6 of amp
    idx, _ = rn.centred_mean(t, z)
    kept = idx[(idx >= 5_000)]
    sine = amp * np.sin(2 * np.pi * f * t[kept] + 0.3)
    assert abs(hi - sine.max()) < 1e-12 and abs(lo - sine.min()) < 1e-12  # round-off
    assert hi == pytest.approx(amp, rel=1e-5) and lo == pytest.approx(-amp, rel=1e-5)
    tm, zm = rn.window_mean(t, z)
    old = z - np.interp(t, tm, zm)
    assert np.max(old[band]) > amp + 0.2 * rate * 0.25  # the old edge: the ramp's rise


def test_two_drum_values_are_the_rows(rn):
    """The raw numbers docs/numbers.json keeps are the ones the table prints."""
    res = _two_drum()
    res.meta.update({"static_residual": 1e-9, "static_scale": 5e4, "method": "DOPRI5",
                     "rtol": 1e-6, "wall_time": 1.0, "rhs_evaluations": 10, "events": 3})
    v = rn.two_drum_values(res)
    rows = dict(rn.two_drum_numbers(res))
    assert rows["force peak inside the band [kN]"] == ", ".join(
        f"{n} {v['peak_band'][n] / 1e3:.1f}" for n in rn.NIPS)
    assert rows["share of samples open, inside the band [%]"] == ", ".join(
        f"{n} {100 * v['open_share_band'][n]:.1f}" for n in rn.NIPS)
    assert v["band"]["t"] == [100.0, 139.98]
    for body in ("rider", "set"):  # constant heights: no bounce (cumulative-sum round-off)
        assert np.allclose(v["bounce_band"][body], 0.0, atol=1e-12)
