"""The quadrature rules for blocks of pairs
(:mod:`signorini.estimator.h_half_norm.pair_rules`), each against a closed form or an
independent integral."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import dblquad

from signorini.estimator.h_half_norm import positive_part_pieces
from signorini.estimator.h_half_norm.pair_rules import (
    duffy_angular_order,
    duffy_pair_integral,
    far_pair_integral,
    same_edge_integral,
    same_edge_pairs,
    zero_run_integral,
)

from .polylines import on_line, polyline

WHOLE = np.array([[0.0, 1.0]])


def test_same_edge_integral_of_one_piece():
    """v = t² on [0, 1]: ∫∫ (t + s)² = 7/6."""
    pc = positive_part_pieces(*on_line([0, 1], lambda x: x**2))
    ii, jj, mult = same_edge_pairs(pc)
    np.testing.assert_array_equal([ii, jj, mult], [[0], [0], [1.0]])
    assert same_edge_integral(pc, ii, jj)[0] == pytest.approx(7 / 6, rel=1e-15)


def test_same_edge_integral_of_two_pieces_of_one_edge():
    """v = (t − 0.3)(t − 0.7) is positive on [0, 0.3] and [0.7, 1]: the divided difference
    t + s − 1 makes every same-edge pair a polynomial integral."""
    pc = positive_part_pieces(*on_line([0, 1], lambda x: (x - 0.3) * (x - 0.7)))
    ii, jj, mult = same_edge_pairs(pc)
    np.testing.assert_array_equal(ii, [0, 1, 0])
    np.testing.assert_array_equal(jj, [0, 1, 1])
    np.testing.assert_array_equal(mult, [1.0, 1.0, 2.0])
    got = same_edge_integral(pc, ii, jj)

    def f(s, t):
        return (t + s - 1.0) ** 2

    expected = [
        dblquad(f, 0, 0.3, 0, 0.3)[0],
        dblquad(f, 0.7, 1, 0.7, 1)[0],
        dblquad(f, 0, 0.3, 0.7, 1)[0],
    ]
    np.testing.assert_allclose(got, expected, rtol=1e-13)


def test_far_pair_integral_against_a_finer_rule():
    """Two unit segments at separation ratio r: each tier's rule agrees with 40 x 40 points."""
    for r, n in ((1.0, 12), (4.0, 8), (16.0, 6), (64.0, 4)):
        x0 = np.array([[0.0, 0.0], [1.0 + r, 0.3]])
        x1 = np.array([[1.0, 0.0], [2.0 + r, -0.2]])
        w = np.array([[0.5, 1.0, 1.2], [2.0, 0.3, 1.5]])
        pc = positive_part_pieces(x0, x1, w)
        p, q = np.array([0]), np.array([1])
        got = far_pair_integral(pc, p, WHOLE, q, WHOLE, n)[0]
        fine = far_pair_integral(pc, p, WHOLE, q, WHOLE, 40)[0]
        assert got == pytest.approx(fine, rel=2e-15), (r, n)


@pytest.mark.parametrize("degrees", [25.0, 90.0, 135.0, 180.0])
def test_duffy_pair_integral_against_dblquad(degrees):
    """Arms of length 1 from a corner, v = 1 + t (t = distance to the corner):
    ∫∫ (t − s)² / (t² + s² − 2 t s cos α)."""
    al = np.deg2rad(degrees)
    arm = np.array([np.cos(al), np.sin(al)])
    x0, x1, w = polyline([arm, [0.0, 0.0], [1.0, 0.0]], lambda p: 1 + np.hypot(p[:, 0], p[:, 1]))
    pc = positive_part_pieces(x0, x1, w)
    # piece 0 runs towards the corner (it ends there), piece 1 starts there
    got = duffy_pair_integral(
        pc, np.array([0]), WHOLE, np.array([True]), np.array([1]), WHOLE, np.array([False])
    )[0]
    cos = np.cos(al)
    expected, _ = dblquad(
        lambda s, t: (t - s) ** 2 / (t * t + s * s - 2 * t * s * cos),
        0,
        1,
        0,
        1,
        epsabs=1e-14,
        epsrel=1e-13,
    )
    assert got == pytest.approx(expected, rel=1e-12)


def test_duffy_angular_order_grows_as_the_edges_fold():
    a = b = np.ones(5)
    cos = np.cos(np.array([np.pi, np.pi / 2, 0.3, 0.01, 1e-4]))
    order = duffy_angular_order(a, b, cos)
    assert order[0] == order[1] == 20  # the floor
    assert np.all(np.diff(order) >= 0) and order[3] > 20 and order[4] == 400  # the cap


def test_duffy_rejects_a_jump_at_the_common_point():
    x0 = np.array([[0.0, 0.0], [0.0, 0.0]])
    x1 = np.array([[1.0, 0.0], [0.0, 1.0]])
    w = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])  # v = 1 and v = 2 meet at the origin
    pc = positive_part_pieces(x0, x1, w, validate=False)
    starts = np.array([False])
    with pytest.raises(ValueError, match="overlap or cross"):
        duffy_pair_integral(pc, np.array([0]), WHOLE, starts, np.array([1]), WHOLE, starts)


@pytest.mark.parametrize("run", [2.0, 5.0])
def test_zero_run_integral_touching_in_closed_form(run):
    """v = t on [0, 1], v = 0 on the run [−L, 0]: ∫_0^1 t² (1/t − 1/(t + L)) dt
    = L − L² ln(1 + 1/L), by the touching rule (run ≥ TOUCH_RUN_RATIO panels long)."""
    x0, x1, w = on_line([-run, 0, 1], lambda x: x)
    pc = positive_part_pieces(x0, x1, w)
    assert pc.n_pieces == 1 and pc.n_runs == 1
    got = zero_run_integral(pc, np.array([0]), WHOLE, pc.run_start, pc.run_end, 12)[0]
    assert got == pytest.approx(run - run**2 * np.log(1 + 1 / run), rel=1e-14)
