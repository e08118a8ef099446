"""The PETSc + MUMPS backend (signorini.algebra.backends.petsc) against PARDISO and SuperLU.

Runs where petsc4py with MUMPS is importable (the extra ``signorini[mpi]``) and is skipped
elsewhere, except where ``SIGNORINI_REQUIRE_PETSC=1`` (CI's MPI stage) turns the skip into a
failure. The error of a missing petsc4py is tested everywhere.
"""

from __future__ import annotations

import ctypes
import importlib.util
import os
import re
import sys

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from linalg_problems import block_spd, p2_elasticity

from signorini.algebra import (
    BackendUnavailableError,
    FactorizationError,
    available_backends,
    make_solver,
    solver_factory,
)
from signorini.algebra.backends import petsc as petsc_backend
from signorini.algebra.backends.mkl import mkl_runtime_candidates, mkl_threads_local, mkl_version
from signorini.algebra.backends.petsc import petsc_solver, row_block
from signorini.algebra.backends.selection import solver_library
from signorini.algebra.backends.solvers import SolverRequest
from signorini.examples import example_6_2, example_6_2_coulomb
from signorini.loop import adaptive


def petsc_problem() -> str | None:
    try:
        petsc_backend.petsc_module()
    except BackendUnavailableError as err:
        return str(err)
    return None


PROBLEM = petsc_problem()
if PROBLEM is not None and os.environ.get("SIGNORINI_REQUIRE_PETSC") == "1":
    raise RuntimeError(f"SIGNORINI_REQUIRE_PETSC=1 but the petsc backend is unusable: {PROBLEM}")
needs_petsc = pytest.mark.skipif(PROBLEM is not None, reason=f"petsc backend: {PROBLEM}")
REFERENCE = "pardiso" if "pardiso" in available_backends() else "scipy"


def test_a_missing_petsc4py_names_the_extra(monkeypatch):
    petsc_backend.petsc_module.cache_clear()
    monkeypatch.setitem(sys.modules, "petsc4py", None)  # import petsc4py raises ImportError
    monkeypatch.setitem(sys.modules, "dolfinx_solver", None)
    try:
        with pytest.raises(BackendUnavailableError, match=r"petsc4py.*signorini\[mpi\]"):
            make_solver(solver_factory("petsc"))
        assert solver_library("petsc").startswith("PETSc (not usable: the petsc backend needs")
        assert "petsc" not in available_backends()
    finally:
        petsc_backend.petsc_module.cache_clear()


@pytest.mark.parametrize("n", [1, 2, 7, 100])
def test_row_blocks_cover_the_rows_once_in_order(n):
    for size in (1, 2, 3, 8):
        blocks = [row_block(n, rank, size) for rank in range(size)]
        assert blocks[0][0] == 0 and blocks[-1][1] == n
        assert all(a[1] == b[0] for a, b in zip(blocks, blocks[1:], strict=False))
        lengths = [hi - lo for lo, hi in blocks]
        assert max(lengths) - min(lengths) <= 1 and lengths == sorted(lengths, reverse=True)


@needs_petsc
def test_cholesky_agrees_with_superlu_and_keeps_its_analysis():
    rng = np.random.default_rng(3)
    A = block_spd(14, 11, rng)
    b = rng.standard_normal((A.shape[0], 3))
    solver = make_solver(petsc_solver, symmetric=True)
    assert solver.backend == "petsc" and solver.reuses_analysis
    solver.factorize(A)
    x = solver.solve(b)
    exact = spla.spsolve(A.tocsc(), b)
    assert np.abs(x - exact).max() / np.abs(exact).max() < 1e-12
    # a refactorization with stored entries masked out (the active set's step): same
    # pattern, no new analysis, and the answer of the masked matrix
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    held = rng.uniform(size=A.shape[0]) < 0.3  # decoupled from the rest: still SPD
    keep = held[rows] == held[A.indices]
    masked = sp.csr_matrix((A.data * keep, A.indices, A.indptr), shape=A.shape)
    solver.refactorize(keep)
    x = solver.solve(b[:, 0])
    exact = spla.spsolve(masked.tocsc(), b[:, 0])
    assert np.abs(x - exact).max() / np.abs(exact).max() < 1e-12
    assert (solver.n_analyses, solver.n_factorizations, solver.n_solves) == (1, 2, 2)
    solver.close()


@needs_petsc
def test_mumps_cholesky_compresses_node_blocks():
    """A matrix of 2 x 2 node blocks (a P2 stiffness, λ ≠ μ) goes to MUMPS's Cholesky with its
    graph compressed to the blocks (ICNTL(15) = -2) and is solved to round-off; a matrix
    whose rows are not in blocks (a scalar Laplacian) is not compressed."""
    K, _ = p2_elasticity(10, 8, lam=2.0, mu=0.5)
    K.setdiag(K.diagonal() + 0.1)
    L = sp.diags([-np.ones(39), 2.5 * np.ones(40), -np.ones(39)], [-1, 0, 1], format="csr")
    for A, size in ((K, 2), (L, 1)):
        b = np.random.default_rng(1).standard_normal(A.shape[0])
        solver = make_solver(petsc_solver, symmetric=True)
        solver.factorize(A)
        x = solver.solve(b)
        exact = spla.spsolve(A.tocsc(), b)
        assert np.abs(x - exact).max() <= 1e-12 * np.abs(exact).max()
        factor = solver._ksp.getPC().getFactorMatrix()
        assert solver.block_size == size
        assert int(factor.getMumpsIcntl(15)) == (-2 if size == 2 else 0)
        solver.close()


@needs_petsc
def test_mumps_orders_by_amd_unless_petsc_options_say_otherwise():
    """MUMPS's Cholesky orders by AMD (``INFOG(7) = 0``, docs/parallel.md, *MUMPS's
    ordering*); ``-mat_mumps_icntl_7`` in PETSc's options database is the user's choice."""
    K, _ = p2_elasticity(8, 8)
    K.setdiag(K.diagonal() + 0.1)
    options = petsc_backend.petsc_module().Options()
    used = []
    try:
        for icntl_7 in (None, 5, 3):
            if icntl_7 is not None:
                options["mat_mumps_icntl_7"] = icntl_7
            with make_solver(petsc_solver, K, symmetric=True) as solver:
                used.append(int(solver._ksp.getPC().getFactorMatrix().getMumpsInfog(7)))
    finally:
        options.delValue("mat_mumps_icntl_7")
    assert used == [0, 5, 3]


@needs_petsc
def test_cholesky_refuses_an_indefinite_matrix_and_lu_solves_it():
    A = block_spd(6, 5, np.random.default_rng(0)).tolil()
    A[4, 4] = -A[4, 4]
    A = A.tocsr()
    with pytest.raises(FactorizationError, match="not positive definite: MUMPS met 1 negative"):
        make_solver(petsc_solver, A)
    b = np.ones(A.shape[0])
    x = make_solver(petsc_solver, A, symmetric=False).solve(b)
    assert np.abs(A @ x - b).max() < 1e-12 * np.abs(A).max() * np.abs(x).max()


@needs_petsc
def test_manifest_names_petsc_and_its_ranks():
    blas = " on MKL's BLAS" if petsc_backend._MUMPS_BLAS["mkl"] else ""
    assert re.fullmatch(rf"PETSc 3\.\d+\.\d+ \+ MUMPS{blas} \(1 rank\)", solver_library("petsc"))


@needs_petsc
def test_mumps_calls_mkls_blas_on_one_thread_where_the_wheel_brings_its_openblas(capfd):
    """Where PETSc is the ``mpi`` extra's binary wheel and MKL is installed, MUMPS's BLAS
    calls go to MKL (docs/parallel.md, *MUMPS's BLAS*): MKL's verbose mode lists them, each
    on one thread, and MKL's thread setting is given back after each MUMPS call."""
    wheel = importlib.util.find_spec("dolfinx_solver") is not None
    assert petsc_backend._MUMPS_BLAS["mkl"] == (wheel and mkl_version() is not None)
    if not petsc_backend._MUMPS_BLAS["mkl"]:
        pytest.skip("MUMPS keeps its own BLAS here (another PETSc build, or no MKL)")
    K, _ = p2_elasticity(30, 30, lam=2.0, mu=0.5)
    K.setdiag(K.diagonal() + 0.1)
    b = np.random.default_rng(2).standard_normal(K.shape[0])
    verbose = ctypes.CDLL(mkl_runtime_candidates()[0]).MKL_Verbose
    verbose.argtypes = [ctypes.c_int]
    capfd.readouterr()
    verbose(1)
    try:
        with make_solver(petsc_solver, K, symmetric=True) as solver:
            x = solver.solve(b)
    finally:
        verbose(0)
        ctypes.CDLL(None).fflush(None)
    calls = re.findall(r"MKL_VERBOSE (D[A-Z]+)\(.*NThr:(\d+)", capfd.readouterr().out)
    assert {"DGEMM", "DTRSM"} <= {name for name, _ in calls}
    assert {threads for _, threads in calls} == {"1"}
    assert mkl_threads_local(0) == 0  # no thread-local setting left behind
    exact = spla.spsolve(K.tocsc(), b)
    assert np.abs(x - exact).max() <= 1e-12 * np.abs(exact).max()


def same_levels(problem, levels: int, max_ndof: int = 10**6) -> list[tuple[int, float]]:
    """Run the adaptive loop with the PETSc backend and the reference backend and check they
    agree level by level: Ndof, active set, marked cells, η and u to round-off."""
    runs = {
        name: list(
            adaptive(problem, max_levels=levels, max_ndof=max_ndof, solver=solver_factory(name))
        )
        for name in ("petsc", REFERENCE)
    }
    checked = []
    for a, b in zip(runs["petsc"], runs[REFERENCE], strict=True):
        assert a.record.backend == "petsc" and b.record.backend == REFERENCE
        assert a.record.ndof == b.record.ndof
        np.testing.assert_array_equal(a.result.active, b.result.active)
        if b.marked is not None:
            np.testing.assert_array_equal(a.marked, b.marked)
        scale = np.abs(b.result.u).max()
        assert np.abs(a.result.u - b.result.u).max() <= 1e-11 * scale
        assert a.record.eta == pytest.approx(b.record.eta, rel=1e-11)
        np.testing.assert_allclose(
            a.estimate.eta_terms, b.estimate.eta_terms, rtol=1e-9, atol=1e-12 * b.record.eta
        )
        checked.append((a.record.ndof, a.record.eta))
    return checked


@needs_petsc
def test_example_6_2_adaptive_is_the_reference_run():
    checked = same_levels(example_6_2(), levels=8)
    assert [n for n, _ in checked] == [144, 152, 160, 180, 204, 242, 292, 362]


@needs_petsc
def test_coulomb_friction_on_mumps_lu_is_the_reference_run():
    checked = same_levels(example_6_2_coulomb(), levels=5)
    assert len(checked) == 5 and checked[-1][0] > checked[0][0]


@needs_petsc
@pytest.mark.parametrize("symmetric", [True, False])
def test_an_ordering_renumbers_petsc_and_reaches_mumps_lu(symmetric):
    rng = np.random.default_rng(5)
    A = block_spd(12, 9, rng)
    if not symmetric:  # a Coulomb-like coupling: one row plus a multiple of its neighbour
        A = (A + sp.diags(0.3 * A.diagonal()[:-1], 1)).tocsr()
    b = rng.standard_normal(A.shape[0])
    exact = spla.spsolve(A.tocsc(), b)
    ordering = rng.permutation(A.shape[0])
    request = SolverRequest(symmetric=symmetric, ordering=lambda: ordering)
    solver = petsc_solver(request)
    solver.factorize(A)
    x = solver.solve(b)
    assert np.abs(x - exact).max() <= 1e-12 * np.abs(exact).max()
    # the factory computes the ordering for the LU only (PETSc drops it for MUMPS's Cholesky)
    assert not solver.split
    assert solver._order is None if symmetric else np.array_equal(solver._order, ordering)
    # MUMPS's ordering used: 1 (given) for the LU, AMD (0) for the Cholesky on one process
    used = int(solver._ksp.getPC().getFactorMatrix().getMumpsInfog(7))
    assert used == (0 if symmetric else 1)
    solver.close()
