"""Sparse LU for non-symmetric matrices: SuperLULUSolver and PardisoLUSolver (mtype 11)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd

from signorini.algebra import (
    SOLVERS,
    FactorizationError,
    available_backends,
    make_solver,
    solver_factory,
    superlu_solver,
)


def non_symmetric(seed: int) -> sp.csr_matrix:
    """A node-blocked SPD grid matrix with random non-symmetric changes on its pattern."""
    rng = np.random.default_rng(seed)
    A = block_spd(12, 10, rng)
    data = A.data + 0.3 * np.abs(A.data).max() * rng.uniform(-1, 1, A.nnz)
    return sp.csr_matrix((data, A.indices, A.indptr), shape=A.shape)


@pytest.mark.parametrize("backend", available_backends())
def test_lu_solves_a_non_symmetric_system_and_keeps_its_analysis(backend):
    A = non_symmetric(0)
    assert abs(A - A.T).max() > 0.1 * abs(A).max()
    b = np.random.default_rng(1).standard_normal(A.shape[0])
    solver = make_solver(SOLVERS[backend], symmetric=False)
    assert solver.backend == backend
    solver.factorize(A)
    x = solver.solve(b)
    residual = np.abs(A @ x - b).max() / np.abs(b).max()
    assert residual < 1e-12, residual
    A2 = sp.csr_matrix((A.data * (1 + 0.1 * np.sin(np.arange(A.nnz))), A.indices, A.indptr))
    solver.factorize(A2)
    x2 = solver.solve(np.column_stack([b, 2 * b]))
    residual = np.abs(A2 @ x2[:, 1] - 2 * b).max() / np.abs(2 * b).max()
    assert residual < 1e-12, residual
    assert (solver.n_analyses, solver.n_factorizations) == (1, 2)
    solver.close()


def test_superlu_lu_reports_a_singular_matrix():
    A = non_symmetric(2)
    A.data[A.indptr[3] : A.indptr[4]] = 0.0  # row 3 zero, pattern kept
    with pytest.raises(FactorizationError, match="singular"):
        make_solver(superlu_solver, A, symmetric=False)


def test_an_unknown_backend_name_is_refused():
    with pytest.raises(ValueError, match="unknown backend 'umfpack'"):
        solver_factory("umfpack")


@pytest.mark.skipif("pardiso" not in available_backends(), reason="needs MKL PARDISO")
def test_pardiso_lu_refines_the_solves_of_a_factor_with_a_perturbed_pivot_only():
    """A non-symmetric tridiagonal matrix, then the same pattern with its last two rows made
    to share their trailing 2 x 2 block (singular; the matrix is not, condition 8.7e3):
    PARDISO perturbs that pivot (``iparm[13] = 1``) and the solves of that factor are refined
    (without refinement the residual was 8.5e-13); the regular factor before and after it is
    solved without a step (``iparm[6] = 0``), its residual at round-off all the same."""
    from signorini.algebra.backends.pardiso_lu import REFINEMENT_STEPS, PardisoLUSolver

    n = 200
    rng = np.random.default_rng(3)
    sub, sup = rng.uniform(-1, 1, n - 1), rng.uniform(-1, 1, n - 1)
    regular = sp.diags([sub, 4 + rng.uniform(0, 1, n), sup], [-1, 0, 1], format="csr")
    perturbed = regular.tolil()
    perturbed[n - 1, n - 2], perturbed[n - 1, n - 1] = regular[n - 2, n - 2], regular[n - 2, n - 1]
    perturbed = perturbed.tocsr()
    assert np.linalg.cond(perturbed.toarray()) < 1e4
    b = np.ones(n)
    cases = ((regular, 0, 0), (perturbed, 1, REFINEMENT_STEPS), (regular, 0, 0))
    with PardisoLUSolver() as solver:
        for A, pivots, steps in cases:
            solver.factorize(A)
            assert solver._iparm[13] == pivots
            x = solver.solve(b)
            assert solver._iparm[6] == steps  # refinement steps done in the solve
            assert np.abs(A @ x - b).max() < 1e-14
        assert solver.n_analyses == 1  # one pattern
