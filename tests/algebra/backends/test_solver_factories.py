"""Solvers as objects: a backend added in a few lines, the factory protocol, and what a solver
object given to solve() means (signorini.algebra.backends.solvers,
signorini.algebra.backends.selection)."""

from __future__ import annotations

import csv

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp

from signorini import adaptive, solve
from signorini.algebra import (
    SOLVERS,
    SolverRequest,
    SPDSolver,
    auto_solver,
    superlu_solver,
)
from signorini.cli import main
from signorini.examples import example_6_2, example_6_2_coulomb, example_6_2_tresca


# ---------------------------------------------------------------------- a toy backend
class DenseCholesky(SPDSolver):
    """A dense Cholesky factorization (scipy.linalg): a backend in a dozen lines."""

    backend = "dense"

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        pass

    def _dense(self, A: sp.csr_matrix, keep: np.ndarray | None) -> np.ndarray:
        data = A.data if keep is None else A.data * keep
        return sp.csr_matrix((data, A.indices, A.indptr), shape=A.shape).toarray()

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._factor = sl.cho_factor(self._dense(A, keep))

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return sl.cho_solve(self._factor, b)


class DenseLU(DenseCholesky):
    """A dense LU factorization, for Coulomb's non-symmetric systems."""

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._factor = sl.lu_factor(self._dense(A, keep))

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return sl.lu_solve(self._factor, b)


def dense_solver(request: SolverRequest) -> SPDSolver:
    """The toy backend's factory: Cholesky or LU as asked, no ordering."""
    if request.symmetric:
        return DenseCholesky(check_symmetry=request.check_symmetry)
    return DenseLU(check_symmetry=False)


def assert_same_solution(a, b, rtol: float = 1e-12) -> None:
    assert a.ndof == b.ndof
    np.testing.assert_array_equal(a.active, b.active)
    assert np.abs(a.u - b.u).max() <= rtol * np.abs(b.u).max()
    force = np.abs(b.contact_force).max()
    assert np.abs(a.contact_force - b.contact_force).max() <= rtol * force


@pytest.mark.slow
def test_a_toy_backend_solves_example_6_2_adaptively_as_the_default_solver_does():
    problem = example_6_2()
    toy = list(adaptive(problem, max_ndof=2500, solver=dense_solver))
    ref = list(adaptive(problem, max_ndof=2500))
    print(
        f"{len(toy)} levels, final ndof {toy[-1].record.ndof}, reference {ref[-1].record.backend}"
    )
    assert len(toy) == len(ref) > 8
    for a, b in zip(toy, ref, strict=True):
        assert a.record.backend == "dense"
        assert a.record.pdas_iterations == b.record.pdas_iterations
        assert_same_solution(a.result, b.result)
        assert a.record.eta == pytest.approx(b.record.eta, rel=1e-12)
        np.testing.assert_array_equal(a.marked, b.marked)


@pytest.mark.parametrize("example", [example_6_2_tresca, example_6_2_coulomb])
def test_a_toy_backend_solves_the_friction_examples(example):
    """Tresca asks the factory for a symmetric solver, Coulomb for an LU one."""
    problem = example()
    toy, ref = solve(problem, solver=dense_solver), solve(problem)
    assert toy.report.backend == "dense" and toy.report.iterations == ref.report.iterations
    assert_same_solution(toy, ref)
    np.testing.assert_array_equal(toy.state, ref.state)
    scale = np.abs(ref.tangential_force).max()
    assert np.abs(toy.tangential_force - ref.tangential_force).max() <= 1e-12 * scale


def test_a_registered_toy_backend_runs_from_the_command_line(tmp_path, monkeypatch):
    """One registry line makes a backend a --backend choice, recorded in the manifest."""
    monkeypatch.setitem(SOLVERS, "dense", dense_solver)
    out = tmp_path / "dense"
    argv = ["run", "example-6.2", "--backend", "dense", "--max-ndof", "800", "--quiet"]
    assert main([*argv, "--no-figures", "--no-vtu", "--out", str(out)]) == 0
    with open(out / "history.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) > 3 and {r["backend"] for r in rows} == {"dense"}
    assert '"solver": "dense"' in (out / "signorini-run.json").read_text()


# ---------------------------------------------------------------------- the protocol
def test_a_factory_is_asked_once_per_solve_for_the_kind_of_system():
    asked: list[SolverRequest] = []

    def counting(request: SolverRequest) -> SPDSolver:
        asked.append(request)
        return superlu_solver(request)

    solve(example_6_2(), solver=counting)
    solve(example_6_2_coulomb(), solver=counting)
    assert [r.symmetric for r in asked] == [True, False]
    assert not asked[0].check_symmetry  # the assembled matrix is symmetric by construction
    assert callable(asked[0].ordering)  # offered; SuperLU does not compute it


def test_a_solver_object_is_used_as_it_is_and_not_closed():
    problem = example_6_2()
    with DenseCholesky(check_symmetry=False) as solver:
        first = solve(problem, solver=solver)
        assert solver.n_analyses == 1 and solver.n > 0  # still factorized: not closed
        again = solve(problem, solver=solver)  # the same pattern: the analysis is kept
        assert solver.n_analyses == 1
        assert (
            solver.n_factorizations == first.report.n_factorizations + again.report.n_factorizations
        )
        assert solver.ordering is None  # no ordering set on the caller's solver
    np.testing.assert_array_equal(first.u, again.u)


def test_a_factory_that_makes_no_solver_is_refused():
    with pytest.raises(ValueError, match="returned NoneType, not an SPDSolver"):
        solve(example_6_2(), solver=lambda request: None)
    with pytest.raises(ValueError, match="solver must be an SPDSolver or a solver factory"):
        solve(example_6_2(), solver="scipy")  # names belong to the command line
    assert SOLVERS["auto"] is auto_solver
