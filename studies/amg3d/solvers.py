"""The solvers measured on the clamped cube: one preconditioned CG for all, the preconditioners
(pyamg's smoothed aggregation and root-node AMG, Jacobi) and PARDISO as the exact reference.

Every iterative solver runs the same CG (:func:`pcg`) from zero, stopping on the recursive
residual ``‖r_k‖₂ ≤ rtol ‖b‖₂``, so that the iteration counts compare preconditioners only;
the true residual of the final iterate is reported beside.
"""

from __future__ import annotations

import time
import tracemalloc
from collections.abc import Callable

import numpy as np
import pyamg
import scipy.sparse as sp

Apply = Callable[[np.ndarray], np.ndarray]


def pcg(
    A: sp.spmatrix, b: np.ndarray, precondition: Apply, rtol: float, max_it: int
) -> tuple[np.ndarray, np.ndarray]:
    """Preconditioned CG from zero; the solution and the relative residuals ‖r_k‖/‖b‖,
    shape (k + 1,), of every iteration (the recursive residual)."""
    x = np.zeros_like(b)
    r = b.copy()
    z = precondition(r)
    p = z.copy()
    rz = r @ z
    norm_b = np.linalg.norm(b)
    history = [1.0]
    for _ in range(max_it):  # CG iterations
        q = A @ p
        alpha = rz / (p @ q)
        x += alpha * p
        r -= alpha * q
        history.append(np.linalg.norm(r) / norm_b)
        if history[-1] <= rtol:
            break
        z = precondition(r)
        rz, rz_old = r @ z, rz
        p *= rz / rz_old
        p += z
    return x, np.array(history)


def amg_hierarchy(K: sp.bsr_matrix, variant: str, modes: np.ndarray) -> pyamg.MultilevelSolver:
    """The pyamg hierarchy of a variant: ``sa`` smoothed aggregation (pyamg's defaults:
    symmetric strength θ = 0, standard aggregation, Jacobi-smoothed prolongator, symmetric
    Gauss–Seidel smoothing), ``sa-trans`` the same with the three translations only,
    ``sa-theta`` with strength threshold θ = 0.02, ``sa-cheb`` with Chebyshev smoothing,
    ``rootnode`` pyamg's root-node AMG; all but ``sa-trans`` with the six rigid modes."""
    if variant == "sa-trans":
        return pyamg.smoothed_aggregation_solver(K, B=modes[:, :3])
    if variant == "sa":
        return pyamg.smoothed_aggregation_solver(K, B=modes)
    if variant == "sa-theta":
        return pyamg.smoothed_aggregation_solver(
            K, B=modes, strength=("symmetric", {"theta": 0.02})
        )
    if variant == "sa-cheb":
        smoother = ("chebyshev", {"degree": 2})
        return pyamg.smoothed_aggregation_solver(
            K, B=modes, presmoother=smoother, postsmoother=smoother
        )
    if variant == "rootnode":
        return pyamg.rootnode_solver(K, B=modes)
    raise ValueError(f"unknown AMG variant {variant!r}")


def measure_iterative(
    K: sp.bsr_matrix, F: np.ndarray, modes: np.ndarray, variant: str, max_it: int = 3000
) -> dict:
    """Set-up and CG to 1e-10 with one preconditioner; its iterations to 1e-8 and 1e-10."""
    tracemalloc.start()
    t0 = time.perf_counter()
    row: dict = {"solver": variant}
    A = K.tocsr() if variant == "jacobi" else K
    if variant == "jacobi":
        inverse = 1 / K.diagonal()

        def precondition(r: np.ndarray) -> np.ndarray:
            return inverse * r

        row["op_cx"] = row["grid_cx"] = 1.0
        row["levels"] = 1
    else:
        ml = amg_hierarchy(K, variant, modes)
        precondition = ml.aspreconditioner(cycle="V")
        row["op_cx"] = ml.operator_complexity()
        row["grid_cx"] = ml.grid_complexity()
        row["levels"] = len(ml.levels)
    t1 = time.perf_counter()
    x, history = pcg(A, F, precondition, 1e-10, max_it)
    t2 = time.perf_counter()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    reached = np.flatnonzero(history <= 1e-8)
    row["setup"] = t1 - t0
    row["it8"] = int(reached[0]) if reached.size else -1
    row["it10"] = history.size - 1 if history[-1] <= 1e-10 else -1
    row["solve"] = t2 - t1
    row["true_res"] = float(np.linalg.norm(F - A @ x) / np.linalg.norm(F))
    row["peak_MB"] = peak / 2**20
    return row


def measure_pardiso(K: sp.bsr_matrix, F: np.ndarray) -> dict:
    """PARDISO's Cholesky (the package's backend): analysis + factorization, one solve,
    its own peak memory report."""
    from signorini.algebra.backends.pardiso import PardisoSolver

    A = K.tocsr()
    t0 = time.perf_counter()
    solver = PardisoSolver(A, check_symmetry=False)
    t1 = time.perf_counter()
    x = solver.solve(F)
    t2 = time.perf_counter()
    memory = solver.memory_kib
    row = {
        "solver": "pardiso",
        "setup": t1 - t0,
        "it8": 0,
        "it10": 0,
        "solve": t2 - t1,
        "true_res": float(np.linalg.norm(F - A @ x) / np.linalg.norm(F)),
        "op_cx": solver.factor_nnz / ((A.nnz + A.shape[0]) / 2),  # fill of the factor
        "grid_cx": np.nan,
        "levels": 0,
        "peak_MB": max(memory["analysis_peak"], memory["permanent"] + memory["factorization"])
        / 1024,
    }
    solver.close()
    return row
