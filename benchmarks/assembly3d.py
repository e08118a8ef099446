"""Benchmark: the 3D P2 elasticity stiffness matrix, unknowns per second, against NGSolve and
scikit-fem on the same mesh in one run.

On the Kuhn mesh of the unit cube (``signorini.mesh.builders3d.box``, ``n`` cubes a side,
``6 n³`` tetrahedra, ``3 (2 n + 1)³`` unknowns) it times
``signorini.fem.stiffness3d.assemble_stiffness_3d`` twice over: *cold*, the first assembly
on the mesh (its node-pair pattern, :mod:`signorini.fem.pattern3d`, built inside the timed
call, as on each new mesh of an adaptive loop) and *warm*, again on the same mesh (the
pattern kept on the space's DOF map: the element matrices and their sum only). The peers,
if installed, on the same points and cells, each on one thread:

* NGSolve, ``BilinearForm(2 μ ε(u) : ε(v) + λ div u div v).Assemble()`` on ``VectorH1(order
  = 2)``: cold (a new form, its matrix graph built) and warm (the same form assembled again);
* scikit-fem, ``asm(linear_elasticity, Basis(MeshTet, ElementVector(ElementTetP2())))``
  (COO → CSR every time: against our cold time), up to ``--skfem-max`` (it is slow).

Each time is the best of ``--repeat`` runs. The matrices are checked against ours by ``x^T K
x`` of the interpolants of a random quadratic field (the DOF orders differ; P2 interpolates a
quadratic exactly). Freed memory is kept for reuse as the command line keeps it
(:func:`signorini.runtime.retain_freed_memory`).

    python benchmarks/assembly3d.py                       # n = 8, 16, 24, 35 (1.07e6 unknowns)
    python benchmarks/assembly3d.py --sizes 12 --repeat 5 --skfem-max 12
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini.fem.material import Material
from signorini.fem.space import space_of
from signorini.fem.stiffness3d import assemble_stiffness_3d
from signorini.mesh.builders3d import box
from signorini.runtime import retain_freed_memory

MATERIAL = Material.from_young(1.0, 0.3)


def best_of(repeat: int, run) -> tuple[float, object]:
    """The fastest of ``repeat`` runs (seconds) and the last result (the previous one freed
    before each run, as a program that assembles again would)."""
    best, out = np.inf, None
    for _ in range(repeat):
        out = None
        t0 = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - t0)
    return best, out


def quadratic(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The quadratic field ``u_i = A_ijk x_j x_k`` at points ``x (n, 3)``, ``(n, 3)``."""
    return np.einsum("ijk,...j,...k->...i", A, x, x)


def ngsolve_assembly(mesh, repeat: int, A: np.ndarray):
    """NGSolve's cold and warm times and its energy of the field ``A``, or ``None``."""
    try:
        import ngsolve as ngs
        from netgen.meshing import FaceDescriptor
        from netgen.meshing import Mesh as NetgenMesh
    except ImportError:
        return None
    ngs.SetNumThreads(1)
    netgen = NetgenMesh(dim=3)
    netgen.AddPoints(np.ascontiguousarray(mesh.points))
    netgen.Add(FaceDescriptor(surfnr=1, domin=1, bc=1))
    netgen.AddElements(dim=3, index=1, data=mesh.cells.astype(np.int32), base=0)
    fes = ngs.VectorH1(ngs.Mesh(netgen), order=2)
    u, v = fes.TnT()
    lam, mu = MATERIAL.lam, MATERIAL.mu
    integrand = 2 * mu * ngs.InnerProduct(ngs.Sym(ngs.Grad(u)), ngs.Sym(ngs.Grad(v)))
    integrand = integrand + lam * ngs.div(u) * ngs.div(v)

    def cold():
        a = ngs.BilinearForm(fes)
        a += integrand * ngs.dx
        return a.Assemble()

    t_cold, a = best_of(repeat, cold)
    t_warm, _ = best_of(repeat, a.Assemble)
    X = (ngs.x, ngs.y, ngs.z)
    gf = ngs.GridFunction(fes)
    gf.Set(
        ngs.CF(
            tuple(
                sum(A[i, j, k] * X[j] * X[k] for j in range(3) for k in range(3)) for i in range(3)
            )
        )
    )
    energy = ngs.InnerProduct(gf.vec, (a.mat * gf.vec).Evaluate())
    return t_cold, t_warm, energy


def skfem_assembly(mesh, repeat: int, A: np.ndarray):
    """scikit-fem's time and its energy of the field ``A``, or ``None`` if it is absent."""
    try:
        from skfem import Basis, ElementTetP2, ElementVector, MeshTet, asm
        from skfem.models.elasticity import linear_elasticity
    except ImportError:
        return None
    m = MeshTet(mesh.points.T.copy(), mesh.cells.T.copy())
    basis = Basis(m, ElementVector(ElementTetP2()))
    form = linear_elasticity(MATERIAL.lam, MATERIAL.mu)
    t, K = best_of(repeat, lambda: asm(form, basis))
    # scikit-fem's DOFs: component c of the node at doflocs (its nodal and edge DOFs)
    comp = np.empty(basis.N, dtype=np.int64)
    for c in range(3):
        comp[basis.nodal_dofs[c]] = c
        comp[basis.edge_dofs[c]] = c
    x = quadratic(A, basis.doflocs.T)[np.arange(basis.N), comp]
    return t, float(x @ (K @ x))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 24, 35])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--skfem-max", type=int, default=16, help="largest n for scikit-fem")
    parser.add_argument("--no-peer", action="store_true", help="skip NGSolve and scikit-fem")
    args = parser.parse_args()
    retain_freed_memory()  # as the command line does: freed pages reused, not faulted in anew
    rng = np.random.default_rng(0)
    print(
        f"{'n':>3s} {'unknowns':>9s} {'cold s':>7s} {'warm s':>7s} {'cold 1e6/s':>10s} "
        f"{'warm 1e6/s':>10s} {'ngs cold':>8s} {'ngs warm':>8s} {'ngs/ours c':>10s} "
        f"{'ngs/ours w':>10s} {'skfem s':>8s} {'skfem/ours':>10s} {'energy diff':>11s}"
    )
    for n in args.sizes:
        mesh = box(n, n, n)
        V = space_of(mesh)
        V.cell_dofs  # noqa: B018 (the space's DOF map, not timed: it is the mesh's topology)

        def assemble(cell_dofs, V=V):
            return assemble_stiffness_3d(V.mapping, cell_dofs, V.n_dofs, MATERIAL)

        # cold: a new DOF array each time, so the pattern is built inside the timed call
        copies = [V.cell_dofs.copy() for _ in range(args.repeat)]
        t_cold, _ = best_of(args.repeat, lambda c=copies: assemble(c.pop()))
        t_warm, K = best_of(args.repeat, lambda V=V: assemble(V.cell_dofs))
        A = rng.normal(size=(3, 3, 3))
        x = quadratic(A, V.node_points).ravel()
        ours = float(x @ (K @ x))
        cols = [f"{n:3d} {V.n_dofs:9d} {t_cold:7.3f} {t_warm:7.3f}"]
        cols.append(f"{V.n_dofs / t_cold / 1e6:10.3f} {V.n_dofs / t_warm / 1e6:10.3f}")
        diff = 0.0
        ngs = None if args.no_peer else ngsolve_assembly(mesh, args.repeat, A)
        if ngs is None:
            cols.append(f"{'-':>8s} {'-':>8s} {'-':>10s} {'-':>10s}")
        else:
            c, w, energy = ngs
            cols.append(f"{c:8.3f} {w:8.3f} {c / t_cold:10.2f} {w / t_warm:10.2f}")
            diff = max(diff, abs(energy - ours) / abs(ours))
        skf = None if args.no_peer or n > args.skfem_max else skfem_assembly(mesh, 1, A)
        if skf is None:
            cols.append(f"{'-':>8s} {'-':>10s}")
        else:
            cols.append(f"{skf[0]:8.3f} {skf[0] / t_cold:10.2f}")
            diff = max(diff, abs(skf[1] - ours) / abs(ours))
        cols.append(f"{diff:11.1e}")
        print(" ".join(cols), flush=True)


if __name__ == "__main__":
    main()
