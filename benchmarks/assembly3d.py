"""Benchmark: the 3D P2 elasticity stiffness matrix, unknowns per second, against scikit-fem.

On the Kuhn mesh of the unit cube (``signorini.mesh.builders3d.box``, ``n`` cubes a side,
``6 n³`` tetrahedra, ``3 (2 n + 1)³`` unknowns) it times the assembly of
``signorini.fem.stiffness3d.assemble_stiffness_3d`` (element matrices and the node-block
CSR) and, if scikit-fem is installed, ``asm(linear_elasticity, Basis(MeshTet,
ElementVector(ElementTetP2())))`` on the same points and cells, in one run: the best of
``--repeat`` runs each, the ratio of the two, and the two matrices' difference after
matching the DOF order (scikit-fem numbers its DOFs by component blocks of its own edge
order, so the check compares ``x^T K x`` for the interpolants of random quadratic fields).
Freed memory is kept for reuse as the command line keeps it
(:func:`signorini.runtime.retain_freed_memory`).

    python benchmarks/assembly3d.py                 # n = 8, 12, 16
    python benchmarks/assembly3d.py --sizes 20 24 --repeat 2
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
    """The fastest of ``repeat`` runs (seconds) and the last result."""
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - t0)
    return best, out


def quadratic_energy(K, points: np.ndarray, field) -> float:
    """``x^T K x`` of the nodal values ``field(points) (n, 3)`` in interleaved order."""
    x = field(points).ravel()
    return float(x @ (K @ x))


def skfem_assembly(mesh, repeat: int):
    """scikit-fem's time, its matrix and its DOF points, or ``None`` if it is absent."""
    try:
        from skfem import Basis, ElementTetP2, ElementVector, MeshTet, asm
        from skfem.models.elasticity import linear_elasticity
    except ImportError:
        return None
    m = MeshTet(mesh.points.T.copy(), mesh.cells.T.copy())
    basis = Basis(m, ElementVector(ElementTetP2()))
    form = linear_elasticity(MATERIAL.lam, MATERIAL.mu)
    t, K = best_of(repeat, lambda: asm(form, basis))
    return t, K, basis


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[8, 12, 16])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-peer", action="store_true", help="skip scikit-fem")
    args = parser.parse_args()
    retain_freed_memory()  # as the command line does: freed pages reused, not faulted in anew
    rng = np.random.default_rng(0)
    print(
        f"{'n':>4s} {'unknowns':>10s} {'ours s':>8s} {'ours 1e6/s':>10s} {'skfem s':>8s} "
        f"{'skfem/ours':>10s} {'energy rel. diff':>16s}"
    )
    for n in args.sizes:
        mesh = box(n, n, n)
        V = space_of(mesh)
        V.cell_dofs  # noqa: B018 (the space's DOF map, not timed: it is the mesh's topology)
        t, K = best_of(
            args.repeat,
            lambda V=V: assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL),
        )
        rate = V.n_dofs / t / 1e6
        peer = None if args.no_peer else skfem_assembly(mesh, args.repeat)
        if peer is None:
            print(f"{n:4d} {V.n_dofs:10d} {t:8.3f} {rate:10.3f} {'-':>8s} {'-':>10s} {'-':>16s}")
            continue
        t_skf, K_skf, basis = peer
        A = rng.normal(size=(3, 3, 3))

        def field(x, A=A):
            return np.einsum("ijk,...j,...k->...i", A, x, x)

        ours = quadratic_energy(K, V.node_points, field)
        # scikit-fem's DOFs: component c of the node at doflocs (its nodal and edge DOFs)
        comp = np.empty(basis.N, dtype=np.int64)
        for c in range(3):
            comp[basis.nodal_dofs[c]] = c
            comp[basis.edge_dofs[c]] = c
        x = field(basis.doflocs.T)[np.arange(basis.N), comp]
        theirs = float(x @ (K_skf @ x))
        diff = abs(ours - theirs) / abs(ours)
        print(
            f"{n:4d} {V.n_dofs:10d} {t:8.3f} {rate:10.3f} {t_skf:8.3f} {t_skf / t:10.2f} "
            f"{diff:16.2e}"
        )


if __name__ == "__main__":
    main()
