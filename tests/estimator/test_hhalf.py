"""H^{1/2}(Γ_C) norm of the positive part of a piecewise quadratic (η7).

Closed forms used below (t = arc length, ``|·|^2_{1/2}`` the double integral):

* ``v = t`` on [0, 1]: ``1``;  ``v = t^2``: ``∫∫ (t + s)^2 = 7/6``;
  ``v = (t - 1/2)^2``: ``∫∫ (t + s - 1)^2 = 1/6``.
* ``v = (t - a)^+`` on [0, 1]: ``(1 - a)^2 + 2 ∫_0^{1-a} τ^2 (1/τ - 1/(τ + a)) dτ
  = 1 - a^2 + 2 a^2 ln a``.
* hat ``(1 - |t|)^+`` on [-L, L]: ``8 - 8 ln 2 + 4 K(L)`` with
  ``K = 2L - 2 + 4 ln 2 - (L-1)^2 ln(L/(L-1)) - (L+1)^2 ln((L+1)/L)``
  (the first part from ``∫_0^1∫_0^1 (x-s)^2/(x+s)^2 = 3 - 4 ln 2``, ``K`` from
  ``∫_0^1 (1-x)^2 [1/(1-x) - 1/(L-x) + 1/(1+x) - 1/(L+x)] dx``).
* L-shape (unit arms along e1 and e2 from the corner): ``v = x`` on the
  horizontal arm, 0 on the vertical one: ``1 + 2 ∫_0^1 x arctan(1/x) dx = 2``;
  ``v = x`` and ``v = y``: ``2 + 2 ∫∫ (x-y)^2/(x^2+y^2) = 4 - 2 ln 2``.
* two unit segments, v = 1 on one and 0 on the other: at distance 1 on the
  same line ``2 ln(4/3)``; parallel at distance 1 ``π - 2 ln 2``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import dblquad, quad

import signorini.estimator.hhalf as hh
from signorini.estimator.hhalf import (
    hhalf_norm2_positive_part,
    hhalf_seminorm2_positive_part,
    l2_norm2_positive_part,
    positive_part_pieces,
    segment_inverse_square_integral,
)

LN2 = np.log(2.0)


# ----------------------------------------------------------------------------- helpers


def polyline(vertices, f, breaks=None):
    """Edges of the polyline through ``vertices``; each segment cut at ``breaks``.

    ``f(points (n, 2)) -> (n,)`` gives w, sampled at start, midpoint and end
    (so w is exactly f wherever f is a quadratic along each edge).
    ``breaks`` lists, per segment, interior cut parameters in (0, 1).
    """
    vertices = np.asarray(vertices, dtype=float)
    x0, x1 = [], []
    for i, (p, q) in enumerate(zip(vertices[:-1], vertices[1:], strict=True)):
        cuts = [] if breaks is None else list(breaks[i])
        t = np.array([0.0, *sorted(cuts), 1.0])
        x0.append(p + t[:-1, None] * (q - p))
        x1.append(p + t[1:, None] * (q - p))
    x0, x1 = np.concatenate(x0), np.concatenate(x1)
    w = np.column_stack([f(x0), f(0.5 * (x0 + x1)), f(x1)])
    return x0, x1, w


def on_line(t, f):
    """Edges [t_i, t_{i+1}] x {0} of the x-axis with w = f(x)."""
    t = np.asarray(t, dtype=float)
    x0 = np.column_stack([t[:-1], np.zeros(t.size - 1)])
    x1 = np.column_stack([t[1:], np.zeros(t.size - 1)])
    w = np.column_stack([f(t[:-1]), f(0.5 * (t[:-1] + t[1:])), f(t[1:])])
    return x0, x1, w


def refine_edges(x0, x1, w, n):
    """Split every edge into ``n`` equal edges carrying the same quadratic."""
    a = w[:, 0]
    b = -3 * w[:, 0] + 4 * w[:, 1] - w[:, 2]
    c = 2 * w[:, 0] - 4 * w[:, 1] + 2 * w[:, 2]

    def q(s):
        return a[:, None] + s * (b[:, None] + s * c[:, None])

    s0 = np.arange(n) / n
    s1 = (np.arange(n) + 1) / n
    nx0 = x0[:, None, :] + s0[None, :, None] * (x1 - x0)[:, None, :]
    nx1 = x0[:, None, :] + s1[None, :, None] * (x1 - x0)[:, None, :]
    nw = np.stack([q(s0), q(0.5 * (s0 + s1)), q(s1)], axis=-1)
    return nx0.reshape(-1, 2), nx1.reshape(-1, 2), nw.reshape(-1, 3)


def rigid(points, angle, shift):
    c, s = np.cos(angle), np.sin(angle)
    return points @ np.array([[c, s], [-s, c]]) + np.asarray(shift)


def monotone_polyline(seed, n_seg=5, n_cut=2):
    """A random x-monotone (hence non-self-intersecting) polyline with a random w."""
    rng = np.random.default_rng(seed)
    xs = np.cumsum(rng.uniform(0.3, 1.0, n_seg + 1))
    ys = rng.uniform(-0.8, 0.8, n_seg + 1)
    vertices = np.column_stack([xs, ys])
    breaks = [rng.uniform(0.05, 0.95, n_cut) for _ in range(n_seg)]
    x0, x1, _ = polyline(vertices, lambda p: p[:, 0], breaks)
    k = x0.shape[0]
    nodal = rng.normal(0.2, 1.0, k + 1)
    w = np.column_stack([nodal[:-1], rng.normal(0.2, 1.0, k), nodal[1:]])
    return x0, x1, w


def quadratic_max(w):
    """Exact maximum over [0, 1] of the quadratic through (start, mid, end) values."""
    b = -3 * w[:, 0] + 4 * w[:, 1] - w[:, 2]
    c = 2 * w[:, 0] - 4 * w[:, 1] + 2 * w[:, 2]
    out = np.maximum(w[:, 0], w[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(c < 0, -b / (2 * c), -1.0)
    inner = (s > 0) & (s < 1)
    return np.where(inner, np.maximum(out, w[:, 0] + s * (b + s * c)), out)


def hat_closed_form(L):
    if L == 1.0:
        k = 0.0
    else:
        k = (
            2 * L
            - 2
            + 4 * LN2
            - (L - 1) ** 2 * np.log(L / (L - 1))
            - (L + 1) ** 2 * np.log((L + 1) / L)
        )
    return 8 - 8 * LN2 + 4 * k


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


L_SHAPE = [[0.0, 1.0], [0.0, 0.0], [1.0, 0.0]]


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
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces == 0
    total, share = hhalf_norm2_positive_part(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 3)))
    assert total == 0.0 and share.shape == (0,)


def test_positive_part_pieces_and_zero_runs():
    # roots at x = 0.25 (inside an edge) and 1.5 (at a node) of w = (x - 0.25)(1.5 - x)
    x0, x1, w = on_line([-1, 0, 0.5, 1.5, 2, 3], lambda x: (x - 0.25) * (1.5 - x))
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces == 2
    np.testing.assert_array_equal(pc.edge, [1, 2])
    np.testing.assert_allclose(pc.start[:, 0], [0.25, 0.5], rtol=1e-15)
    np.testing.assert_allclose(pc.length.sum(), 1.25, rtol=1e-15)
    # the zero set is two maximal runs, [-1, 0.25] and [1.5, 3]
    runs = np.sort(np.column_stack([pc.run_start[:, 0], pc.run_end[:, 0]]), axis=1)
    runs = runs[np.argsort(runs[:, 0])]
    np.testing.assert_allclose(runs, [[-1, 0.25], [1.5, 3]], rtol=1e-15)
    # v at the ends of the pieces vanishes where they meet the zero runs
    u = np.array([0.0, 1.0])
    v = pc.coef[:, :1] + u * (pc.coef[:, 1:2] + u * pc.coef[:, 2:3])
    assert abs(v[0, 0]) < 1e-15 and abs(v[1, 1]) < 1e-15


def test_rigid_motion_invariance():
    x0, x1, w = monotone_polyline(3)
    ref, share = hhalf_norm2_positive_part(x0, x1, w)
    for angle, shift in ((0.7, (3.0, -2.0)), (np.pi, (0.0, 0.0)), (-2.1, (100.0, 50.0))):
        val, sh = hhalf_norm2_positive_part(rigid(x0, angle, shift), rigid(x1, angle, shift), w)
        assert val == pytest.approx(ref, rel=1e-12)
        np.testing.assert_allclose(sh, share, rtol=1e-10, atol=1e-14 * ref)
    # reversing the orientation of every edge changes nothing either
    val, sh = hhalf_norm2_positive_part(x1, x0, w[:, ::-1])
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


# ----------------------------------------------------------------------------- quadrature


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


def test_quadrature_is_converged(monkeypatch):
    # tightening every rule and criterion must not change the result
    cases = [monotone_polyline(s) for s in (0, 1, 2)]
    cases.append(
        polyline(
            [[np.cos(0.2), np.sin(0.2)], [0, 0], [1, 0]],
            lambda p: 1 + np.hypot(p[:, 0], p[:, 1]),
            [[0.5], [0.5]],
        )
    )
    cases.append(on_line([-1, 0, 1e-6, 2e-6, 1], lambda x: x + 0.5e-6))
    base = [hhalf_norm2_positive_part(*c)[0] for c in cases]
    monkeypatch.setattr(hh, "_FAR_TIERS", ((64.0, 12), (16.0, 16), (4.0, 32)))
    monkeypatch.setattr(hh, "_TOUCH_RUN_RATIO", 8.0)
    monkeypatch.setattr(hh, "_TOUCH_RUN_ORDER", 32)
    monkeypatch.setattr(hh, "_DUFFY_ORDER", (6, 60))
    tight = [hhalf_norm2_positive_part(*c)[0] for c in cases]
    np.testing.assert_allclose(base, tight, rtol=1e-13)


def test_many_edges_small_support_is_fast():
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
    assert elapsed < 1.0
    assert 0 < np.count_nonzero(share) <= 40
    # each bump equals the same bump computed on its own with the rest of Γ_C as zero set:
    # compare with a coarse restriction holding the same support (the far zero set only
    # enters through analytic integrals over runs)
    support = np.flatnonzero(share > 0)
    lo, hi = support.min() - 1, support.max() + 2
    sub = slice(lo, hi)
    pad_x0 = np.vstack([[[0.0, 0.0]], x0[sub], [[t[hi], 0.0]]])
    pad_x1 = np.vstack([[[t[lo], 0.0]], x1[sub], [[1.0, 0.0]]])
    pad_w = np.vstack([[[-1.0, -1.0, w[lo, 0]]], w[sub], [[w[hi - 1, 2], -1.0, -1.0]]])
    assert hhalf_norm2_positive_part(pad_x0, pad_x1, pad_w)[0] == pytest.approx(total, rel=1e-12)


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize(
    ("x0", "x1", "w", "match"),
    [
        (np.zeros((2, 3)), np.ones((2, 2)), np.ones((2, 3)), "x0 must have shape"),
        (np.zeros((2, 2)), np.ones((3, 2)), np.ones((2, 3)), "same number of edges"),
        (np.zeros((2, 2)), np.ones((2, 2)), np.ones((2, 2)), "w must have shape"),
        (np.zeros((1, 2)), np.array([[np.nan, 1.0]]), np.ones((1, 3)), "NaN"),
        (np.zeros((1, 2)), np.zeros((1, 2)), np.ones((1, 3)), "zero length"),
        ([["a", "b"]], [[1.0, 1.0]], [[1.0, 1.0, 1.0]], "real array"),
    ],
)
def test_bad_input(x0, x1, w, match):
    with pytest.raises(ValueError, match=match):
        hhalf_norm2_positive_part(x0, x1, w)


def test_jump_of_the_positive_part_is_rejected():
    x0 = np.array([[0.0, 0.0], [1.0, 0.0]])
    x1 = np.array([[1.0, 0.0], [2.0, 0.0]])
    w = np.array([[1.0, 1.0, 1.0], [0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match="discontinuous"):
        hhalf_norm2_positive_part(x0, x1, w)
    # a jump between negative values is harmless: v = max(w, 0) is continuous
    w = np.array([[1.0, 0.5, -1.0], [-2.0, -2.0, -2.0]])
    assert hhalf_norm2_positive_part(x0, x1, w)[0] > 0


@pytest.mark.parametrize("cross_at", [0.5, 0.3])
def test_crossing_edges_are_reported(cross_at):
    # two crossing edges with v > 0 on both (the norm is infinite): crossing at the
    # midpoints, where bisection points coincide, and at a generic point
    x0 = np.array([[0.0, 0.0], [cross_at, -0.5]])
    x1 = np.array([[1.0, 0.0], [cross_at, 0.7]])
    w = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    with pytest.raises(ValueError, match="overlap or cross"):
        hhalf_norm2_positive_part(x0, x1, w)
    # a positive piece crossing a zero edge
    with pytest.raises(ValueError, match="overlap or cross"):
        hhalf_norm2_positive_part(x0, x1, np.array([[1.0, 1.0, 1.0], [-1.0, -1.0, -1.0]]))


# ----------------------------------------------------------------------------- brute force


def brute_force_seminorm(x0, x1, w):
    """Nested adaptive quad of (v(x)-v(y))^2/|x-y|^2, v = max(w, 0) evaluated pointwise.

    Every pair of edges is integrated separately, with the kinks of v (roots found
    by ``np.roots``) and the diagonal passed to QUADPACK as break points.
    """
    a = w[:, 0]
    b = -3 * w[:, 0] + 4 * w[:, 1] - w[:, 2]
    c = 2 * w[:, 0] - 4 * w[:, 1] + 2 * w[:, 2]
    length = np.hypot(*(x1 - x0).T)
    kinks = []
    for i in range(len(x0)):
        r = np.roots([c[i], b[i], a[i]]) if c[i] != 0 else np.roots([b[i], a[i]])
        kinks.append(sorted(float(z.real) for z in r if abs(z.imag) < 1e-14 and 0 < z.real < 1))

    def v(i, t):
        return max(a[i] + t * (b[i] + t * c[i]), 0.0)

    total = 0.0
    for i in range(len(x0)):
        for j in range(len(x0)):

            def inner(t, i=i, j=j):
                x = x0[i] + t * (x1[i] - x0[i])
                vx = v(i, t)

                def f(s):
                    d = x - x0[j] - s * (x1[j] - x0[j])
                    d2 = d @ d
                    return 0.0 if d2 == 0.0 else (vx - v(j, s)) ** 2 / d2

                brk = kinks[j] + ([t] if i == j else [])
                val = quad(f, 0, 1, points=brk or None, epsabs=1e-15, epsrel=1e-12, limit=200)
                return val[0] * length[j]

            val = quad(inner, 0, 1, points=kinks[i] or None, epsabs=1e-15, epsrel=1e-12, limit=200)
            total += val[0] * length[i]
    return total


@pytest.mark.slow
def test_polyline_against_brute_force():
    pts = np.array([[0.0, 0.0], [1.0, 0.2], [1.3, 1.0], [0.7, 1.5]])
    x0, x1 = pts[:-1], pts[1:]
    w = np.array([[0.4, -0.5, -0.1], [-0.1, 0.36, 0.64], [0.64, 0.2, 0.3]])
    ref = brute_force_seminorm(x0, x1, w)
    assert hhalf_seminorm2_positive_part(x0, x1, w)[0] == pytest.approx(ref, rel=1e-10)
