"""User functions of ``x`` (:mod:`signorini.problem.fields`): constants as functions, the calling
convention, and the one check of what a user function returns."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from signorini import (
    Contact,
    ContactProblem,
    Dirichlet,
    Material,
    Neumann,
    Roller,
    rectangle,
    solve,
)
from signorini.problem.fields import (
    CALL_NAMED,
    CALL_POSITIONAL,
    CALL_X,
    ProblemError,
    check_function,
    check_numbers,
    constant_field,
    evaluate_field,
)

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


def test_user_functions_receive_flat_points():
    # points of any leading shape reach the user as (n, 2): x[:, 0] works as x[..., 0] does
    seen = []

    def gap(x):
        seen.append(x.shape)
        return x[:, 0] - 2 * x[:, 1]

    values = evaluate_field(gap, X, "the gap", shape=())
    assert seen == [(12, 2)]
    assert np.array_equal(values, X[..., 0] - 2 * X[..., 1])

    def u(x):
        return np.column_stack([x[:, 1], -x[:, 0]])

    assert np.array_equal(evaluate_field(u, X, "u"), np.stack([X[..., 1], -X[..., 0]], -1))


def test_the_normal_reaches_the_user_broadcast_to_the_points():
    n = np.array([[0.0, -1.0], [1.0, 0.0], [0.6, 0.8], [-1.0, 0.0]])[:, None, :]  # (4, 1, 2)
    got = evaluate_field(lambda x, normal: 2.0 * normal, X, "g", normal=n)
    assert got.shape == (4, 3, 2)
    assert np.array_equal(got, 2.0 * np.broadcast_to(n, X.shape))


def test_evaluate_field_constants_and_shapes():
    assert np.array_equal(evaluate_field(lambda x: np.array([1.0, 2.0]), X, "f")[3, 2], [1, 2])
    assert np.array_equal(evaluate_field(lambda x: 0.5, X, "gap", shape=()), np.full((4, 3), 0.5))
    grad = evaluate_field(lambda x: np.eye(2), X, "the gradient", shape=(2, 2))
    assert grad.shape == (4, 3, 2, 2) and np.array_equal(grad[1, 1], np.eye(2))
    with pytest.raises(
        ProblemError,
        match=r"^the body force must return shape \(12, 2\) for points of shape \(12, 2\), "
        r"got \(12,\)$",
    ):
        evaluate_field(lambda x: x[:, 0], X, "the body force")
    with pytest.raises(
        ProblemError,
        match=r"^the gap function of contact part 'right' must return shape \(12,\) for points "
        r"of shape \(12, 2\), got \(12, 2\)$",
    ):
        evaluate_field(lambda x: x, X, "the gap function of contact part 'right'", shape=())
    with pytest.raises(ProblemError, match="the gradient must return shape"):
        evaluate_field(lambda x: x, X, "the gradient", shape=(2, 2))
    # only one value per point or one value for all: no other broadcasting
    with pytest.raises(ProblemError, match=r"got \(1, 2\)"):
        evaluate_field(lambda x: np.zeros((1, 2)), X, "u")


def test_a_user_function_that_raises_is_named():
    def g(x, normal):
        return 1 // 0

    with pytest.raises(
        ProblemError,
        match=r"^the traction of Neumann part 'top' raised ZeroDivisionError: "
        "integer division or modulo by zero$",
    ) as info:
        evaluate_field(g, X, "the traction of Neumann part 'top'", normal=X)
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_a_user_function_that_returns_no_numbers():
    with pytest.raises(ProblemError, match=r"^the gap returned None \(is a return statement"):
        evaluate_field(lambda x: None, X, "the gap", shape=())
    with pytest.raises(ProblemError, match="^the gap must return an array of numbers, got str"):
        evaluate_field(lambda x: "far", X, "the gap", shape=())


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_evaluate_field_rejects_non_finite_values(bad):
    def f(x):
        out = np.zeros(x.shape)
        out[7, 0] = bad
        return out

    with pytest.raises(ProblemError, match="the traction of part 'top' returned NaN or inf"):
        evaluate_field(f, X, "the traction of part 'top'")


def test_calling_forms():
    def named(x, normal):
        return normal

    def keyword_only(x, *, normal):
        return normal

    def extras(x, **kw):
        return kw["normal"]

    assert check_function(named, "g", "a traction", normal=True) == CALL_NAMED
    assert check_function(keyword_only, "g", "a traction", normal=True) == CALL_NAMED
    assert check_function(extras, "g", "a traction", normal=True) == CALL_NAMED
    assert check_function(lambda x: x, "g", "a traction", normal=True) == CALL_X
    assert check_function(lambda x: x, "f", "a field") == CALL_X
    assert check_function(np.sin, "f", "a field") == CALL_X
    with pytest.warns(DeprecationWarning, match=r"name the parameter `normal` \(def g\(x, normal"):
        assert check_function(lambda x, n: n, "g", "a traction", normal=True) == CALL_POSITIONAL


def test_wrong_signatures_are_named():
    with pytest.raises(
        ProblemError,
        match=r"^Neumann\(traction=...\) must be a traction; got a function with signature "
        r"\(x, y, z\)$",
    ):
        check_function(lambda x, y, z: x, "Neumann(traction=...)", "a traction", normal=True)
    # without a normal to pass, two arguments is not a field of x
    with pytest.raises(ProblemError, match=r"signature \(x, n\)$"):
        check_function(lambda x, n: x, "Contact(gap=...)", "a gap")
    with pytest.raises(ProblemError, match=r"signature \(\)$"):
        check_function(lambda: 0, "Contact(gap=...)", "a gap")
    with pytest.raises(ProblemError, match=r"^f must be a function; got 3$"):
        check_function(3, "f", "a function")


def test_no_warning_for_the_current_forms():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_function(lambda x, normal: x, "g", "a traction", normal=True)
        check_function(lambda x: x, "g", "a traction", normal=True)


@pytest.mark.parametrize(
    ("value", "size"),
    [((1.0, 2.0, 3.0), 2), ((np.nan, 0.0), 2), ("ab", 2), ("1", 1), (None, 1), ([[1.0, 2.0]], 2)],
)
def test_check_numbers(value, size):
    with pytest.raises(ProblemError, match=rf"^A must be B; got {re_repr(value)}$"):
        check_numbers(value, size, "A", "B")


def re_repr(value) -> str:
    return re.escape(repr(value))


def test_problem_error_is_a_value_error():
    assert issubclass(ProblemError, ValueError)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Dirichlet((1e200, None)), r"Dirichlet\(value=\.\.\.\) = \(1e\+200, None\) is "),
        (lambda: Dirichlet((0.0, -1e300)), r"Dirichlet\(value=\.\.\.\) = \(0\.0, -1e\+300\) is "),
        (lambda: Contact(gap=1e300), r"Contact\(gap=\.\.\.\) = 1e\+300 is "),
    ],
)
def test_lengths_whose_squares_overflow_are_refused_naming_the_condition(build, message):
    with pytest.raises(ProblemError, match=message + r".*beyond ±1\.34e\+150.*overflow"):
        build()


def _floated(young=10.0, **kwargs) -> ContactProblem:
    """The unit square under force control: a roller on its left, its bottom on a floor."""
    conditions = {
        "left": Roller(),
        "right": Neumann(),
        "top": Neumann(kwargs.pop("top", (0.0, -1.0))),
        "bottom": Contact(gap=0.0),
    }
    return ContactProblem(
        rectangle(nx=2, ny=2), Material.from_young(young, 0.3), conditions, **kwargs
    )


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"top": (0.0, -1e300)}, r"the traction of Neumann part 'top' is too large"),
        ({"body_force": lambda x: (0.0, -1e300)}, r"the body force is too large"),
        ({"top": lambda x: (0.0, -1e160)}, r"the traction of Neumann part 'top' is too large"),
    ],
    ids=["traction", "body-force", "traction-function"],
)
def test_a_load_whose_displacement_overflows_is_refused_naming_it(kwargs, message):
    # before: NumPy's "array must not contain infs or NaNs" from the force-control check
    with pytest.raises(
        ProblemError,
        match=message + r" for the body's stiffness: .* so the displacement reaches at least "
        r".* beyond ±1\.34e\+150",
    ):
        solve(_floated(**kwargs))


def test_a_load_as_extreme_as_the_modulus_is_solved_under_force_control():
    # E = 1e300 pressed by 0.1 E: the same displacement as E = 10 pressed by 1
    small, large = solve(_floated()), solve(_floated(1e300, top=(0.0, -1e299)))
    np.testing.assert_allclose(large.u, small.u, rtol=1e-12, atol=1e-14)
    assert large.total_contact_force == pytest.approx(1e299, rel=1e-12)


def test_a_dirichlet_function_whose_squares_overflow_is_named():
    problem = ContactProblem(
        rectangle(nx=2, ny=2),
        Material.from_young(10.0, 0.3),
        {
            "left": Neumann(),
            "right": Neumann(),
            "top": Dirichlet(lambda x: np.column_stack([0 * x[:, 0], -1e300 + 0 * x[:, 0]])),
            "bottom": Contact(gap=0.0),
        },
    )
    with pytest.raises(
        ProblemError, match=r"the Dirichlet value of part 'top' returned 1e\+300 .*beyond"
    ):
        solve(problem)
