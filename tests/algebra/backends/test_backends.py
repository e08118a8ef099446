"""The backends by name (signorini.algebra.backends.selection): "auto", the registry, loud
fallback."""

from __future__ import annotations

import importlib.metadata
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

from signorini.algebra import (
    SOLVERS,
    BackendUnavailableError,
    SolverFallbackWarning,
    auto_solver,
    available_backends,
    make_solver,
    pardiso_solver,
    solve_pdas,
    solver_factory,
    solver_name,
    superlu_solver,
)
from signorini.algebra.backends import mkl, pardiso
from signorini.algebra.backends import selection as backends
from signorini.algebra.backends.petsc import petsc_module

try:  # the optional "petsc" backend (signorini[mpi]) is listed where it loads
    petsc_module()
    PETSC: tuple[str, ...] = ("petsc",)
except BackendUnavailableError:
    PETSC = ()


@pytest.fixture
def broken_pardiso(monkeypatch):
    """PARDISO cannot load (no MKL found), with every cache cleared before and after."""

    def clear():
        mkl.pardiso_function.cache_clear()
        pardiso.pardiso_problem.cache_clear()
        backends._warn_fallback.cache_clear()

    clear()
    monkeypatch.setattr(mkl, "mkl_runtime_candidates", lambda: [])
    yield
    clear()


def test_auto_takes_pardiso_when_mkl_is_installed():
    try:
        importlib.metadata.distribution("mkl")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("the mkl distribution is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fallback warning either
        solver = make_solver()
    assert solver.backend == "pardiso" and solver.reuses_analysis
    assert available_backends() == ("pardiso", "scipy", *PETSC)
    gamg = ("petsc-gamg",) if PETSC else ()  # iterative: listed only when asked for
    assert available_backends(iterative=True) == ("pardiso", "scipy", *PETSC, *gamg, "amg")


def test_unknown_backend_lists_valid():
    with pytest.raises(ValueError, match="unknown backend 'mumps'.*auto, pardiso, scipy, petsc"):
        solver_factory("mumps")
    assert tuple(SOLVERS) == ("auto", "pardiso", "scipy", "petsc", "petsc-gamg", "amg")


def test_the_registry_names_each_factory_once():
    for name, factory in SOLVERS.items():
        assert solver_factory(name) is factory and solver_name(factory) == name
    assert solver_name(auto_solver) == "auto" and solver_name(superlu_solver) == "scipy"
    with pytest.raises(ValueError, match="not a registered backend"):
        solver_name(lambda request: None)
    with pytest.raises(ValueError, match="solver must be an SPDSolver or a solver factory"):
        make_solver("scipy")  # a name is not a factory
    with pytest.raises(ValueError, match="returned int, not an SPDSolver"):
        make_solver(lambda request: 3)


def test_auto_falls_back_to_superlu_with_one_warning(broken_pardiso):
    with pytest.warns(SolverFallbackWarning, match="falling back to SuperLU: .*mkl_rt") as caught:
        solver = make_solver(auto_solver)
    assert len(caught) == 1 and caught[0].filename == __file__  # points at the caller
    assert solver.backend == "scipy" and not solver.reuses_analysis
    assert available_backends() == ("scipy", *PETSC)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once per process: a second fallback is silent
        result = solve_pdas(sp.identity(3, format="csr"), np.ones(3), [0], 0.5)
    assert result.backend == "scipy"  # the history's backend column reports what was used
    assert np.array_equal(result.x, [0.5, 1.0, 1.0])


def test_explicit_pardiso_raises_when_unavailable(broken_pardiso):
    with pytest.raises(BackendUnavailableError, match="pardiso backend is not usable here: MKL"):
        make_solver(pardiso_solver)
    with pytest.raises(RuntimeError, match="no file found"):
        solve_pdas(sp.identity(3, format="csr"), np.ones(3), [0], 0.5, solver=pardiso_solver)
    assert make_solver(superlu_solver).backend == "scipy"  # asked for: no warning needed
