"""Boundary conditions (:mod:`signorini.problem.conditions`): data as given, handed out as
functions of ``x``."""

from __future__ import annotations

import numpy as np

from signorini.problem.conditions import Contact, Dirichlet, Neumann

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

    def g(x, n):
        return x[..., :1] * n

    assert not Neumann(g).is_zero
    assert np.array_equal(Neumann(g).field()(X, N), [[0.0, 0.0], [0.0, -2.0], [0.0, -4.0]])


def test_contact_gap_field():
    assert np.array_equal(Contact().gap_field()(X), np.zeros(3))
    assert np.array_equal(Contact(0.25).gap_field()(X), [0.25] * 3)
    assert np.array_equal(Contact(lambda x: x[..., 1] - x[..., 0]).gap_field()(X), [1.0] * 3)
    assert Contact().normal is None
