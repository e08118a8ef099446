"""Measure the 3D linear solvers on P2 elasticity: ``PYTHONPATH=src python studies/amg3d/run.py``.

The cube [0, 1]³ clamped on ``x = 0`` under the body force (0, 0, −1), E = 1, uniform and
graded towards a corner (γ = 3, :mod:`amg3d.system`), ν = 0.3 and 0.45. Per solver, one
row: unknowns, set-up seconds (AMG hierarchy; PARDISO analysis + factorization), CG
iterations from zero to the relative residual 1e-8 and 1e-10, the solve's seconds (to
1e-10), the true residual, operator and grid complexity (PARDISO: the factor's fill
nnz(L)/nnz(tril A)), the hierarchy's levels and the peak memory of set-up + solve (traced
NumPy allocations; PARDISO: its own report).

Then the reuse across active sets: the z-DOFs of the face z = 0 with x > 1/2 eliminated
(rows and columns zeroed, the diagonal kept, as the active set methods do), solved (a) with a
new hierarchy of the eliminated matrix, (b) with the hierarchy of the unconstrained matrix,
(c) with the hierarchy of the previous active set (x > 0.45), both as
``x = P M⁻¹ P r + D⁻¹ (I − P) r`` (P the projection on the free DOFs).

Options: ``--sizes 7,11,17,24,35`` (cubes per direction), ``--big 24`` (from this n on
only ``sa`` and ``sa-trans``), ``--huge 35`` (from this n on only ``sa``), ``--pardiso-max
130000`` unknowns, ``--jacobi-max 40000``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pyamg
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from amg3d.solvers import measure_iterative, measure_pardiso, pcg  # noqa: E402
from amg3d.system import clamped_system, rigid_modes  # noqa: E402

AMG = ("sa", "sa-trans", "sa-theta", "sa-cheb", "rootnode")
COLUMNS = "mesh nu N solver setup it8 it10 solve true_res op_cx grid_cx levels peak_MB".split()


def line(row: dict) -> str:
    """One table row, fixed width."""
    cells = []
    for key in COLUMNS:
        value = row[key]
        if isinstance(value, float):
            text = f"{value:.1e}" if key == "true_res" else f"{value:.2f}"
        else:
            text = str(value)
        cells.append(f"{text:>9}")
    return " ".join(cells)


def _eliminated(K: sp.csr_matrix, free: np.ndarray) -> sp.csr_matrix:
    """``K`` with the rows and columns off ``free`` zeroed, the diagonal kept."""
    P = sp.diags(free.astype(float))
    return (P @ K @ P + sp.diags(np.where(free, 0.0, K.diagonal()))).tocsr()


def _projected(ml: pyamg.MultilevelSolver, free: np.ndarray, diagonal: np.ndarray):
    """``r ↦ P M⁻¹ P r + D⁻¹ (I − P) r`` with ``ml``'s V-cycle as ``M⁻¹``."""
    M = ml.aspreconditioner()
    inverse = np.where(free, 0.0, 1 / diagonal)
    return lambda r: np.where(free, M(np.where(free, r, 0.0)), 0.0) + inverse * r


def reuse(n: int, gamma: float, nu: float) -> str:
    """CG iterations to 1e-8 on an eliminated system (an active set): with a new hierarchy,
    with the unconstrained matrix's, and with the hierarchy of the previous active set."""
    system = clamped_system(n, gamma, nu)
    K, F, points = system.K.tocsr(), system.F, system.points
    modes = rigid_modes(points)
    on_face = np.isclose(points[:, 2], 0)

    def free_of(x0: float) -> np.ndarray:
        free = np.ones(K.shape[0], dtype=bool)
        free[np.flatnonzero(on_face & (points[:, 0] > x0)) * 3 + 2] = False
        return free

    previous, free = free_of(0.45), free_of(0.5)
    A = _eliminated(K, free)
    b = np.where(free, F, 0.0)
    t0 = time.perf_counter()
    ml = pyamg.smoothed_aggregation_solver(A.tobsr(blocksize=(3, 3)), B=modes * free[:, None])
    setup = time.perf_counter() - t0
    counts = {"new": pcg(A, b, ml.aspreconditioner(), 1e-8, 500)[1].size - 1}
    for name, other in (("unconstrained", np.ones_like(free)), ("previous", previous)):
        B = _eliminated(K, other).tobsr(blocksize=(3, 3))
        old = pyamg.smoothed_aggregation_solver(B, B=modes * other[:, None])
        counts[name] = pcg(A, b, _projected(old, free, K.diagonal()), 1e-8, 500)[1].size - 1
    changed = int((free != previous).sum())
    return (
        f"reuse n={n} N={K.shape[0]} mesh={gamma:g} nu={nu} eliminated={(~free).sum()} "
        f"(previous differs in {changed}): set-up {setup:.2f} s; iterations to 1e-8 "
        + ", ".join(f"{k} {v}" for k, v in counts.items())
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="7,11,17,24,35")
    parser.add_argument("--big", type=int, default=24)
    parser.add_argument("--huge", type=int, default=35)
    parser.add_argument("--pardiso-max", type=int, default=130_000)
    parser.add_argument("--jacobi-max", type=int, default=40_000)
    parser.add_argument("--nus", default="0.3,0.45")
    parser.add_argument("--gammas", default="1,3")
    parser.add_argument("--no-reuse", action="store_true")
    args = parser.parse_args()
    print(" ".join(f"{c:>9}" for c in COLUMNS), flush=True)
    for n in map(int, args.sizes.split(",")):
        for gamma in map(float, args.gammas.split(",")):
            for nu in map(float, args.nus.split(",")):
                t0 = time.perf_counter()
                system = clamped_system(n, gamma, nu)
                N = system.K.shape[0]
                head = {"mesh": "uniform" if gamma == 1 else f"graded{gamma:g}", "nu": nu, "N": N}
                print(
                    f"# n={n} N={N} nnz={system.K.nnz} h_max/h_min={system.h_ratio:.0f} "
                    f"assembly {time.perf_counter() - t0:.1f} s",
                    flush=True,
                )
                modes = rigid_modes(system.points)
                variants = AMG if n < args.big else ("sa", "sa-trans")
                variants = variants if n < args.huge else ("sa",)
                if N <= args.jacobi_max:
                    variants = (*variants, "jacobi")
                for variant in variants:
                    row = measure_iterative(system.K, system.F, modes, variant)
                    print(line(head | row), flush=True)
                if N <= args.pardiso_max:
                    print(line(head | measure_pardiso(system.K, system.F)), flush=True)
                del system
    if not args.no_reuse:
        for gamma in map(float, args.gammas.split(",")):
            print(reuse(11, gamma, 0.3), flush=True)


if __name__ == "__main__":
    main()
