"""Benchmark: throughput of each phase of the adaptive loop against its limit, as a table.

Runs Example 6.2 adaptively (θ = 0.4) and, at the first level with at least each of
``--sizes`` unknowns, reports the unknowns per second of the phases as the loop ran them:
refinement (unknowns of the refined mesh per second of NVB refinement with the prolongation
of the warm start), assembly and estimator (unknowns of the level per second). For the
same level's stiffness matrix (Dirichlet DOFs eliminated) it factorizes with PARDISO and
divides the operation count PARDISO reports (``iparm[18]``, Mflop) by the time of the
numerical factorization alone (the fastest of ``--repeat`` refactorizations, the analysis
done before), and compares that rate with the machine's dense peak: the best of
``--repeat`` products of two ``--blas-n`` × ``--blas-n`` float64 matrices with NumPy
(2 n³ flop each). The result is a Markdown table; benchmarks/README.md (*Throughput of each
phase*) shows two runs' (2 cores shared with other jobs: at 10⁶ unknowns refinement, assembly
and estimator 1.9–2.6 million unknowns per second, the factorization 32.7 GFlop/s = 27 % of the
dense peak).

    python benchmarks/throughput.py                     # levels at 1e5 and 1e6 unknowns
    python benchmarks/throughput.py --sizes 200000 --blas-n 2000

With ``--dim 3`` it runs ``--problem`` (``example-6.2-3d`` or ``hertz-3d``) adaptively with
the loop's own solver and prints, at the first level with at least each of ``--sizes``
unknowns, the refinement, assembly and estimator rates in unknowns per second per core: the
wall-clock rate divided by the cores the level kept busy (its process CPU time over its wall
time), no factorization columns.

    python benchmarks/throughput.py --dim 3 --sizes 50000 200000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from adaptive import reduced_system  # benchmarks/adaptive.py: the floor's system

from signorini import adaptive, example_6_2
from signorini.algebra.backends.pardiso import PardisoSolver, pardiso_solver
from signorini.runtime import retain_freed_memory


def dense_peak_gflops(n: int, repeat: int) -> float:
    """GFlop/s of the fastest of ``repeat`` products of two n x n float64 matrices."""
    rng = np.random.default_rng(0)
    a, b = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        a @ b
        best = min(best, time.perf_counter() - t0)
    return 2.0 * n**3 / best / 1e9


def factorization_rate(problem, mesh, repeat: int) -> tuple[float, float, float]:
    """PARDISO's operation count of the level's factorization (Mflop), the fastest numerical
    factorization (seconds) and its rate (GFlop/s). In CSR form (``blocks=False``): in 2 x 2
    blocks PARDISO counts a block's product as one operation, and rounds the count to whole
    millions, which is 0 on the first levels."""
    K, _, _ = reduced_system(problem, mesh)
    with PardisoSolver(check_symmetry=False, blocks=False) as solver:
        solver.factorize(K)  # analysis and a first factorization
        best = np.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            solver.factorize(K)  # same pattern: the numerical factorization only
            best = min(best, time.perf_counter() - t0)
        mflop = float(solver.factor_mflop)
    return mflop, best, mflop / 1e3 / best


def measure(sizes: list[int], theta: float, repeat: int) -> list[dict[str, float]]:
    """One row per size: the phases' rates at the first adaptive level with ≥ size unknowns."""
    problem = example_6_2()
    targets = sorted(sizes)
    rows: list[dict[str, float]] = []
    pending: dict[str, float] | None = None  # a chosen level waiting for the next one's size
    generator = adaptive(problem, theta=theta, max_ndof=np.inf, solver=pardiso_solver)
    for level in generator:
        r = level.record
        if pending is not None:
            pending["refine"] = r.ndof / pending.pop("t_refine")
            rows.append(pending)
            pending = None
            if len(rows) == len(sizes):
                break
        if r.ndof < targets[len(rows)]:
            continue
        mflop, seconds, gflops = factorization_rate(problem, level.result.mesh, repeat)
        pending = {
            "ndof": r.ndof,
            "t_refine": r.t_refine,
            "assemble": r.ndof / r.t_assemble,
            "estimate": r.ndof / r.t_estimate,
            "mflop": mflop,
            "factorize": seconds,
            "gflops": gflops,
        }
    generator.close()
    return rows


def measure_3d(name: str, sizes: list[int], theta: float) -> list[dict[str, float]]:
    """One row per size for the 3D problem ``name``: the phases' rates per core at the first
    adaptive level with ≥ size unknowns (refinement: the next level's unknowns per second of
    the refinement that made them)."""
    from signorini.examples import EXAMPLES

    targets = sorted(sizes)
    rows: list[dict[str, float]] = []
    pending: dict[str, float] | None = None
    generator = adaptive(EXAMPLES[name].problem(), theta=theta, max_ndof=np.inf)
    while True:
        wall, cpu = time.perf_counter(), time.process_time()
        level = next(generator, None)
        if level is None:
            break
        r = level.record
        cores = max((time.process_time() - cpu) / (time.perf_counter() - wall), 1.0)
        if pending is not None:
            pending["refine"] = r.ndof / (pending.pop("t_refine") * cores)
            rows.append(pending)
            pending = None
            if len(rows) == len(sizes):
                break
        if r.ndof < targets[len(rows)]:
            continue
        pending = {
            "ndof": r.ndof,
            "cores": cores,
            "t_refine": r.t_refine,
            "assemble": r.ndof / (r.t_assemble * cores),
            "estimate": r.ndof / (r.t_estimate * cores),
        }
    generator.close()
    return rows


def table_3d(rows: list[dict[str, float]]) -> str:
    """The Markdown table of :func:`measure_3d`'s rows."""
    lines = [
        "| unknowns | cores busy | refinement (unknowns/s/core) | assembly (unknowns/s/core) "
        "| estimator (unknowns/s/core) |",
        "|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['ndof']:,} | {row['cores']:.2f} | {row['refine']:.3g} "
            f"| {row['assemble']:.3g} | {row['estimate']:.3g} |".replace(",", " ")
        )
    return "\n".join(lines)


def table(rows: list[dict[str, float]], peak: float) -> str:
    """The Markdown table of :func:`measure`'s rows against the dense peak (GFlop/s)."""
    lines = [
        "| unknowns | refinement (unknowns/s) | assembly (unknowns/s) | estimator (unknowns/s) "
        "| factorization (Gflop) | factorization (s) | factorization (GFlop/s) | of dense peak |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['ndof']:,} | {row['refine']:.3g} | {row['assemble']:.3g} "
            f"| {row['estimate']:.3g} | {row['mflop'] / 1e3:.3g} | {row['factorize']:.3g} "
            f"| {row['gflops']:.3g} | {100 * row['gflops'] / peak:.2g} % |".replace(",", " ")
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--theta", type=float, default=0.4)
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs")
    parser.add_argument("--blas-n", type=int, default=4000, help="order of the dense product")
    parser.add_argument("--dim", type=int, choices=(2, 3), default=2)
    parser.add_argument(
        "--problem", choices=("example-6.2-3d", "hertz-3d"), default="example-6.2-3d",
        help="the 3D problem (with --dim 3)",
    )  # fmt: skip
    args = parser.parse_args()
    if min(args.sizes) < 1 or args.repeat < 1 or args.blas_n < 1:
        parser.error("--sizes, --repeat and --blas-n must be positive")
    retain_freed_memory()
    if args.dim == 3:
        print(table_3d(measure_3d(args.problem, args.sizes, args.theta)))
        return
    peak = dense_peak_gflops(args.blas_n, args.repeat)
    rows = measure(args.sizes, args.theta, args.repeat)
    print(table(rows, peak))
    print()
    print(
        f"dense peak: {peak:.4g} GFlop/s (NumPy float64 product of order {args.blas_n}, "
        f"best of {args.repeat}); factorization: MKL PARDISO, numerical phase only"
    )


if __name__ == "__main__":
    main()
