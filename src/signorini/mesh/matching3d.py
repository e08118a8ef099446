"""An initial tagging with the matching condition for any conforming tetrahedral mesh: each
cell subdivided into 12 tagged sub-tetrahedra (docs/method.md, *Three dimensions:
bisection*, *The initial condition*).

Every tetrahedron ``T`` is split through its barycentre ``c_T`` into four cones over its
faces, and every face ``F`` through its barycentre ``c_F`` into three triangles over its
edges, so that ``T`` is the union of the 12 sub-tetrahedra

    ``(a, c_F, c_T, b)_2``     for each face ``F`` of ``T`` and each edge ``a–b`` of ``F``,

tagged as written: the refinement edge ``x0–x3`` is the edge ``a–b`` of the initial mesh,
``x1`` the face barycentre, ``x2`` the cell barycentre, type ``gamma = 2``. This is the
classical remedy for an initial mesh without the matching condition (Kossaczký [1]_;
Stevenson [2]_, who shows that such a subdivision of an arbitrary conforming partition
satisfies it). The type and the order of ``x1, x2`` are those that the package's
check :func:`~signorini.mesh.refine3d.matches` accepts (as do ``(a, c_T, c_F, b)`` and
type 1) and that keep the fewest similarity classes and the largest dihedral angles under
uniform bisection of a regular tetrahedron (nine bisections: at most 6 classes and 22.2°,
against 7–8 classes and 17.0–19.1° for the other three). For types 1 and 2 the tagged simplices
``(x0, x1, x2, x3)_gamma`` and ``(x3, x1, x2, x0)_gamma`` have the same children, so which
end of ``a–b`` comes first does not matter (the smaller vertex number is taken).

Face barycentres are shared by the two cells of a face; those of a boundary face of a part
that carries a :class:`~signorini.mesh.surfaces.Surface` are projected onto it. Each
boundary face becomes three faces of its part, each sub-cell takes its cell's region, and
sub-cell ``12 k + 3 j + i`` lies in cell ``k`` (face ``j`` of :data:`TETRAHEDRON.facets`,
its edge from vertex ``i`` to vertex ``i + 1 mod 3``).

References
----------
.. [1] I. Kossaczký, A recursive approach to local mesh refinement in two and three
   dimensions, J. Comput. Appl. Math. 55 (1994) 275–288.
.. [2] R. Stevenson, The completion of locally refined simplicial partitions created by
   bisection, Math. Comp. 77 (2008) 227–241.
"""

from __future__ import annotations

import numpy as np

from .bisect3d import boundary_of
from .mesh import Mesh
from .reference import TETRAHEDRON
from .surfaces import Surface
from .tags3d import ATTRIBUTE, Tags, mesh_cells, with_face_parts
from .validation import MeshError

__all__ = ["GAMMA", "SUBCELLS", "matching_subdivision", "prepare_for_bisection"]

#: Sub-tetrahedra per cell: 4 faces × 3 edges.
SUBCELLS = 12
#: The type of every sub-tetrahedron.
GAMMA = 2


def matching_subdivision(
    points: np.ndarray, cells: np.ndarray, cell2facet: np.ndarray, facet_point: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 12 sub-tetrahedra of every cell in their tag order (the module's rule).

    Parameters
    ----------
    points : (n_points, 3) float64 array
    cells : (n, 4) int64 array
        Positively oriented; face ``j`` is ``cells[:, TETRAHEDRON.facets[j]]`` (outward).
    cell2facet : (n, 4) int64 array
        The facet index of face ``j`` of each cell.
    facet_point : (n_facets, 3) float64 array
        The point of each facet's barycentre vertex (on the surface for a curved part).

    Returns
    -------
    points : (n_points + n_facets + n, 3) float64 array
        The old points, the facet points, then the cells' barycentres.
    order : (12 n, 4) int64 array
        ``(a, c_F, c_T, b)`` of each sub-tetrahedron, ``a < b``; sub-cell ``12 k + 3 j + i``
        in cell ``k``.
    volume6 : (12 n,) float64 array
        ``det[b - a, c_T - a, c_F - a]`` with ``a, b`` in the order of the outward face
        ``F``: six times the sub-tetrahedron's volume, positive for every sub-cell of a
        valid subdivision (``c_T`` lies on the inner side of ``F``).
    """
    n_points, n = points.shape[0], cells.shape[0]
    face = cells[:, TETRAHEDRON.facets]  # (n, 4, 3), outward
    a, b = face, np.roll(face, -1, axis=2)  # the edges of each face, in its orientation
    c_face = np.broadcast_to(n_points + cell2facet[:, :, None], a.shape)
    c_cell = np.broadcast_to(
        (n_points + facet_point.shape[0] + np.arange(n, dtype=np.int64))[:, None, None], a.shape
    )
    new_points = np.concatenate([points, facet_point, points[cells].mean(axis=1)])
    order = np.stack([np.minimum(a, b), c_face, c_cell, np.maximum(a, b)], axis=-1).reshape(-1, 4)
    x = new_points[np.stack([a, b, c_face, c_cell], axis=-1).reshape(-1, 4)]
    volume6 = np.linalg.det(np.stack([x[:, 1] - x[:, 0], x[:, 3] - x[:, 0], x[:, 2] - x[:, 0]], 1))
    return new_points, order, volume6


def prepare_for_bisection(mesh: Mesh) -> Mesh:
    """The mesh subdivided into 12 sub-tetrahedra per cell, tagged with the matching
    condition for bisection (module docstring): an initialisation of an arbitrary (e.g.
    Gmsh) tetrahedral mesh, opt-in beside the default colouring
    (:func:`~signorini.mesh.tags3d.coloured_tags`; docs/method.md, *The default for a Gmsh
    mesh*).

    Parameters
    ----------
    mesh : Mesh
        A conforming tetrahedral mesh (``dim == 3``); parts, their surfaces and regions
        are carried to the sub-cells. Attach surfaces (:meth:`Mesh.with_curve`) before: a
        new Mesh made from the result loses its tags.

    Returns
    -------
    Mesh
        ``12 n_cells`` cells (sub-cell ``12 k + …`` in cell ``k``), the old points first,
        carrying its :class:`~signorini.mesh.tags3d.Tags`, which refinement continues.

    Raises
    ------
    MeshError
        If the mesh is not tetrahedral, or a face barycentre projected onto a surface turns
        a sub-cell inside out or flat (the mesh is too coarse for the surface).
    """
    if mesh.dim != 3:
        raise MeshError(f"prepare_for_bisection: a tetrahedral mesh is needed, got dim {mesh.dim}")
    facet_point = mesh.points[mesh.facets].mean(axis=1)
    for part, surface in enumerate(mesh.curves):  # a loop over parts, not facets
        if isinstance(surface, Surface):
            on = np.flatnonzero(mesh.facet_part == part)
            facet_point[on] = surface.project(facet_point[on])
    points, order, volume6 = matching_subdivision(
        mesh.points, mesh.cells, mesh.cell2facet, facet_point
    )
    if np.any(volume6 <= 0):
        bad = int(np.flatnonzero(volume6 <= 0)[0]) // SUBCELLS
        raise MeshError(
            f"prepare_for_bisection: a face barycentre on a surface turns a sub-cell of cell "
            f"{bad} {mesh.cells[bad].tolist()} inside out or flat: the mesh is too coarse for "
            "the surface"
        )
    boundary, part = _boundary_thirds(mesh)
    gamma = np.full(order.shape[0], GAMMA, dtype=np.int8)
    tags: Tags = with_face_parts(points, order, gamma, boundary, part)
    cells = mesh_cells(tags)
    outward, part = boundary_of(cells, tags)
    refined = Mesh(
        points,
        cells,
        outward,
        part,
        mesh.part_names,
        validate=False,
        curves=mesh.curves,
        cell_region=np.repeat(mesh.cell_region, SUBCELLS),
        region_names=mesh.region_names,
    )
    setattr(refined, ATTRIBUTE, tags)
    return refined


def _boundary_thirds(mesh: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """The three faces ``(u, v, c_F)`` of each boundary face ``(u, v, w)`` split at its
    barycentre vertex ``c_F`` ``(3 n_b, 3)``, and their parts ``(3 n_b,)``."""
    face = mesh.boundary  # (n_b, 3)
    centre = np.broadcast_to((mesh.n_points + mesh.boundary_facet)[:, None], face.shape)
    thirds = np.stack([face, np.roll(face, -1, axis=1), centre], axis=-1).reshape(-1, 3)
    return thirds, np.repeat(mesh.boundary_part, 3)
