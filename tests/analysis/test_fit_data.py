"""The measured table of ``winder.fit``: CSV, NPZ, Parquet, a Result and a mapping read
to the same columns and units; bad tables are refused naming the column."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import winder
from winder.analysis.fit_data import parse_param, read_table

T = np.array([0.1, 0.25, 0.3])
Z = np.array([0.5, 0.51, 0.52])


def test_every_format_reads_the_same(tmp_path):
    csv = tmp_path / "d.csv"
    csv.write_text("t,z [m]\n" + "\n".join(f"{float(a)!r},{float(b)!r}" for a, b in zip(T, Z,
                                                                          strict=True)))
    npz = tmp_path / "d.npz"
    np.savez(npz, t=T, z=Z, __units__=np.array(json.dumps({"z": "m"})))
    pq = tmp_path / "d.parquet"
    pd.DataFrame({"t": T, "z [m]": Z}).to_parquet(pq)
    result = winder.Result({"t": T, "z": Z}, {}, units={"t": "s", "z": "m"})
    for source in (csv, npz, pq, result, {"t": T, "z [m]": Z}):
        table = read_table(source)
        np.testing.assert_array_equal(table.t, T)
        np.testing.assert_array_equal(table.columns["z"], Z)
        assert table.units == {"z": "m"}


@pytest.mark.parametrize(("columns", "message"), [
    ({"z [m]": Z}, "no time column 't'"),
    ({"t": [0.1, 0.1, 0.2], "z [m]": Z}, "column 't' is not increasing at row 1"),
    ({"t": T, "z [m]": [0.5, np.inf, 0.5]}, "column 'z' row 1 is inf, not finite"),
    ({"t": T, "z [m]": Z, "z [mm]": Z}, "column 'z' is given twice"),
    ({"t [ms]": T, "z [m]": Z}, "column 't' must be in s"),
])
def test_bad_tables_name_the_column(columns, message):
    with pytest.raises(winder.ArgumentError, match=message):
        read_table(columns)


def test_param_specs():
    assert parse_param("contact.stiffness=1e6:1e9").lo == 1e6
    assert parse_param("contact.stiffness=:1e9").lo is None
    with pytest.raises(winder.ArgumentError, match="need LO < HI"):
        parse_param("contact.stiffness=2:1")
    with pytest.raises(winder.ArgumentError, match="bounds are KEY=LO:HI"):
        parse_param("contact.stiffness=5")
