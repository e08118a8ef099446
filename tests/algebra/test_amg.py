"""The ``"amg"`` backend (signorini.algebra.backends.amg): CG + pyamg's smoothed aggregation
on 2D P2 elasticity from the package and a 3D P2 study matrix (studies/amg3d)."""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from signorini.algebra import SingularSystemError, make_solver, solve_pdas, superlu_solver
from signorini.algebra.backends.amg import REUSE_CHANGED, AmgSolver, amg_solver
from signorini.algebra.backends.selection import solver_factory
from signorini.algebra.backends.solvers import SolverRequest
from signorini.algebra.inexact import KKT_RTOL

STUDIES = Path(__file__).resolve().parents[2] / "studies"


@cache
def block():
    """The pressed block of tests/contact_problems.py (16 x 8 squares), assembled, and its
    rigid motions in the system's unknowns."""
    from signorini.contact.rigid_modes import system_rigid_modes
    from signorini.contact.system import assemble
    from signorini.fem.material import Material
    from signorini.mesh.builders import rectangle
    from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

    mesh = rectangle(0.0, 2.0, 0.0, 1.0, nx=16, ny=8)
    problem = ContactProblem(
        mesh=mesh,
        material=Material.from_young(1.0, 0.3),
        conditions={
            "top": Dirichlet((0.01, -0.02)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=lambda x: 0.04 * (x[:, 0] - 1.0) ** 2),
        },
    )
    a = assemble(problem, mesh)
    return a, system_rigid_modes(a)


def clamped_2d():
    """The block's stiffness with the Dirichlet rows and columns eliminated (the diagonal
    kept), a load, and the rigid modes."""
    a, modes = block()
    free = np.ones(a.K.shape[0], dtype=bool)
    free[a.dirichlet] = False
    P = sp.diags(free.astype(float))
    K = (P @ a.K @ P + sp.diags(np.where(free, 0.0, a.K.diagonal()))).tocsr()
    b = np.where(free, np.random.default_rng(1).standard_normal(K.shape[0]), 0.0)
    return K, b, modes


@cache
def cube():
    """The 3D P2 cube of studies/amg3d, 3 x 3 x 3 cubes, clamped on x = 0, and its six
    rigid modes."""
    sys.path.insert(0, str(STUDIES))
    from amg3d.system import clamped_system, rigid_modes

    system = clamped_system(3, gamma=2.0)
    return system.K.tocsr(), system.F, rigid_modes(system.points)


def test_2d_elasticity_is_solved_to_its_tolerance_and_agrees_with_a_direct_solve():
    K, b, modes = clamped_2d()
    exact = sp.linalg.spsolve(K.tocsc(), b)
    with AmgSolver(K, near_nullspace=modes, rtol=1e-10) as solver:
        x = solver.solve(b)
        assert np.linalg.norm(b - K @ x) <= 1e-10 * np.linalg.norm(b)
        assert solver.backend == "amg" and solver.n_setups == 1
        assert solver.iterations[0] < 40
    # the error is at the level of the tolerance times the condition number's share
    assert np.linalg.norm(x - exact) <= 1e-6 * np.linalg.norm(exact)


def test_3d_elasticity_needs_fewer_iterations_with_the_six_rigid_modes():
    K, F, modes = cube()
    counts = {}
    for label, B in (("rigid", modes), ("translations", None)):
        with AmgSolver(K, near_nullspace=B, block_size=3) as solver:
            x = solver.solve(F)
            assert np.linalg.norm(F - K @ x) <= 1e-8 * np.linalg.norm(F)
            counts[label] = solver.iterations[0]
    exact = sp.linalg.spsolve(K.tocsc(), F)
    assert np.linalg.norm(x - exact) <= 1e-5 * np.linalg.norm(exact)
    assert counts["rigid"] < counts["translations"], counts


def test_the_hierarchy_is_kept_for_the_same_matrix_and_reused_across_masks():
    K, b, modes = clamped_2d()
    keep = np.ones(K.nnz, dtype=bool)
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    fixed = np.zeros(K.shape[0], dtype=bool)
    fixed[[5, 17]] = True  # two more eliminated DOFs: their off-diagonal entries dropped
    other = keep & ~((fixed[rows] | fixed[K.indices]) & (rows != K.indices))
    b2 = np.where(fixed, 0.0, b)
    with AmgSolver(near_nullspace=lambda: modes, reuse=True) as solver:
        solver.factorize(K, keep)
        solver.solve(b)
        solver.refactorize(keep)  # the same matrix: the hierarchy stands
        assert solver.n_setups == 1
        solver.refactorize(other)  # another active set: the old hierarchy, projected
        x = solver.solve(b2)
        assert solver.n_setups == 1
    A = sp.csr_matrix((K.data * other, K.indices, K.indptr), K.shape)
    assert np.linalg.norm(b2 - A @ x) <= 1e-8 * np.linalg.norm(b2)
    with AmgSolver(near_nullspace=modes) as fresh:  # without reuse: a new hierarchy
        fresh.factorize(K, keep)
        fresh.refactorize(other)
        assert fresh.n_setups == 2


def test_a_hierarchy_is_rebuilt_for_a_set_that_differs_in_more_than_a_few_dofs():
    """``reuse`` keeps the hierarchy while the free DOFs differ from its own in at most
    :data:`REUSE_CHANGED`, and builds a new one beyond (counted from the hierarchy's set, not
    from the last one)."""
    K, b, modes = clamped_2d()
    keep = np.ones(K.nnz, dtype=bool)
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))

    def eliminated(dofs):
        fixed = np.zeros(K.shape[0], dtype=bool)
        fixed[dofs] = True
        return keep & ~((fixed[rows] | fixed[K.indices]) & (rows != K.indices))

    free = np.flatnonzero(K.diagonal() != 0)[: 2 * REUSE_CHANGED + 2]
    with AmgSolver(near_nullspace=modes, reuse=True) as solver:
        solver.factorize(K, keep)
        solver.refactorize(eliminated(free[:REUSE_CHANGED]))  # within: kept
        assert solver.n_setups == 1
        solver.refactorize(eliminated(free[: REUSE_CHANGED + 1]))  # one more: new
        assert solver.n_setups == 2
        solver.refactorize(eliminated(free[REUSE_CHANGED + 1 :]))  # 2 × (k + 1) from it: new
        assert solver.n_setups == 3


def test_a_confirming_solve_starts_from_the_last_solution():
    K, b, modes = clamped_2d()
    with AmgSolver(K, near_nullspace=modes) as solver:
        solver.solve(b)
        solver.rtol = 1e-11
        x = solver.solve(b)
        assert solver.iterations[1] < solver.iterations[0]
    assert np.linalg.norm(b - K @ x) <= 1e-11 * np.linalg.norm(b)


def starts_from_the_iterate_it_is_handed(solver, K, b) -> None:
    """``solver.start_from`` (a solver that takes a guess, set up on ``K``): from the solution
    itself no CG iteration, from a perturbation of it fewer than from zero, the next solve
    from zero again; the answers meet the tolerance; a guess of the wrong shape or not
    finite refused by name."""
    x = solver.solve(b)  # from zero
    solver.start_from(x)
    solver.solve(2.0 * b - b)  # the same b, not recognised as the last right-hand side
    near = x * (1.0 + 1e-6 * np.random.default_rng(2).standard_normal(x.size))
    solver.start_from(near)
    y = solver.solve(b)
    solver.solve(b[::-1].copy())  # from zero
    cold, again, warm, cold2 = solver.iterations
    assert again == 0 and warm < cold / 2 and cold2 > warm
    with pytest.raises(ValueError, match=rf"x must be a finite \({x.size},\) array"):
        solver.start_from(x[:-1])
    with pytest.raises(ValueError, match="x must be a finite"):
        solver.start_from(np.full_like(x, np.nan))
    assert np.linalg.norm(b - K @ y) <= 1e-8 * np.linalg.norm(b)


def test_a_solve_starts_from_the_iterate_it_is_handed():
    """:meth:`AmgSolver.start_from` (:func:`starts_from_the_iterate_it_is_handed`); a direct
    solver ignores a guess."""
    K, b, modes = clamped_2d()
    with AmgSolver(K, near_nullspace=modes) as solver:
        starts_from_the_iterate_it_is_handed(solver, K, b)
    with make_solver(superlu_solver, K) as direct:
        direct.start_from(np.zeros(3))  # ignored, whatever its shape
        assert np.linalg.norm(b - K @ direct.solve(b)) <= 1e-12 * np.linalg.norm(b)


def test_bad_input_is_refused():
    K, b, modes = clamped_2d()
    with pytest.raises(ValueError, match="A must be square|square"):
        AmgSolver(sp.random(6, 5, density=0.5, format="csr", random_state=0))
    unsymmetric = K.tolil()
    unsymmetric[0, 1] += 1.0
    with pytest.raises(ValueError, match="not symmetric"):
        AmgSolver(unsymmetric.tocsr())
    with pytest.raises(ValueError, match=r"near_nullspace must be an \(1122, k\) array"):
        AmgSolver(K, near_nullspace=modes[:-1])
    with pytest.raises(ValueError, match="near_nullspace has non-finite"):
        AmgSolver(K, near_nullspace=np.full_like(modes, np.nan))
    with pytest.raises(ValueError, match="rtol must be a number in"):
        AmgSolver(rtol=1.0)
    with pytest.raises(ValueError, match="block_size must be a positive integer"):
        AmgSolver(block_size=0)


def test_a_singular_system_is_refused():
    """A free chain of springs: the load is not orthogonal to the constant nullspace."""
    n = 200
    K = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    K[0, 0] = K[n - 1, n - 1] = 1.0
    with AmgSolver(K.tocsr(), block_size=1, max_it=300) as solver:
        with pytest.raises(SingularSystemError, match=r"CG \+ AMG did not reach .* 1e-08"):
            solver.solve(np.ones(n))


def test_the_factory_is_registered_and_gives_lu_for_non_symmetric_systems():
    assert solver_factory("amg") is amg_solver
    lu = amg_solver(SolverRequest(symmetric=False))
    assert lu.rtol is None and lu.backend == "scipy"
    spd = amg_solver(SolverRequest())
    assert isinstance(spd, AmgSolver) and spd.rtol == 1e-8
    lu.close()
    spd.close()


def test_pdas_through_amg_gives_the_direct_active_set():
    a, modes = block()
    args = (a.K, a.F, a.contact.constrained_dofs, a.contact.gap, a.dirichlet, a.dirichlet_values)
    exact = solve_pdas(*args, solver=superlu_solver)
    with make_solver(amg_solver, rigid_modes=lambda: modes, check_symmetry=False) as solver:
        result = solve_pdas(*args, solver=solver)
        assert solver.iterations and max(solver.iterations) < 60
    assert np.array_equal(result.active, exact.active) and exact.active.sum() >= 5
    assert result.kkt.max <= KKT_RTOL
    assert np.linalg.norm(result.x - exact.x) <= 1e-6 * np.linalg.norm(exact.x)


def test_the_automatic_choice_takes_amg_for_large_3d_systems_but_not_for_pairs():
    """``"auto"``: a symmetric 3D system of AMG_FROM_3D unknowns or more on CG + AMG, one
    just below, a 2D one, a non-symmetric one and one that couples bodies through contact
    pairs (whatever its size) on a direct factorization."""
    from signorini.algebra.backends.selection import AMG_FROM_3D, auto_solver

    def backend(**request) -> str:
        made = auto_solver(SolverRequest(**request))
        made.close()
        return made.backend

    assert backend(dimension=3, size=AMG_FROM_3D) == "amg"
    direct = {"pardiso", "scipy"}
    assert backend(dimension=3, size=AMG_FROM_3D - 1) in direct
    assert backend(dimension=2, size=10 * AMG_FROM_3D) in direct
    assert backend(dimension=3, size=AMG_FROM_3D, symmetric=False) in direct | {"pardiso-lu"}
    assert backend(dimension=3, size=10 * AMG_FROM_3D, coupled=True) in direct
    assert not SolverRequest(dimension=3, size=10**7, coupled=True).multigrid_from(1)
