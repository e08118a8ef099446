"""Benchmark: the vertex-graph ordering of the unknowns against PARDISO's own analysis.

On Example 6.2's adaptive mesh within the budget (made in a child process, as in
``cold.py``) and on a uniform mesh of the unit square with about as many unknowns (the
example's material and parts; a random load where the example loads none), one complete
direct solve of the stiffness matrix (Dirichlet DOFs eliminated in place, as PDAS
factorizes it) twice per ordering, the faster kept:

- **own**: PARDISO's analysis with its parallel METIS on the matrix graph (the floor of
  ``adaptive.py``);
- **vertex graph**: :func:`signorini.contact.ordering.dof_ordering` (METIS on the mesh's
  vertex graph, extended to the P2 nodes; its time counted) handed to PARDISO as its user
  permutation;
- **in blocks**: the same ordering, the matrix handed over in 2 x 2 node blocks (PARDISO's
  BSR form, what the adaptive loop does; docs/method.md, *Block Cholesky*). The two rows
  above are in CSR form (``PardisoSolver(blocks=False)``).

It prints per mesh the ordering, analysis, factorization and solve times, the factor's
non-zeros and PARDISO's operation count, how far the two solutions are apart (both solves
must have residuals below 1e-12 relative; they differ by round-off times the condition
number of the graded mesh's matrix: 9e-11 at 1.2 M unknowns), and as its last line
``ordering_ratio=X``: the complete solve with the vertex-graph ordering over the one with
PARDISO's own, on the adaptive mesh; before it ``blocks_ratio=X``: the complete solve in
blocks over the one in CSR form, both with the vertex-graph ordering, on the adaptive mesh.
PARDISO's own memory (``iparm[15] + iparm[16]``, its peak) is printed for each.

Measured 2026-11-26 (2 cores, the faster of two alternating runs each): at 1 230 378
unknowns of Example 6.2's adaptive mesh the complete solve in blocks took 0.853 times as long
as in CSR form (analysis 0.558, factorization 0.977, solve 1.164), with PARDISO's memory
0.742 times as large and the solutions 1.7e-15 apart; on the uniform mesh of 1 232 450
unknowns 1.019 (analysis 0.632, factorization 1.207, solve 0.945; memory 0.804).

    python benchmarks/ordering.py                     # just above 10^6 unknowns
    python benchmarks/ordering.py --max-ndof 200000
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from cold import load_mesh

from signorini import example_6_2
from signorini.algebra import SymmetricEliminator
from signorini.algebra.backends.pardiso import PardisoSolver
from signorini.contact import assemble
from signorini.contact.ordering import dof_ordering
from signorini.mesh.builders import rectangle
from signorini.runtime import retain_freed_memory


def complete_solve(K, keep, b, space, ordered: bool, blocks: bool) -> dict[str, float]:
    """One ordering (if ``ordered``) + analysis + factorization + solve with a fresh solver,
    in 2 x 2 blocks or in CSR form."""
    t0 = time.perf_counter()
    ordering = dof_ordering(space) if ordered else None
    t_order = time.perf_counter() - t0
    with PardisoSolver(check_symmetry=False, ordering=ordering, blocks=blocks) as solver:
        solver.factorize(K, keep=keep)
        x = solver.solve(b)
        total = time.perf_counter() - t0
        return {
            "ordering": t_order,
            "analysis": solver.time_analysis,
            "factorization": solver.time_factorization,
            "solve": solver.time_solve,
            "total": total,
            "nnz": solver.factor_nnz,
            "mflop": solver.factor_mflop,
            "memory": (solver.memory_kib["permanent"] + solver.memory_kib["factorization"]) / 1024,
            "x": x,
        }


def compare(name: str, problem, mesh) -> tuple[float, float]:
    a = assemble(problem, mesh)
    fixed = np.zeros(a.K.shape[0], dtype=bool)
    fixed[a.dirichlet] = True
    eliminator = SymmetricEliminator(a.K)
    keep = eliminator.keep_mask(fixed)
    values = np.zeros(a.K.shape[0])
    values[a.dirichlet] = a.dirichlet_values
    b = eliminator.rhs(a.K, a.F, fixed, values)
    if not np.abs(b).max() > 0:  # a mesh without the example's loaded parts: any load
        b = np.random.default_rng(0).standard_normal(b.size)
    A, _ = eliminator.apply(a.K, b, fixed, values)
    runs = {}
    variants = {"own": (False, False), "vertex graph": (True, False), "in blocks": (True, True)}
    for _ in range(2):  # alternating, the faster of two kept
        for label, (ordered, blocks) in variants.items():
            run = complete_solve(a.K, keep, b, a.space, ordered, blocks)
            if label not in runs or run["total"] < runs[label]["total"]:
                runs[label] = run
    print(f"{name}: {a.K.shape[0]} unknowns ({problem.free_ndof(mesh)} free), {mesh.n_cells} cells")
    for label, r in runs.items():
        print(
            f"  {label:>12s}: ordering {r['ordering']:.3f} s, analysis {r['analysis']:.3f} s, "
            f"factorization {r['factorization']:.3f} s, solve {r['solve']:.3f} s, complete "
            f"{r['total']:.3f} s; factor {r['nnz'] / 1e6:.2f} M non-zeros, {r['mflop']} Mflop, "
            f"PARDISO's memory {r['memory']:.0f} MiB"
        )
    own, ours, blocks = runs["own"], runs["vertex graph"], runs["in blocks"]
    dx = np.abs(ours["x"] - own["x"]).max() / np.abs(own["x"]).max()
    residual = max(np.abs(b - A @ r["x"]).max() for r in runs.values()) / np.abs(b).max()
    ratio = ours["total"] / own["total"]
    print(
        f"  vertex graph / own: complete solve {ratio:.3f}, factor non-zeros "
        f"{ours['nnz'] / own['nnz']:.3f}, Mflop {ours['mflop'] / own['mflop']:.3f}; "
        f"solutions agree to {dx:.1e} (relative; residuals <= {residual:.1e})"
    )
    in_blocks = blocks["total"] / ours["total"]
    db = np.abs(blocks["x"] - ours["x"]).max() / np.abs(ours["x"]).max()
    print(
        f"  in blocks / CSR (vertex graph): complete solve {in_blocks:.3f}, analysis "
        f"{blocks['analysis'] / ours['analysis']:.3f}, factorization "
        f"{blocks['factorization'] / ours['factorization']:.3f}, solve "
        f"{blocks['solve'] / ours['solve']:.3f}, PARDISO's memory "
        f"{blocks['memory'] / ours['memory']:.3f}; solutions agree to {db:.1e}"
    )
    # both are backward stable solves; they differ by round-off times the condition number
    if not residual <= 1e-12:
        raise SystemExit("a solve does not satisfy its system")
    return ratio, in_blocks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-ndof", type=int, default=1_300_000)
    parser.add_argument("--theta", type=float, default=0.4)
    args = parser.parse_args()
    retain_freed_memory()
    path = Path(tempfile.mkdtemp(prefix="signorini-ordering-")) / "mesh.npz"
    command = [sys.executable, str(Path(__file__).with_name("cold.py"))]
    command += ["--max-ndof", str(args.max_ndof), "--theta", str(args.theta)]
    subprocess.run([*command, "--make-mesh", str(path)], check=True)
    problem = example_6_2()
    mesh = load_mesh(path)
    nx = max(int(round(np.sqrt(problem.free_ndof(mesh) / 8))), 2)
    compare(f"uniform mesh {nx} x {nx}", problem, rectangle(nx=nx, ny=nx))
    ratio, in_blocks = compare("Example 6.2, adaptive mesh", problem, mesh)
    print(f"blocks_ratio={in_blocks:.3f}")
    print(f"ordering_ratio={ratio:.3f}")


if __name__ == "__main__":
    main()
