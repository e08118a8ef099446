"""Benchmark: the frictional contact solver against the frictionless one, and its LU backends.

The system is a block ``(0, 2) × (0, 1)`` (E = 1, ν = 0.3, P2 on ``nx × nx/2`` union-jack
squares) pushed down by 0.02 and sideways by 0.01 at its top onto the obstacle
``ψ(x) = 0.04 (x − 1)²`` below its bottom: contact in the middle, open ends, stick and slip
zones (the same problem as ``tests/contact_problems.pressed_block``). For each backend it
times ``solve_pdas`` (frictionless) and ``solve_friction`` for classical and contact-only
Tresca (bounds 0.1 and 0.2 times the largest frictionless Λ_n) and Coulomb (F = 0.2, 0.5),
alternating within one process, the minimum over ``--repeat`` rounds, and prints the
iterations, the node states and the time ratio friction / frictionless. Then the Coulomb
systems (F = 0.5) with SuperLU, PARDISO ``mtype = 11`` and PARDISO without weighted matching.

Run: ``python benchmarks/friction_solver.py --nx 160`` (103 362 unknowns). Figures in
docs/method.md, *Friction: the algebraic problem and its solver*.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini.algebra import (
    SOLVERS,
    available_backends,
    check_friction,
    make_solver,
    solve_friction,
    solve_pdas,
    superlu_solver,
)
from signorini.algebra.backends.pardiso_lu import PardisoLUSolver
from signorini.contact.system import assemble
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann, Tresca


def pressed_block(nx: int):
    mesh = rectangle(0.0, 2.0, 0.0, 1.0, nx=nx, ny=nx // 2)
    problem = ContactProblem(
        mesh=mesh,
        material=Material.from_young(1.0, 0.3),
        conditions={
            "top": Dirichlet((0.01, -0.02)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(gap=lambda x: 0.04 * (x[:, 0] - 1.0) ** 2),
        },
    )
    a = assemble(problem, mesh)
    z = a.contact.nodes
    return a.K, a.F, 2 * z, 2 * z + 1, a.contact.gap, a.dirichlet, a.dirichlet_values


def friction(system, law, weight, **kwargs):
    """``solve_friction`` of ``system`` with one law at every node and its weight (Tresca:
    the bound, Coulomb: the coefficient), the problem's checks included."""
    return solve_friction(check_friction(*system, laws=law, weight=weight), **kwargs)


def timed(function, *args, **kwargs):
    t0 = time.perf_counter()
    result = function(*args, **kwargs)
    return result, time.perf_counter() - t0


def compare_laws(system, repeat: int) -> None:
    K, F, normal, tangent, gap, d, xd = system
    for backend in available_backends():
        frictionless = solve_pdas(K, F, normal, gap, d, xd, solver=SOLVERS[backend])
        top = frictionless.multiplier.max()
        laws = {
            "Tresca classical 0.1": (Tresca(0.0), 0.1 * top),
            "Tresca in contact 0.2": (Tresca(0.0, everywhere=False), 0.2 * top),
            "Coulomb 0.2": (Coulomb(0.2), 0.2),
            "Coulomb 0.5": (Coulomb(0.5), 0.5),
        }
        best = dict.fromkeys(["pdas", *laws], np.inf)
        results = {}
        for _ in range(repeat):
            _, t = timed(solve_pdas, K, F, normal, gap, d, xd, solver=SOLVERS[backend])
            best["pdas"] = min(best["pdas"], t)
            for name, (law, weight) in laws.items():
                results[name], t = timed(friction, system, law, weight, solver=SOLVERS[backend])
                best[name] = min(best[name], t)
        print(f"{backend}: solve_pdas {frictionless.iterations} iterations")
        for name, r in results.items():
            counts = np.bincount(r.state, minlength=3)
            print(
                f"  {name:22s} {r.iterations:3d} iterations, inactive/stick/slip {counts}, "
                f"time / solve_pdas {best[name] / best['pdas']:.2f}, KKT {r.kkt.max:.1e}"
            )


def compare_lu(system, repeat: int) -> None:
    makers = {"SuperLU": lambda: make_solver(superlu_solver, symmetric=False)}
    if "pardiso" in available_backends():
        makers["PARDISO mtype 11"] = PardisoLUSolver
        makers["  without matching"] = lambda: PardisoLUSolver(matching=False)
    best = dict.fromkeys(makers, np.inf)
    results = {}
    for _ in range(repeat):
        for name, make in makers.items():
            with make() as solver:
                results[name], t = timed(friction, system, Coulomb(0.5), 0.5, solver=solver)
            best[name] = min(best[name], t)
    x = results["SuperLU"].x
    print("Coulomb F = 0.5, LU backends (time / SuperLU's):")
    for name, r in results.items():
        factor = r.times["factorization"] / results["SuperLU"].times["factorization"]
        print(
            f"  {name:20s} total {best[name] / best['SuperLU']:.3f}, factorizations "
            f"{factor:.3f}, |x - x_SuperLU| / |x| {np.abs(r.x - x).max() / np.abs(x).max():.1e}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nx", type=int, default=160, help="squares along the block (even)")
    parser.add_argument("--repeat", type=int, default=2, help="rounds; the minimum is kept")
    args = parser.parse_args()
    system = pressed_block(args.nx)
    print(f"{system[0].shape[0]} unknowns, {system[2].size} contact nodes")
    compare_laws(system, args.repeat)
    compare_lu(system, args.repeat)


if __name__ == "__main__":
    main()
