"""The CSV history (:mod:`signorini.output.history`): writing, reading back, the columns a
figure needs, and fitted slopes."""

from __future__ import annotations

import csv
import math
import os

import numpy as np
import pytest

import signorini.output.files as files
from signorini.output import HistoryWriter, fitted_slope, read_history
from signorini.output.history import history_columns

NDOF = np.array([150.0, 420.0, 1100.0, 2900.0, 7600.0, 20000.0])


def files_in(folder) -> list[str]:
    return sorted(os.listdir(folder))


# ---------------------------------------------------------------------------- writing
def read_rows(path) -> tuple[list[str], list[dict]]:
    with open(path, newline="") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
        return list(reader.fieldnames or []), rows


def test_history_writer_rewrites_a_parsable_file_after_each_append(tmp_path):
    path = tmp_path / "history.csv"
    history = HistoryWriter(path)
    rows = [
        {
            "level": 0,
            "ndof": 144,
            "eta": 310.85036363636,
            "error_energy": math.nan,
            "backend": "pardiso",
        },
        {
            "level": 1,
            "ndof": 152,
            "eta": 1.2345678901234567e-300,
            "error_energy": 0.1 + 0.2,
            "backend": "scipy",
        },
        {
            "level": 2,
            "ndof": 10**12,
            "eta": 2.0**0.5,
            "error_energy": 7.0,
            "backend": "a,b",
            "extra_column": 3.5,
        },
    ]
    for i, row in enumerate(rows):
        history.append(row)
        assert files_in(tmp_path) == ["history.csv"]
        columns, back = read_rows(path)
        assert len(back) == i + 1
        expected_columns = ["level", "ndof", "eta", "error_energy", "backend"]
        if i == 2:
            expected_columns.append("extra_column")
        assert columns == expected_columns
        for want, got in zip(rows[: i + 1], back, strict=True):
            assert int(got["level"]) == want["level"] and int(got["ndof"]) == want["ndof"]
            assert float(got["eta"]) == want["eta"]  # floats round-trip exactly
            if math.isnan(want["error_energy"]):
                assert got["error_energy"] == "nan"
            else:
                assert float(got["error_energy"]) == want["error_energy"]
            assert got["backend"] == want["backend"]
        if i == 2:
            assert [r["extra_column"] for r in back] == ["", "", "3.5"]


def test_history_writer_keeps_the_old_file_when_writing_fails(tmp_path, monkeypatch):
    path = tmp_path / "history.csv"
    history = HistoryWriter(path)
    history.append({"level": 0, "eta": 1.5})
    before = path.read_bytes()

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(files.os, "replace", fail)
    with pytest.raises(OSError, match="disk full"):
        history.append({"level": 1, "eta": 0.75})
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert files_in(tmp_path) == ["history.csv"]


# ---------------------------------------------------------------------------- reading
def test_read_history_round_trip(tmp_path):
    rows = [
        {"level": 0, "ndof": 146, "eta": 0.125, "error_energy": float("nan"),
         "backend": "scipy", "eta_6": 0.0, "note": ""},
        {"level": 1, "ndof": 402, "eta": 0.0441, "error_energy": 0.03125,
         "backend": "pardiso", "eta_6": 1.5e-17, "note": "x"},
        {"level": 2, "ndof": 1118, "eta": 0.0157, "error_energy": "",
         "backend": "pardiso", "eta_6": 0.0, "note": ""},
    ]  # fmt: skip
    path = tmp_path / "history.csv"
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    h = read_history(path)
    assert list(h) == list(rows[0])
    assert h["level"].dtype == np.int64 and h["ndof"].dtype == np.int64
    np.testing.assert_array_equal(h["ndof"], [146, 402, 1118])
    assert h["eta"].dtype == np.float64
    np.testing.assert_array_equal(h["eta"], [0.125, 0.0441, 0.0157])
    np.testing.assert_array_equal(h["error_energy"], [np.nan, 0.03125, np.nan])
    np.testing.assert_array_equal(h["eta_6"], [0.0, 1.5e-17, 0.0])
    assert h["backend"].dtype.kind == "U"
    assert list(h["backend"]) == ["scipy", "pardiso", "pardiso"]
    assert list(h["note"]) == ["", "x", ""]


def test_what_the_writer_writes_the_reader_reads_bit_for_bit(tmp_path):
    rng = np.random.default_rng(3)
    written = {
        "level": np.arange(5),
        "ndof": np.array([144, 402, 1118, 3000, 10**9]),
        "eta": rng.lognormal(size=5),
        "error_energy": np.r_[np.nan, rng.lognormal(size=4) * 1e-300],
        "backend": np.array(["pardiso", "scipy", "a,b", 'say "x"', "pardiso"]),
    }
    history = HistoryWriter(tmp_path / "history.csv")
    for i in range(5):
        history.append({k: v[i].item() for k, v in written.items()})
    back = read_history(tmp_path / "history.csv")
    assert list(back) == list(written)
    for k, v in written.items():
        np.testing.assert_array_equal(back[k], v, err_msg=k)
        assert back[k].dtype.kind == v.dtype.kind, k


def test_read_history_of_a_header_only_file(tmp_path):
    p = tmp_path / "h.csv"
    p.write_text("level,ndof,eta\n")
    h = read_history(p)
    assert list(h) == ["level", "ndof", "eta"] and all(v.size == 0 for v in h.values())
    with pytest.raises(FileNotFoundError):
        read_history(tmp_path / "missing.csv")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty file"),
        ("level,ndof\n0,10\n1,20,30\n", "line 3 has 3 fields"),
        ("ndof,ndof\n1,2\n", "repeated"),
        ("ndof,\n1,2\n", "empty column name"),
    ],
)
def test_read_history_rejects_a_malformed_file(tmp_path, text, message):
    p = tmp_path / "h.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_history(p)


def test_history_columns_as_floats(tmp_path):
    h = {"ndof": np.array([10, 20]), "eta": np.array([1.0, 0.5]), "note": np.array(["a", "b"])}
    cols = history_columns(h, ("ndof", "eta"), ("error_energy",))
    assert list(cols) == ["ndof", "eta"] and cols["ndof"].dtype == np.float64
    with pytest.raises(ValueError, match=r"lacks column\(s\) \['error_energy'\]"):
        history_columns(h, ("ndof", "error_energy"))
    with pytest.raises(ValueError, match="'note' is not numeric"):
        history_columns(h, ("note",))
    with pytest.raises(ValueError, match="must be 1-d"):
        history_columns({"ndof": np.ones((2, 2))}, ("ndof",))
    with pytest.raises(ValueError, match="mapping"):
        history_columns([1, 2], ("ndof",))


# ---------------------------------------------------------------------------- fitted slopes
@pytest.mark.parametrize("const", [3.0, 2.0, 0.01])
def test_fitted_slope_recovers_minus_one(const):
    for last in (3, len(NDOF)):
        slope = fitted_slope(NDOF, const / NDOF, last=last)
        assert abs(slope + 1.0) < 1e-12, f"observed rate {slope!r} over {last} levels, not -1"


def test_fitted_slope_uses_only_the_last_points():
    # rate -1/2 on the first three levels, -1 on the last three (continuous at NDOF[2])
    values = np.where(np.arange(NDOF.size) <= 2, NDOF**-0.5, NDOF[2] ** 0.5 / NDOF)
    last3, first3 = fitted_slope(NDOF, values, last=3), fitted_slope(NDOF[:3], values[:3])
    assert abs(last3 + 1.0) < 1e-12, f"observed rate {last3} on the last three levels"
    assert abs(first3 + 0.5) < 1e-12, f"observed rate {first3} on the first three levels"
    expected = np.polyfit(np.log(NDOF), np.log(values), 1)[0]
    assert fitted_slope(NDOF, values, last=6) == pytest.approx(expected, rel=1e-12)
    assert -1.0 < expected < -0.5


def test_fitted_slope_matches_polyfit_on_noisy_data():
    rng = np.random.default_rng(7)
    values = 5.0 * NDOF**-0.8 * np.exp(0.2 * rng.standard_normal(NDOF.size))
    for last in (2, 4, 6):
        expected = np.polyfit(np.log(NDOF[-last:]), np.log(values[-last:]), 1)[0]
        assert fitted_slope(NDOF, values, last=last) == pytest.approx(expected, rel=1e-10)


def test_fitted_slope_skips_nan_and_zero():
    values = 3.0 / NDOF
    values[[1, 4]] = [np.nan, 0.0]
    # valid points: 0, 2, 3, 5 -> the last three are 2, 3, 5, all on the line
    noisy = values.copy()
    noisy[0] = 1.0  # outside the last three valid points: no influence
    for v in (values, noisy):
        slope = fitted_slope(NDOF, v)
        assert abs(slope + 1.0) < 1e-12, f"observed rate {slope}"


@pytest.mark.parametrize(
    ("ndof", "values", "last", "match"),
    [
        ([100.0], [1.0], 3, "at least 2"),
        ([100.0, 200.0, 400.0], [np.nan, 0.0, 1.0], 3, "at least 2"),
        ([100.0, 200.0], [1.0, 0.5], 1, "last"),
        ([100.0, 200.0], [1.0, 0.5], 2.5, "last"),
        ([100.0, 200.0], [1.0, 0.5], True, "last"),
        ([100.0, 200.0], [1.0, 0.5, 0.2], 3, "equal length"),
        ([[100.0, 200.0]], [[1.0, 0.5]], 3, "1-d"),
        ([100.0, 100.0], [1.0, 0.5], 3, "distinct"),
        (["a", "b"], [1.0, 0.5], 3, "numeric"),
    ],
)
def test_fitted_slope_rejects_bad_input(ndof, values, last, match):
    with pytest.raises(ValueError, match=match):
        fitted_slope(ndof, values, last=last)
