"""The REFINE step on tetrahedral meshes: tagged-simplex bisection
(:mod:`signorini.mesh.bisect3d`) behind :func:`signorini.mesh.refine.refine_nvb` and
:func:`~signorini.mesh.refine.refine_uniform`, which dispatch here on ``mesh.dim == 3``
(docs/method.md, *Three dimensions: bisection*).

The refined mesh carries its cells' tags (:func:`tags_of`), so the
next refinement continues the bisection sequence; boundary faces are read from the face
tags, parts and regions go to the children, and new vertices of edges of a part that carries
a :class:`~signorini.mesh.surfaces.Surface` are placed by its ``halfway``.
"""

from __future__ import annotations

import logging

import numpy as np

from .bisect3d import KEY_BASE, bisect_tagged, boundary_of, edge_key
from .builders3d import kuhn_paths
from .mesh import Mesh
from .surfaces import Surface
from .tags3d import (
    ATTRIBUTE,
    Tags,
    coloured_tags,
    greedy_colouring,
    kuhn_tags,
    mesh_cells,
    with_face_parts,
)
from .topology3d import refined_topology
from .validation import MeshError

__all__ = ["UNIFORM_BISECTIONS", "bisect_mesh", "matches", "tagged", "tags_of"]

logger = logging.getLogger(__name__)

#: Bisections of every cell per level of uniform refinement in 3D: ``h`` halves and the
#: number of cells grows eightfold (the children of a Kuhn cell after three bisections are
#: Kuhn cells of half the size).
UNIFORM_BISECTIONS = 3

#: The cached properties of :class:`Mesh` that hold its edge and facet topology; a refined
#: mesh receives them from :func:`~signorini.mesh.topology3d.refined_topology`.
EDGE_CACHE, FACET_CACHE = "_edge_topology", "_topology"


def bisect_mesh(
    mesh: Mesh, marked: np.ndarray, bisections: int = 1
) -> tuple[Mesh, np.ndarray, np.ndarray, np.ndarray]:
    """Bisect the marked cells of a tetrahedral mesh ``bisections`` times each (the children
    of a marked cell are marked for the next bisection), with closure.

    Parameters
    ----------
    mesh : Mesh
        ``dim == 3``.
    marked : (n_cells,) bool array
    bisections : int
        1 for ``refine_nvb``, :data:`UNIFORM_BISECTIONS` for a uniform level.

    Returns
    -------
    mesh : Mesh
        The refined mesh (old points keep their indices; new points follow), tagged.
    parent : (n_cells_new,) int64 array
        The old cell that contains each new cell.
    edge_point : (n_edges_old,) int64 array
        The new vertex at the midpoint of each bisected old edge, ``-1`` elsewhere.
    parent_edge : (n_points_new - n_points_old, 2) int64 array
        The ends of the edge each new vertex bisected (old edges and edges made in this
        step; :attr:`~signorini.mesh.refine.Refinement.parent_edge`).

    Raises
    ------
    MeshError
        If a new vertex placed on a surface turns a cell inside out or flat.
    """
    old = edge_key(mesh.edges[:, 0], mesh.edges[:, 1])
    edge_point = np.full(old.size, -1, dtype=np.int64)
    parent = np.arange(mesh.n_cells, dtype=np.int64)
    marked = np.asarray(marked, dtype=bool)
    n_old = mesh.n_points
    ends = []
    for _ in range(bisections):  # a loop over bisections, not cells
        mesh, step, split_key, split_point = _bisect_once(mesh, marked[parent])
        parent = parent[step]
        if split_key.size:
            pos = np.minimum(np.searchsorted(split_key, old), split_key.size - 1)
            hit = (split_key[pos] == old) & (edge_point < 0)
            edge_point[hit] = split_point[pos[hit]]
            by_point = np.argsort(split_point)  # new points are numbered in order
            ends.append(np.column_stack(np.divmod(split_key[by_point], KEY_BASE)))
    parent_edge = np.concatenate(ends) if ends else np.zeros((0, 2), dtype=np.int64)
    assert parent_edge.shape[0] == mesh.n_points - n_old
    return mesh, parent, edge_point, parent_edge


def _bisect_once(mesh: Mesh, marked: np.ndarray) -> tuple[Mesh, np.ndarray, np.ndarray, np.ndarray]:
    """One :func:`~signorini.mesh.bisect3d.bisect_tagged` of a Mesh: the tagged child mesh,
    the parent map and the bisected edges' keys and new vertices."""
    tags = tags_of(mesh)
    curved = np.array([isinstance(c, Surface) for c in mesh.curves], dtype=bool)

    def halfway(part: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return mesh.curves[part].halfway(a, b)

    result = bisect_tagged(
        mesh.points, tags, marked, curved=curved if curved.any() else None, halfway=halfway
    )
    cells = mesh_cells(result.tags)
    if curved.any():
        _check_volumes(result.points, cells, mesh.n_points)
    boundary, part = boundary_of(cells, result.tags)
    refined = Mesh(
        result.points,
        cells,
        boundary,
        part,
        mesh.part_names,
        validate=False,
        curves=mesh.curves,
        cell_region=mesh.cell_region[result.parent],  # a child takes its parent's region
        region_names=mesh.region_names,
    )
    setattr(refined, ATTRIBUTE, result.tags)
    if np.array_equal(mesh.cells, mesh_cells(tags)):  # kept rows keep their local order
        known = refined_topology(
            mesh.edges,
            mesh.cell2edge,
            mesh.facets,
            mesh.cell2facet,
            cells,
            result.touched,
            result.split_key,
        )
        if known is not None:  # hand the child its topology (Mesh's cached properties)
            refined.__dict__[EDGE_CACHE], refined.__dict__[FACET_CACHE] = known
    return refined, result.parent, result.split_key, result.split_point


def _check_volumes(points: np.ndarray, cells: np.ndarray, n_old: int) -> None:
    """Raise if a cell with a new vertex (index ``>= n_old``) is not positively oriented."""
    touched = np.flatnonzero((cells >= n_old).any(axis=1))
    p = points[cells[touched]]
    det = np.linalg.det(p[:, 1:] - p[:, :1])
    if np.any(det <= 0):
        bad = cells[touched[np.flatnonzero(det <= 0)[0]]]
        raise MeshError(
            f"refinement: placing new vertices on a surface turns cell {bad.tolist()} inside "
            "out or flat: the initial mesh is too coarse for the surface"
        )


def tagged(mesh: Mesh, order: np.ndarray, gamma: np.ndarray | None = None) -> Mesh:
    """``mesh`` with the tag order ``order (n_cells, 4)`` (e.g. the Kuhn paths a builder
    knows, :func:`~signorini.mesh.builders3d.kuhn_paths`) and types ``gamma`` (0 by default)
    attached for bisection; returns ``mesh``."""
    gamma = np.zeros(mesh.n_cells, np.int8) if gamma is None else gamma
    tags: Tags = with_face_parts(mesh.points, order, gamma, mesh.boundary, mesh.boundary_part)
    if not np.array_equal(np.sort(order, axis=1), np.sort(mesh.cells, axis=1)):
        raise MeshError("tagged: the order must list each cell's own vertices")
    setattr(mesh, ATTRIBUTE, tags)
    return mesh


def matches(points: np.ndarray, tags: Tags) -> bool:
    """Whether :data:`UNIFORM_BISECTIONS` bisections of every cell each need one round, no
    closure: a consequence of Stevenson's matching condition (a check, not a proof)."""
    for _ in range(UNIFORM_BISECTIONS):  # a loop over bisections, not cells
        result = bisect_tagged(points, tags, np.ones(tags.order.shape[0], dtype=bool))
        if result.rounds != 1:
            return False
        points, tags = result.points, result.tags
    return True


def tags_of(mesh: Mesh) -> Tags:
    """The :class:`~signorini.mesh.tags3d.Tags` of a tetrahedral mesh, attached to it: those
    refinement (or :func:`tagged`) attached; else the Kuhn paths of an axis-aligned Kuhn mesh
    (:func:`~signorini.mesh.tags3d.kuhn_tags`); else the Kuhn paths of a mapped Kuhn grid in
    the builders' cell order (:func:`~signorini.mesh.builders3d.kuhn_paths`, plain or
    mirrored) if they pass :func:`matches`; else (any conforming mesh, e.g. from Gmsh)
    Diening, Gehring and Storn's initialisation from a greedy vertex colouring
    (:func:`~signorini.mesh.tags3d.coloured_tags`, logged at ``INFO``), with which the
    bisection keeps its closure estimate and shape regularity (docs/method.md, *The initial
    condition*)."""
    tags = getattr(mesh, ATTRIBUTE, None)
    if tags is not None:
        return tags
    gamma = np.zeros(mesh.n_cells, np.int8)

    def tags_in(order: np.ndarray) -> Tags:
        return with_face_parts(mesh.points, order, gamma, mesh.boundary, mesh.boundary_part)

    try:
        tags = tags_in(kuhn_tags(mesh.points, mesh.cells))
    except MeshError:
        tags = None
    if tags is None and mesh.n_cells % 6 == 0:
        for mirrored in (False, True):
            candidate = tags_in(kuhn_paths(mesh.cells, mirrored=mirrored))
            if matches(mesh.points, candidate):
                tags = candidate
                break
    if tags is None:
        colour = greedy_colouring(mesh.edges, mesh.n_points)
        tags = tags_in(coloured_tags(mesh.cells, colour))
        logger.info(
            "bisection: %d tetrahedra tagged from a greedy colouring of their vertices in %d "
            "colours (Diening-Gehring-Storn)",
            mesh.n_cells,
            int(colour.max(initial=0)) + 1,
        )
    setattr(mesh, ATTRIBUTE, tags)
    return tags
