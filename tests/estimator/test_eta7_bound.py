"""The localised bound of η7 (estimator/h_half_norm/localised.py) against independent values.

Every asserted number comes from a computation that does not use the module: closed-form
integrals and scipy quadrature of the Sobolev-Slobodeckij double integral, or the package's
exact η7 (tested on its own in tests/estimator/h_half_norm/).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from signorini.estimator.h_half_norm import (
    curve_weights,
    facet_norms2_positive_part,
    hhalf_norm2_positive_part,
    localised_bound2,
    localised_bound2_positive_part,
)


def straight_chain(breaks):
    """Edges ``[b_i, b_{i+1}]`` on the x-axis, ``(k, 2)`` start and end points."""
    b = np.asarray(breaks, dtype=float)
    zero = np.zeros_like(b)
    return np.c_[b[:-1], zero[:-1]], np.c_[b[1:], zero[1:]]


def nodal(f, x0, x1):
    """``f`` at ``[start, end, midpoint]`` of each edge (f a function of the points)."""
    return np.c_[f(x0), f(x1), f(0.5 * (x0 + x1))]


def hat(p):
    return np.maximum(0.0, 1.0 - np.abs(p[:, 0]))


def hat_norm2_on_interval(half_length):
    """``‖v‖² + ∫∫ (v(x) − v(y))² / (x − y)²`` on ``[−L, L]`` for the hat ``max(0, 1 − |x|)``.

    On the whole line the seminorm is ``2π ∫ |ξ| |v̂|² dξ = 8 ∫_0^∞ sin⁴u / u³ du = 8 ln 2``
    (Di Nezza, Palatucci, Valdinoci, Prop. 3.4, with v̂ = (2π)^{-1/2} sinc²(ξ/2)); the pairs
    with ``y`` outside ``[−L, L]`` contribute ``2 ∫ v(x)² (1/(L − x) + 1/(L + x)) dx``.
    """
    L = half_length
    outside, _ = integrate.quad(
        lambda x: (1.0 - abs(x)) ** 2 * (1.0 / (L - x) + 1.0 / (L + x)), -1.0, 1.0, points=[0.0]
    )
    return 2.0 / 3.0 + 8.0 * np.log(2.0) - 2.0 * outside


def test_hat_seminorm_by_double_quadrature_matches_closed_form():
    # the reference of the tests below, checked by a second independent computation:
    # scipy's double quadrature over the squares of the kinks of v (the integrand is bounded)
    grid = [-2.0, -1.0, 0.0, 1.0, 2.0]

    def f(y, x):
        v = lambda s: max(0.0, 1.0 - abs(s))  # noqa: E731
        return 0.0 if x == y else (v(x) - v(y)) ** 2 / (x - y) ** 2

    total = sum(
        integrate.dblquad(f, a, b, c, d, epsabs=1e-11, epsrel=1e-11)[0]
        for a, b in zip(grid[:-1], grid[1:], strict=True)
        for c, d in zip(grid[:-1], grid[1:], strict=True)
    )
    assert total + 2.0 / 3.0 == pytest.approx(hat_norm2_on_interval(2.0), rel=1e-8)


@pytest.mark.parametrize("n_edges", [4, 8, 32])
def test_hat_on_a_segment(n_edges):
    x0, x1 = straight_chain(np.linspace(-2.0, 2.0, n_edges + 1))
    w = nodal(hat, x0, x1)
    exact = hat_norm2_on_interval(2.0)
    assert hhalf_norm2_positive_part(x0, x1, w)[0] == pytest.approx(exact, rel=1e-10)
    norms = facet_norms2_positive_part(x0, x1, w)
    assert norms.l2.sum() == pytest.approx(2.0 / 3.0, rel=1e-13)
    assert norms.gradient.sum() == pytest.approx(2.0, rel=1e-13)
    near, far = curve_weights(x0, x1)
    guaranteed, _ = localised_bound2(norms, near, far)
    assert guaranteed >= exact  # η7² ≤ G², the constant 1
    unit, _ = localised_bound2(norms)
    assert unit >= exact / max(1.0, near.max(), far.max())  # η7² ≤ C B²


def test_uniform_straight_weights():
    # inside a uniform straight chain α = 2 ln 2 + 2 · 2 J(h, h) / h = 10 ln 2, β = 8
    x0, x1 = straight_chain(np.linspace(0.0, 1.0, 6))
    near, far = curve_weights(x0, x1)
    assert near[1:-1] == pytest.approx(10.0 * np.log(2.0), rel=1e-14)
    assert far[1:-1] == pytest.approx(8.0, rel=1e-14)
    assert near[0] == pytest.approx(6.0 * np.log(2.0), rel=1e-14)
    assert far[0] == pytest.approx(4.0, rel=1e-14)


def random_gap(rng, k):
    """Continuous piecewise quadratic data with a sign change: a P2 field's trace."""
    vertex = rng.normal(size=k + 1)
    mid = rng.normal(size=k)
    return np.c_[vertex[:-1], vertex[1:], mid]


@pytest.mark.parametrize("seed", range(6))
def test_guaranteed_bound_on_graded_straight_chains(seed):
    rng = np.random.default_rng(seed)
    k = 12
    breaks = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.0, k))])
    x0, x1 = straight_chain(breaks)
    w = random_gap(rng, k)
    exact, _ = hhalf_norm2_positive_part(x0, x1, w)
    near, far = curve_weights(x0, x1)
    guaranteed, shares = localised_bound2(facet_norms2_positive_part(x0, x1, w), near, far)
    assert exact > 0.0
    assert guaranteed >= exact
    assert shares.sum() == pytest.approx(guaranteed, rel=1e-14)


@pytest.mark.parametrize("angle", [0.3, 1.0, 2.0, 2.8])
def test_guaranteed_bound_at_a_corner(angle):
    # two edges meeting at the interior angle θ: only same-edge and adjacent pairs
    rng = np.random.default_rng(7)
    z = np.zeros(2)
    a = np.array([-1.3, 0.0])
    b = 0.7 * np.array([-np.cos(angle), np.sin(angle)])
    x0, x1 = np.array([a, z]), np.array([z, b])
    for _ in range(5):
        w = random_gap(rng, 2)
        exact, _ = hhalf_norm2_positive_part(x0, x1, w)
        near, _ = curve_weights(x0, x1)  # no far pairs: the far weight is not needed
        norms = facet_norms2_positive_part(x0, x1, w)
        guaranteed, _ = localised_bound2(norms, near, 0.0)
        assert guaranteed >= exact


def test_facet_norms_at_a_root():
    # v = (x − 0.3)⁺ on [0, 1]: ‖v‖² = 0.7³ / 3, ‖v'‖² = 0.7
    x0, x1 = straight_chain([0.0, 1.0])
    w = nodal(lambda p: p[:, 0] - 0.3, x0, x1)
    norms = facet_norms2_positive_part(x0, x1, w)
    assert norms.l2[0] == pytest.approx(0.7**3 / 3.0, rel=1e-13)
    assert norms.gradient[0] == pytest.approx(0.7, rel=1e-13)
    assert norms.h[0] == 1.0


def test_scaling_and_zero():
    rng = np.random.default_rng(3)
    x0, x1 = straight_chain(np.linspace(0.0, 2.0, 9))
    w = random_gap(rng, 8)
    total, shares = localised_bound2_positive_part(x0, x1, w)
    for alpha in (1e-3, 0.5, 7.0):
        scaled, _ = localised_bound2_positive_part(x0, x1, alpha * w)
        assert np.sqrt(scaled) == pytest.approx(alpha * np.sqrt(total), rel=1e-12)
    for negative in (np.zeros_like(w), nodal(lambda p: -1.0 - p[:, 0] ** 2, x0, x1)):
        zero, zero_shares = localised_bound2_positive_part(x0, x1, negative)
        assert zero == 0.0 and np.all(zero_shares == 0.0)
    # edges where the quadratic is negative (its maximum on the edge) carry nothing
    a, b, c = (
        w[:, 0],
        -3.0 * w[:, 0] + 4.0 * w[:, 2] - w[:, 1],
        2.0 * w[:, 0] - 4.0 * w[:, 2] + 2.0 * w[:, 1],
    )
    t = np.linspace(0.0, 1.0, 2001)[:, None]
    negative_edges = np.all(a + t * (b + t * c) < 0.0, axis=0)
    assert negative_edges.any()
    assert np.all(shares[negative_edges] == 0.0)


def bisected(x0, x1):
    mid = 0.5 * (x0 + x1)
    return np.concatenate([x0, mid]), np.concatenate([mid, x1])


def test_refinement_changes_the_bound_by_at_most_two():
    # a global quadratic is its own P2 trace on every mesh; bisecting every edge doubles
    # Σ h⁻¹‖v‖²_F and halves Σ h‖v'‖²_F, so B² changes by a factor in [1/2, 2] per step
    def f(p):
        return 0.2 + p[:, 0] * (1.0 - p[:, 0])

    x0, x1 = straight_chain(np.linspace(-0.5, 1.5, 5))
    previous = None
    for _ in range(5):
        total, _ = localised_bound2_positive_part(x0, x1, nodal(f, x0, x1))
        norms = facet_norms2_positive_part(x0, x1, nodal(f, x0, x1))
        # the L² norm of v itself does not change (computed independently once)
        l2_exact, _ = integrate.quad(lambda s: max(0.0, 0.2 + s * (1.0 - s)) ** 2, -0.5, 1.5)
        assert norms.l2.sum() == pytest.approx(l2_exact, rel=1e-10)
        if previous is not None:
            assert 0.5 * previous <= total * (1 + 1e-12)
            assert total <= 2.0 * previous * (1 + 1e-12)
        previous = total
        x0, x1 = bisected(x0, x1)


def test_weights_need_one_chain():
    x0 = np.array([[0.0, 0.0], [2.0, 0.0]])
    x1 = np.array([[1.0, 0.0], [3.0, 0.0]])
    with pytest.raises(ValueError, match="connected"):
        curve_weights(x0, x1)
