"""simulate() and Stepper() check every argument before any work: a bad one raises
ArgumentError (a ValueError) or ArgumentTypeError (a TypeError) naming the argument, the
value and the valid range."""

from __future__ import annotations

import math
import time

import pytest

import winder

NAN, INF = math.nan, math.inf

BAD = [  # (keyword arguments, what the message must contain)
    ({"rtol": 2}, r"rtol = 2 is out of range; valid: finite, > 0 and <= 0.1"),
    ({"rtol": NAN}, r"rtol = nan .* finite, > 0 and <= 0.1"),
    ({"rtol": 0.0}, r"rtol = 0.0 .* > 0 and <= 0.1"),
    ({"rtol": -1e-6}, r"rtol = -1e-06 .* > 0 and <= 0.1"),
    ({"rtol": INF}, r"rtol = inf .* finite"),
    ({"atol": -1.0}, r"atol = -1.0 .* finite, > 0 and <= 0.001"),
    ({"atol": 0.0}, r"atol = 0.0 .* finite, > 0 and <= 0.001"),
    ({"atol": NAN}, r"atol = nan"),
    ({"atol": 1e300}, r"atol = 1e\+300 is out of range; valid: finite, > 0 and <= 0.001"),
    ({"atol": 0.0011}, r"atol = 0.0011 .* <= 0.001 \(an absolute tolerance"),
    ({"max_step": NAN}, r"max_step = nan .* finite and > 0"),
    ({"max_step": 0.0}, r"max_step = 0.0 .* finite and > 0"),
    ({"max_step": -1.0}, r"max_step = -1.0"),
    ({"output_step": 0.0}, r"output_step = 0.0 .* finite and > 0"),
    ({"output_step": -0.1}, r"output_step = -0.1"),
    ({"output_step": NAN}, r"output_step = nan"),
    ({"output_step": INF}, r"output_step = inf"),
    ({"t_end": 0.0}, r"t_end = 0.0 .* finite and > 0"),
    ({"t_end": -5.0}, r"t_end = -5.0"),
    ({"t_end": NAN}, r"t_end = nan"),
    ({"t_end": INF}, r"t_end = inf"),
    ({"t_start": 800.0}, r"t_start = 800.0 .* < \[scene\] duration = 700"),
    ({"method": "Euler"}, r"method = 'Euler' is unknown; valid: auto, DOPRI5, RK4"),
    ({"backend": "gpu"}, r"backend = 'gpu' is unknown; valid: compiled, pinocchio"),
    ({"jacobian": "analytic"}, r"jacobian = 'analytic' is unknown; valid: exact, fd, pinocchio"),
    ({"method": "DOPRI5", "backend": "pinocchio"}, r"method = 'DOPRI5' needs backend "
                                                    r"'compiled'.*valid methods"),
    ({"max_rhs": 0}, r"max_rhs = 0 .* whole number >= 1"),
    ({"max_rhs": 2.5}, r"max_rhs = 2.5"),
    ({"max_wall": 0.0}, r"max_wall = 0.0 .* > 0"),
    ({"max_wall": NAN}, r"max_wall = nan"),
    ({"initial_state": [1.0, 2.0]}, r"initial_state = \[1, 2\] .* 6 finite values"),
    ({"t_end": 1e12, "output_step": 1e-3}, r"t_end = 1e\+12 s with output_step = 0.001 s "
                                            r"asks for 1e\+15 output samples; the limit is "
                                            r"10,000,000"),
    ({"t_end": 1e12}, r"t_end = 1e\+12 s with \[scene\] output_step = 0.01 s asks for "
                      r"1e\+14"),
]

BAD_TYPES = [
    ({"rtol": "1e-6"}, r"rtol must be a real number"),
    ({"t_end": None, "output_step": "0.1"}, r"output_step must be a real number"),
    ({"method": 4}, r"method must be a string"),
    ({"progress": "yes"}, r"progress must be True or False"),
    ({"max_rhs": True}, r"max_rhs must be a real number"),
    ({"initial_state": "abc"}, r"initial_state must be 6 numbers"),
]


@pytest.mark.parametrize(("kwargs", "message"), BAD)
def test_bad_argument_is_named_before_any_work(paper_scene, kwargs, message) -> None:
    start = time.perf_counter()
    with pytest.raises(winder.ArgumentError, match=message) as info:
        winder.simulate(paper_scene, **kwargs)
    assert isinstance(info.value, ValueError)
    assert time.perf_counter() - start < 2.0  # refused up front, not after integrating


@pytest.mark.parametrize(("kwargs", "message"), BAD_TYPES)
def test_bad_argument_type_is_named(paper_scene, kwargs, message) -> None:
    with pytest.raises(winder.ArgumentTypeError, match=message) as info:
        winder.simulate(paper_scene, **kwargs)
    assert isinstance(info.value, TypeError)


def test_absurd_scene_duration_is_refused(paper_scene) -> None:
    """Refused where it is written: the scene names the key, its value and its range."""
    with pytest.raises(winder.SceneError, match=r"\[scene\] duration: .*1e\+300"):
        paper_scene.replace(scene={"duration": 1e300})
    with pytest.raises(winder.ArgumentError, match=r"t_end = 1e\+06 s with output_step = "
                                                   r"1e-06 s asks for 1e\+12 output samples"):
        winder.simulate(paper_scene, t_end=1e6, output_step=1e-6)


def test_scene_given_as_a_path(models_dir) -> None:
    """A str or Path is loaded as the scene file; the result equals the loaded scene's."""
    path = models_dir / "free_spin.toml"
    ref = winder.simulate(winder.load_scene(path), t_end=1.0)
    for scene in (path, str(path)):
        res = winder.simulate(scene, t_end=1.0)
        assert res["roll_speed"].tolist() == ref["roll_speed"].tolist()
    with pytest.raises(winder.SceneError, match="no_such.toml"):
        winder.simulate(models_dir / "no_such.toml")


@pytest.mark.parametrize("scene", [None, 42, {"scene": {}}])
def test_scene_of_another_type_is_named(scene) -> None:
    with pytest.raises(winder.ArgumentTypeError, match="scene must be a winder.Scene or the "
                                                       "path of a scene file"):
        winder.simulate(scene)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"rtol": 0.0}, r"rtol = 0.0 .* > 0 and <= 0.1"), ({"rtol": NAN}, "rtol = nan"),
    ({"atol": -1.0}, "atol = -1.0"), ({"atol": 1e300}, r"atol = 1e\+300 .* <= 0.001"),
    ({"max_rhs": 0}, "max_rhs = 0"), ({"max_wall": -1.0}, "max_wall = -1.0")])
def test_stepper_arguments(paper_scene, kwargs, message) -> None:
    with pytest.raises(winder.ArgumentError, match=message):
        winder.Stepper(paper_scene, **kwargs)


@pytest.mark.parametrize("dt", [0.0, -1e-3, NAN, INF, 1e-300])
def test_stepper_step_names_dt(paper_scene, dt) -> None:
    with pytest.raises(winder.ArgumentError, match=r"dt = .* is out of range; valid: finite "
                                                   r"and >= 1e-14 s"):
        winder.Stepper(paper_scene).step(dt)


def test_max_wall_scene_key(paper_scene) -> None:
    """``[solver] max_wall`` is read from the scene (default 600 s)."""
    assert paper_scene.solver.max_wall == 600.0
    scene = paper_scene.replace(solver={"max_wall": 1e-3})
    with pytest.raises(winder.BudgetExceeded, match="max_wall = 0.001 s"):
        winder.simulate(scene, method="RK45", rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("kwargs", [{"max_rhs": 10**400}, {"atol": 10**400},
                                    {"max_wall": -10**400}])
def test_integer_beyond_the_float_range_is_named(paper_scene, kwargs) -> None:
    """A 400-digit integer is an argument error naming the argument, shown short."""
    (name,) = kwargs
    with pytest.raises(winder.ArgumentError, match=rf"{name} = .*characters as text\) is out "
                                                   "of range"):
        winder.simulate(paper_scene, **kwargs)


def test_scene_and_simulate_count_samples_alike(paper_scene) -> None:
    """duration / output_step + 1 samples (both ends): one more than the limit is refused by
    the scene already, not first by simulate after the scene loaded."""
    from winder.scene import MAX_SAMPLES

    with pytest.raises(winder.SceneError, match="output_step"):
        paper_scene.replace(scene={"duration": 1e6, "output_step": 1e6 / MAX_SAMPLES})
    ok = paper_scene.replace(scene={"duration": 1e6, "output_step": 1e6 / (MAX_SAMPLES - 1)})
    from winder.solve.simulate import _output_grid

    assert len(_output_grid(0.0, 1e6, ok.scene.output_step, "d", "s")) == MAX_SAMPLES
