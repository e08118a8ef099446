"""Panel geometry and the closed form of ``∫_{[a, b]} |x − y|^{-2}``
(:mod:`signorini.estimator.h_half_norm.panels`)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from signorini.estimator.h_half_norm import parameters, segment_inverse_square_integral


def test_segment_inverse_square_integral_against_quad():
    rng = np.random.default_rng(5)
    a, b = np.array([0.3, -0.2]), np.array([1.4, 0.9])
    d = b - a
    pts = [rng.uniform(-2, 3, 2) for _ in range(20)]
    pts += [a - 0.7 * d, b + 1e-3 * d, a + 0.5 * d + 1e-6 * np.array([-d[1], d[0]])]
    length = np.hypot(*d)
    for x in pts:
        ref, _ = quad(
            lambda s, x=x: 1.0 / np.sum((a + s * d - x) ** 2),
            0,
            1,
            epsabs=0,
            epsrel=1e-13,
            limit=200,
            points=[np.clip(np.dot(x - a, d) / length**2, 0, 1)],
        )
        val = segment_inverse_square_integral(x, a, b)
        assert val == pytest.approx(ref * length, rel=1e-10), x
    # collinear: 1/|x - a| - 1/|x - b| = L / (|x - a| |x - b|), far out and very close
    for xi in (-3.0, -1e-7, 2.5, 1 + 1e-7):
        x = a + xi * d
        exact = length / (np.hypot(*(x - a)) * np.hypot(*(x - b)))
        assert segment_inverse_square_integral(x, a, b) == pytest.approx(exact, rel=1e-12)


def test_series_and_arctangent_agree_at_the_switch():
    """Seen from x = (0, −h), the segment [(1, 0), (2, 0)] has ``|cross| / dot = h / (2 + h²)``;
    on both sides of ``SERIES_SWITCH`` the value is the exact
    ``(arctan(2/h) − arctan(1/h)) / h = arctan(h / (2 + h²)) / h``."""
    a, b = np.array([1.0, 0.0]), np.array([2.0, 0.0])
    for h in 2 * parameters.SERIES_SWITCH * np.array([0.5, 0.999, 1.001, 2.0]):
        x = np.array([0.0, -h])
        exact = np.arctan(h / (2 + h * h)) / h
        assert segment_inverse_square_integral(x, a, b) == pytest.approx(exact, rel=1e-14), h


def test_broadcasting_and_validation():
    x = np.zeros((4, 3, 2))
    x[..., 1] = np.arange(1, 4)
    a, b = np.array([-1.0, 0.0]), np.array([1.0, 0.0])
    out = segment_inverse_square_integral(x, a, b)
    assert out.shape == (4, 3)
    # above the midpoint at height y: 2 arctan(1/y) / y
    np.testing.assert_allclose(out[0], 2 * np.arctan(1 / np.arange(1, 4)) / np.arange(1, 4))
    with pytest.raises(ValueError, match="last axis"):
        segment_inverse_square_integral(np.zeros(3), a, b)
