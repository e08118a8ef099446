"""Benchmark: the adaptive loop of Example 6.2 (or ``--problem hertz-3d``: P2 tetrahedra) on
one backend, per rank: the time of each phase, the communication, and the peak memory
(docs/parallel.md, *Measurements*).

Run it serially, or under ``mpiexec -n N`` with ``--backend petsc``; every rank prints one
line with its totals over the levels (assembly, the solve phase — PDAS with its
factorizations and solves, in which MUMPS's and the gathers' communication is —, the
estimator, marking, refinement), the seconds spent in the collectives of
:class:`signorini.algebra.ranks.Ranks` (the sums, gathers and maxima of the assembly, the
PDAS loop and the estimator, timed around each call: waiting for a slower rank included;
PETSc's own messages inside the factorization, solve and gather are not), its peak
resident memory (``VmHWM``) and that per unknown of the last level, and the bytes per unknown
of what every rank holds whole (the replicated mesh, space, contact set and solution: the
NumPy arrays they hold, :func:`replicated_bytes`).

    python benchmarks/ranks.py --backend pardiso --max-ndof 1000000
    mpiexec -n 2 python benchmarks/ranks.py --backend petsc --max-ndof 1000000
    mpiexec -n 2 python benchmarks/ranks.py --problem hertz-3d --backend petsc-gamg --max-ndof 60000
"""

from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from signorini import adaptive, example_6_2
from signorini.algebra import SOLVERS, solver_factory
from signorini.algebra.ranks import solver_ranks
from signorini.examples import hertz_3d

PROBLEMS = {"example-6.2": example_6_2, "hertz-3d": lambda: hertz_3d(h_contact=0.2)}


def replicated_bytes(result) -> int:
    """The bytes of the NumPy arrays the mesh, the space, the contact set and the solution of
    ``result`` hold as attributes (cached ones included; each array counted once): what every
    rank holds whole."""
    seen, total = set(), 0
    for owner in (result.mesh, result.space, result.contact, result):
        for value in vars(owner).values():
            if isinstance(value, np.ndarray) and id(value) not in seen:
                seen.add(id(value))
                total += value.nbytes
    return total


def _timed_collectives(ranks) -> list[float]:
    """Wrap ``ranks``' collectives so that each call adds its seconds to the returned list's
    only entry."""
    spent = [0.0]
    for name in ("sum", "gather", "max"):
        inner = getattr(ranks, name)

        def timed(a, inner=inner):
            t0 = time.perf_counter()
            out = inner(a)
            spent[0] += time.perf_counter() - t0
            return out

        setattr(ranks, name, timed)
    return spent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=1_000_000)
    parser.add_argument("--backend", default="auto", choices=tuple(SOLVERS))
    parser.add_argument("--problem", default="example-6.2", choices=tuple(PROBLEMS))
    args = parser.parse_args()
    solver = solver_factory(args.backend)
    ranks = solver_ranks(solver)
    communication = _timed_collectives(ranks)
    phases = dict.fromkeys(("assemble", "solve", "estimate", "mark", "refine"), 0.0)
    t0 = time.perf_counter()
    for level in adaptive(
        PROBLEMS[args.problem](), theta=0.4, max_ndof=args.max_ndof, solver=solver
    ):
        r = level.record
        for key, value in zip(
            phases, (r.t_assemble, r.t_solve, r.t_estimate, r.t_mark, r.t_refine), strict=True
        ):
            phases[key] += value
    total = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    held = replicated_bytes(level.result)
    print(
        f"rank {ranks.rank} of {ranks.size} ({args.backend}): {r.level + 1} levels to {r.ndof} "
        f"unknowns, eta {r.eta:.6e}; total {total:.2f} s; "
        + ", ".join(f"{k} {v:.2f} s" for k, v in phases.items())
        + f"; Ranks collectives {communication[0]:.2f} s; peak "
        f"{peak / 2**20:.0f} MiB = {peak / 1024 / r.ndof:.2f} KiB per unknown; replicated "
        f"{held / 2**20:.1f} MiB = {held / r.ndof:.0f} B per unknown",
        flush=True,
    )


if __name__ == "__main__":
    main()
