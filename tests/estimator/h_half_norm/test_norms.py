"""The public H^{1/2}(Γ_C) norm functions (:mod:`signorini.estimator.h_half_norm.norms`):
closed forms on a line and at corners, per-edge shares, invariances, cost, and a brute
force check. The closed forms are listed in :mod:`.polylines`."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import dblquad

from signorini.estimator.h_half_norm import (
    hhalf_norm2_positive_part,
    hhalf_seminorm2_positive_part,
    l2_norm2_positive_part,
)

from .polylines import (
    L_SHAPE,
    LN2,
    brute_force_seminorm,
    hat_closed_form,
    monotone_polyline,
    on_line,
    polyline,
    quadratic_max,
    refine_edges,
    rigid,
)

# --------------------------------------------------------------------------- closed forms on a line


@pytest.mark.parametrize("t", [[0, 1], [0, 0.5, 1], [0, 0.13, 0.5, 0.61, 1], np.linspace(0, 1, 12)])
def test_linear_function_on_unit_interval(t):
    x0, x1, w = on_line(t, lambda x: x)
    semi, semi_e = hhalf_seminorm2_positive_part(x0, x1, w)
    l2, l2_e = l2_norm2_positive_part(x0, x1, w)
    full, full_e = hhalf_norm2_positive_part(x0, x1, w)
    assert semi == pytest.approx(1.0, rel=1e-14)
    assert l2 == pytest.approx(1.0 / 3.0, rel=1e-14)
    assert full == pytest.approx(4.0 / 3.0, rel=1e-14)
    np.testing.assert_allclose(full_e, semi_e + l2_e, rtol=1e-14, atol=1e-16)


@pytest.mark.parametrize("t", [[0, 1], [0, 0.3, 1], [0, 0.25, 0.5, 0.75, 1]])
def test_quadratic_function_on_unit_interval(t):
    x0, x1, w = on_line(t, lambda x: x**2)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(7.0 / 6.0, rel=1e-14)
    assert l2_norm2_positive_part(x0, x1, w)[0] == pytest.approx(0.2, rel=1e-14)


@pytest.mark.parametrize(
    "t",
    [
        [0, 1],  # root inside the only edge
        [0, 0.3, 0.7, 1],  # root inside an interior edge
        [0, 0.5, 1],  # root at a node
        [0, 0.25, 0.5, 0.75, 1],  # root at a node, several edges on both sides
    ],
)
def test_shifted_ramp_half(t):
    x0, x1, w = on_line(t, lambda x: x - 0.5)
    semi = hhalf_seminorm2_positive_part(x0, x1, w)[0]
    assert semi == pytest.approx(0.75 - 0.5 * LN2, rel=1e-13)
    assert l2_norm2_positive_part(x0, x1, w)[0] == pytest.approx(1.0 / 24.0, rel=1e-13)


@pytest.mark.parametrize("a", [0.37, 0.05, 0.9, 1e-3])
def test_shifted_ramp_general(a):
    exact = 1 - a**2 + 2 * a**2 * np.log(a)
    for t in ([0, 1], [0, 0.2, 0.55, 1], np.linspace(0, 1, 8)):
        x0, x1, w = on_line(t, lambda x, a=a: x - a)
        assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(exact, rel=1e-13)


@pytest.mark.parametrize("L", [1.0, 1.5, 2.0, 5.0])
def test_hat_function(L):
    # the kink at 0 must be a node; the roots ±1 fall inside edges or on nodes
    for t in (
        [-L, 0, L],
        [-L, -0.7, 0, 1.3, L] if L > 1.3 else [-L, -0.7, 0, L],
        np.linspace(-L, L, 9),
    ):
        x0, x1, w = on_line(t, lambda x: 1 - np.abs(x))
        semi, _ = hhalf_seminorm2_positive_part(x0, x1, w)
        assert semi == pytest.approx(hat_closed_form(L), rel=1e-13), t
        assert l2_norm2_positive_part(x0, x1, w)[0] == pytest.approx(2 / 3, rel=1e-13)


def test_parabola_touching_zero_and_near_tangency():
    # v = (t - 1/2)^2 >= 0 with a double root: no split, 1/6
    x0, x1, w = on_line([0, 1], lambda x: (x - 0.5) ** 2)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(1 / 6, rel=1e-14)
    # the negative of it has an empty positive part
    assert hhalf_norm2_positive_part(x0, x1, -w)[0] == 0.0
    # two roots 1e-7 apart (a zero run of length 2e-7 inside the edge): continuity in eps
    for eps in (1e-14, -1e-14):
        x0, x1, w = on_line([0, 1], lambda x, e=eps: (x - 0.5) ** 2 + e)
        assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(1 / 6, abs=1e-10)


def test_disconnected_segments():
    # v = 1 on [0,1] x {0}, 0 on a second unit segment; the gap is not part of Γ_C
    x0 = np.array([[0.0, 0.0], [2.0, 0.0]])
    x1 = np.array([[1.0, 0.0], [3.0, 0.0]])
    w = np.array([[1.0, 1.0, 1.0], [-1.0, -1.0, -1.0]])
    semi, share = hhalf_seminorm2_positive_part(x0, x1, w)
    assert semi == pytest.approx(2 * np.log(4 / 3), rel=1e-14)
    assert share[1] == 0.0
    # parallel copy at distance 1
    x0 = np.array([[0.0, 0.0], [1.0, 1.0]])
    x1 = np.array([[1.0, 0.0], [0.0, 1.0]])
    semi, _ = hhalf_seminorm2_positive_part(x0, x1, w)
    assert semi == pytest.approx(np.pi - 2 * LN2, rel=1e-14)


# ----------------------------------------------------------------------------- corners


@pytest.mark.parametrize("cuts", [None, [[0.5], [0.5]], [[0.2, 0.7], [0.4]]])
def test_l_shape_closed_forms(cuts):
    def lin(p):
        return p[:, 0]

    def both(p):
        return p[:, 0] + p[:, 1]

    def shifted(p):
        return 1 + p[:, 0] + p[:, 1]

    x0, x1, w = polyline(L_SHAPE, lin, cuts)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(2.0, rel=1e-13)
    x0, x1, w = polyline(L_SHAPE, both, cuts)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(4 - 2 * LN2, rel=1e-13)
    # non-zero at the corner: same differences, same seminorm
    x0, x1, w = polyline(L_SHAPE, shifted, cuts)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(4 - 2 * LN2, rel=1e-13)
    assert l2_norm2_positive_part(x0, x1, w)[0] == pytest.approx(2 * 7 / 3, rel=1e-13)


def test_l_shape_linear_and_zero_against_dblquad():
    # independent check of the closed form 2: within the arm 1, across 2 ∫∫ x^2/(x^2+y^2)
    across, err = dblquad(lambda y, x: x * x / (x * x + y * y), 0, 1, 0, 1, epsabs=1e-13)
    x0, x1, w = polyline(L_SHAPE, lambda p: p[:, 0], [[0.3], [0.6]])
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(1 + 2 * across, rel=1e-11)


@pytest.mark.parametrize("degrees", [25.0, 60.0, 135.0])
def test_angle_with_support_through_the_corner_against_dblquad(degrees):
    # arms of length 1 from the corner; v = 1 + t on both (t = distance to the corner)
    al = np.deg2rad(degrees)
    arm = np.array([np.cos(al), np.sin(al)])
    vertices = [arm, [0.0, 0.0], [1.0, 0.0]]
    x0, x1, w = polyline(vertices, lambda p: 1 + np.hypot(p[:, 0], p[:, 1]), [[0.4], [0.7]])
    cos = np.cos(al)
    across, _ = dblquad(
        lambda s, t: (t - s) ** 2 / (t * t + s * s - 2 * t * s * cos),
        0,
        1,
        0,
        1,
        epsabs=1e-13,
        epsrel=1e-13,
    )
    exact = 1 + 1 + 2 * across
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(exact, rel=1e-11)


@pytest.mark.parametrize("degrees", [30.0, 120.0])
def test_angle_with_zero_arm_against_dblquad(degrees):
    # v = (t - a)^+ on the horizontal arm, v = 0 on the other arm
    a = 0.3
    al = np.deg2rad(degrees)
    arm = np.array([np.cos(al), np.sin(al)])
    vertices = [arm, [0.0, 0.0], [1.0, 0.0]]
    # w = x - a - 10 y is linear, so exactly quadratic on each edge, and < 0 on the tilted arm
    x0, x1, w = polyline(vertices, lambda p: p[:, 0] - a - 10 * p[:, 1])
    cos = np.cos(al)
    across, _ = dblquad(
        lambda s, t: (t - a) ** 2 / (t * t + s * s - 2 * t * s * cos),
        a,
        1,
        0,
        1,
        epsabs=1e-13,
        epsrel=1e-13,
    )
    exact = (1 - a**2 + 2 * a**2 * np.log(a)) + 2 * across
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(exact, rel=1e-11)


# --------------------------------------------------------------------------- shares and invariances


def test_shares_in_closed_form():
    # v = t on [0, 1/2] ∪ [1/2, 1]: edge 1 gets 1/24 (L2) + 1/4 (own) + 1/4 (half the pair)
    x0, x1, w = on_line([0, 0.5, 1], lambda x: x)
    total, share = hhalf_norm2_positive_part(x0, x1, w)
    np.testing.assert_allclose(share, [13 / 24, 19 / 24], rtol=1e-14)
    # the zero-run term goes to the edge where v lives
    x0, x1, w = on_line([0, 0.5, 1], lambda x: x - 0.5)
    total, share = hhalf_norm2_positive_part(x0, x1, w)
    assert share[0] == 0.0
    assert share[1] == pytest.approx(0.75 - 0.5 * LN2 + 1 / 24, rel=1e-13)


def test_shares_of_a_symmetric_function_are_symmetric():
    t = np.linspace(-2.0, 2.0, 9)
    x0, x1, w = on_line(t, lambda x: 1 - x * x)
    total, share = hhalf_norm2_positive_part(x0, x1, w)
    np.testing.assert_allclose(share, share[::-1], rtol=1e-12)
    assert share.sum() == pytest.approx(total, rel=1e-15)
    assert np.all(share[[0, 1, 6, 7]] == 0.0) and np.all(share[2:6] > 0)


def test_nonpositive_function_gives_exact_zero():
    x0, x1, w = polyline(L_SHAPE, lambda p: -((p[:, 0] - 0.5) ** 2) - p[:, 1], [[0.5], [0.3]])
    total, share = hhalf_norm2_positive_part(x0, x1, w)
    assert total == 0.0 and share.shape == (x0.shape[0],) and np.all(share == 0.0)
    total, share = hhalf_norm2_positive_part(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 3)))
    assert total == 0.0 and share.shape == (0,)


def test_edge_node_order_is_start_end_midpoint():
    """v = t on [0, 1] is [0, 1, 1/2] at [start, end, midpoint], seminorm 1; the same
    numbers in the order (start, midpoint, end) are 3.5 t − 3 t², another function."""
    x0, x1 = np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]])
    assert hhalf_seminorm2_positive_part(x0, x1, [[0.0, 1.0, 0.5]])[0] == pytest.approx(1.0)
    other = hhalf_seminorm2_positive_part(x0, x1, [[0.0, 0.5, 1.0]])[0]
    assert abs(other - 1.0) > 0.1


def test_rigid_motion_and_orientation_invariance():
    x0, x1, w = monotone_polyline(3)
    ref, share = hhalf_norm2_positive_part(x0, x1, w)
    for angle, shift in ((0.7, (3.0, -2.0)), (np.pi, (0.0, 0.0)), (-2.1, (100.0, 50.0))):
        val, sh = hhalf_norm2_positive_part(rigid(x0, angle, shift), rigid(x1, angle, shift), w)
        assert val == pytest.approx(ref, rel=1e-12)
        np.testing.assert_allclose(sh, share, rtol=1e-10, atol=1e-14 * ref)
    # reversing the orientation of every edge (start and end swap) changes nothing either
    val, sh = hhalf_norm2_positive_part(x1, x0, w[:, [1, 0, 2]])
    assert val == pytest.approx(ref, rel=1e-12)
    np.testing.assert_allclose(sh, share, rtol=1e-10, atol=1e-14 * ref)


def test_refinement_and_edge_order_invariance():
    x0, x1, w = monotone_polyline(7)
    ref, share = hhalf_norm2_positive_part(x0, x1, w)
    for n in (2, 3):
        val, sh = hhalf_norm2_positive_part(*refine_edges(x0, x1, w, n))
        assert val == pytest.approx(ref, rel=1e-12)
        np.testing.assert_allclose(sh.reshape(-1, n).sum(axis=1), share, rtol=1e-9, atol=1e-13)
    perm = np.random.default_rng(1).permutation(x0.shape[0])
    val, sh = hhalf_norm2_positive_part(x0[perm], x1[perm], w[perm])
    assert val == pytest.approx(ref, rel=1e-13)
    np.testing.assert_allclose(sh, share[perm], rtol=1e-12, atol=1e-15)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**31 - 1), angle=st.floats(-np.pi, np.pi))
def test_property_invariances(seed, angle):
    x0, x1, w = monotone_polyline(seed, n_seg=3, n_cut=1)
    ref, share = hhalf_norm2_positive_part(x0, x1, w)
    semi, _ = hhalf_seminorm2_positive_part(x0, x1, w)
    l2, _ = l2_norm2_positive_part(x0, x1, w)
    assert ref == pytest.approx(semi + l2, rel=1e-14)
    assert np.all(share >= 0.0) and share.sum() == pytest.approx(ref, rel=1e-14)
    # edges on which v = 0 get exactly nothing, the others something
    wmax = quadratic_max(w)
    assert np.all(share[wmax < -1e-12] == 0.0)
    assert np.all(share[wmax > 1e-6] > 0.0)
    shift = (1.0, 2.0)
    moved = hhalf_norm2_positive_part(rigid(x0, angle, shift), rigid(x1, angle, shift), w)[0]
    assert moved == pytest.approx(ref, rel=1e-11)
    refined = hhalf_norm2_positive_part(*refine_edges(x0, x1, w, 2))[0]
    assert refined == pytest.approx(ref, rel=1e-11)


def test_trusted_call_gives_the_same_numbers():
    x0, x1, w = monotone_polyline(11)
    checked = hhalf_norm2_positive_part(x0, x1, w)
    trusted = hhalf_norm2_positive_part(x0, x1, w, validate=False)
    assert checked[0] == trusted[0]
    np.testing.assert_array_equal(checked[1], trusted[1])


# ----------------------------------------------------------------------------- cost


def test_many_edges_small_support_is_integrated_near_its_support():
    """100 000 edges, v > 0 on a few: the time is printed, never asserted (it is the
    machine's); what is asserted is that the norm lives on the support's edges."""
    k = 100_000
    t = np.linspace(0.0, 1.0, k + 1)

    def f(x):
        return -1.0 + 2.0 * sum(np.exp(-(((x - c) / 3e-5) ** 2)) for c in (0.1, 0.33, 0.5, 0.8))

    x0, x1, w = on_line(t, f)
    hhalf_norm2_positive_part(x0[:10], x1[:10], w[:10])  # warm-up (imports, caches)
    start = time.perf_counter()
    total, share = hhalf_norm2_positive_part(x0, x1, w)
    elapsed = time.perf_counter() - start
    print(f"\n{k} edges, v > 0 on {np.count_nonzero(share)} of them: {elapsed:.3f} s")
    assert 0 < np.count_nonzero(share) <= 40
    # each bump equals the same bump computed on its own with the rest of Γ_C as zero set:
    # compare with a coarse restriction holding the same support (the far zero set only
    # enters through analytic integrals over runs)
    support = np.flatnonzero(share > 0)
    lo, hi = support.min() - 1, support.max() + 2
    sub = slice(lo, hi)
    pad_x0 = np.vstack([[[0.0, 0.0]], x0[sub], [[t[hi], 0.0]]])
    pad_x1 = np.vstack([[[t[lo], 0.0]], x1[sub], [[1.0, 0.0]]])
    pad_w = np.vstack([[[-1.0, w[lo, 0], -1.0]], w[sub], [[w[hi - 1, 1], -1.0, -1.0]]])
    assert hhalf_norm2_positive_part(pad_x0, pad_x1, pad_w)[0] == pytest.approx(total, rel=1e-12)


# ----------------------------------------------------------------------------- brute force


@pytest.mark.slow
def test_polyline_against_brute_force():
    pts = np.array([[0.0, 0.0], [1.0, 0.2], [1.3, 1.0], [0.7, 1.5]])
    x0, x1 = pts[:-1], pts[1:]
    w = np.array([[0.4, -0.1, -0.5], [-0.1, 0.64, 0.36], [0.64, 0.3, 0.2]])
    ref = brute_force_seminorm(x0, x1, w)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(ref, rel=1e-10)


def _corner_edges():
    # two edges meeting at a right angle at (1, 0): the floor and the wall of a corner
    x0 = np.array([[0.0, 0.0], [1.0, 1.0]])
    x1 = np.array([[1.0, 0.0], [1.0, 0.0]])
    return x0, x1


def test_round_off_jump_at_a_corner_is_measured_on_the_data_scale():
    # a corner node closed to round-off on both contact parts: the two gaps u·n − ψ differ by
    # 8.7e-19 there, where the penetration's own size is 1.7e-18 (the other nodes are open by
    # 1e-3). Measured on v's own size the jump read as a discontinuity ("v jumps by …");
    # on the data's size (max|w| by default, or the displacement's) it is round-off.
    x0, x1 = _corner_edges()
    w_small = np.array([[1.2e-18, 1.7e-18, 1.5e-18], [1e-18, 0.83e-18, 0.9e-18]])
    # with an open edge elsewhere on Γ_C
    far0, far1 = np.array([[5.0, 0.0]]), np.array([[6.0, 0.0]])
    w = np.vstack([w_small, [-1e-3, -1e-3, -1e-3]])
    total, share = hhalf_norm2_positive_part(np.vstack([x0, far0]), np.vstack([x1, far1]), w)
    assert 0.0 < total < 1e-34 and share[2] == 0.0
    # data all of round-off size (every node closed): the caller's scale (max|u_h|) decides
    with pytest.raises(ValueError, match="v jumps by"):
        hhalf_norm2_positive_part(x0, x1, w_small, validate=False)
    total, _ = hhalf_norm2_positive_part(x0, x1, w_small, validate=False, scale=1e-2)
    assert 0.0 < total < 1e-34
    total_checked, _ = hhalf_norm2_positive_part(x0, x1, w_small, scale=1e-2)
    assert total_checked == total


def test_a_true_jump_at_a_corner_is_still_refused():
    x0, x1 = _corner_edges()
    w = np.array([[0.0, 1.0, 0.5], [0.0, 0.5, 0.25]])
    with pytest.raises(ValueError, match="discontinuous"):
        hhalf_norm2_positive_part(x0, x1, w, scale=1.0)
    with pytest.raises(ValueError, match="v jumps by"):
        hhalf_norm2_positive_part(x0, x1, w, validate=False, scale=1.0)
