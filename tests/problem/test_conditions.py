"""Boundary conditions (:mod:`signorini.problem.conditions`): data checked when a condition is
built, handed out as functions of ``x``."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from signorini import Contact, Dirichlet, ExactSolution, Neumann, ProblemError
from signorini.problem.fields import evaluate_field

X = np.array([[0.0, 1.0], [2.0, 3.0], [4.0, 5.0]])
N = np.array([[0.0, -1.0]] * 3)


def test_dirichlet_field():
    assert np.array_equal(Dirichlet().field()(X), np.zeros((3, 2)))
    assert np.array_equal(Dirichlet((0.5, -1.0)).field()(X), [[0.5, -1.0]] * 3)

    def u(x):
        return 2 * x

    assert Dirichlet(u).field() is u


def test_neumann_field_and_zero_traction():
    assert Neumann().is_zero and Neumann((0, 0)).is_zero
    assert not Neumann((0.0, 1e-300)).is_zero
    assert np.array_equal(Neumann((1.0, 2.0)).field()(X, N), [[1.0, 2.0]] * 3)

    def g(x, normal):
        return x[:, :1] * normal

    assert not Neumann(g).is_zero
    assert np.array_equal(Neumann(g).field()(X, N), [[0.0, 0.0], [0.0, -2.0], [0.0, -4.0]])


def test_the_three_forms_of_a_traction_give_the_same_values():
    def named(x, normal):
        return x[:, :1] * normal

    def keyword_only(x, *, normal):
        return x[:, :1] * normal

    def old(x, n):
        return x[:, :1] * n

    expected = X[:, :1] * N
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the current forms do not warn
        forms = [Neumann(named), Neumann(keyword_only), Neumann(lambda x: X[:, :1] * N)]
    with pytest.warns(DeprecationWarning, match="name the parameter `normal`") as record:
        forms.append(Neumann(old))
    assert record[0].filename == __file__  # the warning points at the user's line
    for cond in forms:
        got = evaluate_field(cond.field(), X, "the traction", normal=N)
        assert np.array_equal(got, expected)


def test_contact_gap_field():
    assert np.array_equal(Contact().gap_field()(X), np.zeros(3))
    assert np.array_equal(Contact(0.25).gap_field()(X), [0.25] * 3)
    assert np.array_equal(Contact(lambda x: x[..., 1] - x[..., 0]).gap_field()(X), [1.0] * 3)
    assert Contact().normal is None


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (
            lambda: Dirichlet((0.1, 0, 0, 0)),
            "Dirichlet(value=...) must be two finite numbers (u_x, u_y) or a function u_D(x) "
            "of points x (n, 2); got (0.1, 0, 0, 0)",
        ),
        (
            lambda: Dirichlet("0"),
            "Dirichlet(value=...) must be two finite numbers (u_x, u_y) or a function u_D(x) "
            "of points x (n, 2); got '0'",
        ),
        (
            lambda: Dirichlet(lambda x, y: x),
            "Dirichlet(value=...) must be two finite numbers (u_x, u_y) or a function u_D(x) "
            "of points x (n, 2); got a function with signature (x, y)",
        ),
        (
            lambda: Neumann((np.inf, 0.0)),
            "Neumann(traction=...) must be two finite numbers (g_x, g_y) or a function g(x) or "
            "g(x, normal) of points x (n, 2) and outward unit normals normal (n, 2); "
            "got (inf, 0.0)",
        ),
        (
            lambda: Neumann(lambda x, n, t: x),
            "Neumann(traction=...) must be two finite numbers (g_x, g_y) or a function g(x) or "
            "g(x, normal) of points x (n, 2) and outward unit normals normal (n, 2); "
            "got a function with signature (x, n, t)",
        ),
        (
            lambda: Contact(gap="abc"),
            "Contact(gap=...) must be a finite number or a function gap(x) of points x (n, 2); "
            "got 'abc'",
        ),
        (
            lambda: Contact(gap=(0.1, 0.2)),
            "Contact(gap=...) must be a finite number or a function gap(x) of points x (n, 2); "
            "got (0.1, 0.2)",
        ),
        (
            lambda: Contact(normal=(0.0, 0.0)),
            "Contact(normal=...) must be None or two finite numbers, not both zero; got (0.0, 0.0)",
        ),
        (
            lambda: Contact(normal=(np.nan, 1.0)),
            "Contact(normal=...) must be None or two finite numbers, not both zero; got (nan, 1.0)",
        ),
        (
            lambda: ExactSolution(lambda x: x, (1.0, 0.0)),
            "ExactSolution(gradient=...) must be a function grad(x) of points x (n, 2); "
            "got (1.0, 0.0)",
        ),
    ],
)
def test_bad_data_are_named_when_the_condition_is_built(build, message):
    with pytest.raises(ProblemError, match=f"^{re.escape(message)}$"):
        build()
