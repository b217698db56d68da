"""The command line's error contract: junk options, unwritable outputs, scene names that try
to pick a directory, damaged result files, budgets. Every case ends with exit status 2 and a
few lines naming the option or file (or a sane run), no traceback, nothing left on disk."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from cli_corpus import Case, corpus, good_result_arrays, new_option_cases, quick_scene, run_case
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import winder
from winder import cli
from winder.cli import main
from winder.io.files import STEM_MAX, check_output_dir, check_output_file, safe_stem

CASES = [*corpus(), *new_option_cases()]


@pytest.mark.parametrize("case", CASES, ids=[f"{c.category}: {c.label}" for c in CASES])
def test_corpus_case_ends_cleanly(case: Case, tmp_path: Path) -> None:
    outcome = run_case(main, case, tmp_path / "case")
    assert outcome.clean, (outcome.problems, outcome.stderr)


# ---- options: a reference predicate of the valid range, drawn junk --------------------------
def _as_float(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


#: option → (subcommand, reference validity predicate of the value)
OPTIONS = {
    "--t-end": ("run", lambda x: math.isfinite(x) and x > 0),
    "--rtol": ("run", lambda x: 0 < x <= 0.1),
    "--atol": ("run", lambda x: 0 < x <= 1e-3),
    "--max-step": ("run", lambda x: math.isfinite(x) and x > 0),
    "--max-evals": ("run", lambda x: 1 <= x <= 1e15 and x == int(x)),
    "--max-wall": ("run", lambda x: math.isfinite(x) and x > 0),
    "--every": ("view", lambda x: math.isfinite(x) and x > 0),
    "--playback": ("view", lambda x: 0 < x <= 3600),
    "--points": ("modes", lambda x: 2 <= x <= 100_000 and x == int(x)),
    "--web-speed": ("modes", lambda x: math.isfinite(x) and x > 0),
}

_values = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(min_value=-1e20, max_value=1e20).map(lambda x: f"{x:g}"),
    st.integers(min_value=-10**20, max_value=10**20).map(str),
    st.text(alphabet="0123456789.eE+-xinfa ,_", max_size=10),
    st.sampled_from(["nan", "inf", "-inf", "1e309", "0", "-0", "1e-400", "", " "]),
)


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(option=st.sampled_from(sorted(OPTIONS)), value=_values)
def test_any_option_value_is_named_or_accepted(option: str, value: str, tmp_path: Path,
                                               capsys) -> None:
    """A missing scene file after the option: a valid value gets as far as the scene (its
    error names the scene), an invalid one is refused naming the option, before anything
    is read or written."""
    assume(value != "--")  # argparse's end-of-options marker, removed before the option sees it
    command, valid = OPTIONS[option]
    missing = tmp_path / "no-such-scene.toml"
    argv = [command, str(missing), f"{option}={value}"]
    if command == "run":
        argv += ["--out", str(tmp_path / "o" / "r.npz")]
    capsys.readouterr()
    status = main(argv)
    err = capsys.readouterr().err
    x = _as_float(value)
    ok = x is not None and valid(x)
    assert status == 2, (argv, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) <= 3, err
    assert (str(missing) in err) if ok else (f"argument {option}" in err and "valid:" in err), \
        (value, err)
    assert not (tmp_path / "o").exists()


# ---- output paths -------------------------------------------------------------------------
def test_checks_create_nothing_and_name_the_argument(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    cases = {
        str(tmp_path / "file" / "r.csv"): "is a file",
        str(tmp_path): "is a directory",
        str(tmp_path / ("x" * 256 + ".csv")): "bytes long",
        str(tmp_path / ("x" * 256) / "r.csv"): "bytes long",
        str(tmp_path / "a\0b.csv"): "NUL",
        "/proc/winder-test/r.csv": "cannot write",
        "": "empty",
    }
    before = sorted(tmp_path.rglob("*"))
    for path, problem in cases.items():
        with pytest.raises(winder.WinderError, match="--out") as info:
            check_output_file(path, "--out", suffixes=(".csv",))
        assert problem in str(info.value), (path, str(info.value))
        assert isinstance(info.value, OSError)
    with pytest.raises(winder.WinderError, match=r"--plots .*is a file"):
        check_output_dir(tmp_path / "file", "--plots")
    assert sorted(tmp_path.rglob("*")) == before  # nothing created, probes removed
    # accepted: new nested folders, a 250-byte name
    assert check_output_file(tmp_path / "a" / "b" / ("y" * 246 + ".csv"), "--out")
    assert check_output_dir(tmp_path / "new" / "dir", "--plots")
    assert sorted(tmp_path.rglob("*")) == before


def test_read_only_directory(tmp_path: Path) -> None:
    """A directory the process cannot write (as root, permission bits do not stop writes:
    the check probes, so a read-only mount is what it catches; otherwise chmod 555)."""
    if os.geteuid() == 0:
        target = Path("/sys/winder-test.csv")  # sysfs: not writable, even by root
    else:
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        target = ro / "r.csv"
    with pytest.raises(winder.WinderError, match="cannot write"):
        check_output_file(target, "--out", suffixes=(".csv",))
    assert not target.exists()


@given(st.text(max_size=400))
@settings(max_examples=200, deadline=None)
def test_safe_stem_never_leaves_the_directory(text: str) -> None:
    stem = safe_stem(text)
    assert stem and len(stem.encode()) <= STEM_MAX
    assert "/" not in stem and "\\" not in stem and "\0" not in stem
    assert not stem.startswith(".") and stem not in (".", "..")
    assert Path("out", stem + "_fig8_normal_force.png").parent == Path("out")


@pytest.mark.parametrize("name", ["../x", "/abs/path", "a\0b", "n" * 400, "..", ""])
def test_plot_files_stay_in_their_directory(name: str, tmp_path: Path) -> None:
    from winder.plots.figures import paper_figures

    res = winder.Result({k: np.asarray(v) for k, v in good_result_arrays().items()} | {
        "normal_force": np.zeros(50), "friction_force": np.zeros(50),
        "inertia": np.full(50, 0.12)}, {"scene": name})
    out = tmp_path / "plots"
    paths = paper_figures(res, out)
    assert [p.parent for p in paths] == [out]
    assert sorted(tmp_path.rglob("*")) == [out, *paths]
    assert all(len(p.name.encode()) <= 255 for p in paths)


def test_250_character_output_name_works(tmp_path: Path, capsys) -> None:
    out = tmp_path / ("r" * 246 + ".csv")
    assert main(["run", str(quick_scene(tmp_path)), "--out", str(out)]) == 0
    assert winder.load_result(out).t[-1] == pytest.approx(0.5)
    assert winder.load_result(out.with_suffix(".npz")).meta["scene"] == "free_spin"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [out.name, out.with_suffix(".npz").name, "scene.toml"])


# ---- write both or neither ----------------------------------------------------------------
def test_csv_twin_not_left_when_the_npz_fails(tmp_path: Path, monkeypatch, capsys) -> None:
    writer = winder.Result._writer

    def failing(self, path):
        if str(path).endswith(".npz"):
            def write(tmp: Path) -> None:
                tmp.write_bytes(b"half")
                raise OSError(28, "No space left on device")
            return write
        return writer(self, path)
    monkeypatch.setattr(winder.Result, "_writer", failing)
    out = tmp_path / "sub" / "r.csv"
    assert main(["run", str(quick_scene(tmp_path)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "r.npz" in err and "No space left" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["scene.toml"]  # sub/ removed too


# ---- budgets --------------------------------------------------------------------------------
def _budget_stub(monkeypatch, partial: winder.Result | None) -> dict:
    seen: dict = {}

    def simulate(scene, **kw):
        seen.update(kw)
        raise winder.BudgetExceeded(
            "wall-clock budget of 0.5 s (max_wall) reached at t = 0.25 s, step 1e-3 s",
            time=0.25, state={"z": 0.5}, step=1e-3, partial=partial)
    monkeypatch.setattr("winder.solve.simulate.simulate", simulate)
    return seen


def test_budget_options_reach_simulate(tmp_path: Path, monkeypatch, capsys) -> None:
    seen = _budget_stub(monkeypatch, None)
    out = tmp_path / "r.npz"
    assert main(["run", str(quick_scene(tmp_path)), "--out", str(out), "--max-evals", "1e6",
                 "--max-wall", "0.5"]) == 2
    assert seen["max_rhs"] == 1_000_000 and isinstance(seen["max_rhs"], int)
    assert seen["max_wall"] == 0.5
    err = capsys.readouterr().err
    assert "max_wall" in err and "--keep-partial" in err and not out.exists()


def test_keep_partial_writes_the_partial_result(tmp_path: Path, monkeypatch, capsys) -> None:
    arrays = good_result_arrays(26)
    partial = winder.Result({k: v[:13] for k, v in arrays.items()}, {"scene": "free_spin"})
    _budget_stub(monkeypatch, partial)
    out = tmp_path / "r.csv"
    assert main(["run", str(quick_scene(tmp_path)), "--out", str(out), "--max-wall", "0.5",
                 "--keep-partial"]) == 2
    err = capsys.readouterr().err
    assert f"partial result up to t = {partial.t[-1]:g} s written" in err, err
    np.testing.assert_array_equal(winder.load_result(out.with_suffix(".npz"))["radius"],
                                  partial["radius"])
    # the CSV keeps 15 significant digits
    np.testing.assert_allclose(winder.load_result(out)["radius"], partial["radius"],
                               rtol=1e-14, atol=0)
    assert winder.load_result(out.with_suffix(".npz")).meta["partial"] is True


def test_keep_partial_without_a_sample(tmp_path: Path, monkeypatch, capsys) -> None:
    _budget_stub(monkeypatch, None)
    out = tmp_path / "r.npz"
    assert main(["run", str(quick_scene(tmp_path)), "--out", str(out), "--keep-partial"]) == 2
    assert "no partial result" in capsys.readouterr().err and not out.exists()


def test_real_evaluation_budget_stops_cleanly(tmp_path: Path, capsys) -> None:
    out = tmp_path / "r.npz"
    assert main(["run", str(quick_scene(tmp_path, duration=5.0)), "--out", str(out),
                 "--max-evals", "50"]) == 2
    err = capsys.readouterr().err
    assert "50" in err and "Traceback" not in err and not out.exists()


# ---- internal errors ------------------------------------------------------------------------
def test_internal_error_says_so(tmp_path: Path, monkeypatch, capsys) -> None:
    def broken(args):
        raise ZeroDivisionError("a bug")
    monkeypatch.setattr(cli, "_cmd_modes", broken)
    assert main(["modes", "x.toml"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" in err and "ZeroDivisionError" in err
    assert "internal error" in err and "bug in winder" in err


def test_usage_errors_are_short(capsys) -> None:
    assert main(["run"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--out" in err
    assert main(["--help"]) == 0
