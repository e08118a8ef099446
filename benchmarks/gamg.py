"""Benchmark: CG + GAMG with the rigid-body near-nullspace on Example 6.2's adaptive meshes.

The adaptive loop (θ = 0.4, the serial default backend) runs to ``--max-ndof``; on the levels
whose unknowns first pass 17 000 × 2^k, the PDAS system of the level's solution — the
stiffness matrix in the contact node frames with the Dirichlet DOFs and the active normal DOFs
fixed, i.e. the system the last PDAS iteration solved — is solved again by PETSc's CG
preconditioned by GAMG, with the three rigid motions of the plane, (1, 0), (0, 1) and
(−y, x), written in the node frames (``(u·n, u·t)`` at constrained nodes) and restricted to
the free DOFs as its near-nullspace. Printed per level: unknowns, CG iterations to
``rtol = 1e-10`` (preconditioned residual norm, PETSc's default test), the relative error
of u against the direct solution, and the seconds of GAMG's set-up and of the solve. The
meshes are strongly graded at the kink of the obstacle and at the ends of the contact zone:
the hard case for an algebraic multigrid.

With ``--loop`` it runs instead the whole adaptive loop twice, one run after the other in
this process: on the ``"petsc"`` backend (MUMPS) and on ``"petsc-gamg"`` (CG + GAMG with the
inexact active set rule, docs/parallel.md, *Inexact active set iterations*). Printed per
level: unknowns, active set iterations of each, the CG iterations of each GAMG solve, the
solve phase's seconds of each (``t_solve``: set-ups or factorizations and solves), the
largest KKT residual of the GAMG run; at the end the loops' totals and their ratio. The runs
must give the same unknowns and active sets on every level (checked).

Needs the extra ``signorini[mpi]``; under ``mpiexec -n N`` the rows are split as by the
``petsc`` backend (every rank runs the loop). Measured figures: docs/parallel.md.

    python benchmarks/gamg.py                     # to just above 10⁶ unknowns
    python benchmarks/gamg.py --max-ndof 300000 --no-nullspace
    python benchmarks/gamg.py --loop --max-ndof 300000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse as sp

from signorini import adaptive, example_6_2
from signorini.algebra import solver_factory
from signorini.algebra.backends.petsc import petsc_module, row_block
from signorini.contact import assemble


def pdas_system(result) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray, np.ndarray]:
    """The free-DOF block of the level's last PDAS system, its right-hand side, the free
    DOFs and the full vector of fixed values (Dirichlet data, gap at active nodes)."""
    a = assemble(result.problem, result.space.mesh)
    n = a.K.shape[0]
    fixed = np.zeros(n, dtype=bool)
    x = np.zeros(n)
    fixed[a.dirichlet] = True
    x[a.dirichlet] = a.dirichlet_values
    normal_dofs = 2 * a.contact.nodes[result.active]
    fixed[normal_dofs] = True
    x[normal_dofs] = a.contact.gap[result.active]
    free = np.flatnonzero(~fixed)
    K = a.K.tocsr()
    b = a.F[free] - K[free][:, np.flatnonzero(fixed)] @ x[fixed]
    return K[free][:, free].tocsr(), b, free, a


def rigid_modes(a, free: np.ndarray) -> np.ndarray:
    """(n_free, 3) orthonormal basis of the rigid motions in the node frames, free rows."""
    xy = a.space.node_points
    modes = np.zeros((2 * xy.shape[0], 3))
    modes[0::2, 0] = 1.0
    modes[1::2, 1] = 1.0
    modes[0::2, 2] = -xy[:, 1]
    modes[1::2, 2] = xy[:, 0]
    nodes, normal = a.contact.nodes, a.contact.normal
    for k in range(3):  # the three modes; rotate at the constrained nodes
        vx, vy = modes[2 * nodes, k].copy(), modes[2 * nodes + 1, k].copy()
        modes[2 * nodes, k] = vx * normal[:, 0] + vy * normal[:, 1]
        modes[2 * nodes + 1, k] = -vx * normal[:, 1] + vy * normal[:, 0]
    q, _ = np.linalg.qr(modes[free])
    return q


def solve_gamg(K, b, modes, rtol: float, nullspace: bool):
    """CG + GAMG on the rows of this rank; returns (x, iterations, setup s, solve s)."""
    PETSc = petsc_module()
    comm = PETSc.COMM_WORLD
    n = K.shape[0]
    lo, hi = row_block(n, comm.getRank(), comm.getSize())
    first, last = K.indptr[lo], K.indptr[hi]
    csr = (
        (K.indptr[lo : hi + 1] - first).astype(PETSc.IntType),
        K.indices[first:last].astype(PETSc.IntType),
        K.data[first:last],
    )
    A = PETSc.Mat().createAIJ(size=((hi - lo, n), (hi - lo, n)), csr=csr, comm=comm)
    A.assemble()
    A.setOption(PETSc.Mat.Option.SPD, True)
    vectors = []
    if nullspace:
        for k in range(modes.shape[1]):
            v = A.createVecLeft()
            v.setArray(modes[lo:hi, k])
            vectors.append(v)
        A.setNearNullSpace(PETSc.NullSpace().create(vectors=vectors, comm=comm))
    ksp = PETSc.KSP().create(comm=comm)
    ksp.setOperators(A)
    ksp.setType("cg")
    ksp.getPC().setType("gamg")
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=2000)
    rhs, x = A.createVecs()
    rhs.setArray(b[lo:hi])
    t0 = time.perf_counter()
    ksp.setUp()
    t1 = time.perf_counter()
    ksp.solve(rhs, x)
    t2 = time.perf_counter()
    scatter, everywhere = PETSc.Scatter.toAll(x)
    scatter.scatter(x, everywhere)
    iterations = ksp.getIterationNumber()
    if ksp.getConvergedReason() < 0:
        iterations = -iterations
    return everywhere.getArray().copy(), iterations, t1 - t0, t2 - t1


def loop_run(backend: str, max_ndof: int) -> tuple[list, list, float]:
    """The adaptive loop of Example 6.2 on ``backend``: its levels, every solver it made,
    and its total seconds (wall clock, and this process's CPU time)."""
    made = []
    factory = solver_factory(backend)

    def recording(request):
        solver = factory(request)
        made.append(solver)
        return solver

    t0, c0 = time.perf_counter(), time.process_time()
    levels = list(adaptive(example_6_2(), max_ndof=max_ndof, max_levels=200, solver=recording))
    return levels, made, (time.perf_counter() - t0, time.process_time() - c0)


def compare_loops(max_ndof: int, say) -> None:
    """``--loop``: MUMPS's and GAMG's adaptive loops, level by level (module docstring)."""
    mumps, _, t_mumps = loop_run("petsc", max_ndof)
    gamg, solvers, t_gamg = loop_run("petsc-gamg", max_ndof)
    say(f"{'ndof':>8} {'pdas':>4} {'gamg':>4} {'CG iterations':<24} {'mumps s':>8} "
        f"{'gamg s':>8} {'kkt':>8}")  # fmt: skip
    cg = [s.iterations for s in solvers if hasattr(s, "iterations")]
    every = []
    for a, b in zip(mumps, gamg, strict=True):
        if a.record.ndof != b.record.ndof or not np.array_equal(a.result.active, b.result.active):
            raise SystemExit(f"the runs part at {a.record.ndof} unknowns")
        its = cg.pop(0) if cg else []
        while cg and len(its) < b.result.report.n_solves:  # a level's nested coarse solve
            its = its + cg.pop(0)
        every += its
        say(
            f"{a.record.ndof:>8} {a.record.pdas_iterations:>4} {b.record.pdas_iterations:>4} "
            f"{' '.join(map(str, its)):<24} {a.record.t_solve:>8.2f} {b.record.t_solve:>8.2f} "
            f"{b.result.report.kkt.max:>8.1e}",
            flush=True,
        )
    t_solve = sum(level.record.t_solve for level in mumps), sum(lv.record.t_solve for lv in gamg)
    (t_mumps, cpu_mumps), (t_gamg, cpu_gamg) = t_mumps, t_gamg
    say(
        f"loop CPU time (this process): MUMPS {cpu_mumps:.1f} s, GAMG {cpu_gamg:.1f} s (ratio "
        f"{cpu_gamg / cpu_mumps:.2f})"
    )
    say(
        f"loop total: MUMPS {t_mumps:.1f} s, GAMG {t_gamg:.1f} s (ratio {t_gamg / t_mumps:.2f}); "
        f"solve phase: {t_solve[0]:.1f} s, {t_solve[1]:.1f} s (ratio "
        f"{t_solve[1] / t_solve[0]:.2f}); CG iterations per solve: mean {np.mean(every):.1f}, "
        f"max {max(every)}; largest KKT residual {max(lv.result.report.kkt.max for lv in gamg):.1e}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=1_000_000)
    parser.add_argument("--rtol", type=float, default=1e-10)
    parser.add_argument("--no-nullspace", action="store_true", help="GAMG's default (constants)")
    parser.add_argument("--loop", action="store_true", help="the whole loop: MUMPS against GAMG")
    args = parser.parse_args()
    rank = petsc_module().COMM_WORLD.getRank()
    say = print if rank == 0 else (lambda *a, **k: None)
    if args.loop:
        compare_loops(args.max_ndof, say)
        return
    say(f"{'ndof':>9} {'free':>9} {'its':>5} {'rel.err':>9} {'setup s':>8} {'solve s':>8}")
    target = 17_000
    for level in adaptive(example_6_2(), max_ndof=args.max_ndof, max_levels=200):
        if level.record.ndof < target and level.next_mesh is not None:
            continue
        while target <= level.record.ndof:
            target *= 2
        K, b, free, a = pdas_system(level.result)
        modes = rigid_modes(a, free)
        x, its, setup, solve = solve_gamg(K, b, modes, args.rtol, not args.no_nullspace)
        exact = level.result.u.reshape(-1)
        # the loop's u is Cartesian; compare in the frames the system is written in
        u = exact.copy()
        nodes, normal = a.contact.nodes, a.contact.normal
        ux, uy = exact[2 * nodes], exact[2 * nodes + 1]
        u[2 * nodes] = ux * normal[:, 0] + uy * normal[:, 1]
        u[2 * nodes + 1] = -ux * normal[:, 1] + uy * normal[:, 0]
        error = np.abs(x - u[free]).max() / np.abs(u[free]).max()
        say(
            f"{level.record.ndof:>9} {free.size:>9} {its:>5} {error:>9.1e} {setup:>8.2f} "
            f"{solve:>8.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
