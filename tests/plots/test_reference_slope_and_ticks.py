"""The reference triangle has the element's optimal slope (−1 for P2, −1/2 for P1), and a
log axis of less than a decade gets tick labels that do not overlap (the ``captured``
fixture measures every label's extent with the figure's renderer)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from signorini.cli import main
from signorini.plots import make_figures, plot_contributions, plot_estimator
from signorini.plots.slopes import optimal_slope

from .figure_checks import synthetic_history, write_csv


def triangle_slope(info: dict) -> float:
    """The slope of the drawn triangle's hypotenuse, in decades per decade."""
    (triangle,) = info["patches"]
    (x0, y0), (x1, y1) = triangle.get_xy()[:2]
    return float(np.log10(y1 / y0) / np.log10(x1 / x0))


def test_the_optimal_slope_follows_the_degree():
    from signorini.fem.element import P1, P2

    assert optimal_slope(P2.degree) == -1.0 and optimal_slope(P1.degree) == -0.5
    with pytest.raises(ValueError, match="degree must be 1"):
        optimal_slope(3)


@pytest.mark.parametrize(("degree", "slope", "text"), [(2, -1.0, "−1"), (1, -0.5, "−0.50")])
def test_make_figures_draw_the_elements_reference_slope(tmp_path, captured, degree, slope, text):
    h = synthetic_history()
    make_figures(write_csv(tmp_path / "h.csv", h), tmp_path, "run", degree=degree)
    assert len(captured) == 3  # error and estimator, efficiency, contributions
    for info in (captured[0], captured[2]):
        assert triangle_slope(info) == pytest.approx(slope, rel=1e-12)
        assert text in info["texts"]
    assert not captured[1]["patches"]  # the efficiency index has no rate


def test_a_p1_run_draws_slope_minus_one_half(tmp_path, captured):
    out = tmp_path / "p1"
    argv = ["run", "example-6.1", "--element", "P1", "--max-ndof", "300", "--out", str(out)]
    assert main([*argv, "--no-vtu", "--quiet"]) == 0
    convergence = {Path(i["file"]).stem: i for i in captured if i["patches"]}
    assert sorted(convergence) == ["example-6.1_contributions", "example-6.1_error_estimator"]
    for info in convergence.values():
        assert triangle_slope(info) == pytest.approx(-0.5, rel=1e-12)


@pytest.mark.parametrize(("lo", "hi"), [(5000, 9000), (640, 3000), (144, 600), (2000, 2600)])
def test_short_runs_get_labels_that_do_not_overlap(tmp_path, captured, lo, hi):
    """5000 to 9000 unknowns once got linear ticks 5×10³, 5.5×10³, … 9×10³, each label into
    the next; now each short axis shows at least two labelled ticks, none overlapping."""
    ndof = np.geomspace(lo, hi, 6).round()
    h = {"ndof": ndof, "eta": 3.0 / ndof}
    for k in range(1, 8):
        h[f"eta_{k}"] = (0.5 + 0.1 * k) * ndof ** (-0.5 - 0.05 * k)
    plot_estimator(h, tmp_path / "e")
    plot_contributions(h, tmp_path / "c")
    for info in captured:  # the fixture failed the save on any overlap
        ax = 0
        lo_view, hi_view = sorted(info["data_lim"][ax].intervalx)
        ticks = np.array(info["xticks"][-1])
        shown = ticks[(ticks >= lo_view * 0.97) & (ticks <= hi_view * 1.03)]
        print(f"{lo}-{hi}: x ticks {shown}")
        assert shown.size >= 2
