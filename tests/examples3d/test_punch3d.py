"""punch-3d: the rounded box's signed distance and gradient, and bad arguments refused."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples.punch3d import punch_3d, rounded_box_distance

LOWER, UPPER, R = np.array([1.2, -0.3, 1.19]), np.array([2.8, 0.3, 2.0]), 0.2


def test_rounded_box_distance_is_the_distance_and_its_gradient_is_unit():
    phi, grad = rounded_box_distance(0.5 * (LOWER + UPPER), 0.5 * (UPPER - LOWER), R)
    rng = np.random.default_rng(7)
    x = rng.uniform(LOWER - 0.6, UPPER + 0.6, size=(2000, 3))
    # outside the inner box: the distance to its closest point, less r
    outside = (np.clip(x, LOWER, UPPER) != x).any(axis=1)
    direct = np.linalg.norm(x - np.clip(x, LOWER, UPPER), axis=1) - R
    np.testing.assert_allclose(phi(x)[outside], direct[outside], rtol=0, atol=1e-14)
    # inside it: minus the distance to its nearest face, less r
    inner = ~outside
    depth = np.minimum(x - LOWER, UPPER - x).min(axis=1)
    np.testing.assert_allclose(phi(x)[inner], -depth[inner] - R, rtol=0, atol=1e-14)
    g = grad(x)
    np.testing.assert_allclose(np.linalg.norm(g, axis=1), 1.0, rtol=1e-14)
    h = 1e-6
    fd = np.stack([(phi(x + h * e) - phi(x - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
    smooth = np.abs(fd - g).max(axis=1) < 1e-5  # away from the inner box's medial planes
    assert smooth[outside].all() and smooth.mean() > 0.9


@pytest.mark.parametrize(
    "kwargs", [{"edge": 2.5}, {"side": 1.5}, {"radius": 0.6}, {"radius": -0.1}, {"edge": 0.0}]
)
def test_bad_geometry_is_refused_naming_the_arguments(kwargs):
    with pytest.raises(ValueError, match="punch_3d: need 0 < edge < width"):
        punch_3d(**kwargs)
