"""The convergence figures (:mod:`signorini.plots.convergence`): each draws the history's
columns against N_dof, and every slope its legend states is the fitted slope of the line
drawn."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from signorini.output import fitted_slope
from signorini.plots import (
    STYLES,
    plot_adaptive_vs_uniform,
    plot_contributions,
    plot_efficiency,
    plot_error_and_estimator,
    plot_estimator,
)
from signorini.plots.style import NDOF_LABEL, SINGLE_COLUMN

from .figure_checks import NDOF, check_written, legend_slope, synthetic_history, write_csv


def check_legend_slopes(info: dict, last: int) -> dict[str, float]:
    """Every stated slope is the fitted slope of its own line, to the two decimals shown;
    returns the stated slope of each label's prefix."""
    stated = {}
    for label, (x, y) in info["lines"].items():
        slope = legend_slope(label)
        if slope is None:
            continue
        observed = fitted_slope(x, y, last=last)
        assert slope == pytest.approx(round(observed, 2), abs=1e-12), (
            f"{label!r} states {slope}, the line's fitted slope is {observed:.4f}"
        )
        stated[label.rsplit(", slope", 1)[0]] = slope
    return stated


def test_error_and_estimator_figure(tmp_path, captured):
    import matplotlib.pyplot as plt

    h = synthetic_history()
    h["eta"] = 3.0 * NDOF**-0.8  # a rate of its own, so a mixed-up label would show
    stem = tmp_path / "nested" / "dir" / "fig6.1a"
    written = plot_error_and_estimator(h, stem, title="Example 6.1")
    check_written(written, stem, width_in=SINGLE_COLUMN)
    (info,) = captured
    assert info["scales"] == [("log", "log")] and info["xlabel"] == [NDOF_LABEL]
    assert info["titles"] == ["Example 6.1"]
    stated = check_legend_slopes(info, last=3)
    err_label, eta_label = STYLES["error_energy"]["label"], STYLES["eta"]["label"]
    assert list(stated) == [err_label, eta_label]
    assert stated[err_label] == pytest.approx(-1.0) and stated[eta_label] == pytest.approx(-0.8)
    # the lines are the history's columns
    for label, key in ((err_label, "error_energy"), (eta_label, "eta")):
        (x, y) = next(v for k, v in info["lines"].items() if k.startswith(label))
        np.testing.assert_array_equal(x, NDOF)
        np.testing.assert_array_equal(y, h[key])
    # the reference triangle has slope −1 and is labelled so
    assert "\u22121" in info["texts"] and len(info["patches"]) == 1
    assert plt.get_fignums() == []  # nothing left open in pyplot


@pytest.mark.parametrize("last", [2, 4])
def test_stated_slopes_follow_last(tmp_path, captured, last):
    """Rate −1/2 on the first levels, −1 on the last: the stated slope depends on how many
    final levels are fitted, and always matches the fit of the line drawn."""
    values = np.where(np.arange(NDOF.size) <= 2, NDOF**-0.5, NDOF[2] ** 0.5 / NDOF)
    plot_estimator({"ndof": NDOF, "eta": values}, tmp_path / "est", last=last)
    stated = check_legend_slopes(captured[0], last=last)
    expected = fitted_slope(NDOF, values, last=last)
    print(f"last={last}: stated {stated}, fitted {expected:.4f}")
    assert stated == {STYLES["eta"]["label"]: round(expected, 2)}


def test_efficiency_figure_from_csv_path(tmp_path, captured):
    h = synthetic_history()
    h["efficiency"] = np.array([np.nan, 1.2, 1.4, 1.5, 1.6, 1.6])
    path = write_csv(tmp_path / "history.csv", h)
    written = plot_efficiency(path, tmp_path / "eff.png")  # a .png suffix is dropped
    check_written(written, tmp_path / "eff")
    (info,) = captured
    assert info["scales"] == [("log", "linear")]
    # where the efficiency is unknown, eta / error is drawn
    (x, y) = info["lines"][STYLES["efficiency"]["label"]]
    np.testing.assert_allclose(y, np.r_[1.5, h["efficiency"][1:]], rtol=1e-15)
    mean = np.mean(y)
    (label,) = [k for k in info["lines"] if k.startswith("mean ")]
    assert float(label.split()[1]) == pytest.approx(mean, abs=5e-3)
    np.testing.assert_allclose(info["lines"][label][1], mean)
    assert info["ylim"][0] == pytest.approx((0.0, 1.2 * y.max()))


def test_contributions_draw_each_known_term_and_list_vanishing_ones(tmp_path, captured, caplog):
    h = synthetic_history(zero_terms=("eta_2", "eta_6"))
    h["eta_4"][2] = 0.0  # a single zero leaves a gap, not an error
    h["eta_7"][:] = np.nan  # unknown on every level: skipped with a warning
    with caplog.at_level(logging.WARNING):
        written = plot_contributions(h, tmp_path / "contrib")
    check_written(written, tmp_path / "contrib")
    (info,) = captured
    # legend in the order eta_1 ... eta_7; eta_2 and eta_6 listed as identically zero
    prefixes = [t.split(",")[0] for t in info["legend"]]
    assert prefixes == [
        r"$\eta_1$",
        r"$\eta_2 \equiv 0$",
        r"$\eta_3$",
        r"$\eta_4$",
        r"$\eta_5$",
        r"$\eta_6 \equiv 0$",
    ]
    assert "eta_7" in caplog.text
    stated = check_legend_slopes(info, last=3)
    for k in (1, 3, 5):
        assert stated[rf"$\eta_{k}$"] == pytest.approx(round(-0.5 - 0.1 * k, 2))
    (x, y) = next(v for k, v in info["lines"].items() if k.startswith(r"$\eta_4$"))
    assert np.isnan(y[2]) and np.all(np.isfinite(np.delete(y, 2)))


def test_estimator_figure_and_suffix_kept(tmp_path, captured):
    ndof = np.array([150.0, 240.0, 400.0, 700.0, 1200.0, 2000.0])  # only 1.1 decades
    h = {"ndof": ndof, "eta": 4.0 * ndof**-0.75}
    written = plot_estimator(h, tmp_path / "fig6.3")  # ".3" is not an image suffix
    check_written(written, tmp_path / "fig6.3")
    stated = check_legend_slopes(captured[0], last=3)
    assert stated == {STYLES["eta"]["label"]: -0.75}
    # a short log axis gets 2 and 5 times powers of ten as labelled major ticks
    assert {200.0, 500.0, 1000.0, 2000.0} <= set(captured[0]["xticks"][0])


def test_adaptive_vs_uniform_figure(tmp_path, captured):
    uniform_ndof = np.array([150.0, 560.0, 2200.0, 8700.0])
    histories = {
        "adaptive": synthetic_history(),
        "uniform": {"ndof": uniform_ndof, "eta": 2.0 * uniform_ndof ** (-2.0 / 3.0)},
    }
    written = plot_adaptive_vs_uniform(histories, tmp_path / "cmp", key="eta")
    check_written(written, tmp_path / "cmp")
    (info,) = captured
    stated = check_legend_slopes(info, last=3)
    assert stated == {"adaptive": -1.0, "uniform": -0.67}
    assert info["ylabel"] == [STYLES["eta"]["label"]]
    # a column without a style is labelled by its name; no triangle when asked for none
    plot_adaptive_vs_uniform(histories, tmp_path / "n", key="ndof", reference_slope=None)
    assert captured[1]["ylabel"] == ["ndof"] and not captured[1]["patches"]


def test_bad_inputs_raise_value_errors(tmp_path):
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
    with pytest.raises(ValueError, match="eta_1"):
        plot_contributions({"ndof": NDOF, "eta": 1 / NDOF}, tmp_path / "x")
    with pytest.raises(ValueError, match="no positive finite efficiency"):
        plot_efficiency({"ndof": NDOF, "efficiency": np.zeros(NDOF.size)}, tmp_path / "x")
    with pytest.raises(ValueError, match="non-empty mapping"):
        plot_adaptive_vs_uniform({}, tmp_path / "x")
    assert not any(tmp_path.iterdir())
