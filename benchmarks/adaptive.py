"""Benchmark: Example 6.2, adaptive (θ = 0.4), from the initial mesh to ≥ 10⁶ unknowns.

Per level it prints the unknowns, the time of each phase (assembly, PDAS with its linear
solves, factorizations and whether the symbolic analysis was reused, estimator, marking,
refinement, output) and the *floor*: one complete direct solve of that level's stiffness
matrix (analysis + factorization + solve with a fresh solver), measured in the same run and
not counted in our total. Each level's row ends with its peak resident memory (``peakMiB``:
``VmHWM``, reset when the level starts, read before the floor's solve) and that over the
memory of its Cholesky factor (``peak/L``, 8 bytes per non-zero PARDISO reports, the factor of
the loop's ordering); the summary gives PARDISO's own memory on the last level, that of the
loop's largest solver (``iparm[14..16]``, read as it is closed). The floor is measured
twice: with PARDISO's own ordering (``floor``, ``ratio``) and with the loop's ordering
(``ordered``, ``ratio_o``: the solver is offered
:func:`signorini.contact.ordering.dof_ordering`, computed inside the timed solve, as the loop
does), the strictest floor. At the end it prints the ratios of issues #4 and #26, each
measured in this run: the last level's peak beyond PARDISO's own memory, the ratio to the
ordered floors split into the phases' shares (which sum to it: what the linear solves cost
against what the rest of the loop costs), and as its last two lines
``ratio_to_ordered_floor=X`` and ``ratio_to_floor=X``.

Measured to 5·10⁶ unknowns (``--max-ndof 6000000``, 2026-11-26, 2 cores, a slower day than
2026-11-23's 149 s): 50 levels to 5 394 800 unknowns in 211 s (sum of floors 212 s with
PARDISO's own ordering, ``ratio_to_floor=0.997``; 109 s with the loop's,
``ratio_to_ordered_floor=1.946``); peak 12 461 MiB on the last level, 3.51 x the factor of the
loop's ordering (3554 MiB; PARDISO's own peak 7368 MiB = 2.07 x). The floor keeps PARDISO's
own METIS analysis; the loop orders the unknowns by
:func:`signorini.contact.ordering.dof_ordering`.

With ``--friction coulomb`` (or ``tresca``) the same run solves Example 6.2 with friction on
its contact part (``signorini.examples.paper_friction``: F = 0.3, or s = 30) by the semismooth
Newton method; the table gains ``iters``, its iterations per level, and the floor stays the
same: one complete direct (Cholesky) solve of the level's stiffness matrix.

    python benchmarks/adaptive.py                 # to just above 10⁶ unknowns
    python benchmarks/adaptive.py --max-ndof 200000
    python benchmarks/adaptive.py --friction coulomb
    python benchmarks/adaptive.py --max-ndof 6000000   # to 5.4 million unknowns, 10 GiB
    python benchmarks/adaptive.py --no-floor --max-ndof 11000000   # to 10.1 million, 18 GiB

Measured with ``--no-floor --max-ndof 11000000`` (2026-11-26, the matrix in 2 x 2 blocks):
53 levels to 10 146 688 unknowns in 450 s, peak 18 121 MiB on the last level, 2.55 x its
factor (930 M non-zeros, 7097 MiB). ``--no-floor`` skips the floors and reads the factor's
size from the loop's own solvers.

With ``--problem two-cylinders`` the run is the two-body Hertz problem
(:func:`signorini.examples.two_bodies.two_cylinders`, mortar contact between two elastic
bodies); its floor factorizes the two-body matrix (the relative displacement's basis,
docs/method.md, *Two bodies*).

    python benchmarks/adaptive.py --problem two-cylinders

With ``--problem example-6.2-3d`` or ``hertz-3d`` the run is the 3D loop and its floor is one
complete iterative solve per level (AMG set-up + CG to the loop's tolerance, from zero):
``benchmarks/floor3d.py`` prints that table.

    python benchmarks/adaptive.py --problem example-6.2-3d --max-ndof 200000
"""

from __future__ import annotations

import argparse
import functools
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from signorini import adaptive, example_6_2
from signorini.algebra import SOLVERS, eliminate_symmetric, make_solver, solver_factory
from signorini.contact import assemble
from signorini.contact.ordering import dof_ordering
from signorini.examples import example_6_2_coulomb, example_6_2_tresca, two_cylinders
from signorini.output import HistoryWriter, write_vtu
from signorini.runtime import retain_freed_memory


def reduced_system(problem, mesh):
    """The level's stiffness matrix and load with the Dirichlet DOFs eliminated (what the
    floor factorizes), and the loop's ordering of its unknowns (a callable, as the loop
    offers it to the solver)."""
    a = assemble(problem, mesh)
    fixed = np.zeros(a.K.shape[0], dtype=bool)
    fixed[a.dirichlet] = True
    x_fixed = np.zeros(a.K.shape[0])
    x_fixed[a.dirichlet] = a.dirichlet_values
    coupling = None if a.contact.transfer is None else a.contact.transfer.nodes
    K, b = eliminate_symmetric(a.K, a.F, fixed, x_fixed)
    return K, b, lambda: dof_ordering(a.space, coupling)


def floor_seconds(problem, mesh, backend: str, *, ordered: bool = False) -> tuple[float, int]:
    """One analysis + factorization + solve of the level's matrix (Dirichlet DOFs
    eliminated), with a fresh solver; also the factor's non-zeros when known. ``ordered``:
    the solver is offered the loop's
    ordering (METIS on the vertex graph, computed inside the timed solve, as in the loop);
    otherwise PARDISO orders by itself."""
    K, b, ordering = reduced_system(problem, mesh)
    offered = ordering if ordered else None
    with make_solver(SOLVERS[backend], check_symmetry=False, ordering=offered) as solver:
        t0 = time.perf_counter()
        solver.factorize(K)
        solver.solve(b)
        seconds = time.perf_counter() - t0
        nnz = int(getattr(solver, "factor_nnz", 0))
    return seconds, nnz


def remembering_factory(factory, made: list[tuple[int, dict[str, int]]]):
    """``factory`` (its attributes too:
    :func:`~signorini.algebra.backends.selection.takes_ordering`,
    :func:`~signorini.algebra.ranks.solver_ranks`), whose solvers append their factor's size
    and PARDISO's memory to ``made`` when closed (closing zeroes ``iparm[14..16]``)."""

    @functools.wraps(factory)
    def remembering(request):
        solver = factory(request)
        close = solver.close

        def closing():
            nnz = int(getattr(solver, "factor_nnz", 0))
            made.append((nnz, dict(getattr(solver, "memory_kib", {}))))
            close()

        solver.close = closing
        return solver

    return remembering


def peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def reset_peak() -> bool:
    """Reset the resident set's high-water mark (``VmHWM``) to the current resident set
    (Linux); False where that is not possible."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        return False
    return True


def level_peak_bytes(resettable: bool) -> int:
    """Peak resident set since the last :func:`reset_peak` (``VmHWM``; the reset also resets
    ``getrusage``'s ``ru_maxrss``), or of the whole process where it cannot be reset."""
    if not resettable:
        return peak_rss_bytes()
    with open("/proc/self/status") as f:
        line = next(line for line in f if line.startswith("VmHWM:"))
    return int(line.split()[1]) * 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--max-ndof",
        type=int,
        default=1_300_000,
        help="budget of unknowns (the default ends just above 10^6)",
    )
    parser.add_argument("--theta", type=float, default=0.4)
    parser.add_argument("--backend", default="auto", choices=tuple(SOLVERS))
    parser.add_argument("--vtu", action="store_true", help="also write a VTU file per level")
    parser.add_argument("--out", type=Path, default=None, help="folder for history/VTU")
    parser.add_argument(
        "--friction",
        choices=("none", "coulomb", "tresca"),
        default="none",
        help="Example 6.2 with Coulomb (F = 0.3) or Tresca (s = 30) friction on Γ_C",
    )
    parser.add_argument(
        "--problem",
        choices=("example-6.2", "two-cylinders", "example-6.2-3d", "hertz-3d"),
        default="example-6.2",
        help="Example 6.2 (with --friction) or the two-cylinder problem of two elastic bodies",
    )
    parser.add_argument(
        "--no-floor",
        action="store_true",
        help="skip the floors (each level's peak and time only: the largest runs, where a "
        "floor's solve beside the loop's data would raise the peak)",
    )
    args = parser.parse_args()
    retain_freed_memory()
    if args.problem.endswith("-3d"):  # the 3D floor: benchmarks/floor3d.py
        if args.friction != "none":
            parser.error("--friction applies to example-6.2 only")
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from floor3d import run

        run(args.problem, args.theta, args.max_ndof, level_peak_bytes, reset_peak)
        return
    out = args.out or Path(tempfile.mkdtemp(prefix="signorini-bench-"))
    history = HistoryWriter(out / "history.csv")
    problem = {
        "none": example_6_2,
        "coulomb": example_6_2_coulomb,
        "tresca": example_6_2_tresca,
    }[args.friction]()
    if args.problem == "two-cylinders":
        if args.friction != "none":
            parser.error("--friction applies to example-6.2 only")
        problem = two_cylinders()
    friction = args.friction != "none"

    cols = (
        "level",
        "ndof",
        "assemble",
        "pdas",
        "solves",
        "facts",
        "updates",
        "reused",
        "estimate",
        "mark",
        "refine",
        "output",
        "total",
        "floor",
        "ratio",
        "ordered",
        "ratio_o",
        "peakMiB",
        "peak/L",
    ) + (("iters",) if friction else ())
    print(" ".join(f"{c:>9s}" for c in cols))
    total = floor = ordered_floor = 0.0
    phases = dict.fromkeys(("assemble", "pdas", "estimate", "mark", "refine", "output"), 0.0)
    solves_after_5: list[int] = []
    iterations: list[int] = []
    last_nnz = 0
    memory: dict[str, int] = {}
    level_peaks: list[int] = []  # bytes, each level's own
    with_floors = 0  # bytes: the process's peak, floor measurements included
    factory = solver_factory(args.backend)
    made: list[tuple[int, dict[str, int]]] = []  # the level's solvers: factor size, memory
    remembering = remembering_factory(factory, made)
    generator = adaptive(problem, theta=args.theta, max_ndof=args.max_ndof, solver=remembering)
    while True:
        resettable = reset_peak()
        t0 = time.perf_counter()
        level = next(generator, None)
        if level is None:
            break
        r = level.record
        t_out = time.perf_counter()
        history.append(r.row())
        if args.vtu:
            write_vtu(out / f"level_{r.level:03d}.vtu", level.result, level.estimate)
        t_output = time.perf_counter() - t_out
        level_total = time.perf_counter() - t0
        level_peak = level_peak_bytes(resettable)  # the level's own, the floor's not included
        mesh = level.result.mesh
        backend = r.backend
        del level  # free the level before the floor measurement
        # the loop's own solvers (closed): the largest factor's size and PARDISO's memory
        last_nnz, memory = max(made, key=lambda m: m[0], default=(0, {}))
        made.clear()
        if args.no_floor:
            level_floor = level_ordered = float("nan")
        else:
            level_floor, own_nnz = floor_seconds(problem, mesh, backend)
            level_ordered, ordered_nnz = floor_seconds(problem, mesh, backend, ordered=True)
            last_nnz = ordered_nnz or own_nnz  # the Cholesky factor, also under Coulomb's LU
        level_peaks.append(level_peak)
        with_floors = max(with_floors, level_peak_bytes(resettable))
        total += level_total
        floor += level_floor
        ordered_floor += level_ordered
        for key, value in (
            ("assemble", r.t_assemble),
            ("pdas", r.t_solve),
            ("estimate", r.t_estimate),
            ("mark", r.t_mark),
            ("refine", r.t_refine),
            ("output", t_output),
        ):
            phases[key] += value
        if r.level >= 5:
            solves_after_5.append(r.n_solves)
        reused = "yes" if r.n_analyses == 1 and r.n_factorizations >= 1 else "no"
        values = (
            r.level,
            r.ndof,
            r.t_assemble,
            r.t_solve,
            r.n_solves,
            r.n_factorizations,
            r.n_updates,
            reused,
            r.t_estimate,
            r.t_mark,
            r.t_refine,
            t_output,
            level_total,
            level_floor,
            level_total / level_floor,
            level_ordered,
            level_total / level_ordered,
            f"{level_peak / 2**20:.0f}",
            f"{level_peak / (8 * last_nnz):.2f}" if last_nnz else "-",
        ) + ((r.pdas_iterations,) if friction else ())
        iterations.append(r.pdas_iterations)
        print(
            " ".join(f"{v:9.3f}" if isinstance(v, float) else f"{v!s:>9s}" for v in values),
            flush=True,
        )

    overhead = phases["estimate"] + phases["mark"] + phases["refine"]
    factor_bytes = 8 * last_nnz
    peak = max(level_peaks)
    print()
    print(
        f"backend: {backend}; final level: {r.ndof} unknowns, {r.n_cells} cells, eta = {r.eta:.4e}"
    )
    print(
        f"total time {total:.2f} s, sum of floors {floor:.2f} s (PARDISO's own ordering), "
        f"{ordered_floor:.2f} s (the loop's ordering)"
    )
    print("phase totals: " + ", ".join(f"{k} {v:.2f} s" for k, v in phases.items()))
    if solves_after_5:
        print(
            f"PDAS linear solves per level after level 5: {np.mean(solves_after_5):.2f} "
            f"(target <= 1.5)"
        )
    if friction:
        print(
            f"semismooth Newton iterations per level ({args.friction}): "
            + " ".join(str(k) for k in iterations)
        )
    print(
        f"estimator + marking + refinement: {overhead:.2f} s = {100 * overhead / total:.1f} % "
        "of the total (target <= 20 %)"
    )
    if factor_bytes:
        print(
            f"peak memory of the loop {peak / 2**20:.0f} MiB (with the floors "
            f"{with_floors / 2**20:.0f} MiB), factor of the last level "
            f"{factor_bytes / 2**20:.0f} MiB (8 bytes x {last_nnz} non-zeros, the loop's "
            f"ordering): ratio {peak / factor_bytes:.2f} (target <= 2.5)"
        )
    if memory and any(memory.values()):
        own = max(memory["analysis_peak"], memory["permanent"] + memory["factorization"])
        print(
            f"PARDISO's own memory on the last level (the loop's solver, KiB): analysis peak "
            f"iparm[14] = "
            f"{memory['analysis_peak']}, permanent iparm[15] = {memory['permanent']}, "
            f"factorization iparm[16] = {memory['factorization']}; its peak "
            f"{own / 2**10:.0f} MiB = {own * 1024 / factor_bytes:.2f} x the factor"
        )
        rest = level_peaks[-1] - own * 1024
        print(
            f"the last level's peak beyond PARDISO's own: {rest / 2**20:.0f} MiB = "
            f"{rest / factor_bytes:.2f} x the factor (the matrix and the triangle handed to "
            "PARDISO, mesh, contact data, vectors, the interpreter and its libraries)"
        )
    elif not factor_bytes:
        print(f"peak memory {peak / 2**20:.0f} MiB (factor size unknown for {backend})")
    print(f"history: {out / 'history.csv'}")
    if args.no_floor:
        print("no floors measured (--no-floor)")
        return
    shares = dict(phases, between=total - sum(phases.values()))
    print(
        "ratio_to_ordered_floor by phase (each phase's total over the sum of ordered floors; "
        "between: the loop's work outside the phases): "
        + " + ".join(f"{k} {v / ordered_floor:.3f}" for k, v in shares.items())
    )
    print(f"ratio_to_ordered_floor={total / ordered_floor:.3f}")
    print(f"ratio_to_floor={total / floor:.3f}")


if __name__ == "__main__":
    main()
