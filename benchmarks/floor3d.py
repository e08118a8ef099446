"""The 3D floor of ``benchmarks/adaptive.py --problem example-6.2-3d`` (or ``hertz-3d``).

Per level of the adaptive loop (θ as given, the loop's own solver, ``"auto"``: CG + AMG from
:data:`~signorini.algebra.backends.selection.AMG_FROM_3D` unknowns) it prints the unknowns,
the linear solves and CG iterations of the loop, each phase's time, the level's total, the
*floor* — one complete iterative solve of the level's final system (its stiffness matrix with
the Dirichlet DOFs and the final active set eliminated): a fresh pyamg hierarchy with the
rigid modes, then CG from zero to the loop's tolerance :data:`~.amg.RTOL`, measured in the
same run and not counted in the loop's total — its CG iterations, the ratio, and the level's
peak resident memory (per unknown, and over the bytes of the matrix: 12 per non-zero). At
the end each phase's share of the ratio (the shares sum to it), ``largest_ndof=`` and
``ratio_to_floor=``.

    python benchmarks/adaptive.py --problem example-6.2-3d --max-ndof 200000
    python benchmarks/adaptive.py --problem hertz-3d --max-ndof 200000
"""

from __future__ import annotations

import time

import numpy as np

from signorini.algebra import SOLVERS, eliminate_symmetric, make_solver
from signorini.algebra.backends.amg import RTOL
from signorini.contact import assemble
from signorini.contact.rigid_modes import system_rigid_modes
from signorini.examples import EXAMPLES
from signorini.loop import adaptive

PHASES = ("assemble", "pdas", "estimate", "mark", "refine")


def final_system(problem, mesh, result):
    """``(K, b, modes)``: the level's stiffness and load with the Dirichlet DOFs and the
    final active set's DOFs eliminated (at their values), and the rigid modes."""
    a = assemble(problem, mesh)
    n = a.K.shape[0]
    fixed = np.zeros(n, dtype=bool)
    fixed[a.dirichlet] = True
    values = np.zeros(n)
    values[a.dirichlet] = a.dirichlet_values
    cs = a.contact
    if cs.size and result.active is not None and result.active.size:
        dofs = np.asarray(cs.constrained_dofs)[result.active]
        fixed[dofs] = True
        values[dofs] = np.asarray(cs.gap)[result.active]
    K, b = eliminate_symmetric(a.K, a.F, fixed, values)
    return K, b, system_rigid_modes(a)


def floor_seconds(problem, mesh, result) -> tuple[float, int, int]:
    """One AMG set-up + CG from zero to :data:`RTOL` on the level's final system, with a
    fresh solver: seconds, CG iterations, the matrix's non-zeros."""
    K, b, modes = final_system(problem, mesh, result)
    with make_solver(
        SOLVERS["amg"], check_symmetry=False, rigid_modes=lambda: modes, dimension=3,
        size=K.shape[0],
    ) as solver:  # fmt: skip
        t0 = time.perf_counter()
        solver.factorize(K)
        solver.solve(b)
        seconds = time.perf_counter() - t0
        iterations = int(sum(getattr(solver, "iterations", [])))
    return seconds, iterations, int(K.nnz)


def run(name: str, theta: float, max_ndof: int, level_peak, reset_peak) -> None:
    """The 3D table and summary (``level_peak``, ``reset_peak``: adaptive.py's readers of
    the resident set's high-water mark)."""
    problem = EXAMPLES[name].problem()
    cols = ("level", "ndof", "solves", "cg_its") + PHASES
    cols += ("total", "floor", "fl_its", "ratio", "peakMiB", "B/ndof", "peak/A")
    print(" ".join(f"{c:>9s}" for c in cols))
    total = floor = 0.0
    phases = dict.fromkeys(PHASES, 0.0)
    largest = 0
    generator = adaptive(problem, theta=theta, max_ndof=max_ndof)
    while True:
        resettable = reset_peak()
        t0 = time.perf_counter()
        level = next(generator, None)
        if level is None:
            break
        r = level.record
        level_total = time.perf_counter() - t0
        peak = level_peak(resettable)
        level_floor, floor_its, nnz = floor_seconds(problem, level.result.mesh, level.result)
        del level
        total, floor, largest = total + level_total, floor + level_floor, max(largest, r.ndof)
        times = (r.t_assemble, r.t_solve, r.t_estimate, r.t_mark, r.t_refine)
        for key, value in zip(PHASES, times, strict=True):
            phases[key] += value
        its = int(r.extra.get("linear_iterations", 0)) if isinstance(r.extra, dict) else 0
        values = (r.level, r.ndof, r.n_solves, its) + times
        values += (level_total, level_floor, floor_its, level_total / level_floor)
        values += (f"{peak / 2**20:.0f}", f"{peak / r.ndof:.0f}", f"{peak / (12 * nnz):.2f}")
        print(
            " ".join(f"{v:9.3f}" if isinstance(v, float) else f"{v!s:>9s}" for v in values),
            flush=True,
        )
    print()
    print(f"total time {total:.2f} s, sum of floors {floor:.2f} s (AMG set-up + CG to {RTOL:g})")
    shares = dict(phases, between=total - sum(phases.values()))
    print(
        "ratio_to_floor by phase (each phase's total over the sum of floors; between: the "
        "loop's work outside the phases): "
        + " + ".join(f"{k} {v / floor:.3f}" for k, v in shares.items())
    )
    print(f"largest_ndof={largest}")
    print(f"ratio_to_floor={total / floor:.3f}")
