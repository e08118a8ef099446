"""The quadratic on an edge (:mod:`signorini.fem.edge_trace`): monomial form, values,
maximum and sign-changing roots, in the edge-node order [start, end, midpoint]."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from signorini.fem.edge_trace import (
    evaluate,
    maximum_on_unit_interval,
    monomial_coefficients,
    roots_in_unit_interval,
)
from signorini.fem.p2 import edge_basis

RNG = np.random.default_rng(7)


def test_monomials_reproduce_the_p2_edge_basis():
    """The monomial form and p2.edge_basis are the same quadratic, node order included."""
    values = RNG.normal(size=(50, 3))
    t = np.linspace(0.0, 1.0, 11)
    expected = values @ edge_basis(t).T
    got = evaluate(monomial_coefficients(values), np.broadcast_to(t, (50, t.size)))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)
    # the nodes: t = 0 is the start, t = 1 the end, t = 1/2 the midpoint
    at_nodes = evaluate(monomial_coefficients(values), np.tile([0.0, 1.0, 0.5], (50, 1)))
    np.testing.assert_allclose(at_nodes, values, rtol=0, atol=1e-14)


def test_monomials_closed_form():
    # v(t) = t²: values 0 at the start, 1 at the end, 1/4 at the midpoint
    np.testing.assert_array_equal(monomial_coefficients(np.array([[0.0, 1.0, 0.25]])), [[0, 0, 1]])
    # v(t) = 2 − 3t: linear, c = 0 exactly
    np.testing.assert_array_equal(
        monomial_coefficients(np.array([[2.0, -1.0, 0.5]])), [[2.0, -3.0, 0.0]]
    )


@pytest.mark.parametrize(
    ("values", "expected"),
    [
        ([0.0, 0.0, 1.0], 1.0),  # 4 t (1 − t): vertex at 1/2
        ([-1.0, 0.0, 0.5], 0.5625),  # −1 + 5t − 4t²: vertex at t = 5/8
        ([1.0, 2.0, 1.0], 2.0),  # convex: the maximum at an end
        ([-1.0, -3.0, -2.0], -1.0),  # linear
    ],
)
def test_maximum_on_unit_interval(values, expected):
    v = np.array([values])
    got = maximum_on_unit_interval(v, monomial_coefficients(v))[0]
    dense = evaluate(monomial_coefficients(v), np.linspace(0, 1, 100001)[None]).max()
    assert got == pytest.approx(expected, rel=1e-14)
    assert got == pytest.approx(dense, abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(
    r1=st.floats(0.001, 0.999),
    r2=st.floats(0.001, 0.999),
    scale=st.floats(1e-12, 1e12),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_roots_of_a_quadratic_with_known_roots(r1, r2, scale, sign):
    """``scale · sign · (t − r1)(t − r2)`` has its sign-changing roots at r1, r2 (none if
    they coincide: a double root does not change sign)."""
    v = sign * scale * (np.array([0.0, 1.0, 0.5]) - r1) * (np.array([0.0, 1.0, 0.5]) - r2)
    roots = roots_in_unit_interval(monomial_coefficients(v[None]))[0]
    if abs(r1 - r2) < 1e-6:
        return  # near-double roots: either kept or dropped, checked below
    found = np.sort(roots[~np.isnan(roots)])
    np.testing.assert_allclose(found, sorted([r1, r2]), rtol=0, atol=1e-9)


def test_roots_special_cases():
    coef = monomial_coefficients(
        np.array(
            [
                [-1.0, 1.0, 0.0],  # linear through 1/2
                [0.25, 0.25, 0.0],  # (t − 1/2)²: double root, no sign change
                [1.0, 1.0, 1.0],  # constant: none
                [0.0, 1.0, 0.25],  # t²: double root at the start, excluded
                [0.0, 0.0, 0.0],  # zero: none
                [-1.0, 1.0, 0.5],  # −1 + 4t − 2t²: roots 1 ± 1/√2, one inside
            ]
        )
    )
    roots = roots_in_unit_interval(coef)
    assert np.nanmax(np.abs(roots[0] - 0.5)) < 1e-15 and np.isnan(roots[0]).sum() == 1
    assert np.isnan(roots[1:5]).all()
    inside = roots[5][~np.isnan(roots[5])]
    a, b, c = coef[5]
    assert inside.size == 1 and abs(a + inside[0] * (b + inside[0] * c)) < 1e-15


def test_roots_snap_drops_roots_near_the_ends_and_close_pairs():
    coef = monomial_coefficients(np.array([[-1e-14, 1.0, 0.5], [0.0, 0.0, 0.0]]))
    coef[1] = [1e-20, -1.0, 1.0]  # roots 1e-20 and 1 − 1e-20
    assert np.isfinite(roots_in_unit_interval(coef[:1])).sum() == 1  # root at ~1e-14
    assert np.isnan(roots_in_unit_interval(coef[:1], snap=1e-13)).all()
    assert np.isnan(roots_in_unit_interval(coef[1:], snap=1e-13)).all()
    # (t − 1/2)² − ε²: two roots 2ε apart, kept at resolution 0, dropped at resolution 4ε
    eps = 1e-5
    pair = np.array([[0.25 - eps**2, -1.0, 1.0]])
    np.testing.assert_allclose(roots_in_unit_interval(pair)[0], [0.5 + eps, 0.5 - eps], rtol=1e-12)
    assert np.isnan(roots_in_unit_interval(pair, snap=4 * eps)).all()
    # closer than the tangency tolerance (vertex value ε² ≤ TANGENT_TOL): a double root
    eps = 1e-7
    assert np.isnan(roots_in_unit_interval(np.array([[0.25 - eps**2, -1.0, 1.0]]))).all()
