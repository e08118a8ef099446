"""The SPD solver interface on every available backend (signorini.algebra.backends.solvers)."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd, p2_elasticity, random_spd_dense, rigid_motions

from signorini.algebra import (
    SOLVERS,
    FactorizationError,
    SymmetricEliminator,
    available_backends,
    eliminate_symmetric,
    make_solver,
)

BACKEND_LIST = available_backends()


def rel_residual(A, x, b):
    return np.linalg.norm(A @ x - b) / np.linalg.norm(b)


@pytest.fixture(params=BACKEND_LIST)
def backend(request):
    return request.param


@pytest.mark.parametrize("nx,ny", [(1, 1), (6, 5), (15, 12)])
def test_solution_matches_dense(backend, nx, ny):
    rng = np.random.default_rng(nx * 100 + ny)
    A = block_spd(nx, ny, rng)
    n = A.shape[0]
    b = rng.standard_normal(n)
    with make_solver(SOLVERS[backend], A) as solver:
        x = solver.solve(b)
        B = rng.standard_normal((n, 3))
        X = solver.solve(B)
    dense = A.toarray()
    assert rel_residual(A, x, b) < 1e-10
    assert np.allclose(x, np.linalg.solve(dense, b), rtol=1e-9, atol=1e-12 * np.abs(x).max())
    assert X.shape == (n, 3)
    assert np.linalg.norm(A @ X - B) / np.linalg.norm(B) < 1e-10
    assert np.allclose(X, np.linalg.solve(dense, B), rtol=1e-9, atol=1e-12 * np.abs(X).max())


def test_backends_agree_on_dense_random_matrix():
    rng = np.random.default_rng(3)
    A = sp.csr_matrix(random_spd_dense(40, rng))
    b = rng.standard_normal(40)
    xs = [make_solver(SOLVERS[name], A).solve(b) for name in BACKEND_LIST]
    reference = np.linalg.solve(A.toarray(), b)
    for x in xs:
        assert np.abs(x - reference).max() < 1e-11 * np.abs(reference).max()


def test_refactorization_reuses_analysis(backend):
    rng = np.random.default_rng(7)
    A = block_spd(10, 9, rng)
    b = rng.standard_normal(A.shape[0])
    solver = make_solver(SOLVERS[backend])
    solver.factorize(A)
    x1 = solver.solve(b)
    # same pattern, different values: scale, then add to the diagonal in place
    A2 = A.copy()
    A2.data *= 3.0
    A2.setdiag(A2.diagonal() + rng.uniform(0, 1, A.shape[0]))
    assert np.array_equal(A2.indices, A.indices)
    solver.factorize(A2)
    x2 = solver.solve(b)
    assert (solver.n_analyses, solver.n_factorizations, solver.n_solves) == (1, 2, 2)
    assert solver.reuses_analysis == (backend in ("pardiso", "petsc"))
    assert rel_residual(A, x1, b) < 1e-10
    assert rel_residual(A2, x2, b) < 1e-10
    # a new pattern forces a new analysis
    A3 = block_spd(4, 4, rng)
    solver.factorize(A3)
    b3 = rng.standard_normal(A3.shape[0])
    assert rel_residual(A3, solver.solve(b3), b3) < 1e-10
    assert (solver.n_analyses, solver.n_factorizations) == (2, 3)
    for phase in ("time_analysis", "time_factorization", "time_solve"):
        assert getattr(solver, phase) > 0
    solver.close()
    with pytest.raises(RuntimeError, match="before a successful factorize"):
        solver.solve(b)
    # after close() the object starts afresh with a new analysis
    solver.factorize(A)
    assert (solver.n_analyses, solver.n_factorizations) == (3, 4)
    assert rel_residual(A, solver.solve(b), b) < 1e-10
    solver.close()


@pytest.mark.parametrize("kind", ["indefinite", "singular"])
def test_not_positive_definite_raises(backend, kind):
    rng = np.random.default_rng(5)
    if kind == "indefinite":
        A = block_spd(6, 6, rng).tolil()
        A[17, 17] = -50.0
        A = A.tocsr()
    else:
        A = block_spd(6, 6, rng, shift=0.0)  # constant vectors (per component) are null
        assert np.abs(A @ np.tile([1.0, 0.0], 36)).max() < 1e-12
    solver = make_solver(SOLVERS[backend])
    with pytest.raises(FactorizationError, match="not positive definite|singular") as info:
        solver.factorize(A)
    assert info.value.backend == backend
    if kind == "indefinite" and info.value.equation is not None:
        assert 0 <= info.value.equation < A.shape[0]
    with pytest.raises(RuntimeError, match="before a successful factorize"):
        solver.solve(np.ones(A.shape[0]))


def test_negative_definite_reports_equation(backend):
    A = -sp.identity(5, format="csr")
    with pytest.raises(FactorizationError) as info:
        make_solver(SOLVERS[backend], A)
    assert info.value.equation is not None and 0 <= info.value.equation < 5


@pytest.mark.parametrize(
    "matrix,message",
    [
        (np.eye(3), "scipy sparse"),
        (sp.csr_matrix(np.ones((2, 3))), "square"),
        (sp.csr_matrix(np.array([[2.0, 1.0], [0.0, 2.0]])), "not symmetric"),
        (sp.csr_matrix(np.array([[0.0, 1.0], [1.0, 2.0]])), "diagonal"),
        (sp.csr_matrix(np.array([[np.nan, 0.0], [0.0, 1.0]])), "non-finite"),
        (sp.csr_matrix((0, 0)), "empty"),
    ],
)
def test_bad_matrix_raises_value_error(backend, matrix, message):
    with pytest.raises(ValueError, match=message):
        make_solver(SOLVERS[backend], matrix)


def test_bad_rhs_raises(backend):
    A = sp.identity(4, format="csr") * 2.0
    solver = make_solver(SOLVERS[backend], A)
    with pytest.raises(ValueError, match="shape"):
        solver.solve(np.ones(5))
    with pytest.raises(ValueError, match="non-finite"):
        solver.solve(np.array([1.0, np.nan, 0.0, 0.0]))
    assert np.allclose(solver.solve(np.arange(4.0)), np.arange(4.0) / 2)


def test_p2_elasticity_fixture_has_three_rigid_motions():
    # The benchmark matrix is only meaningful if it is a true P2 elasticity matrix.
    K, xy = p2_elasticity(3, 2, lam=2.0, mu=0.7)
    R = rigid_motions(xy)
    assert np.abs(K @ R).max() < 1e-12
    eig = np.linalg.eigvalsh(K.toarray())
    assert np.sum(eig < 1e-10 * eig.max()) == 3
    # total strain energy of the linear field u = (x, 0): (lam + 2 mu) / 2 on the unit square
    u = np.zeros(K.shape[0])
    u[0::2] = xy[:, 0]
    assert np.isclose(u @ K @ u, 2.0 + 2 * 0.7, rtol=1e-12)


@pytest.mark.slow
def test_timings_elasticity_200k(capsys):
    """Analysis / factorization / solve times on P2 elasticity: ~200 000 unknowns with
    ``SIGNORINI_BENCHMARK_SIZE=full``, ~29 000 by default (the same checks; the test suite's
    time is its users')."""
    n_side = 158 if os.environ.get("SIGNORINI_BENCHMARK_SIZE") == "full" else 60
    K, xy = p2_elasticity(n_side, n_side)
    n = K.shape[0]
    fixed = np.repeat(xy[:, 0] < 1e-12, 2)  # clamp the left side
    rng = np.random.default_rng(0)
    F = rng.standard_normal(n)
    A, b = eliminate_symmetric(K, F, fixed, 0.0)
    fixed2 = fixed | np.repeat(xy[:, 1] < 1e-12, 2)
    A2, b2 = eliminate_symmetric(K, F, fixed2, 0.0)
    lines = [f"P2 elasticity, n = {n}, nnz = {K.nnz}"]
    for name in BACKEND_LIST:
        solver = make_solver(SOLVERS[name])
        t0 = time.perf_counter()
        solver.factorize(A)
        x = solver.solve(b)
        solver.factorize(A2)
        x2 = solver.solve(b2)
        total = time.perf_counter() - t0
        assert rel_residual(A, x, b) < 1e-10
        assert rel_residual(A2, x2, b2) < 1e-10
        expected_analyses = 1
        assert solver.n_analyses == expected_analyses and solver.n_factorizations == 2
        lines.append(
            f"{name:8s} analysis {solver.time_analysis:6.2f} s | factorization "
            f"{solver.time_factorization / 2:6.2f} s each | solve {solver.time_solve / 2:6.3f} s "
            f"each | total {total:6.2f} s"
        )
        solver.close()
    with capsys.disabled():
        print("\n" + "\n".join(lines))


def test_refactorize_equals_factorize_with_keep(backend):
    """The trusted refactorization of the active set loop gives the checked one's solution."""
    rng = np.random.default_rng(23)
    K = block_spd(9, 8, rng)
    n = K.shape[0]
    b = rng.standard_normal(n)
    elim = SymmetricEliminator(K)
    masks = [rng.random(n) < p for p in (0.1, 0.3, 0.5)]
    solver = make_solver(SOLVERS[backend])
    with pytest.raises(RuntimeError, match="before factorize"):
        solver.refactorize(elim.keep_mask(masks[0]))
    solver.factorize(K, keep=elim.keep_mask(masks[0]))
    for fixed in masks[1:]:
        solver.refactorize(elim.keep_mask(fixed))
        A, rhs = elim.apply(K, b, fixed, 0.0)
        x = solver.solve(rhs)
        reference = make_solver(SOLVERS[backend], A).solve(rhs)
        assert np.abs(x - reference).max() <= 1e-12 * np.abs(reference).max()
        assert rel_residual(A, x, rhs) < 1e-10
    assert (solver.n_analyses, solver.n_factorizations) == (1, 3)
    with pytest.raises(ValueError, match=r"keep must be a boolean mask of shape \(\d+,\)"):
        solver.factorize(K, keep=np.ones(3, dtype=bool))
