"""A computed pressure beside a known one (:mod:`signorini.plots.pressure`)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.plots import plot_pressure_comparison

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


def test_refuses_arrays_of_different_lengths(tmp_path):
    with pytest.raises(ValueError, match="x and pressure"):
        plot_pressure_comparison([0.0, 1.0], [1.0], [0.0], [1.0], tmp_path / "p")
    with pytest.raises(ValueError, match="reference"):
        plot_pressure_comparison([0.0], [1.0], [[0.0]], [[1.0]], tmp_path / "p")
