"""Result files read back: damaged NPZ and CSV files (truncated at any offset, bytes
changed) give a ``ResultFileError`` naming the file, or the rows that are intact; a file
that would need unpickling is refused, never loaded."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest
from cli_corpus import good_result_arrays, write_npz
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import winder
from winder.io.result import ResultFileError

HYPO = settings(max_examples=120, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


#: Units of the channels of :func:`good_result_arrays`.
UNITS = {"t": "s", "radius": "m", "z": "m", "roll_angle": "rad", "roll_speed": "rad/s",
         "drum_speed": "rad/s", "drum_angle": "rad"}


def _original(tmp_path: Path) -> tuple[winder.Result, bytes, bytes]:
    arrays = good_result_arrays(40)
    res = winder.Result(arrays, {"scene": "free_spin"}, units=UNITS)
    res.save(tmp_path / "full.csv", tmp_path / "full.npz")
    return res, (tmp_path / "full.npz").read_bytes(), (tmp_path / "full.csv").read_bytes()


def _load(path: Path) -> winder.Result | None:
    """``load_result``, or ``None`` after checking its error is the clean one."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no stray warnings either
            return winder.load_result(path)
    except ResultFileError as exc:
        assert isinstance(exc, ValueError) and isinstance(exc, winder.WinderError)
        assert str(path) in str(exc) and len(str(exc).splitlines()) == 1
        assert "allow_pickle" not in str(exc)  # never advise unsafe loading
        return None


@HYPO
@given(data=st.data())
def test_truncated_npz_is_refused(data, tmp_path: Path) -> None:
    _, npz, _ = _original(tmp_path)
    cut = data.draw(st.integers(0, len(npz) - 1))
    (tmp_path / "cut.npz").write_bytes(npz[:cut])
    assert _load(tmp_path / "cut.npz") is None  # the archive's directory is at its end


@HYPO
@given(data=st.data())
def test_npz_with_changed_bytes_is_refused_or_intact(data, tmp_path: Path) -> None:
    res, npz, _ = _original(tmp_path)
    raw = bytearray(npz)
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(raw) - 1))
        raw[i] = data.draw(st.integers(0, 255).filter(lambda b, i=i: b != raw[i]))
    (tmp_path / "bad.npz").write_bytes(bytes(raw))
    back = _load(tmp_path / "bad.npz")
    if back is not None:  # a change the archive's checksums allow (names, dates): intact
        for k in res:
            np.testing.assert_array_equal(back[k], res[k])
        assert dict(back.units) == UNITS


@HYPO
@given(data=st.data())
def test_truncated_or_changed_csv(data, tmp_path: Path) -> None:
    """A CSV cut anywhere, or with a byte changed: the clean error, or rows equal to the
    original's (the last row may be cut inside a number and differ)."""
    res, _, csv = _original(tmp_path)
    raw = bytearray(csv[:data.draw(st.integers(0, len(csv)))])
    if raw and data.draw(st.booleans()):
        i = data.draw(st.integers(0, len(raw) - 1))
        raw[i] = data.draw(st.sampled_from(b"\x00\xff,-.e9 \n\r"))
    (tmp_path / "bad.csv").write_bytes(bytes(raw))
    back = _load(tmp_path / "bad.csv")
    if back is not None:
        assert np.all(np.isfinite(back.t)) and np.all(np.diff(back.t) > 0)
        if list(back) == list(res):
            n = len(back.t)
            assert n <= len(res.t)
            for k in res:  # every row before the last is intact unless a byte changed in it
                same = np.isclose(back[k][:n - 1], res[k][:n - 1], rtol=1e-14, atol=0)
                assert same.sum() >= n - 2, k


@HYPO
@given(blob=st.binary(max_size=2000), suffix=st.sampled_from([".npz", ".csv"]))
def test_random_bytes_are_refused(blob: bytes, suffix: str, tmp_path: Path) -> None:
    path = tmp_path / f"junk{suffix}"
    path.write_bytes(blob)
    back = _load(path)
    if back is not None:  # random bytes that happen to be a table of numbers
        assert suffix == ".csv" and np.all(np.diff(back.t) > 0)


def test_pickles_are_never_loaded(tmp_path: Path, monkeypatch) -> None:
    """A pickle given as a result, and an NPZ with an object member: refused without
    unpickling (pickle.loads would run the payload)."""
    ran = []

    class Payload:
        def __reduce__(self):
            return (ran.append, ("unpickled",))
    (tmp_path / "p.npz").write_bytes(pickle.dumps(Payload()))
    arrays = good_result_arrays()
    arrays["radius"] = np.array([Payload()] * len(arrays["t"]), dtype=object)
    with open(tmp_path / "o.npz", "wb") as fh:
        np.savez(fh, **arrays)
    monkeypatch.setattr(pickle, "loads", lambda *a, **k: ran.append("pickle.loads"))
    monkeypatch.setattr(pickle, "load", lambda *a, **k: ran.append("pickle.load"))
    for name in ("p.npz", "o.npz"):
        with pytest.raises(ResultFileError, match=name):
            winder.load_result(tmp_path / name)
    assert ran == []


def test_roundtrip_and_names(tmp_path: Path) -> None:
    res = winder.Result(good_result_arrays(), {"scene": "s", "x": [1, 2]})
    for f in (tmp_path / "r.npz", tmp_path / "r.csv"):
        back = winder.load_result(res.save(f))
        assert list(back) == list(res)
        for k in res:
            np.testing.assert_allclose(back[k], res[k], rtol=5e-15 if f.suffix == ".csv"
                                       else 0, atol=0)
        back["radius"][0] = 1.0  # loaded arrays are the caller's to change (CSV: 15 digits)
    assert winder.load_result(tmp_path / "r.npz").meta == {"scene": "s", "x": [1, 2]}
    for bad in (tmp_path / "missing.npz", tmp_path, tmp_path / "r.txt"):
        with pytest.raises(ResultFileError, match=str(bad.name)):
            winder.load_result(bad)


def test_metadata_and_channels_checked(tmp_path: Path) -> None:
    cases = {
        "meta_list.npz": (good_result_arrays(), [1, 2], "metadata"),
        "meta_text.npz": (good_result_arrays(), "{oops", "metadata"),
        "no_t.npz": ({k: v for k, v in good_result_arrays().items() if k != "t"}, None,
                     "'t'"),
        "back.npz": ({**good_result_arrays(), "t": np.linspace(1, 0, 50)}, None,
                     "not increasing"),
    }
    for name, (arrays, meta, message) in cases.items():
        write_npz(tmp_path / name, arrays, meta)
        with pytest.raises(ResultFileError, match=message):
            winder.load_result(tmp_path / name)


def test_csv_writes_zero_not_minus_zero(tmp_path: Path) -> None:
    """-0.0 is written as 0 (no "-0" in the file); every other value reads back as the
    value its 15 significant digits give, NaN, ±inf and the smallest subnormals included."""
    rng = np.random.default_rng(7)
    special = np.array([-0.0, 0.0, -0.0, -5e-324, 5e-324, -1e-300, 1.0, -1.0, np.nan,
                        np.inf, -np.inf, -2.5e-17, 1e308, -1e308, 0.1, -0.1])
    n = len(special)
    values = np.concatenate([special, -np.abs(rng.standard_normal(64)) * 10.0 **
                             rng.integers(-300, 300, 64)])
    t = np.arange(len(values), dtype=float)
    res = winder.Result({"t": t, "x": values, "zero": -np.zeros(len(values))}, {})
    path = res.to_csv(tmp_path / "r.csv")
    text = path.read_text()
    cells = [c for line in text.splitlines()[1:] for c in line.split(",")]
    assert "-0" not in cells and "-0.0" not in cells
    assert [line.split(",")[2] for line in text.splitlines()[1:]] == ["0"] * len(values)
    back = winder.load_result(path)
    expect = np.array([float(f"{v:.15g}") for v in values])
    np.testing.assert_array_equal(back["x"], expect)  # NaN where NaN
    zeros = expect == 0.0
    assert zeros.sum() == 3 and not np.any(np.signbit(back["x"][zeros]))
    assert not np.any(np.signbit(back["zero"]))
    assert np.array_equal(np.signbit(back["x"][~zeros & ~np.isnan(expect)]),
                          np.signbit(values[~zeros & ~np.isnan(expect)]))
    assert n == 16


# ---- units --------------------------------------------------------------------------------
def test_units_travel_with_the_npz(tmp_path: Path) -> None:
    """``Result.units`` is written to the NPZ (member ``__units__``) and read back equal;
    the CSV keeps its one header row of channel names (no units: they come back empty)."""
    res = winder.Result(good_result_arrays(), {"scene": "s"}, units=UNITS)
    res.save(tmp_path / "r.csv", tmp_path / "r.npz")
    back = winder.load_result(tmp_path / "r.npz")
    assert dict(back.units) == UNITS and list(back.units) == list(UNITS)
    assert back.meta == {"scene": "s"}  # the units are not metadata
    with np.load(tmp_path / "r.npz") as raw:  # what another NPZ reader sees
        assert __import__("json").loads(str(raw["__units__"])) == UNITS
    lines = (tmp_path / "r.csv").read_text().splitlines()
    assert lines[0] == ",".join(res)  # one header row: the channel names, unchanged
    assert np.array(lines[1].split(","), dtype=float).shape == (len(res),)
    assert dict(winder.load_result(tmp_path / "r.csv").units) == {}
    again = winder.load_result(back.save(tmp_path / "again.npz"))  # and once more
    assert dict(again.units) == UNITS


def test_npz_without_units_still_loads(tmp_path: Path) -> None:
    """An NPZ written before results carried units (channels and ``__meta__`` only) loads,
    with no units."""
    arrays = good_result_arrays()
    back = winder.load_result(write_npz(tmp_path / "old.npz", arrays, {"scene": "old"}))
    assert dict(back.units) == {} and back.meta == {"scene": "old"}
    np.testing.assert_array_equal(back["radius"], arrays["radius"])


def test_bad_units_are_refused(tmp_path: Path) -> None:
    """A units member that is not a JSON object of a channel's unit texts is refused, naming
    the file; a Result refuses a unit for a channel it does not have; units are
    read-only."""
    arrays = good_result_arrays()
    for name, units in {"list.npz": "[1, 2]", "text.npz": "{oops",
                        "ghost.npz": '{"speed": "rad/s"}', "number.npz": '{"z": 1}'}.items():
        with open(tmp_path / name, "wb") as fh:
            np.savez(fh, __units__=np.array(units), **arrays)
        with pytest.raises(ResultFileError, match=f"{name}.*units"):
            winder.load_result(tmp_path / name)
    with pytest.raises(winder.WinderError, match="'speed'"):
        winder.Result(arrays, units={"speed": "rad/s"})
    res = winder.Result(arrays, units={"z": "m"})
    with pytest.raises(TypeError):
        res.units["z"] = "mm"  # type: ignore[index]


def test_simulated_results_carry_the_units_of_every_channel(models_dir: Path) -> None:
    """A run's result has a unit for each of its channels, the system's ``channel_units``,
    also written to and read back from its NPZ."""
    res = winder.simulate(models_dir / "free_spin.toml", t_end=1.0, output_step=0.5)
    assert set(res.units) == set(res)
    assert res.units["t"] == "s" and res.units["roll_speed"] == "rad/s"
    assert res.units["inertia_rate"] == "kg·m²/s" and res.units["normal_force"] == "N"
