"""Benchmark: the estimator on several MPI ranks, on one solution of Example 6.2 (or
``--problem hertz-3d``, P2 tetrahedra).

Run under ``mpiexec -n N python benchmarks/estimator_ranks.py [--max-ndof 200000]``: every
rank runs the adaptive loop (θ = 0.4) on the ``"petsc"`` backend to the budget, then times,
on the last level's solution, ``estimate`` with the ranks (each rank integrating its own cells
and edges, the integrals summed over the ranks: docs/parallel.md, *The estimator on several
ranks*) and without (the serial estimator, every cell on each rank), best of ``--repeat``;
also the partition of the space over the ranks (METIS on the vertex graph), and the one
reduction of the integrals alone. Each rank prints one line; the estimates must agree, and the
largest difference is printed.

    mpiexec -n 2 python benchmarks/estimator_ranks.py --max-ndof 200000
    mpiexec -n 2 python benchmarks/estimator_ranks.py --problem hertz-3d --max-ndof 40000
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini import adaptive, example_6_2
from signorini.algebra import solver_factory
from signorini.algebra.ranks import solver_ranks
from signorini.contact.partition import partition
from signorini.estimator.residual import estimate
from signorini.examples import hertz_3d

PROBLEMS = {"example-6.2": example_6_2, "hertz-3d": lambda: hertz_3d(h_contact=0.2)}


def best(func, repeat: int, clock=time.perf_counter) -> tuple[float, object]:
    """The shortest of ``repeat`` calls of ``func`` timed by ``clock``, and its last value."""
    times, value = [], None
    for _ in range(repeat):
        t0 = clock()
        value = func()
        times.append(clock() - t0)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=200_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--problem", default="example-6.2", choices=tuple(PROBLEMS))
    args = parser.parse_args()
    factory = solver_factory("petsc")
    ranks = solver_ranks(factory)
    for level in adaptive(PROBLEMS[args.problem](), max_ndof=args.max_ndof, solver=factory):
        result = level.result
    t_part, part = best(lambda: partition(result.space, ranks), args.repeat)
    t_serial, serial = best(lambda: estimate(result), args.repeat)
    t_ranks, split = best(lambda: estimate(result, ranks=ranks, partition=part), args.repeat)
    cpu_serial, _ = best(lambda: estimate(result), args.repeat, time.process_time)
    cpu_ranks, _ = best(
        lambda: estimate(result, ranks=ranks, partition=part), args.repeat, time.process_time
    )
    mesh = result.mesh  # about the size of the reduction: cells and edges (faces in 3D)
    n_integrals = mesh.n_cells + (mesh.n_edges if mesh.dim == 2 else len(mesh.facet2cell))
    t_sum, _ = best(lambda: ranks.sum(np.zeros(n_integrals)), args.repeat)
    diff = np.abs(split.eta2_cell - serial.eta2_cell).max() / serial.eta2_cell.max()
    print(
        f"rank {ranks.rank}/{ranks.size}: ndof {result.space.n_dofs} cells "
        f"{result.mesh.n_cells} own {int(part.owned_cells.sum())}; estimate on the ranks "
        f"{t_ranks:.3f} s (CPU {cpu_ranks:.3f} s), serial {t_serial:.3f} s (CPU "
        f"{cpu_serial:.3f} s); partition {t_part:.3f} s; a reduction of "
        f"{n_integrals} numbers {t_sum * 1e3:.2f} ms; max diff {diff:.1e}",
        flush=True,
    )


if __name__ == "__main__":
    main()
