"""Benchmark: the linear solver of 3D elasticity, PARDISO against ``"amg"`` (and
``"petsc-gamg"`` where petsc4py loads), on the package's own path (docs/method.md, *Three
dimensions: the linear solver (measured)*).

A cantilever on the Kuhn mesh of the unit cube (``signorini.mesh.builders3d.box``, ``n``
cubes a side, ``3 (2 n + 1)³`` P2 unknowns): clamped on ``x0``, a body force, traction-free
elsewhere. Each system is assembled once (``signorini.contact.system.assemble``) and solved
by ``signorini.contact.solution.solve(..., assembled=...)`` with each solver **alternately**
(PARDISO, amg, PARDISO, amg, … ``--repeat`` times each), so that the machine's noise shows
as the spread of one solver's times on the same matrix. Printed per system: the free
unknowns ``ndof`` and all of them, ``n_dofs`` (what ``auto_solver`` chooses by), and per
solver its best time (set-up and solve: analysis, factorization or hierarchy, and the
solves of the active set loop: without contact one for PARDISO, for an iterative solver a
second to the tightened tolerance), its spread (max/min), the set-up and solve seconds of
that best run (``setup``: analysis and factorization or the AMG hierarchy; ``solve``: the
solves), the peak memory of the solve above the memory before it (``VmHWM`` after returning
freed memory to the system and resetting the mark through ``/proc/self/clear_refs``,
Linux), and an iterative solver's CG iterations (summed over its solves).

Graded meshes: the same cube refined by the package's 3D bisection (``refine_nvb``) towards
the vertex ``(0, 0, 0)`` or the edge ``x = y = 0``: each local level bisects the cells that
touch it, ``--levels`` times; the AMG iterations on them show whether they stay bounded.

``--solvers`` names the solvers (default: PARDISO up to ``--pardiso-up-to`` and amg);
``petsc-gamg`` needs the extra ``signorini[mpi]`` (a Python >= 3.12 venv, docs/parallel.md),
and its GAMG options come from PETSc's options database with the prefix ``signorini_gamg_``
(``PETSC_OPTIONS="-signorini_gamg_pc_gamg_threshold 0.02"``).

    python benchmarks/solve3d.py                          # the table of docs/method.md
    python benchmarks/solve3d.py --sizes 4 8 --graded 2 --levels 4 --repeat 1   # a quick look
    python benchmarks/solve3d.py --sizes 35 --graded 30 --towards edge --repeat 1 --solvers amg
    .venv-mpi/bin/python benchmarks/solve3d.py --solvers amg petsc-gamg --repeat 1
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import time

import numpy as np

from signorini.algebra.backends.selection import SOLVERS, available_backends
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.fem.material import Material
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb
from signorini.problem.conditions import Dirichlet, Neumann
from signorini.problem.problem import ContactProblem

MATERIAL = Material.from_young(1.0, 0.3)


def cantilever(mesh: Mesh) -> ContactProblem:
    """Clamped on ``x0``, the body force ``(0, 0.3, −1)``, traction-free elsewhere."""
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions["x0"] = Dirichlet((0.0, 0.0, 0.0))
    force = np.array([0.0, 0.3, -1.0])
    return ContactProblem(mesh, MATERIAL, conditions, body_force=lambda x: force)


def graded(n: int, towards: str, levels: int) -> Mesh:
    """``box(n, n, n)`` bisected ``levels`` times at the cells touching the vertex ``0`` or
    the edge ``x = y = 0`` (``towards`` = ``"vertex"`` or ``"edge"``)."""
    mesh = box(n, n, n)
    for _ in range(levels):
        x = mesh.points[mesh.cells]  # (m, 4, 3)
        on = np.abs(x[..., :2]).max(axis=-1) if towards == "edge" else np.abs(x).max(axis=-1)
        mesh = refine_nvb(mesh, (on < 1e-12).any(axis=1)).mesh
    return mesh


def _trim() -> None:
    """Return glibc's freed memory to the system (``malloc_trim``; nothing elsewhere)."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass


def _peak_kb() -> tuple[int, int]:
    """``VmRSS`` and ``VmHWM`` of this process, kB."""
    status = dict(line.split(":", 1) for line in open("/proc/self/status"))
    return int(status["VmRSS"].split()[0]), int(status["VmHWM"].split()[0])


def timed_solve(problem: ContactProblem, assembled, solver: str) -> dict[str, float]:
    """One solve (set-up included): its seconds (``total``, and ``setup``: analysis and
    factorization or hierarchy, ``solve``: the solves), its peak memory above the memory
    before it (``peak``, MB) and the CG iterations (``its``, 0 for a direct solver)."""
    _trim()  # freed memory back to the system, so that the peak is this solve's own
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")  # resets VmHWM to the current RSS
    except OSError:
        pass
    gc.collect()
    before = _peak_kb()[0]
    t0 = time.perf_counter()
    result = solve(problem, assembled.space.mesh, solver=SOLVERS[solver], assembled=assembled)
    seconds = time.perf_counter() - t0
    peak = (_peak_kb()[1] - before) / 1024.0
    times = result.report.times
    return {
        "total": seconds,
        "setup": times.get("analysis", 0.0) + times.get("factorization", 0.0),
        "solve": times.get("solve", 0.0),
        "peak": peak,
        "its": sum(result.report.linear_iterations),
    }


def compare(mesh: Mesh, solvers: list[str], repeat: int, label: str) -> None:
    """One row: the system of ``mesh`` solved by ``solvers`` alternately, ``repeat`` each."""
    problem = cantilever(mesh)
    assembled = assemble(problem, mesh)
    runs: dict[str, list[dict[str, float]]] = {s: [] for s in solvers}
    for _ in range(repeat):
        for s in solvers:
            runs[s].append(timed_solve(problem, assembled, s))
    cells = []
    for s in solvers:
        best = min(runs[s], key=lambda r: r["total"])
        spread = max(r["total"] for r in runs[s]) / best["total"]
        peak = max(r["peak"] for r in runs[s])
        cell = (
            f"{s} {best['total']:7.2f} s (×{spread:4.2f}) setup {best['setup']:6.2f} solve "
            f"{best['solve']:6.2f} {peak:7.0f} MB"
        )
        cells.append(cell + (f" {best['its']:3d} its" if best["its"] else ""))
    ndof, size = problem.free_ndof(assembled.space), assembled.space.n_dofs
    print(f"{label:>16s} {ndof:9d} {size:9d} {mesh.n_cells:9d}   " + "   ".join(cells), flush=True)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[8, 12, 16, 20, 28])
    parser.add_argument(
        "--pardiso-up-to", type=int, default=20, help="largest n PARDISO solves (default 20)"
    )
    parser.add_argument("--graded", type=int, nargs="*", default=[2, 4, 8])
    parser.add_argument("--levels", type=int, default=15)
    parser.add_argument("--towards", nargs="+", default=["vertex", "edge"])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument(
        "--solvers", nargs="+", help="the solvers (default: PARDISO up to --pardiso-up-to, amg)"
    )
    args = parser.parse_args(argv)
    direct = ["pardiso"] if "pardiso" in available_backends() else ["scipy"]
    head = f"{'mesh':>16s} {'ndof':>9s} {'n_dofs':>9s} {'cells':>9s}"
    print(head + "   solver best (max/min) setup solve peak [its]", flush=True)
    for n in args.sizes:
        solvers = args.solvers or (direct if n <= args.pardiso_up_to else []) + ["amg"]
        repeat = args.repeat if n <= args.pardiso_up_to else 1
        compare(box(n, n, n), solvers, repeat, f"box {n}")
    for towards in args.towards:
        for n in args.graded:
            mesh = graded(n, towards, args.levels)
            compare(mesh, args.solvers or ["amg"], 1, f"{towards} {n}+{args.levels}")


if __name__ == "__main__":
    main()
