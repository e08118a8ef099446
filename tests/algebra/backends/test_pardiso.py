"""MKL PARDISO backend (signorini.algebra.backends.pardiso): finding MKL, pattern reuse,
failures."""

from __future__ import annotations

import ctypes.util
import importlib.metadata
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import block_spd, p2_elasticity

from signorini.algebra import (
    BackendUnavailableError,
    FactorizationError,
    SymmetricEliminator,
    available_backends,
)
from signorini.algebra.backends import mkl, pardiso
from signorini.algebra.backends.mkl import mkl_runtime_candidates
from signorini.algebra.backends.pardiso import PardisoSolver, pardiso_problem

HAS_PARDISO = "pardiso" in available_backends()


def _mkl_distribution():
    try:
        return importlib.metadata.distribution("mkl")
    except importlib.metadata.PackageNotFoundError:
        return None


@pytest.fixture
def pardiso_probe_reset():
    """Clear the cached library and probe before and after the test."""

    def clear():
        mkl.pardiso_function.cache_clear()
        pardiso.pardiso_problem.cache_clear()

    clear()
    yield
    clear()


def test_mkl_is_found_in_the_installed_distribution():
    dist = _mkl_distribution()
    if dist is None:
        pytest.skip("the mkl distribution is not installed")
    files = {Path(dist.locate_file(f)).resolve() for f in dist.files}
    first = Path(mkl_runtime_candidates()[0])
    assert first in files and first.name.startswith("libmkl_rt")
    assert pardiso_problem() is None and HAS_PARDISO


def test_pypardiso_is_not_imported():
    code = "import sys, signorini.algebra as a; a.make_solver(); print('pypardiso' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_missing_library_is_reported(monkeypatch, pardiso_probe_reset):
    monkeypatch.setattr(mkl, "mkl_runtime_candidates", lambda: [])
    reason = pardiso_problem()
    assert reason is not None and "mkl_rt could not be loaded (no file found)" in reason
    with pytest.raises(BackendUnavailableError, match="no file found"):
        PardisoSolver()


def test_unloadable_and_symbolless_libraries_are_reported(
    tmp_path, monkeypatch, pardiso_probe_reset
):
    garbage = tmp_path / "libmkl_rt.so.3"
    garbage.write_bytes(b"not a shared library")
    libm = ctypes.util.find_library("m")
    if libm is None:
        pytest.skip("no C math library to stand in for a library without pardiso")
    monkeypatch.setattr(mkl, "mkl_runtime_candidates", lambda: [str(garbage), libm])
    reason = pardiso_problem()
    assert reason is not None
    assert str(garbage) in reason and libm in reason and "pardiso" in reason


def test_wrong_solution_is_reported(monkeypatch, pardiso_probe_reset):
    if not HAS_PARDISO:
        pytest.skip("PARDISO not available")
    monkeypatch.setattr(PardisoSolver, "_solve", lambda self, b: np.zeros_like(b))
    assert "solved a 2 x 2 test system wrongly" in pardiso_problem()


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_pattern_reuse_with_explicit_zeros():
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
        assert np.linalg.norm(A @ x - b) < 1e-10 * np.linalg.norm(b)
        assert np.allclose(x[fixed], values[fixed], rtol=1e-12, atol=1e-12)
    assert solver.n_analyses == 1
    assert solver.n_factorizations == 4
    assert solver.factor_nnz >= (A.nnz + n) // 2
    solver.close()
    solver.close()  # idempotent


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_negative_pivot_names_the_equation():
    rng = np.random.default_rng(5)
    A = block_spd(6, 6, rng).tolil()
    A[17, 17] = -50.0
    with pytest.raises(FactorizationError, match="PARDISO phase 22 failed with error -4") as info:
        PardisoSolver(A.tocsr())
    assert info.value.code == -4 and info.value.backend == "pardiso"


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_reported_operation_count_and_memory_of_a_dense_factorization():
    """A dense SPD matrix stored sparse: PARDISO's operation count is about the n³/3 of a
    dense Cholesky factorization, and its factorization memory holds at least the n(n+1)/2
    doubles of the triangular factor; the analysis reports before any factorization is
    needed again."""
    n = 400
    B = np.random.default_rng(0).standard_normal((n, n))
    A = sp.csr_matrix(B @ B.T + n * np.eye(n))
    with PardisoSolver(A) as solver:
        ratio = solver.factor_mflop * 1e6 / (n**3 / 3)
        memory = solver.memory_kib
    assert 0.9 <= ratio <= 1.5, ratio
    assert set(memory) == {"analysis_peak", "permanent", "factorization"}
    assert memory["factorization"] * 1024 >= 8 * n * (n + 1) // 2, memory
    assert memory["analysis_peak"] > 0 and memory["permanent"] > 0, memory


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_an_analysis_beside_the_caller_is_the_analysis_of_factorize():
    """``analyze(A, beside=True)`` runs in the background while the caller writes ``A``'s
    values; the factorization then uses the new values and the same analysis: the solution
    is bit for bit that of a solver that analyses in ``factorize``, counted once."""
    rng = np.random.default_rng(5)
    K = block_spd(40, 40, rng)
    b = rng.standard_normal(K.shape[0])
    order = rng.permutation(K.shape[0] // 2)
    ordering = np.stack([2 * order, 2 * order + 1], axis=1).ravel()
    A = K.copy()
    A.data[:] = 0.0  # the values are written only after the analysis started
    with PardisoSolver(check_symmetry=False, ordering=ordering) as ahead:
        ahead.analyze(A, beside=True)
        A.data[:] = K.data
        ahead.factorize(A)
        x = ahead.solve(b)
        assert (ahead.n_analyses, ahead.n_factorizations) == (1, 1)
        assert ahead.time_analysis > 0.0
        ahead.factorize(K)  # the same pattern: no second analysis
        assert ahead.n_analyses == 1
    with PardisoSolver(check_symmetry=False, ordering=ordering) as in_turn:
        in_turn.factorize(K)
        assert np.array_equal(x, in_turn.solve(b))


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_an_error_of_an_analysis_beside_is_raised_by_factorize():
    K = sp.csr_matrix(np.array([[2.0, 1.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 2.0]]))
    K.eliminate_zeros()  # row 1 stores no diagonal entry
    solver = PardisoSolver()
    solver.analyze(K, beside=True)  # returns at once
    with pytest.raises(ValueError, match="diagonal entry; rows 1 have none"):
        solver.factorize(K)
    solver.analyze(K, beside=True)
    solver.close()  # waits, and says nothing of it: the error concerns no one now


@pytest.mark.parametrize("backend", available_backends())
def test_an_analysis_that_reads_the_values_is_done_in_the_callers_thread(backend):
    """PARDISO's LU with weighted matching (and SuperLU) read the values in the analysis:
    ``beside`` is ignored, and the analysis is done (and counted) before ``analyze`` returns
    (one beside is counted when a factorization waits for it)."""
    from signorini.algebra import SOLVERS, make_solver
    from signorini.algebra.backends.pardiso_lu import PardisoLUSolver

    K = block_spd(6, 6, np.random.default_rng(2))
    made = PardisoLUSolver(matching=True) if backend == "pardiso" else None
    with made or make_solver(SOLVERS[backend], symmetric=False) as solver:
        assert solver.analysis_reads_values
        solver.analyze(K, beside=True)
        assert solver.n_analyses == 1


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_an_lu_without_matching_analyses_beside_and_solves_as_with_it():
    """PARDISO's LU without weighted matching (the factory's) reads no value in its
    analysis, which runs beside the caller while the caller writes the values (counted when
    the factorization waits for it); its solution of a non-symmetric matrix (a stiffness
    whose rows 2z + 1 have a multiple of rows 2z subtracted, as on Coulomb's slipping nodes)
    agrees with the matching LU's to round-off."""
    from signorini.algebra import make_solver, pardiso_solver
    from signorini.algebra.backends.pardiso_lu import PardisoLUSolver

    K = _elasticity_spd(8, 6)
    A = K.tolil()
    for z in range(0, K.shape[0], 6):
        A[z + 1] = A[z + 1] - 0.9 * A[z]
    A = sp.csr_matrix(A)
    b = np.random.default_rng(5).standard_normal(A.shape[0])
    with PardisoLUSolver(matching=True) as matched:
        matched.factorize(A)
        expected = matched.solve(b)
    with make_solver(pardiso_solver, symmetric=False) as solver:
        assert not solver.analysis_reads_values
        values = A.data.copy()
        A.data[:] = 1.0  # the analysis beside does not read them
        solver.analyze(A, beside=True)
        assert solver.n_analyses == 0  # not done yet, or not counted yet
        A.data[:] = values
        solver.factorize(A)
        x = solver.solve(b)
        assert solver.n_analyses == 1
    assert np.abs(A @ x - b).max() <= 1e-13 * np.abs(b).max()
    assert np.abs(x - expected).max() <= 1e-12 * np.abs(expected).max()


def _elasticity_spd(nx: int, ny: int) -> sp.csr_matrix:
    """A P2 plane-strain stiffness (λ ≠ μ: its off-diagonal node blocks are not symmetric)
    made definite by a small shift of the stored diagonal."""
    K, _ = p2_elasticity(nx, ny, lam=2.0, mu=0.5)
    K.setdiag(K.diagonal() + 0.1)
    return K


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_node_blocks_go_over_in_blocks_and_solve_as_in_csr():
    """A matrix of 2 x 2 node blocks is analysed in BSR form, with PARDISO's ordering or one
    that keeps each node's rows together; the solution, the factor's size and the operation
    count are those of the CSR form with the same ordering."""
    K = _elasticity_spd(12, 10)
    n = K.shape[0]
    rng = np.random.default_rng(2)
    b = rng.standard_normal(n)
    nodes = rng.permutation(n // 2)
    pairs = np.column_stack([2 * nodes, 2 * nodes + 1]).reshape(-1)
    for ordering in (None, pairs):
        with (
            PardisoSolver(K, ordering=ordering) as blocks,
            PardisoSolver(K, ordering=ordering, blocks=False) as csr,
        ):
            assert (blocks.block_size, csr.block_size) == (2, 1)
            x, y = blocks.solve(b), csr.solve(b)
            assert np.linalg.norm(K @ x - b) <= 1e-12 * np.linalg.norm(b)
            assert np.allclose(x, y, rtol=0, atol=1e-11 * np.abs(y).max())
            if ordering is not None:  # the same elimination order: about the same factor
                # (whole 2 x 2 blocks stored: a little more), counted in scalar entries
                assert 1.0 <= blocks.factor_nnz / csr.factor_nnz <= 1.05
                assert abs(blocks.factor_mflop - csr.factor_mflop) <= 0.1 * csr.factor_mflop + 1


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_an_ordering_that_splits_a_node_keeps_csr():
    K = _elasticity_spd(6, 5)
    n = K.shape[0]
    split = np.arange(n)
    split[[1, 2]] = split[[2, 1]]  # node 0's second row after node 1's first
    b = np.ones(n)
    with PardisoSolver(K, ordering=split) as solver:
        assert solver.block_size == 1
        x = solver.solve(b)
    assert np.linalg.norm(K @ x - b) <= 1e-12 * np.linalg.norm(b)


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_eliminated_dofs_in_blocks():
    """PDAS's elimination (``keep``) zeroes entries inside node blocks: the block form
    factorizes the eliminated matrix as the CSR form does, on one analysis."""
    K = _elasticity_spd(8, 8)
    n = K.shape[0]
    rng = np.random.default_rng(4)
    elim = SymmetricEliminator(K)
    b = rng.standard_normal(n)
    with PardisoSolver(K) as blocks, PardisoSolver(K, blocks=False) as csr:
        for k in range(3):
            fixed = np.zeros(n, dtype=bool)
            fixed[rng.choice(n, 5 + 7 * k, replace=False)] = True  # single rows of a block
            keep = elim.keep_mask(fixed)
            blocks.refactorize(keep)
            csr.refactorize(keep)
            A = sp.csr_matrix((K.data * keep, K.indices, K.indptr), shape=K.shape)
            x, y = blocks.solve(b), csr.solve(b)
            assert np.linalg.norm(A @ x - b) <= 1e-12 * np.linalg.norm(b)
            assert np.allclose(x, y, rtol=0, atol=1e-11 * np.abs(y).max())
        assert blocks.n_analyses == 1 and blocks.block_size == 2


@pytest.mark.skipif(not HAS_PARDISO, reason="PARDISO not available")
def test_a_singular_block_matrix_names_its_equation():
    """In blocks PARDISO reports a zero pivot vaguely; the solver repeats the factorization
    in CSR form, whose error names the failure and the equation."""
    K, _ = p2_elasticity(5, 4, lam=2.0, mu=0.5)  # floating: rigid motions are null
    with pytest.raises(FactorizationError, match="error -4: zero or negative pivot") as info:
        PardisoSolver(K)
    assert info.value.equation is not None and 0 <= info.value.equation < K.shape[0]
