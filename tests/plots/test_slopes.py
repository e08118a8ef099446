"""Slope triangles and slope labels (:mod:`signorini.plots.slopes`)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from signorini.plots import add_slope_triangle
from signorini.plots.slopes import FIT_SCATTER, slope_label, steady_slope, triangle_vertices

from .figure_checks import NDOF, legend_slope


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
    observed = (y1 - y0) / (x1 - x0)
    assert observed == pytest.approx(slope, rel=1e-12), f"hypotenuse slope {observed}"
    # right angle: the corner shares x with one end and y with the other
    np.testing.assert_allclose(corner, (x0, y1) if slope < 0 else (x1, y0), rtol=1e-12)
    # inside the data's x range, and every vertex below both curves
    lx = np.log10(NDOF)
    assert lx[0] <= v[:, 0].min() and v[:, 0].max() <= lx[-1]
    for curve in (err, eta):
        assert np.all(v[:, 1] < np.interp(v[:, 0], lx, np.log10(curve)))
    # ... but near them: within a decade and a half below the lower curve
    assert np.all(v[:, 1] > np.interp(v[:, 0], lx, np.log10(err)) - 1.5)
    # the legs are labelled 1 and with the slope
    labels = [t.get_text().replace("\u2212", "-") for t in ax.texts]
    assert sorted(labels) == sorted(["1", f"{slope:.0f}" if slope.is_integer() else f"{slope:.2f}"])


def test_triangle_lies_below_every_curve_with_its_own_abscissae():
    low = (np.array([100.0, 1000.0, 10_000.0]), np.array([1e-2, 1e-3, 1e-4]))
    high = (np.array([300.0, 3000.0]), np.array([1.0, 0.1]))
    v = triangle_vertices([low, high], slope=-1.0)
    lv = np.log10(v)
    gap = max(0.12, 0.06 * 4.0)  # the curves span 4 decades in y
    below = np.interp(lv[:, 0], np.log10(low[0]), np.log10(low[1])) - lv[:, 1]
    print(f"vertices {v.tolist()}, distance below the lower curve {below}")
    assert below.min() == pytest.approx(gap, rel=1e-12)


def test_no_triangle_without_two_valid_points():
    fig = Figure()
    ax = fig.add_subplot()
    assert add_slope_triangle(ax, NDOF, [np.zeros(NDOF.size)]) is None
    assert triangle_vertices([(NDOF[:1], np.ones(1))], slope=-1.0) is None
    assert not ax.patches and not ax.texts
    with pytest.raises(ValueError, match="where"):
        triangle_vertices([(NDOF, 1 / NDOF)], slope=-1.0, where=1.5)


def test_slope_label_states_the_fitted_slope_or_nothing():
    values = 5.0 * NDOF**-0.8
    label = slope_label("q", NDOF, values, last=3)
    assert label.startswith("q, slope ") and legend_slope(label) == -0.8
    assert slope_label("q", NDOF[:1], values[:1], last=3) == "q"


# --- a slope is printed only where it is a rate -------------------------------------------

RUN = np.geomspace(100.0, 1e5, 12)  # an adaptive run's N_dof; the fit window is its finer half


def test_steady_slope_of_a_power_law_is_its_exponent():
    assert steady_slope(RUN, 3.0 * RUN**-1.0) == pytest.approx(-1.0, abs=1e-12)
    assert steady_slope(RUN, RUN**-1.5, last=4) == pytest.approx(-1.5, abs=1e-12)
    assert slope_label("x", RUN, RUN**-1.0, None) == "x, slope \u22121.00"


def test_no_slope_for_a_term_at_round_off_on_a_level_of_the_window():
    """hertz's eta_7: round-off (NaN once taken out) on five of the nine levels of the window;
    the four others fit a rising line, once printed as "slope 1.09"."""
    values = 1e-9 * RUN**1.1
    values[[6, 8, 9, 10, 11]] = np.nan
    assert steady_slope(RUN, values) is None
    assert slope_label(r"$\eta_7$", RUN, values, None) == r"$\eta_7$ (no steady rate)"
    # out of the window (the coarse half) a missing level does not matter
    values = RUN**-1.0
    values[1] = np.nan
    assert steady_slope(RUN, values) == pytest.approx(-1.0, abs=1e-12)


def test_no_slope_for_a_term_that_jumps_by_a_decade_inside_the_window():
    values = RUN**-1.0
    values[9:] *= 10.0  # one jump by a decade
    assert steady_slope(RUN, values) is None
    # scatter of 0.1 decade about a line is a rate (the scatter's root mean square is 0.1)
    wiggle = 10.0 ** (0.1 * np.where(np.arange(RUN.size) % 2, 1.0, -1.0))
    assert steady_slope(RUN, RUN**-1.0 * wiggle) == pytest.approx(-1.0, abs=0.1)
    assert steady_slope(RUN, RUN**-1.0 * wiggle**2) is None  # 0.2 decade > FIT_SCATTER
    assert FIT_SCATTER == 0.15


def test_no_slope_for_a_term_zero_on_every_level():
    assert steady_slope(RUN, np.zeros(RUN.size)) is None
    assert slope_label("x", RUN, np.full(RUN.size, np.nan), None) == "x"
