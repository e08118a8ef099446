"""KKT residuals (signorini.algebra.kkt) on closed-form points."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from signorini.algebra import kkt_residuals


def test_kkt_residuals_closed_form():
    K = sp.identity(3, format="csr")
    F = np.array([1.0, 2.0, 0.0])
    c, g = np.array([0, 1]), np.array([0.5, 5.0])
    x = np.array([0.6, 2.0, 0.0])  # violates x_0 <= 0.5 by 0.1, multiplier 0.4
    kkt = kkt_residuals(K, F, x, c, g)
    assert kkt.disp_scale == 5.0  # max(|x|, |g|)
    assert kkt.force_scale == 2.0  # max(|F|, |K||x|)
    assert np.isclose(kkt.primal, 0.1 / 5.0)
    assert kkt.dual == 0.0
    assert np.isclose(kkt.complementarity, 0.4 * 0.1 / (2.0 * 5.0))
    assert kkt.stationarity == 0.0
    x2 = np.array([0.5, 2.0, 0.3])  # free row residual -0.3; x_0 at the bound
    kkt2 = kkt_residuals(K, F, x2, c, g, dirichlet=[2], dirichlet_values=0.1)
    assert np.isclose(kkt2.dirichlet, 0.2 / 5.0)
    assert kkt2.stationarity == 0.0  # row 2 is a Dirichlet row, not a free one
    kkt3 = kkt_residuals(K, np.array([0.0, 2.0, 0.0]), np.array([0.5, 2.0, 0.0]), c, g)
    assert np.isclose(kkt3.dual, 0.5 / 2.0)  # multiplier -0.5 at the active bound
    assert np.isclose(kkt3.max, 0.25)


def test_stationarity_on_a_free_row_and_zero_scales():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    kkt = kkt_residuals(K, np.array([0.0, 1.0]), np.array([0.0, 0.0]), [0], 0.0)
    # x = 0: force scale max|F| = 1, displacement scale 1 (all vanish), row 1 residual 1
    assert (kkt.force_scale, kkt.disp_scale) == (1.0, 1.0)
    assert kkt.stationarity == 1.0 and kkt.max == 1.0
    with pytest.raises(ValueError, match=r"x must have shape \(2,\)"):
        kkt_residuals(K, np.zeros(2), np.zeros(3), [0], 0.0)
