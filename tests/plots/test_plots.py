"""Tests of :mod:`signorini.plots`: slopes, the CSV history, slope triangles and the figures."""

from __future__ import annotations

import csv
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from signorini.plots import (
    add_slope_triangle,
    fitted_slope,
    make_figures,
    plot_adaptive_vs_uniform,
    plot_contributions,
    plot_deformed,
    plot_efficiency,
    plot_error_and_estimator,
    plot_estimator,
    plot_mesh,
    read_history,
)
from signorini.plots import figures as plots

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
NDOF = np.array([150.0, 420.0, 1100.0, 2900.0, 7600.0, 20000.0])


def synthetic_history(zero_terms: tuple[str, ...] = ("eta_6", "eta_7")) -> dict[str, np.ndarray]:
    """eta = 3 / ndof, error = 2 / ndof, eta_k = c_k / ndof (zero for ``zero_terms``)."""
    n = NDOF.size
    h = {
        "level": np.arange(n),
        "ndof": NDOF.astype(np.int64),
        "n_cells": (NDOF / 6).astype(np.int64),
        "eta": 3.0 / NDOF,
        "error_energy": 2.0 / NDOF,
        "error_h1": 2.5 / NDOF,
        "efficiency": np.full(n, 1.5),
        "pdas_iterations": np.full(n, 2),
        "n_active": np.arange(n) * 4,
    }
    for k in range(1, 8):
        h[f"eta_{k}"] = np.zeros(n) if f"eta_{k}" in zero_terms else (0.3 * k) / NDOF
    return h


def png_size(path: Path) -> tuple[int, int]:
    """Width and height from the IHDR chunk of a PNG file."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def check_written(paths: list[Path], stem: Path, width_in: float | None = None) -> None:
    """``paths`` are ``<stem>.png`` and ``<stem>.pdf``, both real, non-trivial files."""
    assert [Path(p) for p in paths] == [Path(f"{stem}.png"), Path(f"{stem}.pdf")]
    png, pdf = (Path(p) for p in paths)
    assert png.read_bytes()[:8] == PNG_SIGNATURE
    assert png.stat().st_size > 5000
    assert pdf.read_bytes()[:5] == b"%PDF-"
    assert pdf.stat().st_size > 5000
    if width_in is not None:  # 150 dpi
        assert png_size(png)[0] == round(width_in * plots.DPI)


@pytest.fixture
def captured(monkeypatch):
    """Record the texts of every figure just before it is saved."""
    seen: list[dict] = []
    original = plots._save

    def spy(fig, path):
        legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
        seen.append(
            {
                "legend": [t.get_text() for lg in legends for t in lg.get_texts()],
                "xlabel": [ax.get_xlabel() for ax in fig.axes],
                "ylabel": [ax.get_ylabel() for ax in fig.axes],
                "scales": [(ax.get_xscale(), ax.get_yscale()) for ax in fig.axes],
                "texts": [t.get_text() for ax in fig.axes for t in ax.texts],
                "n_axes": len(fig.axes),
                "xticks": [list(ax.get_xticks()) for ax in fig.axes],
            }
        )
        return original(fig, path)

    monkeypatch.setattr(plots, "_save", spy)
    return seen


# --------------------------------------------------------------------------------------------
# fitted_slope
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("const", [3.0, 2.0, 0.01])
def test_fitted_slope_recovers_minus_one(const):
    assert abs(fitted_slope(NDOF, const / NDOF) - (-1.0)) < 1e-12
    assert abs(fitted_slope(NDOF, const / NDOF, last=len(NDOF)) - (-1.0)) < 1e-12


def test_fitted_slope_uses_only_the_last_points():
    # rate -1/2 on the first three levels, -1 on the last three (continuous at NDOF[2])
    values = np.where(np.arange(NDOF.size) <= 2, NDOF**-0.5, NDOF[2] ** 0.5 / NDOF)
    assert abs(fitted_slope(NDOF, values, last=3) + 1.0) < 1e-12
    assert abs(fitted_slope(NDOF[:3], values[:3], last=3) + 0.5) < 1e-12
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
    assert abs(fitted_slope(NDOF, values) + 1.0) < 1e-12
    noisy = values.copy()
    noisy[0] = 1.0  # outside the last three valid points: no influence
    assert abs(fitted_slope(NDOF, noisy) + 1.0) < 1e-12


@pytest.mark.parametrize(
    ("ndof", "values", "last", "match"),
    [
        ([100.0], [1.0], 3, "at least 2"),
        ([100.0, 200.0, 400.0], [np.nan, 0.0, 1.0], 3, "at least 2"),
        ([100.0, 200.0], [1.0, 0.5], 1, "last"),
        ([100.0, 200.0], [1.0, 0.5], 2.5, "last"),
        ([100.0, 200.0], [1.0, 0.5, 0.2], 3, "equal length"),
        ([[100.0, 200.0]], [[1.0, 0.5]], 3, "1-d"),
        ([100.0, 100.0], [1.0, 0.5], 3, "distinct"),
    ],
)
def test_fitted_slope_rejects_bad_input(ndof, values, last, match):
    with pytest.raises(ValueError, match=match):
        fitted_slope(ndof, values, last=last)


# --------------------------------------------------------------------------------------------
# read_history
# --------------------------------------------------------------------------------------------
def test_read_history_round_trip(tmp_path):
    rows = [
        {
            "level": 0,
            "ndof": 146,
            "eta": 0.125,
            "error_energy": float("nan"),
            "backend": "scipy",
            "eta6": 0.0,
            "note": "",
        },
        {
            "level": 1,
            "ndof": 402,
            "eta": 0.0441,
            "error_energy": 0.03125,
            "backend": "pardiso",
            "eta6": 1.5e-17,
            "note": "x",
        },
        {
            "level": 2,
            "ndof": 1118,
            "eta": 0.0157,
            "error_energy": "",
            "backend": "pardiso",
            "eta6": 0.0,
            "note": "",
        },
    ]
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
    np.testing.assert_array_equal(h["eta6"], [0.0, 1.5e-17, 0.0])
    assert h["backend"].dtype.kind == "U"
    assert list(h["backend"]) == ["scipy", "pardiso", "pardiso"]
    assert list(h["note"]) == ["", "x", ""]


def test_read_history_of_the_run_writer(tmp_path):
    io = pytest.importorskip("signorini.output")
    writer = io.HistoryWriter(tmp_path / "history.csv")
    h0 = synthetic_history()
    for i in range(NDOF.size):
        row = {k: v[i].item() for k, v in h0.items()}
        if i == 0:
            row["efficiency"] = math.nan
        writer.append(row)
    h = read_history(tmp_path / "history.csv")
    assert set(h) == set(h0)
    for k, v in h0.items():
        expected = np.array(v, dtype=float)
        if k == "efficiency":
            expected[0] = np.nan
        np.testing.assert_array_equal(h[k].astype(float), expected, err_msg=k)


def test_read_history_header_only_and_bad_files(tmp_path):
    p = tmp_path / "h.csv"
    p.write_text("level,ndof,eta\n")
    h = read_history(p)
    assert list(h) == ["level", "ndof", "eta"] and all(v.size == 0 for v in h.values())
    p.write_text("")
    with pytest.raises(ValueError, match="empty"):
        read_history(p)
    p.write_text("level,ndof\n0,10\n1,20,30\n")
    with pytest.raises(ValueError, match="line 3 has 3 fields"):
        read_history(p)
    p.write_text("ndof,ndof\n1,2\n")
    with pytest.raises(ValueError, match="repeated"):
        read_history(p)
    with pytest.raises(FileNotFoundError):
        read_history(tmp_path / "missing.csv")


# --------------------------------------------------------------------------------------------
# slope triangle (no drawing)
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("slope", [-1.0, -1.5, 0.5])
def test_slope_triangle_has_the_slope_and_sits_below_the_data(slope):
    fig = Figure()
    ax = fig.add_subplot()
    ax.set_xscale("log")
    ax.set_yscale("log")
    err, eta = 2.0 / NDOF, 3.0 / NDOF
    eta_gappy = eta.copy()
    eta_gappy[3] = 0.0
    tri = add_slope_triangle(ax, NDOF, [err, eta_gappy], slope=slope)
    v = np.log10(tri.get_xy()[:3])
    (x0, y0), (x1, y1), corner = v
    assert (y1 - y0) / (x1 - x0) == pytest.approx(slope, rel=1e-12)
    # right angle: the corner shares x with one end and y with the other
    np.testing.assert_allclose(corner, (x0, y1) if slope < 0 else (x1, y0), rtol=1e-12)
    # inside the data's x range, and every vertex below both curves
    lx = np.log10(NDOF)
    assert lx[0] <= v[:, 0].min() and v[:, 0].max() <= lx[-1]
    for curve in (err, eta):
        assert np.all(v[:, 1] < np.interp(v[:, 0], lx, np.log10(curve)))
    # ... but near them: within a decade below the lower curve
    assert np.all(v[:, 1] > np.interp(v[:, 0], lx, np.log10(err)) - 1.5)
    labels = [t.get_text() for t in ax.texts]
    assert "1" in labels
    assert any(s.replace("\u2212", "-") in (f"{slope:.0f}", f"{slope:.2f}") for s in labels)


def test_slope_triangle_without_data_is_skipped():
    fig = Figure()
    ax = fig.add_subplot()
    assert add_slope_triangle(ax, NDOF, [np.zeros(NDOF.size)]) is None
    assert not ax.patches


# --------------------------------------------------------------------------------------------
# figures
# --------------------------------------------------------------------------------------------
def test_error_and_estimator_figure(tmp_path, captured):
    import matplotlib.pyplot as plt

    stem = tmp_path / "nested" / "dir" / "fig6.1a"
    written = plot_error_and_estimator(synthetic_history(), stem, title="Example 6.1")
    check_written(written, stem, width_in=plots.SINGLE_COLUMN)
    (info,) = captured
    assert info["scales"] == [("log", "log")]
    assert info["xlabel"] == [r"$N_{\mathrm{dof}}$"]
    assert info["legend"] == [
        r"$\|u-u_h\|_a$, slope " + "\u22121.00",
        r"$\eta_h$, slope " + "\u22121.00",
    ]
    assert "1" in info["texts"] and "\u22121" in info["texts"]
    assert plt.get_fignums() == []  # nothing left open in pyplot


def test_efficiency_figure_from_csv_path(tmp_path, captured):
    h = synthetic_history()
    path = tmp_path / "history.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(h))
        w.writerows(zip(*(v.tolist() for v in h.values()), strict=True))
    written = plot_efficiency(path, tmp_path / "eff.png")  # a .png suffix is dropped
    check_written(written, tmp_path / "eff")
    (info,) = captured
    assert info["scales"] == [("log", "linear")]
    assert "mean 1.50" in info["legend"]


def test_contributions_with_vanishing_terms(tmp_path, captured):
    h = synthetic_history(zero_terms=("eta_6", "eta_7"))
    h["eta_4"][2] = 0.0  # a single zero leaves a gap, not an error
    written = plot_contributions(h, tmp_path / "contrib")
    check_written(written, tmp_path / "contrib")
    (info,) = captured
    legend = info["legend"]
    assert r"$\eta_6 \equiv 0$" in legend and r"$\eta_7 \equiv 0$" in legend
    assert r"$\eta_1$, slope " + "\u22121.00" in legend
    assert r"$\eta_4$, slope " + "\u22121.00" in legend
    assert len(legend) == 7


def test_estimator_figure_and_suffix_kept(tmp_path, captured):
    ndof = np.array([150.0, 240.0, 400.0, 700.0, 1200.0, 2000.0])  # only 1.1 decades
    h = {"ndof": ndof, "eta": 4.0 * ndof**-0.75}
    written = plot_estimator(h, tmp_path / "fig6.3")  # ".3" is not an image suffix
    check_written(written, tmp_path / "fig6.3")
    assert captured[0]["legend"] == [r"$\eta_h$, slope " + "\u22120.75"]
    # a short log axis gets 2 and 5 times powers of ten as labelled major ticks
    assert {200.0, 500.0, 1000.0, 2000.0} <= set(captured[0]["xticks"][0])


def test_adaptive_vs_uniform_figure(tmp_path, captured):
    adaptive = synthetic_history()
    uniform = {
        "ndof": np.array([150, 560, 2200, 8700]),
        "eta": 2.0 * np.array([150, 560, 2200, 8700.0]) ** -(2.0 / 3.0),
    }
    written = plot_adaptive_vs_uniform(
        {"adaptive": adaptive, "uniform": uniform}, tmp_path / "cmp", key="eta"
    )
    check_written(written, tmp_path / "cmp")
    assert captured[0]["legend"] == ["adaptive, slope \u22121.00", "uniform, slope \u22120.67"]


def square_mesh(n: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """Unit square, n x n squares each cut along a diagonal, counter-clockwise."""
    x = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(x, x)
    points = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    b, c, d = a + 1, a + n + 2, a + n + 1
    cells = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return points, cells


def test_mesh_figure(tmp_path, captured):
    p, c = square_mesh()
    bottom = np.column_stack([np.arange(6), np.arange(1, 7)])
    written = plot_mesh(p, c, tmp_path / "mesh", title="mesh", highlight=bottom)
    check_written(written, tmp_path / "mesh")
    assert captured[0]["legend"] == [r"contact boundary $\Gamma_C$"]


def test_deformed_figure_with_pressure_and_obstacle(tmp_path, captured):
    p, c = square_mesh()
    u = np.column_stack([0.05 * p[:, 1], -0.02 * p[:, 0]])
    n_extra = 10  # P2 midpoint rows after the vertices are ignored
    u_p2 = np.vstack([u, np.full((n_extra, 2), 99.0)])
    right = p[np.isclose(p[:, 0], 1.0)]
    pressure = 1.0 - np.abs(right[:, 1] - 0.5)
    y = np.linspace(0.0, 1.0, 11)
    obstacle = np.column_stack([1.0 - 0.2 + 0.5 * np.abs(y - 0.5), y])
    written = plot_deformed(
        p,
        c,
        u_p2,
        tmp_path / "deformed",
        contact_points=right,
        pressure=pressure,
        scale=3.0,
        obstacle=obstacle,
    )
    check_written(written, tmp_path / "deformed")
    (info,) = captured
    assert info["xlabel"][:2] == [r"$x$", r"$y$"]  # pressure against y on x = 1
    assert info["legend"] == ["reference", "obstacle"]


# --------------------------------------------------------------------------------------------
# input checking (no drawing)
# --------------------------------------------------------------------------------------------
def test_bad_inputs_raise_value_errors(tmp_path):
    p, c = square_mesh(2)
    h = synthetic_history()
    with pytest.raises(ValueError, match="lacks column"):
        plot_estimator({"ndof": NDOF}, tmp_path / "x")
    with pytest.raises(ValueError, match="no positive finite error_energy"):
        plot_error_and_estimator({**h, "error_energy": np.full(NDOF.size, np.nan)}, tmp_path / "x")
    with pytest.raises(ValueError, match="different lengths"):
        plot_estimator({"ndof": NDOF, "eta": 1 / NDOF[:-1]}, tmp_path / "x")
    with pytest.raises(ValueError, match="ndof must be positive"):
        plot_estimator({"ndof": np.r_[0.0, NDOF[1:]], "eta": 1 / NDOF}, tmp_path / "x")
    with pytest.raises(ValueError, match="empty"):
        plot_estimator({"ndof": np.array([]), "eta": np.array([])}, tmp_path / "x")
    with pytest.raises(ValueError, match="not numeric"):
        plot_estimator({"ndof": NDOF, "eta": np.array(["a"] * NDOF.size)}, tmp_path / "x")
    with pytest.raises(ValueError, match="last must be"):
        plot_contributions(h, tmp_path / "x", last=1)
    with pytest.raises(ValueError, match="non-empty mapping"):
        plot_adaptive_vs_uniform({}, tmp_path / "x")
    with pytest.raises(ValueError, match="outside"):
        plot_mesh(p, c + 100, tmp_path / "x")
    with pytest.raises(ValueError, match="integer"):
        plot_mesh(p, c.astype(float), tmp_path / "x")
    with pytest.raises(ValueError, match="highlight"):
        plot_mesh(p, c, tmp_path / "x", highlight=np.array([[0, 99]]))
    with pytest.raises(ValueError, match="displacement"):
        plot_deformed(p, c, np.zeros((3, 2)), tmp_path / "x")
    with pytest.raises(ValueError, match="together"):
        plot_deformed(p, c, np.zeros_like(p), tmp_path / "x", pressure=np.ones(3))
    with pytest.raises(ValueError, match="pressure must have shape"):
        plot_deformed(
            p, c, np.zeros_like(p), tmp_path / "x", contact_points=p[:3], pressure=np.ones(4)
        )
    with pytest.raises(ValueError, match="not a file path"):
        plot_estimator(h, "")
    assert not any(tmp_path.iterdir())


def test_contact_coordinate_is_arclength_on_a_slanted_boundary():
    s = np.array([0.0, 0.3, 0.45, 1.0])
    d = np.array([3.0, 4.0]) / 5.0
    pts = np.array([2.0, -1.0]) + s[:, None] * d
    order = np.array([2, 0, 3, 1])
    t, label = plots._contact_coordinate(pts[order])
    np.testing.assert_allclose(t, s[order], atol=1e-14)
    assert "s" in label
    t, label = plots._contact_coordinate(np.column_stack([s, np.zeros(4)]))
    assert label == r"$x$" and np.array_equal(t, s)


@pytest.mark.parametrize(
    ("name", "kind"),
    [
        ("example-6.1", "6.1"),
        ("6.2", "6.2"),
        ("ex6_1", "6.1"),
        ("example_6_2", "6.2"),
        ("example-6.12", None),
        ("square", None),
    ],
)
def test_example_names(name, kind):
    assert plots._example_kind(name) == kind


# --------------------------------------------------------------------------------------------
# make_figures (several figures each: slow)
# --------------------------------------------------------------------------------------------
def write_csv(path: Path, h: dict[str, np.ndarray]) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(h))
        w.writerows(zip(*(v.tolist() for v in h.values()), strict=True))
    return path


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "figures"),
    [
        ("example-6.1", ["error_estimator", "efficiency", "contributions"]),
        ("example-6.2", ["estimator", "contributions"]),
    ],
)
def test_make_figures(tmp_path, name, figures):
    h = synthetic_history()
    if name.endswith("6.2"):
        h["error_energy"][:] = np.nan
        h["efficiency"][:] = np.nan
    csv_path = write_csv(tmp_path / "history.csv", h)
    written = make_figures(csv_path, tmp_path / "figs", name)
    expected = [tmp_path / "figs" / f"{name}_{f}.{ext}" for f in figures for ext in ("png", "pdf")]
    assert written == expected
    for i in range(0, len(written), 2):
        check_written(written[i : i + 2], written[i].with_suffix(""))
