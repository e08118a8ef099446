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
from signorini.plots.slopes import finer_half_slope
from signorini.plots.style import NDOF_LABEL, SINGLE_COLUMN

from .figure_checks import NDOF, check_written, legend_slope, synthetic_history, write_csv


def check_legend_slopes(info: dict, last: int | None = None) -> dict[str, float]:
    """Every stated slope is the fitted slope of its own line (over the finer half of the run,
    or the last ``last`` levels), to the two decimals shown; returns the stated slope of each
    label's prefix."""
    stated = {}
    for label, (x, y) in info["lines"].items():
        slope = legend_slope(label)
        if slope is None:
            continue
        observed = fitted_slope(x, y, last=last) if last else finer_half_slope(x, y)
        assert slope == pytest.approx(round(observed, 2), abs=1e-12), (
            f"{label!r} states {slope}, the line's fitted slope is {observed:.4f}"
        )
        stated[label.rsplit(", slope", 1)[0]] = slope
    return stated


@pytest.mark.slow
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
    stated = check_legend_slopes(info)
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


@pytest.mark.slow
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


@pytest.mark.slow
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


@pytest.mark.slow
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
    stated = check_legend_slopes(info)
    for k in (1, 3, 5):
        assert stated[rf"$\eta_{k}$"] == pytest.approx(round(-0.5 - 0.1 * k, 2))
    (x, y) = next(v for k, v in info["lines"].items() if k.startswith(r"$\eta_4$"))
    assert np.isnan(y[2]) and np.all(np.isfinite(np.delete(y, 2)))
    # ... and the zero is drawn on the ≈0 strip, with the zeros of eta_2 and eta_6
    strip = info["lines_by_axes"][1]
    assert sorted(len(xs) for xs, _ in strip) == [1, 6, 6]
    assert any(np.array_equal(xs, [NDOF[2]]) for xs, _ in strip)


def test_estimator_figure_and_suffix_kept(tmp_path, captured):
    ndof = np.array([150.0, 240.0, 400.0, 700.0, 1200.0, 2000.0])  # only 1.1 decades
    h = {"ndof": ndof, "eta": 4.0 * ndof**-0.75}
    written = plot_estimator(h, tmp_path / "fig6.3")  # ".3" is not an image suffix
    check_written(written, tmp_path / "fig6.3")
    stated = check_legend_slopes(captured[0])
    assert stated == {STYLES["eta"]["label"]: -0.75}
    # a short log axis gets 2 and 5 times powers of ten as labelled major ticks
    assert {200.0, 500.0, 1000.0, 2000.0} <= set(captured[0]["xticks"][0])


@pytest.mark.slow
def test_adaptive_vs_uniform_figure(tmp_path, captured):
    uniform_ndof = np.array([150.0, 560.0, 2200.0, 8700.0])
    histories = {
        "adaptive": synthetic_history(),
        "uniform": {"ndof": uniform_ndof, "eta": 2.0 * uniform_ndof ** (-2.0 / 3.0)},
    }
    written = plot_adaptive_vs_uniform(histories, tmp_path / "cmp", key="eta")
    check_written(written, tmp_path / "cmp")
    (info,) = captured
    stated = check_legend_slopes(info)
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


def test_slopes_are_fitted_over_the_finer_half_and_the_legend_says_so(tmp_path, captured):
    ndof = np.geomspace(100.0, 10_000.0, 13)  # the finer half: N_dof >= 1000, 7 levels
    eta = 3.0 / ndof
    eta[-3:] *= np.array([0.8, 1.0, 1.3])  # the last three levels wobble
    plot_estimator({"ndof": ndof, "eta": eta}, tmp_path / "est")
    (info,) = captured
    stated = check_legend_slopes(info)
    half = fitted_slope(ndof[6:], eta[6:], last=7)
    last3 = fitted_slope(ndof, eta, last=3)
    print(f"finer half {half:.3f}, last three {last3:.3f}, stated {stated}")
    assert stated == {STYLES["eta"]["label"]: round(half, 2)}
    assert abs(half + 1.0) < 0.12 and last3 > -0.5  # the last three levels alone mislead
    assert info["caption"] == r"slopes: least squares on $N_{\mathrm{dof}} \geq 1000$"


@pytest.mark.slow
def test_zero_and_round_off_terms_sit_on_the_zero_strip(tmp_path, captured):
    h = synthetic_history(zero_terms=("eta_6",))
    eta7 = h["eta_7"].copy()
    h["eta_7"][[1, 4]] = [1e-17, 0.0]  # round-off on level 1, exactly zero on level 4
    plot_contributions(h, tmp_path / "c")
    (info,) = captured
    # the log axis keeps the meaningful range: nothing below the smallest real value / 10
    smallest = min(np.min(h[k][h[k] > 1e-12]) for k in ("eta_1", "eta_5", "eta_7"))
    assert info["scales"][0] == ("log", "log") and info["ylim"][0][0] > smallest / 10
    # eta_6 (zero everywhere) and eta_7's two levels on the strip, nothing else
    strip = sorted(tuple(x) for x, _ in info["lines_by_axes"][1])
    assert strip == sorted([tuple(NDOF), tuple(NDOF[[1, 4]])])
    assert info["yticklabels"][1] == [r"$\approx$0"]
    assert info["legend_title"].endswith(r"round-off below $10^{-10}\,\eta_h$")
    # eta_7 is zero on a level of the fit window (level 4): no slope is printed for it, while
    # a slope fitted on its real values alone would be a clean -1.2
    label = next(t for t in info["legend"] if t.startswith(r"$\eta_7$"))
    keep = np.isin(np.arange(NDOF.size), [1, 4], invert=True)
    assert round(finer_half_slope(NDOF[keep], eta7[keep]), 2) == -1.2
    assert label == r"$\eta_7$ (no steady rate)"
    assert r"$\eta_6 \equiv 0$" in info["legend"]


@pytest.mark.slow
def test_a_term_at_round_off_on_every_level_is_named_so(tmp_path, captured):
    h = synthetic_history(zero_terms=())
    h["eta_7"] = 1e-17 * np.ones(NDOF.size)
    plot_contributions(h, tmp_path / "c")
    assert captured[0]["legend"][-1] == r"$\eta_7 \approx 0$ (round-off)"
