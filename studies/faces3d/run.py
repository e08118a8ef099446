"""Measure the two discrete contact conditions on P2 faces: ``python studies/faces3d/run.py``.

Prints the checks (patch test, KKT, the independent dual NNLS solve) and, per manufactured
problem, variant and mesh: unknowns, PDAS steps, energy error and its rate in h, the largest
vertex lift-off where the exact solution is in contact, active shares, the vertices' share of
the multiplier, η6 and η6/error with their rates (η6 with ψ, and with ψ_h = I_h ψ), the
recovered pressures' errors.
``--quick`` stops at n = 4.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from faces3d.contact import assemble, solve_dual_nnls, solve_pdas  # noqa: E402
from faces3d.elasticity import energy_error  # noqa: E402
from faces3d.manufactured import full_contact, patch, transition  # noqa: E402
from faces3d.measures import (  # noqa: E402
    eta6,
    liftoff,
    pressure_error,
    recovered_pressure,
    shares,
)
from faces3d.mesh import cube_mesh  # noqa: E402

#: α of variant (b): Popp–Wohlmuth–Gee–Wall's choice for 6-node triangles.
ALPHA = 0.2
VARIANTS = {"a": 0.0, "b": ALPHA}


def measure(n: int, exact, alpha: float, problem=None) -> dict:
    """Solve one variant on the n³ cube and measure it."""
    mesh = cube_mesh(n)
    problem = problem or assemble(mesh, exact)
    sol = solve_pdas(problem, alpha)
    err = energy_error(mesh, sol.u, exact.grad_u, exact.lam, exact.mu)
    row = {"n": n, "N": 3 * mesh.n_nodes, "its": sol.iterations, "err": err}
    row["lift_v"], row["lift_e"] = liftoff(problem, sol, exact)
    row |= shares(problem, sol)
    row["eta6"] = eta6(problem, sol, exact)
    row["eta6_h"] = eta6(problem, sol, exact, interpolated=True)
    row["p1"] = pressure_error(problem, recovered_pressure(problem, sol.force, 0.5), exact, 0.5)
    row["pt"] = (
        pressure_error(problem, recovered_pressure(problem, sol.force, alpha), exact, alpha)
        if alpha
        else np.nan
    )
    row["kkt"] = max(sol.kkt.values())
    return row


def rate(values: list[float], ns: list[int]) -> list[float]:
    """Observed orders in h between consecutive meshes (NaN on the first)."""
    v, n = np.log(values), np.log(ns)
    return [np.nan] + list(-(v[1:] - v[:-1]) / (n[1:] - n[:-1]))


def table(rows: list[dict]) -> None:
    ns = [r["n"] for r in rows]
    r_err = rate([r["err"] for r in rows], ns)
    r_eta = rate([r["eta6"] for r in rows], ns)
    print(
        f"{'n':>3} {'N':>6} {'its':>3} {'error':>9} {'rate':>5} {'lift_v':>9} {'act_v':>5} "
        f"{'act_e':>5} {'λ_v/Σλ':>7} {'η6':>9} {'rate':>5} {'η6/err':>6} {'p_P1':>8} "
        f"{'p̃':>8} {'η6(ψ_h)/err':>11} {'KKT':>8}"
    )
    for r, a, b in zip(rows, r_err, r_eta, strict=True):
        print(
            f"{r['n']:3d} {r['N']:6d} {r['its']:3d} {r['err']:9.3e} {a:5.2f} "
            f"{r['lift_v']:9.2e} {r['active_v']:5.2f} {r['active_e']:5.2f} "
            f"{r['mult_v']:7.3f} {r['eta6']:9.3e} {b:5.2f} {r['eta6'] / r['err']:6.3f} "
            f"{r['p1']:8.2e} {r['pt']:8.2e} {r['eta6_h'] / r['err']:11.3e} {r['kkt']:8.1e}",
            flush=True,
        )


def checks() -> None:
    """Patch test, KKT and the independent solve on the smallest mesh (n = 2)."""
    mesh = cube_mesh(2)
    for exact in (patch(), full_contact(), transition()):
        problem = assemble(mesh, exact)
        for name, alpha in VARIANTS.items():
            sol = solve_pdas(problem, alpha)
            other = solve_dual_nnls(problem, alpha)
            line = (
                f"  {exact.name:12s} ({name}) KKT {max(sol.kkt.values()):.1e}  "
                f"|u_PDAS − u_NNLS| {np.abs(sol.u - other).max():.1e}"
            )
            if exact.name == "patch":
                err = energy_error(mesh, sol.u, exact.grad_u, exact.lam, exact.mu)
                p = recovered_pressure(problem, sol.force, 0.5 if alpha == 0 else alpha)
                p_err = np.nanmax(np.abs(p - 0.1))
                line += f"  energy error {err:.1e}  |p_h − p| {p_err:.1e}"
            print(line, flush=True)


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    start = time.perf_counter()
    print(f"P2 contact on the face z = 0 of the Kuhn cube; (a) nodal, (b) transformed α = {ALPHA}")
    print("checks on n = 2:")
    checks()
    cases = [(full_contact(), [2, 3, 4, 6, 8, 12]), (transition(), [2, 3, 4, 6, 8, 10])]
    for exact, ns in cases:
        ns = [n for n in ns if n <= 4] if quick else ns
        rows = {name: [] for name in VARIANTS}
        for n in ns:
            problem = assemble(cube_mesh(n), exact)
            for name, alpha in VARIANTS.items():
                rows[name].append(measure(n, exact, alpha, problem))
        for name in VARIANTS:
            print(f"\n{exact.name}, variant ({name}):")
            table(rows[name])
    print("\nα of (b) on the full-contact cube, n = 6:")
    exact = full_contact()
    problem = assemble(cube_mesh(6), exact)
    for alpha in (0.1, 0.2, 0.25, 1 / 3, 0.4):
        r = measure(6, exact, alpha, problem)
        print(
            f"  α = {alpha:.3f}: error {r['err']:.4e}  η6/err {r['eta6'] / r['err']:.3f}  "
            f"lift_v {r['lift_v']:.1e}  act_e {r['active_e']:.2f}  p̃ {r['pt']:.2e}"
        )
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main(sys.argv[1:])
