"""Tagged-simplex bisection of tetrahedra: speed and shape regularity.

    python benchmarks/bisect3d.py            # rates, then 30 levels towards a vertex, an
                                             # edge and a face, and the curved sphere part
    python benchmarks/bisect3d.py --quick    # smaller sizes

Speed: uniform refinement of a Kuhn box (three bisections of every cell) and local
refinement (the cells within a ball about a corner) up to about 10⁶ P2 unknowns
(``3 (n_points + n_edges)``); each time includes the child mesh's topology (``edges``,
``cell2edge``, ``facets``, ``facet2cell``, ``boundary_facet``). Shape: per level the cells,
the smallest dihedral angle, and the number of similarity classes, up to similarity
(translation, scaling, rotation, reflection) and up to translation and scaling only
(:func:`~signorini.mesh.quality3d.similarity_classes`).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from signorini.mesh import refine3d
from signorini.mesh.builders3d import box, eighth_ball
from signorini.mesh.quality3d import min_dihedral_angle, similarity_classes
from signorini.mesh.refine import refine_nvb, refine_uniform


def p2_unknowns(mesh) -> int:
    return 3 * (mesh.n_points + mesh.n_edges)


def topology(mesh) -> None:
    """Touch the child mesh's topology, as the next SOLVE reads it."""
    mesh.edges, mesh.cell2edge, mesh.facets, mesh.facet2cell, mesh.boundary_facet  # noqa: B018


def timed(step, mesh, *args, repeat: int = 3):
    """The refined mesh and the best of ``repeat`` times of the step and of its topology
    (the machine is shared)."""
    best = (np.inf, np.inf)
    for _ in range(repeat):
        t0 = time.perf_counter()
        ref = step(mesh, *args)
        t1 = time.perf_counter()
        topology(ref.mesh)
        t2 = time.perf_counter()
        best = min(best, (t1 - t0, t2 - t1), key=sum)
    return ref.mesh, *best


def rates(n: int, levels: int) -> None:
    print("uniform: level  cells  P2 unknowns  bisect s  topology s  cells/s  unknowns/s")
    mesh = box(n, n, n)
    topology(mesh)
    for level in range(levels):
        mesh, tb, tt = timed(refine_uniform, mesh)
        u = p2_unknowns(mesh)
        print(
            f"  {level:2d} {mesh.n_cells:9d} {u:11d} {tb:9.3f} {tt:10.3f} "
            f"{mesh.n_cells / (tb + tt):9.3g} {u / (tb + tt):9.3g}"
        )
    print(
        "local (the 10% of cells nearest a corner): level  cells  P2 unknowns  bisect s  "
        "topology s  unknowns/s"
    )
    mesh = box(n, n, n)
    topology(mesh)
    level = 0
    while p2_unknowns(mesh) < 1.1e6:
        distance = np.linalg.norm(mesh.points[mesh.cells].mean(axis=1), axis=1)
        marked = distance <= np.quantile(distance, 0.1)
        mesh, tb, tt = timed(refine_nvb, mesh, marked)
        u = p2_unknowns(mesh)
        if level % 4 == 3:
            print(
                f"  {level:2d} {mesh.n_cells:9d} {u:11d} {tb:9.3f} {tt:10.3f} {u / (tb + tt):9.3g}"
            )
        level += 1
    distance = np.linalg.norm(mesh.points[mesh.cells].mean(axis=1), axis=1)
    compare_topology(mesh, distance <= np.quantile(distance, 0.1))


def compare_topology(mesh, marked) -> None:
    """The same step with the child's topology handed over and computed by a global
    ``np.unique`` of all edges and faces."""
    handed = refine3d.refined_topology
    for name, known in (("handed", handed), ("global np.unique", lambda *a: None)):
        refine3d.refined_topology = known
        try:
            child, tb, tt = timed(refine_nvb, mesh, marked)
        finally:
            refine3d.refined_topology = handed
        u = p2_unknowns(child)
        print(f"  topology {name}: bisect {tb:.3f} s, topology {tt:.3f} s, {u / (tb + tt):.3g}/s")


def towards(where: str, levels: int, budget: int) -> None:
    print(f"towards a {where}: level  cells  min dihedral  classes  (translation+scaling)")
    mesh = box(1, 1, 1)
    for level in range(levels):
        p = mesh.points[mesh.cells]
        zero = np.abs(p) < 1e-12
        if where == "vertex":
            marked = zero.all(-1).any(1)
        elif where == "edge":
            marked = (zero[..., 1] & zero[..., 2]).sum(1) >= 2
        else:  # the face z = 0, within x < 1/4 as cells shrink
            marked = (zero[..., 2].sum(1) >= 3) & (p[..., 0].min(1) < 0.25)
        if mesh.n_cells > budget:
            break
        mesh = refine_nvb(mesh, marked).mesh
        print(
            f"  {level:2d} {mesh.n_cells:8d} {min_dihedral_angle(mesh.points, mesh.cells):8.3f} "
            f"{similarity_classes(mesh.points, mesh.cells):4d} "
            f"({similarity_classes(mesh.points, mesh.cells, rotations=False)})"
        )


def towards_sphere(levels: int, budget: int) -> None:
    print("towards the curved sphere part of an eighth ball: level  cells  min dihedral  classes")
    mesh = eighth_ball(2)  # tagged by its Kuhn paths (refine3d.tags_of)
    for level in range(levels):
        if mesh.n_cells > budget:
            break
        marked = np.zeros(mesh.n_cells, dtype=bool)
        marked[mesh.facet2cell[mesh.part_facets("sphere"), 0]] = True
        mesh = refine_nvb(mesh, marked).mesh
        print(
            f"  {level:2d} {mesh.n_cells:8d} {min_dihedral_angle(mesh.points, mesh.cells):8.3f} "
            f"{similarity_classes(mesh.points, mesh.cells):6d}"
        )


def arbitrary(levels: int, budget: int) -> None:
    """A Delaunay mesh of a grid and random points (slivers included), tagged by the global
    vertex order (no matching condition): rounds, smallest dihedral angle, classes."""
    from scipy.spatial import Delaunay

    from signorini.mesh.bisect3d import bisect_tagged
    from signorini.mesh.reference import TETRAHEDRON
    from signorini.mesh.tags3d import mesh_cells, sorted_tags, with_face_parts
    from signorini.mesh.topology import boundary_facets

    rng = np.random.default_rng(1)
    g = np.linspace(0.0, 1.0, 4)
    grid = np.stack(np.meshgrid(g, g, g), axis=-1).reshape(-1, 3)
    points = np.vstack([grid, 0.1 + 0.8 * rng.random((60, 3))])
    cells = Delaunay(points).simplices.astype(np.int64)
    p = points[cells]
    det = np.linalg.det(p[:, 1:] - p[:, :1])
    cells = cells[np.abs(det) > 1e-10]
    det = det[np.abs(det) > 1e-10]
    cells[det < 0] = cells[det < 0][:, [0, 2, 1, 3]]
    boundary = boundary_facets(cells, TETRAHEDRON.facets)
    tags = with_face_parts(
        points,
        sorted_tags(cells),
        np.zeros(len(cells), np.int8),
        boundary,
        np.zeros(len(boundary), np.int64),
    )
    print(
        f"arbitrary (Delaunay, {len(cells)} cells, global vertex order): level  cells  rounds  "
        f"min dihedral  classes; initially {min_dihedral_angle(points, cells):.2f}°"
    )
    for level in range(levels):
        cells = mesh_cells(tags)
        if cells.shape[0] > budget:
            break
        x = points[cells]
        marked = (np.abs(x).sum(-1) < 1e-12).any(1)  # towards the corner 0
        marked |= np.linalg.norm(x.mean(1) - 0.5, axis=1) < 0.5 ** (level / 3 + 2)
        result = bisect_tagged(points, tags, marked)
        points, tags = result.points, result.tags
        cells = mesh_cells(tags)
        print(
            f"  {level:2d} {cells.shape[0]:8d} {result.rounds:3d} "
            f"{min_dihedral_angle(points, cells):8.3f} {similarity_classes(points, cells):6d}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    rates(4, 2 if args.quick else 3)
    budget = 20_000 if args.quick else 100_000
    for where in ("vertex", "edge", "face"):
        towards(where, 30, budget)
    towards_sphere(30, budget)
    arbitrary(30, budget)


if __name__ == "__main__":
    main()
