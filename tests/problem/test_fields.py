"""User functions of ``x`` (:mod:`signorini.problem.fields`): constants as functions, and the
one check of what a user function returns."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.problem.fields import ProblemError, constant_field, evaluate_field

X = np.random.default_rng(2).random((4, 3, 2))


def test_constant_fields():
    v = constant_field((1.5, -2.0))(X)
    assert v.shape == (4, 3, 2) and np.array_equal(v[2, 1], [1.5, -2.0])
    v[0, 0] = 0.0  # a fresh array each call
    assert np.array_equal(constant_field((1.5, -2.0))(X)[0, 0], [1.5, -2.0])
    s = constant_field(0.25, shape=())(X)
    assert s.shape == (4, 3) and np.all(s == 0.25)
    with pytest.raises(ValueError):
        constant_field((1.0, 2.0, 3.0))


def test_evaluate_field_broadcasts_and_checks_shape():
    def f(x):
        return np.stack([x[..., 0], 2 * x[..., 1]], axis=-1)

    assert np.array_equal(evaluate_field(f, X, "f"), f(X))
    assert np.array_equal(evaluate_field(lambda x: np.array([1.0, 2.0]), X, "f")[3, 2], [1, 2])
    gap = evaluate_field(lambda x: x[..., 0] - 1, X, "the gap", shape=())
    assert np.array_equal(gap, X[..., 0] - 1)
    grad = evaluate_field(lambda x: np.eye(2), X, "the gradient", shape=(2, 2))
    assert grad.shape == (4, 3, 2, 2) and np.array_equal(grad[1, 1], np.eye(2))
    with pytest.raises(
        ProblemError, match=r"the body force must return shape \(4, 3, 2\) .*got \(4, 3\)"
    ):
        evaluate_field(lambda x: x[..., 0], X, "the body force")
    with pytest.raises(ProblemError, match=r"the gap must return shape \(4, 3\)"):
        evaluate_field(lambda x: x, X, "the gap", shape=())
    with pytest.raises(ProblemError, match="the gradient must return shape"):
        evaluate_field(lambda x: x, X, "the gradient", shape=(2, 2))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_evaluate_field_rejects_non_finite_values(bad):
    def f(x):
        out = np.zeros(x.shape)
        out[1, 2, 0] = bad
        return out

    with pytest.raises(ProblemError, match="the traction of part 'top' returned NaN or inf"):
        evaluate_field(f, X, "the traction of part 'top'")


def test_problem_error_is_a_value_error():
    assert issubclass(ProblemError, ValueError)
