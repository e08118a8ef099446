"""Solve assembled QPs with ``K`` split by rows over the ranks and save what to compare.

Run under ``mpiexec -n N python tests/parallel/mpi_split_solve.py OUT.npz``. Every rank assembles
each problem whole, keeps only the rows of its own nodes (:func:`signorini.contact.partition
.partition`: the other rows empty, as ``assemble`` on a rank of several builds them) and solves
with the ``"petsc"`` backend (or, in the cases named ``… gamg``, with CG + GAMG and the
system's rigid motions as near-nullspace) and ``ranks`` = all the ranks; the same problem is
solved with the whole ``K`` and a serial backend (SuperLU) in each process as the reference,
and in the GAMG cases with the whole ``K`` on every rank on CG + GAMG as well (the replicated
path). Rank 0 writes the results of every case; :mod:`test_split_solve` compares them.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.sparse as sp

from signorini.algebra import FrictionOptions, PDASOptions, solve_friction, solve_pdas
from signorini.algebra.backends.petsc import PetscSolver, petsc_module
from signorini.algebra.backends.petsc_gamg import GamgSolver
from signorini.algebra.backends.selection import solver_factory
from signorini.algebra.backends.solvers import SolverRequest
from signorini.algebra.friction.kkt import check_friction
from signorini.algebra.ranks import world_ranks
from signorini.contact.ordering import dof_ordering
from signorini.contact.partition import partition
from signorini.contact.rigid_modes import system_rigid_modes
from signorini.contact.system import assemble
from signorini.examples import example_6_2, example_6_2_coulomb, example_6_2_tresca
from signorini.examples.two_bodies import two_cylinders
from signorini.mesh.refine import refine_uniform

REFERENCE = solver_factory("scipy")


def own_rows(K: sp.csr_matrix, owned: np.ndarray) -> sp.csr_matrix:
    """``K`` with the rows off ``owned`` (n,) emptied (no stored entries)."""
    lengths = np.diff(K.indptr)
    keep = np.repeat(owned, lengths)
    indptr = np.zeros(K.shape[0] + 1, dtype=K.indptr.dtype)
    np.cumsum(np.where(owned, lengths, 0), out=indptr[1:])
    return sp.csr_matrix((K.data[keep], K.indices[keep], indptr), shape=K.shape)


def assembled(problem, refinements: int):
    mesh = problem.mesh
    for _ in range(refinements):
        mesh = refine_uniform(mesh).mesh
    a = assemble(problem, mesh)
    transfer = a.contact.transfer
    part = partition(a.space, world_ranks(), None if transfer is None else transfer.nodes)
    return a, own_rows(a.K, part.owned_dofs)


def pdas_case(problem, refinements: int, **options) -> dict[str, np.ndarray]:
    """Frictionless PDAS with ``K`` split and whole; the options of :class:`PDASOptions`
    (``x0_scale`` warm-starts both from that multiple of the serial solution)."""
    a, K_own = assembled(problem, refinements)
    cs = a.contact
    x0_scale = options.pop("x0_scale", None)
    solver = solver_factory("petsc")
    if options.pop("gamg", False):
        return gamg_pdas_case(a, K_own, **options)
    if options.pop("ordered", False):  # PETSc's rows in this order within each rank
        solver = PetscSolver(ordering=dof_ordering(a.space), check_symmetry=True)
    args = (cs.constrained_dofs, cs.gap, a.dirichlet, a.dirichlet_values)
    serial = solve_pdas(a.K, a.F, *args, options=PDASOptions(**options), solver=REFERENCE)
    warm = {} if x0_scale is None else {"x0": x0_scale * serial.x}
    if warm:
        serial = solve_pdas(
            a.K, a.F, *args, options=PDASOptions(**options), solver=REFERENCE, **warm
        )
    split = solve_pdas(
        K_own, a.F, *args, options=PDASOptions(**options), solver=solver,
        ranks=world_ranks(), **warm,
    )  # fmt: skip
    out = {"owned_rows": np.array([np.count_nonzero(np.diff(K_own.indptr))])}
    for name, res in (("serial", serial), ("split", split)):
        out |= {
            f"{name}_x": res.x,
            f"{name}_multiplier": res.multiplier,
            f"{name}_active": res.active,
            f"{name}_counts": np.array(
                [res.iterations, res.n_updates, res.n_factorizations, len(res.history)]
            ),
            f"{name}_kkt": np.array(list(res.kkt.columns().values())),
            f"{name}_method": np.array(res.method),
        }
    return out


def gamg_solver(a) -> GamgSolver:
    """CG + GAMG with the rigid motions of ``a`` (in the system's numbering)."""
    return GamgSolver(near_nullspace=lambda: system_rigid_modes(a))


def gamg_numbers(solver: GamgSolver) -> dict[str, np.ndarray]:
    """Whether the solver's matrix was split, its CG iterations, and its near-nullspace's
    vectors of the last factorization gathered into the caller's numbering."""
    return {
        "split": np.array(solver.split),
        "cg": np.array(solver.iterations),
        "modes": solver.near_nullspace_vectors(),
    }


def gamg_pdas_case(a, K_own: sp.csr_matrix, **options) -> dict[str, np.ndarray]:
    """Frictionless PDAS on CG + GAMG with ``K`` split and whole, and on SuperLU."""
    cs = a.contact
    args = (cs.constrained_dofs, cs.gap, a.dirichlet, a.dirichlet_values)
    serial = solve_pdas(a.K, a.F, *args, options=PDASOptions(**options), solver=REFERENCE)
    out = {"owned_rows": np.array([np.count_nonzero(np.diff(K_own.indptr))])}
    out["rigid_modes"] = system_rigid_modes(a)
    split_solver, whole_solver = gamg_solver(a), gamg_solver(a)
    split = solve_pdas(
        K_own, a.F, *args, options=PDASOptions(**options), solver=split_solver, ranks=world_ranks()
    )
    whole = solve_pdas(a.K, a.F, *args, options=PDASOptions(**options), solver=whole_solver)
    for name, res in (("serial", serial), ("split", split), ("whole", whole)):
        out |= {
            f"{name}_x": res.x,
            f"{name}_multiplier": res.multiplier,
            f"{name}_active": res.active,
            f"{name}_counts": np.array([res.iterations]),
            f"{name}_kkt": np.array(list(res.kkt.columns().values())),
        }
    for name, solver in (("split", split_solver), ("whole", whole_solver)):
        out |= {f"{name}_{key}": value for key, value in gamg_numbers(solver).items()}
        solver.close()
    return out


def friction_case(problem, refinements: int, gamg: bool = False) -> dict[str, np.ndarray]:
    """The frictional problem of ``problem`` (its first law's nodes), split and whole; with
    ``gamg`` (a Tresca problem) on CG + GAMG, split and whole, against SuperLU."""
    a, K_own = assembled(problem, refinements)
    cs = a.contact
    law = cs.friction
    nodes = cs.nodes
    reference = np.einsum("kc,kc->k", a.obstacle_motion, cs.tangent[:, 0]) + 0.0

    def problem_of(K):
        return check_friction(
            K, a.F, 2 * nodes, 2 * nodes + 1, cs.gap, a.dirichlet, a.dirichlet_values,
            laws=law.laws, weight=law.weight, law_index=law.index, reference=reference,
        )  # fmt: skip

    options = FrictionOptions()
    serial = solve_friction(problem_of(a.K), options=options, solver=REFERENCE)
    out = {"owned_rows": np.array([np.count_nonzero(np.diff(K_own.indptr))])}
    if gamg:
        out["rigid_modes"] = system_rigid_modes(a)
        split_solver, whole_solver = gamg_solver(a), gamg_solver(a)
        on_ranks = problem_of(K_own).on_ranks(world_ranks())
        split = solve_friction(on_ranks, options=options, solver=split_solver)
        whole = solve_friction(problem_of(a.K), options=options, solver=whole_solver)
        for name, res in (("serial", serial), ("split", split), ("whole", whole)):
            out |= {
                f"{name}_x": res.x,
                f"{name}_multiplier": np.concatenate([res.multiplier_n, res.multiplier_t]),
                f"{name}_active": np.concatenate([res.state, res.direction]),
                f"{name}_counts": np.array([res.iterations]),
                f"{name}_kkt": np.array(list(res.kkt.columns().values())),
            }
        for name, solver in (("split", split_solver), ("whole", whole_solver)):
            out |= {f"{name}_{key}": value for key, value in gamg_numbers(solver).items()}
            solver.close()
        return out
    split = solve_friction(
        problem_of(K_own).on_ranks(world_ranks()),
        options=options,
        solver=solver_factory("petsc"),
    )
    for name, res in (("serial", serial), ("split", split)):
        out |= {
            f"{name}_x": res.x,
            f"{name}_multiplier": np.concatenate([res.multiplier_n, res.multiplier_t]),
            f"{name}_active": np.concatenate([res.state, res.direction]),
            f"{name}_counts": np.array([res.iterations, res.n_factorizations, int(res.symmetric)]),
            f"{name}_kkt": np.array(list(res.kkt.columns().values())),
        }
    return out


CASES = {
    "example-6.2": lambda: pdas_case(example_6_2(), 2),
    "example-6.2 refactorized": lambda: pdas_case(example_6_2(), 2, max_update=0),
    "example-6.2 warm": lambda: pdas_case(example_6_2(), 2, x0_scale=0.9),
    "example-6.2 ordered": lambda: pdas_case(example_6_2(), 2, ordered=True),
    "example-6.2 primal fallback": lambda: pdas_case(example_6_2(), 2, max_iter=2, fallback=True),
    "two-cylinders": lambda: pdas_case(two_cylinders(rings=4), 2),
    "example-6.2-coulomb": lambda: friction_case(example_6_2_coulomb(), 2),
    "example-6.2-tresca": lambda: friction_case(example_6_2_tresca(), 2),
    "example-6.2 gamg": lambda: pdas_case(example_6_2(), 2, gamg=True),
    "two-cylinders gamg": lambda: pdas_case(two_cylinders(rings=4), 2, gamg=True),
    "example-6.2-tresca gamg": lambda: friction_case(example_6_2_tresca(), 2, gamg=True),
}


def refusals() -> dict[str, np.ndarray]:
    """The messages of a whole ``K`` on every rank passed as split, and of a split matrix
    that is not symmetric handed to the Cholesky backend."""
    a, K_own = assembled(example_6_2(), 0)
    cs = a.contact
    messages = []
    try:
        solve_pdas(a.K, a.F, cs.constrained_dofs, cs.gap, a.dirichlet, ranks=world_ranks())
    except ValueError as err:
        messages.append(str(err))
    skew = own_rows((a.K + sp.triu(a.K, 1) * 1e-3).tocsr(), np.diff(K_own.indptr) > 0)
    try:
        solver_factory("petsc")(SolverRequest()).factorize(skew)
    except ValueError as err:
        messages.append(str(err))
    return {"messages": np.array(messages)}


def mumps_orderings() -> np.ndarray:
    """The orderings MUMPS's Cholesky used (``INFOG(7)``) on a split ``K + I``: by default,
    and with ``-mat_mumps_icntl_7 5`` (METIS) in PETSc's options database."""
    a, K_own = assembled(example_6_2(), 1)
    owned = np.diff(K_own.indptr) > 0
    A = own_rows((a.K + sp.identity(a.K.shape[0])).tocsr(), owned)
    options = petsc_module().Options()
    used = []
    for icntl_7 in (None, 5):
        if icntl_7 is not None:
            options["mat_mumps_icntl_7"] = icntl_7
        with PetscSolver(A, check_symmetry=False) as solver:
            used.append(int(solver._ksp.getPC().getFactorMatrix().getMumpsInfog(7)))
    options.delValue("mat_mumps_icntl_7")
    return np.array(used)


if __name__ == "__main__":
    ranks = world_ranks()
    results = {f"refusals/{k}": v for k, v in refusals().items()}
    results["mumps_orderings"] = mumps_orderings()
    for case, run in CASES.items():
        for key, value in run().items():
            results[f"{case}/{key}"] = value
            if key == "owned_rows":
                results[f"{case}/{key}"] = ranks.gather(value)
    if ranks.rank == 0:
        np.savez(sys.argv[1], size=ranks.size, **results)
