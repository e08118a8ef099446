"""Benchmark of the core steps at 10⁵–10⁶ unknowns: refinement, assembly, one PDAS solve.

For Example 6.2 on structured meshes of increasing size it times one uniform NVB refinement
(producing the mesh), the assembly of the contact problem (stiffness, loads, rotated contact
frames), one cold-started PDAS solve and the estimator, and prints the throughput of each
step in unknowns per second and the peak memory of the process so far (sizes run in
increasing order, so the peak belongs to the current size).

    python benchmarks/core.py                      # 1e5, 4e5, 1e6 unknowns
    python benchmarks/core.py --sizes 100000 200000
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from signorini import estimate, example_6_2, refine_uniform
from signorini.algebra import SOLVERS
from signorini.contact import assemble, solve
from signorini.runtime import retain_freed_memory


def timed(func):
    t0 = time.perf_counter()
    out = func()
    return time.perf_counter() - t0, out


def rate(seconds: float, ndof: int) -> str:
    """Time and throughput in millions of unknowns per second."""
    return f"{seconds:6.2f}s {ndof / seconds / 1e6:5.2f}M/s"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000, 400_000, 1_000_000])
    parser.add_argument("--backend", default="auto", choices=tuple(SOLVERS))
    args = parser.parse_args()
    retain_freed_memory()
    print(
        f"{'unknowns':>10s} {'refine':>14s} {'assemble':>14s} {'PDAS solve':>20s} "
        f"{'estimate':>14s} {'peak MiB':>9s}"
    )
    for size in args.sizes:
        # the mesh before the last uniform refinement: about a quarter of the unknowns
        n = max(2, int(round((np.sqrt(size / 2) - 1) / 4)))
        n += n % 2
        problem = example_6_2(nx=n)
        coarse = problem.mesh
        _ = coarse.edges  # topology of the coarse mesh is not part of the refinement

        def refine(coarse=coarse):
            ref = refine_uniform(coarse)
            _ = ref.mesh.edges  # the refined mesh's topology, needed by everything after
            return ref

        t_ref, ref = timed(refine)
        mesh = ref.mesh
        t_asm, assembled = timed(lambda mesh=mesh, p=problem: assemble(p, mesh))
        ndof = assembled.space.n_dofs
        t_pdas, result = timed(
            lambda a=assembled, mesh=mesh, p=problem: solve(
                p, mesh, assembled=a, solver=SOLVERS[args.backend]
            )
        )
        t_est, _ = timed(lambda r=result: estimate(r))
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(
            f"{ndof:10d} {rate(t_ref, ndof):>14s} {rate(t_asm, ndof):>14s} "
            f"{rate(t_pdas, ndof):>14s} ({result.report.iterations:2d} it) "
            f"{rate(t_est, ndof):>14s} {peak:9.0f}",
            flush=True,
        )
        backend = result.report.backend
        del assembled, result, ref, mesh
    print(f"sparse solver backend: {backend}")


if __name__ == "__main__":
    main()
