"""Symmetric elimination with a fixed pattern (signorini.algebra.elimination)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd

from signorini.algebra import SOLVERS, available_backends, make_solver
from signorini.algebra.elimination import SymmetricEliminator, eliminate_symmetric


def _reduced_solution(A, b, fixed, values):
    """Reference: slice the free rows and columns and solve densely."""
    D = A.toarray()
    free = ~fixed
    x = values.copy()
    rhs = b[free] - D[np.ix_(free, fixed)] @ values[fixed]
    x[free] = np.linalg.solve(D[np.ix_(free, free)], rhs)
    return x


@pytest.mark.parametrize("backend", available_backends())
def test_elimination_equals_reduced_system(backend):
    rng = np.random.default_rng(13)
    A = block_spd(7, 6, rng)
    n = A.shape[0]
    b = rng.standard_normal(n)
    fixed = rng.random(n) < 0.3
    values = np.where(fixed, rng.standard_normal(n), 0.0)
    A_el, b_el = eliminate_symmetric(A, b, fixed, values)
    # pattern and diagonal kept, fixed rows and columns zero off the diagonal
    assert np.array_equal(A_el.indptr, A.indptr) and np.array_equal(A_el.indices, A.indices)
    assert np.array_equal(A_el.diagonal(), A.diagonal())
    D = A_el.toarray()
    off = D - np.diag(np.diag(D))
    assert np.abs(off[fixed]).max() == 0 and np.abs(off[:, fixed]).max() == 0
    assert np.abs(D - D.T).max() == 0
    free = ~fixed
    assert np.array_equal(D[np.ix_(free, free)], A.toarray()[np.ix_(free, free)])
    assert np.allclose(b_el[fixed], A.diagonal()[fixed] * values[fixed], rtol=1e-15)
    x = make_solver(SOLVERS[backend], A_el).solve(b_el)
    reference = _reduced_solution(A, b, fixed, values)
    assert np.abs(x - reference).max() < 1e-10 * np.abs(reference).max()
    assert np.abs((b - A @ x)[free]).max() < 1e-10 * np.abs(b).max()


def test_keep_mask_and_rhs_agree_with_apply():
    rng = np.random.default_rng(19)
    A = block_spd(5, 4, rng)
    n = A.shape[0]
    b = rng.standard_normal(n)
    fixed = rng.random(n) < 0.4
    values = np.where(fixed, rng.standard_normal(n), 0.0)
    elim = SymmetricEliminator(A)
    A_el, b_el = elim.apply(A, b, fixed, values)
    keep = elim.keep_mask(fixed)
    assert np.array_equal(np.where(keep, A.data, 0.0), A_el.data)
    assert np.array_equal(elim.rhs(A, b, fixed, values), b_el)
    # kept: exactly the entries with a free row and a free column, and the diagonal
    rows = np.repeat(np.arange(n), np.diff(A.indptr))
    expected = (~fixed[rows] & ~fixed[A.indices]) | (rows == A.indices)
    assert np.array_equal(keep, expected)


def test_elimination_value_forms_and_out():
    rng = np.random.default_rng(17)
    A = block_spd(4, 4, rng)
    n = A.shape[0]
    b = rng.standard_normal(n)
    fixed = np.zeros(n, dtype=bool)
    fixed[[0, 5, 9]] = True
    full = np.zeros(n)
    full[[0, 5, 9]] = [1.0, -2.0, 0.5]
    elim = SymmetricEliminator(A)
    A1, b1 = elim.apply(A, b, fixed, full)
    A2, b2 = elim.apply(A, b, fixed, np.array([1.0, -2.0, 0.5]))
    out = A.copy()
    A3, b3 = elim.apply(A, b, fixed, full, out=out)
    assert A3 is out
    for Ak, bk in ((A2, b2), (A3, b3)):
        assert np.array_equal(Ak.data, A1.data)
        assert np.array_equal(bk, b1)
    A4, b4 = elim.apply(A, b, fixed, 0.0)
    assert np.array_equal(A4.data, A1.data)
    assert np.array_equal(b4[~fixed], b[~fixed])
    assert np.array_equal(b4[fixed], np.zeros(3))


def test_elimination_errors():
    A = sp.csr_matrix(np.array([[2.0, 1.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 2.0]]))
    A.eliminate_zeros()  # no stored diagonal in row 1
    b = np.ones(3)
    with pytest.raises(ValueError, match="no stored diagonal entry in fixed rows 1"):
        eliminate_symmetric(A, b, np.array([False, True, False]), 1.0)
    with pytest.raises(ValueError, match="boolean mask"):
        eliminate_symmetric(A, b, np.array([0, 1]), 1.0)
    with pytest.raises(ValueError, match="x_fixed"):
        eliminate_symmetric(A, b, np.array([True, False, False]), np.ones(2))
    with pytest.raises(ValueError, match="b must have shape"):
        eliminate_symmetric(A, np.ones(4), np.array([True, False, False]), 1.0)
    with pytest.raises(ValueError, match="non-finite"):
        eliminate_symmetric(A, b, np.array([True, False, False]), np.nan)
    with pytest.raises(ValueError, match="sparsity pattern"):
        SymmetricEliminator(A).apply(sp.identity(3, format="csr"), b, np.ones(3, bool), 0.0)
    with pytest.raises(ValueError, match="out does not have the sparsity pattern"):
        SymmetricEliminator(A).apply(A, b, np.zeros(3, bool), 0.0, out=sp.identity(3).tocsr())
