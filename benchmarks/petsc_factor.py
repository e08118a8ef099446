"""Benchmark: MUMPS (the ``petsc`` backend) against PARDISO on the same matrices.

Example 6.2's adaptive loop (θ = 0.4, the default backend) runs to ``--max-ndof``; on its
last level the stiffness matrix with the Dirichlet DOFs eliminated (what
``benchmarks/adaptive.py`` calls the floor) is factorized by each backend in turn,
``--repeat`` times, alternating so that both see the same load on a shared machine. Printed
per backend: the best time of analysis + factorization, of a refactorization (same pattern,
analysis kept) and of one solve, and the residual; for MUMPS also its ordering (``INFOG(7)``:
0 AMD, 5 METIS, 1 given), its factor's entries (``INFOG(29)``) and flops (``RINFOG(3)``). Needs the
extra ``signorini[mpi]``.

Backends: ``pardiso``, ``petsc`` (MUMPS Cholesky, AMD on one process), ``petsc-lu`` (MUMPS
LU, AMD on one process), ``petsc-lu-ordered`` (MUMPS LU given the loop's ordering,
:func:`signorini.contact.ordering.dof_ordering`, as the petsc factory gives it to an LU on one
process).

    python benchmarks/petsc_factor.py --max-ndof 1000000
    python benchmarks/petsc_factor.py --max-ndof 300000 --backends petsc-lu,petsc-lu-ordered
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from adaptive import reduced_system

from signorini import adaptive, example_6_2
from signorini.algebra import SOLVERS, make_solver


def solver_of(backend: str, ordering):
    if backend.startswith("petsc-lu"):
        from signorini.algebra.backends.petsc import PetscLUSolver

        return PetscLUSolver(ordering=ordering() if backend.endswith("ordered") else None)
    return make_solver(SOLVERS[backend], check_symmetry=False)


def timed(backend: str, K, b, ordering) -> tuple[np.ndarray, str]:
    """(analysis + factorization, refactorization, solve) seconds, the relative residual, and
    MUMPS's ordering, factor entries and flops."""
    with solver_of(backend, ordering) as solver:
        t0 = time.perf_counter()
        solver.factorize(K)
        t1 = time.perf_counter()
        solver.factorize(K)
        t2 = time.perf_counter()
        x = solver.solve(b)
        t3 = time.perf_counter()
        about = ""
        if backend.startswith("petsc"):
            f = solver._ksp.getPC().getFactorMatrix()
            about = (
                f"  INFOG(7) {f.getMumpsInfog(7)}  factor entries {f.getMumpsInfog(29)}"
                f"  flops {f.getMumpsRinfog(3):.3e}"
            )
    residual = float(np.abs(K @ x - b).max() / np.abs(b).max())
    return np.array([t1 - t0, t2 - t1, t3 - t2, residual]), about


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--backends", default="pardiso,petsc")
    args = parser.parse_args()
    problem = example_6_2()
    *_, last = adaptive(problem, max_ndof=args.max_ndof, max_levels=200)
    K, b, ordering = reduced_system(problem, last.result.space.mesh)
    print(f"{K.shape[0]} unknowns, {K.nnz} stored entries")
    best: dict[str, np.ndarray] = {}
    about: dict[str, str] = {}
    for _ in range(args.repeat):
        for backend in args.backends.split(","):
            t, about[backend] = timed(backend, K, b, ordering)
            best[backend] = t if backend not in best else np.minimum(best[backend], t)
    for backend, (first, again, solve, residual) in best.items():
        print(
            f"{backend:16s} analysis+factorization {first:6.2f} s  refactorization {again:6.2f} s"
            f"  solve {solve:6.3f} s  residual {residual:.1e}{about[backend]}"
        )


if __name__ == "__main__":
    main()
