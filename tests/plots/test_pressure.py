"""A computed pressure beside a known one (:mod:`signorini.plots.pressure`)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples.partial_slip import (
    COEFFICIENT,
    partial_slip,
    partial_slip_metrics,
    partial_slip_path,
    partial_slip_pressure,
)
from signorini.loop import adaptive
from signorini.plots import plot_pressure_comparison
from signorini.plots.run_figures import pressure_figure

from .figure_checks import check_written


def test_markers_in_order_beside_the_reference_line(tmp_path, captured):
    a, p0 = 0.1, 2.0
    x = np.array([0.05, -0.05, 0.0, 0.15, -0.15, np.nan])
    pressure = p0 * np.sqrt(np.maximum(1 - (x / a) ** 2, 0.0))
    pressure[3] = np.nan  # a Dirichlet node has no pressure
    x_ref = np.linspace(-a, a, 51)
    written = plot_pressure_comparison(
        x,
        pressure,
        x_ref,
        p0 * np.sqrt(1 - (x_ref / a) ** 2),
        tmp_path / "hertz_pressure",
        label="Hertz",
        title="hertz: contact pressure",
    )
    check_written(written, tmp_path / "hertz_pressure")
    (info,) = captured
    assert info["legend"] == ["Hertz", "$p_h$"]
    assert info["titles"] == ["hertz: contact pressure"]
    xs, ps = info["lines"]["$p_h$"]
    assert np.array_equal(xs, [-0.15, -0.05, 0.0, 0.05])  # NaN entries left out, sorted
    assert ps == pytest.approx([0.0, p0 * np.sqrt(0.75), p0, p0 * np.sqrt(0.75)])
    xr, pr = info["lines"]["Hertz"]
    assert np.array_equal(xr, x_ref) and pr.max() == pytest.approx(p0)
    # the curve is drawn above the ~300 markers it is compared with, and the legend box lies
    # clear of the peak (it sits under the axes)
    z_hertz, z_markers = info["zorders_by_axes"][0][:2]
    assert z_hertz > z_markers
    peak = info["data_to_display"][0].transform((0.0, p0))
    (box,) = info["legend_boxes"]
    assert not box.contains(*peak) and box.y1 < info["data_to_display"][0].transform((0, 0))[1]


def test_refuses_arrays_of_different_lengths(tmp_path):
    with pytest.raises(ValueError, match="x and pressure"):
        plot_pressure_comparison([0.0, 1.0], [1.0], [0.0], [1.0], tmp_path / "p")
    with pytest.raises(ValueError, match="reference"):
        plot_pressure_comparison([0.0], [1.0], [[0.0]], [[1.0]], tmp_path / "p")


@pytest.mark.slow
def test_partial_slip_zoom_shows_cattaneo_mindlin(tmp_path, captured):
    """The contact zone of ``partial-slip`` zoomed to |x| <= 1.5 a (once the stick zone was
    7 % of the axis), with Hertz's pressure and Cattaneo–Mindlin's friction stress for the
    level's own forces: q(0) = F p0 (1 - c/a), q = F p on c < |x| < a."""
    *_, last = adaptive(partial_slip(), max_ndof=1500, path=partial_slip_path()[:-1])
    known = partial_slip_pressure(last.result)
    metrics = partial_slip_metrics(last.result)
    lo, hi = known.window
    a = hi / 1.5
    assert lo == -hi and a == pytest.approx(metrics["a"], rel=0.05)  # Hertz's a, the forces' a
    xr, q = known.x_reference, known.tangential_reference
    p0 = known.reference.max()
    c_over_a = metrics["c_over_a_theory"]
    assert known.tangential_label.endswith(f"$c/a$ = {c_over_a:.3f}")
    middle = np.argmin(np.abs(xr))
    assert abs(q[middle]) == pytest.approx(COEFFICIENT * p0 * (1 - c_over_a), rel=1e-9)
    slip = (np.abs(xr) > c_over_a * a * 1.01) & (np.abs(xr) < a)
    np.testing.assert_allclose(np.abs(q[slip]), COEFFICIENT * known.reference[slip], rtol=1e-12)
    # the computed friction stress has the sign of the prediction
    assert np.sign(np.sum(known.tangential)) == np.sign(q[middle])
    pressure_figure("partial-slip", tmp_path, known)
    (info,) = captured
    assert info["legend"][:3] == ["Hertz, $a$ = " + f"{a:.4g}", "$p_h$", known.tangential_label]
    assert {"stick", "slip"} <= set(info["legend"])
    zorders = info["zorders_by_axes"][0]
    assert min(zorders[0], zorders[2]) > max(zorders[1], zorders[3])  # lines above markers
