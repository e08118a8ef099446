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
  permutation.

It prints per mesh the ordering, analysis, factorization and solve times, the factor's
non-zeros and PARDISO's operation count, how far the two solutions are apart (both solves
must have residuals below 1e-12 relative; they differ by round-off times the condition
number of the graded mesh's matrix: 9e-11 at 1.2 M unknowns), and as its last line
``ordering_ratio=X``: the complete solve with the vertex-graph ordering over the one with
PARDISO's own, on the adaptive mesh.

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
from signorini.algebra.pardiso import PardisoSolver
from signorini.contact import assemble
from signorini.contact.ordering import dof_ordering
from signorini.mesh.builders import rectangle
from signorini.runtime import retain_freed_memory


def complete_solve(K, keep, b, space, ordered: bool) -> dict[str, float]:
    """One ordering (if ``ordered``) + analysis + factorization + solve with a fresh solver."""
    t0 = time.perf_counter()
    ordering = dof_ordering(space) if ordered else None
    t_order = time.perf_counter() - t0
    with PardisoSolver(check_symmetry=False, ordering=ordering) as solver:
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
            "x": x,
        }


def compare(name: str, problem, mesh) -> float:
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
    for label, ordered in (("own", False), ("vertex graph", True)):
        first, second = (complete_solve(a.K, keep, b, a.space, ordered) for _ in range(2))
        runs[label] = min(first, second, key=lambda r: r["total"])
    print(f"{name}: {a.K.shape[0]} unknowns ({problem.free_ndof(mesh)} free), {mesh.n_cells} cells")
    for label, r in runs.items():
        print(
            f"  {label:>12s}: ordering {r['ordering']:.3f} s, analysis {r['analysis']:.3f} s, "
            f"factorization {r['factorization']:.3f} s, solve {r['solve']:.3f} s, complete "
            f"{r['total']:.3f} s; factor {r['nnz'] / 1e6:.2f} M non-zeros, {r['mflop']} Mflop"
        )
    own, ours = runs["own"], runs["vertex graph"]
    dx = np.abs(ours["x"] - own["x"]).max() / np.abs(own["x"]).max()
    residual = max(np.abs(b - A @ r["x"]).max() for r in runs.values()) / np.abs(b).max()
    ratio = ours["total"] / own["total"]
    print(
        f"  vertex graph / own: complete solve {ratio:.3f}, factor non-zeros "
        f"{ours['nnz'] / own['nnz']:.3f}, Mflop {ours['mflop'] / own['mflop']:.3f}; "
        f"solutions agree to {dx:.1e} (relative; residuals <= {residual:.1e})"
    )
    # both are backward stable solves; they differ by round-off times the condition number
    if not residual <= 1e-12:
        raise SystemExit("a solve does not satisfy its system")
    return ratio


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
    ratio = compare("Example 6.2, adaptive mesh", problem, mesh)
    print(f"ordering_ratio={ratio:.3f}")


if __name__ == "__main__":
    main()
