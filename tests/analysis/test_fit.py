"""Oracles of ``winder.fit`` (issue 35): noise-free recovery from the other path's data,
sensitivities against central differences, a problem linear in its parameter against the
closed-form least squares, a product pair reported as not identifiable, and the coverage
of the 95 % intervals over noisy repeats."""

from __future__ import annotations

import json

import numpy as np
import pytest

import winder
from winder.analysis.fit_model import FitEventError, ForwardModel, scene_with

from conftest import MODELS

PAPER = MODELS / "paper_winding.toml"
NIP = ["contact.stiffness", "contact.damping"]


@pytest.fixture(scope="module")
def paper() -> winder.Scene:
    return winder.load_scene(PAPER)


def _table(run: winder.Result, channels: list[str], noise: dict[str, float] | None = None,
           seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    keep = run.t > 0
    out = {"t": run.t[keep]}
    for c in channels:
        v = run[c][keep]
        if noise:
            v = v + rng.normal(0.0, noise[c], v.size)
        out[f"{c} [{run.units[c]}]"] = v
    return out


def test_noise_free_recovery_from_the_simulation(paper):
    """Data from ``winder.simulate`` (DOP853, the other path) of the true scene; the fit
    starts 30 % off and recovers both nip parameters (measured: 7e-12 and 1.4e-7)."""
    run = winder.simulate(paper, t_end=1.0, rtol=1e-12, atol=1e-14, output_step=0.004,
                          method="DOP853")
    guess = scene_with(paper, {"contact.stiffness": 2.6e7, "contact.damping": 1.5e4})
    res = winder.fit(guess, _table(run, ["z", "normal_force"]), NIP, rtol=1e-10)
    assert res.converged
    assert res["contact.stiffness"] == pytest.approx(2e7, rel=1e-6)
    assert res["contact.damping"] == pytest.approx(2e4, rel=1e-6)
    assert res.identifiable and res.evaluations >= 3


def test_sensitivities_match_central_differences(paper):
    """CVODES's forward sensitivities (with the balance's and the core's) against central
    differences of the simulated channels (rtol 1e-12; measured ~1e-8)."""
    keys = [*NIP, "paper.density"]
    t = np.linspace(0.002, 0.3, 150)
    fm = ForwardModel(paper, keys, ["z", "normal_force", "roll_speed"], t, rtol=1e-12)
    S = fm.evaluate(fm.theta0).S
    def central(j: int, h: float) -> np.ndarray:
        a, b = fm.theta0.copy(), fm.theta0.copy()
        a[j] += h
        b[j] -= h
        return (fm.evaluate(a, sensitivities=False).y - fm.evaluate(b, sensitivities=False).y) \
            / (2 * h)

    worst = 0.0
    for j, key in enumerate(keys):
        h = 1e-3 * fm.theta0[j]
        fd = (4 * central(j, h / 2) - central(j, h)) / 3  # Richardson: O(h⁴)
        for c, name in enumerate(fm.channels):
            scale = np.max(np.abs(S[c, :, j]))
            if scale * fm.theta0[j] < 1e-9 * np.max(np.abs(fm.evaluate(fm.theta0).y[c])):
                continue  # the channel does not see the key
            err = np.max(np.abs(fd[c] - S[c, :, j])) / scale
            worst = max(worst, err)
            assert err < 1e-6, (key, name, err)
    print(f"sensitivities vs central differences: worst {worst:.2e}")


def test_linear_problem_matches_closed_form_least_squares(paper):
    """A speed-profile drum's torque is linear in its inertia, slope its angular
    acceleration a/R on the ramp: the estimate, σ̂ and the standard error are the
    closed-form ones (ordinary least squares, σ̂² = RSS/(N − 1))."""
    run = winder.simulate(paper, t_end=0.3, rtol=1e-10, atol=1e-12, output_step=0.002,
                          method="DOP853")
    data = _table(run, ["drum_torque"], {"drum_torque": 5.0}, seed=3)
    guess = scene_with(paper, {"drum.inertia": 300.0})
    res = winder.fit(guess, data, ["drum.inertia"], rtol=1e-10)
    slope = 0.5 / 0.5  # web acceleration / drum radius [1/s²]
    y = data["drum_torque [N·m]"]
    base = res.fitted["drum_torque"] - res["drum.inertia"] * slope  # the rest of the torque
    n = y.size
    est = float(np.sum((y - base) * slope) / (n * slope**2))
    rss = float(np.sum((y - base - est * slope) ** 2))
    std = np.sqrt(rss / (n - 1) / (n * slope**2))
    assert res["drum.inertia"] == pytest.approx(est, rel=1e-9, abs=1e-9)
    assert res.std[0] == pytest.approx(std, rel=1e-6)
    assert res.sigma["drum_torque"] == pytest.approx(np.sqrt(rss / (n - 1)), rel=1e-6)
    from scipy.stats import t as student

    q = student.ppf(0.975, n - 1)
    assert res.ci95[0] == pytest.approx([est - q * std, est + q * std], rel=1e-9)


def test_product_pair_is_not_identifiable(paper, tmp_path):
    """The paper's density and the roll's width act only as their product (the wound
    mass): the fit says so and names both."""
    run = winder.simulate(paper, t_end=0.3, rtol=1e-10, atol=1e-12, output_step=0.002,
                          method="DOP853")
    data = _table(run, ["z", "normal_force"], {"z": 1e-9, "normal_force": 1e-3})
    res = winder.fit(paper, data, ["paper.density", "roll.width"],
                     sigma={"z": 1e-9, "normal_force": 1e-3}, rtol=1e-10)
    assert not res.identifiable
    assert set(res.not_identifiable()) == {"paper.density", "roll.width"}
    assert res.singular_values[-1] < 1e-6 * res.singular_values[0]
    # the weakest direction: d(ρw) = 0, i.e. weights ∝ (1/ρ, −1/w) in relative terms
    w = res.weakest
    assert abs(w["paper.density"]) == pytest.approx(abs(w["roll.width"]), rel=1e-4)
    assert np.all(np.isinf(res.std))
    out = res.to_json(tmp_path / "fit.json")
    data = json.loads(out.read_text())
    assert data["identifiability"]["not_identifiable"] == ["paper.density", "roll.width"]


def test_intervals_cover_the_truth(paper):
    """100 noisy repeats of a short nip record (σ given): the 95 % intervals of stiffness
    and damping hold the truth in 95 % of them within the binomial spread (3 σ: ≥ 89)."""
    run = winder.simulate(paper, t_end=0.3, rtol=1e-10, atol=1e-12, output_step=0.004,
                          method="DOP853")
    noise = {"z": 2e-7, "normal_force": 5.0}
    hits = np.zeros(2, dtype=int)
    for seed in range(100):
        data = _table(run, ["z", "normal_force"], noise, seed=seed)
        res = winder.fit(paper, data, NIP, sigma=noise, rtol=1e-9)
        for j, truth in enumerate((2e7, 2e4)):
            hits[j] += res.ci95[j, 0] <= truth <= res.ci95[j, 1]
    assert np.all(hits >= 89), hits


def test_event_in_the_window_is_named(paper):
    """A nip far too soft lifts off... no: a window with the roll turning back at its core
    is held (AT_CORE until it turns); a lift-off stops with the event's time."""
    fm = ForwardModel(paper, NIP, ["z"], np.linspace(0.002, 0.3, 150), rtol=1e-8)
    fm.evaluate(fm.theta0)
    assert 0.0 < fm.tau[0] < 0.3  # the roll turned forwards inside the window
    X = np.zeros((6, 150))
    X[:, :] = np.asarray(fm.system.initial_state())[:, None]
    X[0, 100:] -= 0.1  # the roll lifted 10 cm off the drum
    with pytest.raises(FitEventError, match=r"nip 'nip' lifts off .* t = 0\.19"):
        fm.check_events(X, fm.machine_at(fm.theta0))
