"""Tests of Dörfler marking in :mod:`signorini.estimator.marking` (docs/method.md, *Marking and
refinement*)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from signorini.estimator.marking import TIE_RTOL, mark_doerfler

indicators = st.lists(
    st.floats(min_value=0.0, max_value=1e6, allow_nan=False, allow_infinity=False),
    min_size=1,
    max_size=200,
).map(np.array)
thetas = st.floats(min_value=0.0, max_value=1.0, exclude_min=True)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(eta2=indicators, theta=thetas)
def test_doerfler_set_reaches_theta_and_is_minimal(eta2, theta):
    marked = mark_doerfler(eta2, theta)
    assert marked.dtype == bool and marked.shape == eta2.shape
    total = math.fsum(eta2)
    if total == 0.0:
        assert marked.all()  # nothing to choose from: uniform refinement
        return
    k = int(marked.sum())
    assert k >= 1
    # the set reaches the bulk criterion Σ_M η_T² ≥ θ Σ η_T² (up to round-off)
    assert math.fsum(eta2[marked]) >= theta * total * (1 - 1e-12)
    # indicators within TIE_RTOL · max of each other are ties, taken by cell index (marking's
    # sort key), so "largest" holds up to one tie step per cell
    tie = TIE_RTOL * eta2.max()
    # minimal cardinality: the k - 1 largest indicators (the largest sum any k - 1 cells can
    # have) stay below θ · total
    largest = np.sort(eta2)[::-1]
    assert k == 1 or math.fsum(largest[: k - 1]) < theta * total * (1 + 1e-12) + k * tie
    # the marked cells are the largest ones
    if k < eta2.size:
        assert eta2[marked].min() >= eta2[~marked].max() - tie


def test_a_tie_is_broken_by_cell_index():
    """The case a random search found: two indicators equal to within TIE_RTOL; marking takes
    the first cell although the second is larger in its last bits."""
    eta2 = np.array([999999.9999999999, 1e6])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.4), [True, False])


@settings(max_examples=100, deadline=None)
@given(eta2=indicators)
def test_theta_one_marks_every_cell(eta2):
    assert mark_doerfler(eta2, 1.0).all()


def test_closed_form_marking():
    eta2 = np.array([1.0, 4.0, 2.0, 3.0])  # total 10
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.4), [False, True, False, False])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.41), [False, True, False, True])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.7), [False, True, False, True])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.71), [False, True, True, True])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.9), [False, True, True, True])
    np.testing.assert_array_equal(mark_doerfler(eta2, 0.91), [True, True, True, True])


def test_one_dominant_cell_is_enough():
    eta2 = np.full(1000, 1e-6)
    eta2[417] = 1.0
    marked = mark_doerfler(eta2, 0.5)
    assert np.flatnonzero(marked).tolist() == [417]


@pytest.mark.parametrize("theta", [0.0, -1.0, 1.5, float("nan"), float("inf"), "abc", None])
def test_invalid_theta_raises(theta):
    with pytest.raises(ValueError, match="theta"):
        mark_doerfler(np.ones(5), theta)


@pytest.mark.parametrize(
    ("eta2", "message"),
    [
        (np.array([1.0, np.nan, 2.0]), "NaN"),
        (np.array([1.0, np.inf]), "inf"),
        (np.array([1.0, -0.5, 2.0]), "non-negative"),
        (np.ones((2, 3)), "1-d"),
    ],
)
def test_invalid_indicators_raise(eta2, message):
    with pytest.raises(ValueError, match=message):
        mark_doerfler(eta2, 0.5)


def test_ties_are_broken_by_cell_index_not_by_round_off():
    """Mirror pairs of equal indicators whose last bits differ by round-off (as a change of
    the solver's ordering leaves them): the same cells are marked whichever of a pair is
    larger, the cell with the smaller index first, and the set stays minimal."""
    rng = np.random.default_rng(4)
    half = rng.uniform(1.0, 100.0, size=50)
    eta2 = np.concatenate([half, half])  # cell i and cell i + 50 are mirror images
    reference = mark_doerfler(eta2, 0.37)
    for _ in range(20):
        noisy = eta2 * (1 + 4e-16 * rng.standard_normal(eta2.size))
        marked = mark_doerfler(noisy, 0.37)
        assert np.array_equal(marked, reference)
        order = np.argsort(-noisy)
        k = int(marked.sum())
        assert noisy[marked].sum() >= 0.37 * noisy.sum() * (1 - 1e-14)
        assert noisy[order[: k - 1]].sum() < 0.37 * noisy.sum()  # minimal cardinality
    # one member of the pair at the cut is marked: the one with the smaller index
    cut = np.flatnonzero(reference[:50] != reference[50:])
    assert cut.size == 1 and reference[cut[0]] and not reference[cut[0] + 50]
