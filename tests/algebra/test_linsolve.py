"""Sparse SPD solvers, pattern reuse and symmetric elimination (signorini.algebra.linsolve)."""

from __future__ import annotations

import time

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd, p2_elasticity, random_spd_dense, rigid_motions

from signorini.algebra.linsolve import (
    BACKENDS,
    FactorizationError,
    PardisoSolver,
    SymmetricEliminator,
    available_backends,
    eliminate_symmetric,
    make_solver,
    upper_triangle,
)

BACKEND_LIST = available_backends()
HAS_PARDISO = "pardiso" in BACKEND_LIST


def rel_residual(A, x, b):
    return np.linalg.norm(A @ x - b) / np.linalg.norm(b)


@pytest.fixture(params=BACKEND_LIST)
def backend(request):
    return request.param


def test_pardiso_available_here():
    # pypardiso is installed in this environment; "auto" must then pick it.
    pytest.importorskip("pypardiso")
    assert HAS_PARDISO
    assert make_solver("auto").backend == "pardiso"


def test_auto_is_first_available():
    assert make_solver().backend == BACKEND_LIST[0]
    assert "scipy" in BACKEND_LIST


def test_unknown_backend_lists_valid():
    with pytest.raises(ValueError, match="unknown backend 'mumps'.*auto, pardiso, scipy"):
        make_solver("mumps")
    assert BACKENDS == ("pardiso", "scipy")


@pytest.mark.parametrize("nx,ny", [(1, 1), (6, 5), (15, 12)])
def test_solution_matches_dense(backend, nx, ny):
    rng = np.random.default_rng(nx * 100 + ny)
    A = block_spd(nx, ny, rng)
    n = A.shape[0]
    b = rng.standard_normal(n)
    with make_solver(backend, A) as solver:
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
    xs = [make_solver(name, A).solve(b) for name in BACKEND_LIST]
    reference = np.linalg.solve(A.toarray(), b)
    for x in xs:
        assert np.abs(x - reference).max() < 1e-11 * np.abs(reference).max()


def test_refactorization_reuses_analysis(backend):
    rng = np.random.default_rng(7)
    A = block_spd(10, 9, rng)
    b = rng.standard_normal(A.shape[0])
    solver = make_solver(backend)
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
    assert solver.reuses_analysis == (backend == "pardiso")
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


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_pardiso_pattern_reuse_with_explicit_zeros():
    # Elimination zeroes values but keeps them stored: PARDISO must analyse only once.
    rng = np.random.default_rng(11)
    K = block_spd(8, 8, rng, shift=0.0)  # singular: constant vectors per component are null
    n = K.shape[0]
    F = rng.standard_normal(n)
    solver = PardisoSolver()
    elim = SymmetricEliminator(K)
    for k in range(4):
        fixed = np.zeros(n, dtype=bool)
        fixed[:2] = True  # removes the null space (constant vectors)
        fixed[rng.choice(n, 10 + k, replace=False)] = True
        values = rng.standard_normal(n)
        A, b = elim.apply(K, F, fixed, values)
        solver.factorize(A)
        x = solver.solve(b)
        assert rel_residual(A, x, b) < 1e-10
        assert np.allclose(x[fixed], values[fixed], rtol=1e-12, atol=1e-12)
    assert solver.n_analyses == 1
    assert solver.n_factorizations == 4
    assert solver.factor_nnz >= (A.nnz + n) // 2
    solver.close()
    solver.close()  # idempotent


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
    solver = make_solver(backend)
    with pytest.raises(FactorizationError, match="not positive definite|singular") as info:
        solver.factorize(A)
    assert info.value.backend == backend
    assert isinstance(info.value, ValueError)
    with pytest.raises(RuntimeError, match="before a successful factorize"):
        solver.solve(np.ones(A.shape[0]))


def test_negative_definite_reports_equation(backend):
    A = -sp.identity(5, format="csr")
    with pytest.raises(FactorizationError) as info:
        make_solver(backend, A)
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
        make_solver(backend, matrix)


def test_bad_rhs_raises(backend):
    A = sp.identity(4, format="csr") * 2.0
    solver = make_solver(backend, A)
    with pytest.raises(ValueError, match="shape"):
        solver.solve(np.ones(5))
    with pytest.raises(ValueError, match="non-finite"):
        solver.solve(np.array([1.0, np.nan, 0.0, 0.0]))
    assert np.allclose(solver.solve(np.arange(4.0)), np.arange(4.0) / 2)


def test_upper_triangle_matches_triu_and_keeps_zeros():
    rng = np.random.default_rng(2)
    A = block_spd(5, 7, rng)
    A.data[::7] = 0.0  # explicit zeros must survive
    U = upper_triangle(A)
    T = sp.triu(A, format="csr")
    assert abs(U - T).max() == 0
    assert U.nnz == np.count_nonzero(A.indices >= np.repeat(np.arange(70), np.diff(A.indptr)))
    assert U.nnz > T.count_nonzero()


def _reduced_solution(A, b, fixed, values):
    """Reference: slice the free rows and columns and solve densely."""
    D = A.toarray()
    free = ~fixed
    x = values.copy()
    rhs = b[free] - D[np.ix_(free, fixed)] @ values[fixed]
    x[free] = np.linalg.solve(D[np.ix_(free, free)], rhs)
    return x


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
    x = make_solver(backend, A_el).solve(b_el)
    reference = _reduced_solution(A, b, fixed, values)
    assert np.abs(x - reference).max() < 1e-10 * np.abs(reference).max()
    assert np.abs((b - A @ x)[free]).max() < 1e-10 * np.abs(b).max()


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
    """Analysis / factorization / solve times on ~200 000 P2 elasticity unknowns."""
    K, xy = p2_elasticity(158, 158)
    n = K.shape[0]
    fixed = np.repeat(xy[:, 0] < 1e-12, 2)  # clamp the left side
    rng = np.random.default_rng(0)
    F = rng.standard_normal(n)
    A, b = eliminate_symmetric(K, F, fixed, 0.0)
    fixed2 = fixed | np.repeat(xy[:, 1] < 1e-12, 2)
    A2, b2 = eliminate_symmetric(K, F, fixed2, 0.0)
    lines = [f"P2 elasticity, n = {n}, nnz = {K.nnz}"]
    for name in BACKEND_LIST:
        solver = make_solver(name)
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
