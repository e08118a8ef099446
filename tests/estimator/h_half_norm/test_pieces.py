"""Γ_C cut at the roots of w (:mod:`signorini.estimator.h_half_norm.pieces`), and the
validation of the edge data."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.estimator.h_half_norm import hhalf_norm2_positive_part, positive_part_pieces

from .polylines import L_SHAPE, monomials, monotone_polyline, on_line, polyline


def piece_values(pc, u):
    """v at parameters ``u (q,)`` of every piece, from the pieces' own coefficients."""
    return pc.coef[:, :1] + u * (pc.coef[:, 1:2] + u * pc.coef[:, 2:3])


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
    v = piece_values(pc, np.array([0.0, 1.0]))
    assert abs(v[0, 0]) < 1e-15 and abs(v[1, 1]) < 1e-15


def test_pieces_carry_the_edge_quadratic():
    """On every piece, v(u) equals w at the corresponding edge parameter, and v > 0 inside."""
    x0, x1, w = monotone_polyline(4, n_seg=6, n_cut=2)
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces > 3
    u = np.linspace(0.0, 1.0, 9)
    s = pc.s[:, :1] + (pc.s[:, 1:] - pc.s[:, :1]) * u
    a, b, c = (m[pc.edge, None] for m in monomials(w))
    np.testing.assert_allclose(piece_values(pc, u), a + s * (b + s * c), rtol=1e-12, atol=1e-14)
    assert np.all(piece_values(pc, u[1:-1]) > 0)
    # the pieces' points lie on their edges, at the parameters s
    d = x1[pc.edge] - x0[pc.edge]
    np.testing.assert_allclose(pc.start, x0[pc.edge] + pc.s[:, :1] * d, atol=1e-14)
    np.testing.assert_allclose(pc.end, x0[pc.edge] + pc.s[:, 1:] * d, atol=1e-14)


def test_zero_runs_are_maximal_straight_runs():
    # w < 0 on every edge: five collinear edges merge into one run; an L-shape gives two
    x0, x1, w = on_line(np.linspace(0, 1, 6), lambda x: -1 - x)
    w[2, 2] = 0.5  # one edge positive around its midpoint: cuts the run in two
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces == 1 and pc.n_runs == 2
    x0, x1, w = polyline(L_SHAPE, lambda p: -1 - p[:, 0], [[0.3, 0.6], [0.5]])
    w[0] = [-1.0, -1.0, 1.0]  # the first edge positive inside, the rest zero
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_runs == 3  # the vertical arm split at the piece, the horizontal arm
    lengths = np.sort(np.hypot(*(pc.run_end - pc.run_start).T))
    assert lengths[-1] == pytest.approx(1.0, rel=1e-15)


def test_no_positive_part():
    x0, x1, w = polyline(L_SHAPE, lambda p: -((p[:, 0] - 0.5) ** 2) - p[:, 1], [[0.5], [0.3]])
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces == 0 and pc.v_scale == 0.0 and pc.n_edges == x0.shape[0]
    assert positive_part_pieces(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 3))).n_pieces == 0


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
        positive_part_pieces(x0, x1, w)
    with pytest.raises(ValueError, match=match):
        hhalf_norm2_positive_part(x0, x1, w)


def test_jump_of_the_positive_part_is_rejected():
    x0 = np.array([[0.0, 0.0], [1.0, 0.0]])
    x1 = np.array([[1.0, 0.0], [2.0, 0.0]])
    w = np.array([[1.0, 1.0, 1.0], [0.5, 0.5, 0.5]])
    with pytest.raises(ValueError, match="discontinuous"):
        positive_part_pieces(x0, x1, w)
    # trusted callers skip the check (their data are continuous by construction)
    assert positive_part_pieces(x0, x1, w, validate=False).n_pieces == 2
    # a jump between negative values is harmless: v = max(w, 0) is continuous
    w = np.array([[1.0, -1.0, 0.5], [-2.0, -2.0, -2.0]])
    assert hhalf_norm2_positive_part(x0, x1, w)[0] > 0
