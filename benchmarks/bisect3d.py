"""Tagged-simplex bisection of tetrahedra: speed and shape regularity.

    python benchmarks/bisect3d.py            # rates, then 30 levels towards a vertex, an
                                             # edge and a face, and the curved sphere part
    python benchmarks/bisect3d.py --quick    # smaller sizes
    python benchmarks/bisect3d.py --arbitrary  # only the Delaunay cube and ball, tagged by
                                             # the vertex colouring (the default), the
                                             # global vertex order and the 12-cell
                                             # matching subdivision

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


def delaunay_cube(seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A Delaunay mesh of a 4 × 4 × 4 grid and 60 random points in the unit cube (slivers
    included): points and positively oriented cells."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    g = np.linspace(0.0, 1.0, 4)
    grid = np.stack(np.meshgrid(g, g, g), axis=-1).reshape(-1, 3)
    points = np.vstack([grid, 0.1 + 0.8 * rng.random((60, 3))])
    return points, Delaunay(points).simplices.astype(np.int64)


def delaunay_ball(seed: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """A Gmsh-like unstructured mesh of the unit ball: the centre and quasi-uniform
    (Fibonacci) point sets on the spheres of radii 1/3, 2/3 and 1, slightly jittered, and
    their Delaunay tetrahedra; the north pole ``(0, 0, 1)`` is point 0."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    shells = [np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])]
    for radius, count in ((1.0, 120), (2 / 3, 54), (1 / 3, 14)):
        k = np.arange(count) + 0.5
        z = 1 - 2 * k / count
        phi = np.pi * (1 + 5**0.5) * k + rng.random()
        unit = np.column_stack(
            [np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z]
        )
        jitter = 0.02 * radius * rng.standard_normal(unit.shape)
        x = radius * unit + (jitter if radius < 1 else 0.0)
        shells.append(x / np.linalg.norm(x, axis=1, keepdims=True) if radius == 1 else x)
    points = np.vstack(shells)
    points = points[
        np.r_[0, 1, 2 + np.flatnonzero(np.linalg.norm(points[2:] - points[0], axis=1) > 0.1)]
    ]
    return points, Delaunay(points).simplices.astype(np.int64)


def arbitrary_mesh(points: np.ndarray, cells: np.ndarray):
    """A Mesh of the cells (flat ones dropped, orientation fixed), one boundary part."""
    import warnings

    from signorini.mesh.mesh import Mesh

    p = points[cells]
    cells = cells[np.abs(np.linalg.det(p[:, 1:] - p[:, :1])) > 1e-10]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # slivers
        return Mesh.from_arrays(points, cells, {"boundary": lambda x: np.ones(len(x), bool)})


def arbitrary(levels: int, budget: int) -> None:
    """Arbitrary (Delaunay) meshes tagged by Diening-Gehring-Storn's colouring (the default,
    :func:`~signorini.mesh.tags3d.coloured_tags`), by the global vertex order and by the
    12-cell subdivision (:func:`~signorini.mesh.matching3d.prepare_for_bisection`): per
    level towards a vertex and towards a face, the cells, the closure rounds, the cells
    added per cell marked (the closure estimate), the smallest dihedral angle and the
    similarity classes."""
    from signorini.mesh.bisect3d import bisect_tagged
    from signorini.mesh.matching3d import prepare_for_bisection
    from signorini.mesh.surfaces import Sphere
    from signorini.mesh.tags3d import mesh_cells, sorted_tags, with_face_parts

    sphere = Sphere((0.0, 0.0, 0.0), 1.0)  # the ball's boundary: new vertices on it
    cube = arbitrary_mesh(*delaunay_cube())
    ball = arbitrary_mesh(*delaunay_ball()).with_curve("boundary", sphere)

    def vertex(points, cells, target):
        return (np.abs(points[cells] - target).sum(-1) < 1e-12).any(1)

    def cube_face(points, cells, level):  # the face z = 0 within x < 1/4
        x = points[cells]
        return ((np.abs(x[..., 2]) < 1e-12).sum(1) >= 3) & (x[..., 0].min(1) < 0.25)

    def ball_face(points, cells, level):  # the cells with a boundary face within z > 0.8
        x = points[cells]
        on = np.abs(np.linalg.norm(x, axis=-1) - 1) < 1e-9  # vertices on the sphere
        return (on.sum(1) >= 3) & (np.where(on, x[..., 2], 1.0).min(1) > 0.8)

    cases = (
        ("cube", cube, "vertex", lambda p, c, lev: vertex(p, c, np.zeros(3))),
        ("cube", cube, "face", cube_face),
        ("ball", ball, "vertex", lambda p, c, lev: vertex(p, c, np.array([0.0, 0.0, 1.0]))),
        ("ball", ball, "face", ball_face),
    )
    for name, mesh, where, marking in cases:
        for init in ("colouring", "global order", "12-cell matching"):
            start = prepare_for_bisection(mesh) if init == "12-cell matching" else mesh
            points, tags = start.points, refine3d.tags_of(start)
            if init == "global order":
                order, gamma = sorted_tags(mesh.cells), np.zeros(mesh.n_cells, np.int8)
                tags = with_face_parts(points, order, gamma, mesh.boundary, mesh.boundary_part)
            cells, n_marked = start.cells, 0
            print(
                f"{name} (Delaunay, {mesh.n_cells} cells) towards a {where}, {init}: "
                f"{start.n_cells} cells, min dihedral {min_dihedral_angle(points, cells):.2f}°, "
                f"{similarity_classes(points, cells)} classes, matches "
                f"{refine3d.matches(points, tags)}"
            )
            print("  level  cells  rounds  added/marked  min dihedral  classes")
            for level in range(levels):
                if cells.shape[0] > budget:
                    break
                marked = marking(points, cells, level)
                n_marked += int(marked.sum())
                result = bisect_tagged(
                    points,
                    tags,
                    marked,
                    curved=np.array([name == "ball"]),
                    halfway=lambda part, a, b: sphere.halfway(a, b),
                )
                points, tags = result.points, result.tags
                cells = mesh_cells(tags)
                print(
                    f"  {level:2d} {cells.shape[0]:8d} {result.rounds:3d} "
                    f"{(cells.shape[0] - start.n_cells) / max(n_marked, 1):8.2f} "
                    f"{min_dihedral_angle(points, cells):8.3f} "
                    f"{similarity_classes(points, cells):6d}"
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--arbitrary", action="store_true", help="only the Delaunay meshes")
    args = parser.parse_args()
    budget = 20_000 if args.quick else 100_000
    if not args.arbitrary:
        rates(4, 2 if args.quick else 3)
        for where in ("vertex", "edge", "face"):
            towards(where, 30, budget)
    if not args.arbitrary:
        towards_sphere(30, budget)
    arbitrary(30, budget)


if __name__ == "__main__":
    main()
