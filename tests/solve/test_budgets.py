"""Budgets of every path: evaluations (``max_rhs``) and wall clock (``max_wall``). A run
that reaches one ends cleanly with :class:`winder.BudgetExceeded`: the time, the last
step, the state, the partial result, and whether the run is long, stiff or collapsed."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

import winder
from winder.solve.simulate import budget_error

MODELS = Path(__file__).resolve().parents[2] / "models"

PATHS = [("DOPRI5", "compiled"), ("RK4", "compiled"), ("LSODA", "compiled"),
         ("RK45", "compiled"), ("LSODA", "pinocchio"), ("RK4", "pinocchio")]


@pytest.mark.parametrize(("method", "backend"), PATHS)
def test_evaluation_budget_gives_the_partial_result(paper_scene, method, backend) -> None:
    """The partial result holds the samples up to the time reached, equal to those of a
    run without the budget."""
    kw = {"t_end": 2.0, "output_step": 0.01, "method": method, "backend": backend}
    if method == "RK4":
        kw["max_step"] = 1e-3
    full = winder.simulate(paper_scene, **kw)
    budget = full.meta["rhs_evaluations"] // 3
    with pytest.raises(winder.BudgetExceeded, match=r"max_rhs = \d+ evaluations reached") \
            as info:
        winder.simulate(paper_scene, max_rhs=budget, **kw)
    e = info.value
    assert isinstance(e, winder.SimulationError)
    assert 0.0 < e.time < 2.0 and e.step is not None and e.step > 0
    assert set(e.state) == {"roll.z", "roll.theta", "roll.z_dot", "roll.theta_dot",
                            "roll.radius", "nip.friction"}
    part = e.partial
    assert part.meta["partial"] is True and set(part) == set(full)
    n = len(part.t)
    assert n > 10 and part.t[-1] <= e.time
    np.testing.assert_array_equal(part.t, full.t[:n])
    # measured: 0 (same steps); RK4 compiled 4e-11 relative (after the core event the
    # budget-sized chunk is divided into steps other than the whole run's)
    tol = 1e-9 if (method, backend) == ("RK4", "compiled") else 1e-12
    for name in ("radius", "roll_speed", "z", "drum_torque", "normal_force"):
        np.testing.assert_allclose(part[name], full[name][:n], rtol=tol,
                                   atol=tol * np.max(np.abs(full[name])), err_msg=name)
    assert "--max-evals" in str(e) and f"t = {e.time:.6g} s" in str(e)


@pytest.mark.parametrize(("method", "backend"), PATHS)
def test_wall_budget_stops_the_run(paper_scene, method, backend) -> None:
    """A wall-clock budget of 0.2 s stops a run that would take far longer."""
    kw = {"max_step": 1e-5} if method == "RK4" else {"rtol": 1e-10, "atol": 1e-12}
    start = time.perf_counter()
    with pytest.raises(winder.BudgetExceeded, match=r"max_wall = 0.2 s reached") as info:
        winder.simulate(paper_scene, method=method, backend=backend, max_wall=0.2, **kw)
    # a bound, not a speed target: the run alone would take minutes
    assert time.perf_counter() - start < 30.0
    assert "--max-wall" in str(info.value) and info.value.time < 700.0


def test_long_run_is_called_long(paper_scene) -> None:
    with pytest.raises(winder.BudgetExceeded, match="long, not stiff.*needs about") as info:
        winder.simulate(paper_scene, max_rhs=200_000)
    assert "stiff for" not in str(info.value)


def test_stiff_run_is_called_stiff(paper_scene) -> None:
    """A heavily damped nip (c = 3e7 N·s/m: an eigenvalue near −c/m = −1e6 s⁻¹): DOPRI5's
    steps are limited by stability (``method="auto"`` now takes RODAS4 here)."""
    scene = paper_scene.replace(contact={"damping": 3e7})
    with pytest.raises(winder.BudgetExceeded, match="stiff for 'DOPRI5'.*limited by "
                                                    "stability.*Radau"):
        winder.simulate(scene, t_end=20.0, max_rhs=100_000, method="DOPRI5")


def test_collapsed_step_is_called_collapsed() -> None:
    e = budget_error("max_rhs", 1000, meth="RK45", t=3.0, t_start=0.0, t_end=10.0,
                     step=1e-12, steps=3000, stiff_steps=None, nfev=1000, wall=1.0,
                     state={"z": 0.5})
    assert "collapsed" in str(e) and "long" not in str(e) and e.partial is None
    e = budget_error("max_wall", 5.0, meth="RK45", t=3.0, t_start=0.0, t_end=10.0,
                     step=1e-3, steps=3000, stiff_steps=None, nfev=1000, wall=5.0,
                     state={"z": 0.5})
    assert "long, not stiff" in str(e) and "3.33e+03 evaluations and 16.7 s" in str(e)


def test_stiff_nip_stops_at_the_budget_on_the_pinocchio_path(paper_scene) -> None:
    """Nip stiffness 1e12 with LSODA on the Pinocchio backend (ran for ~28 min before the
    budgets): a small budget stops it with the partial result."""
    scene = paper_scene.replace(contact={"stiffness": 1e12})
    with pytest.raises(winder.BudgetExceeded) as info:
        winder.simulate(scene, backend="pinocchio", max_rhs=20_000)
    assert info.value.partial is not None and info.value.partial.t[-1] > 0


def test_stepper_huge_step_stops_at_its_budget(paper_scene) -> None:
    """Stepper.step(1e12) returns or raises BudgetExceeded, never hangs; the stepper stays
    at the time reached and goes on from there."""
    sim = winder.Stepper(paper_scene, max_rhs=50_000)
    with pytest.raises(winder.BudgetExceeded, match="max_rhs = 50000 evaluations.*"
                                                    "Stepper") as info:
        sim.step(1e12)
    assert sim.t == info.value.time > 0
    assert info.value.partial["radius"][0] == sim.output("radius")
    t = sim.t
    sim.step(1e-3)
    assert sim.t == pytest.approx(t + 1e-3, abs=1e-15)
    wall = winder.Stepper(paper_scene, max_wall=0.05)
    with pytest.raises(winder.BudgetExceeded, match="max_wall = 0.05 s"):
        wall.step(1e12)


def test_stepper_tiny_step_names_dt(paper_scene) -> None:
    sim = winder.Stepper(paper_scene)
    with pytest.raises(winder.ArgumentError, match=r"dt = 1e-300 is out of range; valid: "
                                                   r"finite and >= 1e-14 s"):
        sim.step(1e-300)
    sim.step(1e-14)  # the resolution itself is a valid step
    assert sim.t == 1e-14


def test_default_budget_of_each_path() -> None:
    """Without max_rhs: 50 M evaluations on the compiled methods; on the step-wise paths
    (scipy's methods, the numeric backend) about a minute of their work, fewer in
    proportion for a machine of more than 50 states."""
    from winder.solve.budgets import default_max_rhs

    assert default_max_rhs(stepwise=False, backend="compiled", n_states=213) == 50_000_000
    assert default_max_rhs(stepwise=True, backend="compiled", n_states=6) == 300_000
    assert default_max_rhs(stepwise=True, backend="pinocchio", n_states=6) == 30_000
    assert default_max_rhs(stepwise=True, backend="compiled", n_states=213) == 70_422
    assert winder.load_scene(MODELS / "paper_winding.toml").solver.max_rhs is None


def test_stiff_nip_on_lsoda_stops_at_the_step_wise_budget(tmp_path, monkeypatch, capsys) -> None:
    """Issue 32: ``winder run`` of the paper scene with a 1e12 N/m nip and ``--method
    LSODA`` ran 7 min (9.85 M evaluations) without a word; the step-wise paths' default
    budget (300 000 evaluations: the whole scene stops after 5.5–25 s of CPU on each of
    scipy's methods, docs/speed.md) stops it with exit 2 and a message naming what to
    change, with the progress bar drawn where it stopped. Here
    the default is 10 000 (the same mechanism, the test quick): t_end 20 s needs about
    26 000 evaluations."""
    from winder.cli import main
    from winder.solve import budgets

    scene = tmp_path / "stiff.toml"
    scene.write_text((MODELS / "paper_winding.toml").read_text().replace(
        "stiffness = 2e7 ", "stiffness = 1e12 "))
    assert "stiffness = 1e12" in scene.read_text()
    monkeypatch.setitem(budgets.STEPWISE_MAX_RHS, "compiled", 10_000)
    out = tmp_path / "out" / "r.csv"
    status = main(["run", str(scene), "--out", str(out), "--method", "LSODA", "--t-end", "20",
                   "--progress"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "Traceback" not in err
    assert "budget max_rhs = 10000 evaluations reached at t = " in err
    t = float(err.split("reached at t = ")[1].split()[0])
    assert 0.0 < t < 20.0
    assert "--max-evals" in err and "--method ROS2" in err
    assert f"t = {t:8.2f} s" in err  # the progress bar, drawn at the time reached
    assert sorted(tmp_path.rglob("*")) == [scene]  # nothing on disk
