"""Several bodies in one mesh: the disjoint union of separately meshed bodies
(docs/method.md, *Two bodies*).

Each body keeps its own points, cells, boundary parts, curves and regions; in the union a
part ``top`` of body ``upper`` is named ``"upper.top"`` and a region ``coat`` of it
``"upper.coat"`` (a body meshed without regions is the one region ``"upper"``). The bodies'
meshes need not match where they touch: their points may coincide there or not, and no cell
of one may lie inside the other. Refinement, the P2 space, assembly and the estimator treat
the union as one mesh whose components are the bodies.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .mesh import Mesh
from .regions import DEFAULT_REGION
from .validation import MeshError, winding_numbers
from .validation3d import solid_winding_numbers

__all__ = ["BODY_SEPARATOR", "body_names", "body_of_cells", "union"]

#: joins a body's name and its part's or region's name in the union
BODY_SEPARATOR = "."


def union(bodies: Mapping[str, Mesh]) -> Mesh:
    """One mesh of the bodies ``{name: mesh}``, in the mapping's order.

    Parameters
    ----------
    bodies : mapping body name -> Mesh
        Two or more bodies, each a valid mesh (built by :meth:`Mesh.from_arrays`, a
        builder or :func:`~signorini.mesh.gmsh.read_mesh`); names without
        :data:`BODY_SEPARATOR`.

    Returns
    -------
    Mesh
        Points and cells of the bodies one after the other; parts ``"body.part"``, regions
        ``"body"`` (``"body.region"`` for a body with several), every part's curve kept.

    Raises
    ------
    MeshError
        If ``bodies`` is not a mapping of at least two names to meshes, a name is empty or
        holds the separator, or a cell of one body lies inside another body (they overlap
        instead of touching; the message names both bodies and the cell's centroid).
    """
    if not isinstance(bodies, Mapping) or len(bodies) < 2:
        raise MeshError(
            "union(bodies=...) takes a mapping of two or more body names to meshes, got "
            f"{type(bodies).__name__}"
            + (f" of {len(bodies)}" if isinstance(bodies, Mapping) else "")
        )
    for name, mesh in bodies.items():
        if not isinstance(name, str) or not name or BODY_SEPARATOR in name:
            raise MeshError(
                f"union: body names must be non-empty strings without {BODY_SEPARATOR!r}, "
                f"got {name!r}"
            )
        if not isinstance(mesh, Mesh):
            raise MeshError(
                f"union: body {name!r} must be a signorini Mesh, got {type(mesh).__name__}"
            )
    meshes = list(bodies.values())
    names = list(bodies)
    _check_apart(names, meshes)
    offset = np.cumsum([0] + [m.n_points for m in meshes])
    part_names, region_names = [], []
    boundary_part, cell_region, curves = [], [], []
    for name, mesh in bodies.items():
        boundary_part.append(mesh.boundary_part + len(part_names))
        part_names += [f"{name}{BODY_SEPARATOR}{p}" for p in mesh.part_names]
        curves += list(mesh.curves)
        cell_region.append(mesh.cell_region + len(region_names))
        if mesh.region_names == (DEFAULT_REGION,):
            region_names.append(name)
        else:
            region_names += [f"{name}{BODY_SEPARATOR}{r}" for r in mesh.region_names]
    return Mesh(
        np.concatenate([m.points for m in meshes]),
        np.concatenate([m.cells + offset[b] for b, m in enumerate(meshes)]),
        np.concatenate([m.boundary + offset[b] for b, m in enumerate(meshes)]),
        np.concatenate(boundary_part),
        part_names,
        validate=False,  # each body is valid; touching points may coincide across bodies
        curves=curves,
        cell_region=np.concatenate(cell_region),
        region_names=region_names,
    )


def _check_apart(names: list[str], meshes: list[Mesh]) -> None:
    """No cell centroid of one body lies inside another (winding number of its boundary)."""
    for a, mesh in enumerate(meshes):  # a loop over bodies
        segments = mesh.oriented_boundary(np.flatnonzero(mesh.facet2cell[:, 1] < 0))
        winding = solid_winding_numbers if mesh.dim == 3 else winding_numbers
        for b, other in enumerate(meshes):
            if a == b:
                continue
            if other.dim != mesh.dim:
                raise MeshError(
                    f"union: body {names[b]!r} is {other.dim}D and body {names[a]!r} "
                    f"{mesh.dim}D: the bodies of one mesh have one dimension"
                )
            centroid = other.points[other.cells].mean(axis=1)
            inside = np.flatnonzero(winding(mesh.points, segments, centroid) != 0)
            if inside.size:
                x = ", ".join(f"{v:.6g}" for v in centroid[inside[0]])
                raise MeshError(
                    f"union: body {names[b]!r} overlaps body {names[a]!r}: the centroid "
                    f"({x}) of its cell {inside[0]} ({inside.size} cell(s) "
                    "in all) lies inside the other body. Bodies in contact touch along their "
                    "boundaries; move them apart"
                )


def body_of_cells(mesh: Mesh) -> np.ndarray:
    """The body ``(n_cells,)`` of each cell: the connected components of the cells joined
    through shared edges, numbered in the order of their smallest point index (ties, cells
    meeting at a point only, in the order of their first cell).

    A union numbers its points body after body and refinement keeps the old points' indices
    (new points follow), so on a union and on every refinement of one the bodies are in the
    union's order when each body is connected; the cells' order, which refinement changes,
    does not enter.
    """
    e2c = mesh.facet2cell
    inner = e2c[:, 1] >= 0
    n = mesh.n_cells
    graph = sp.coo_matrix(
        (np.ones(int(inner.sum()), dtype=np.int8), (e2c[inner, 0], e2c[inner, 1])), shape=(n, n)
    )
    n_comp, label = connected_components(graph, directed=False)
    first_point = np.full(n_comp, mesh.n_points)
    np.minimum.at(first_point, label, mesh.cells.min(axis=1))
    first_cell = np.full(n_comp, n)
    np.minimum.at(first_cell, label, np.arange(n))
    rank = np.empty(n_comp, dtype=np.int64)
    rank[np.lexsort((first_cell, first_point))] = np.arange(n_comp)
    return rank[label]


def body_names(mesh: Mesh, body: np.ndarray | None = None) -> list[str]:
    """The name of each body of :func:`body_of_cells`, in its order: the union's name, read
    from the body's regions (``"name"`` or ``"name.region"``, :func:`union`). A body whose
    regions do not all carry one name, or whose name another body carries too (a mesh that
    is not a union, a body in pieces), is ``"body <number>"``. ``body``: the mesh's
    :func:`body_of_cells` where the caller has it."""
    body = body_of_cells(mesh) if body is None else body
    prefix = np.array([r.split(BODY_SEPARATOR, 1)[0] for r in mesh.region_names])
    pairs = np.unique(np.column_stack([body, mesh.cell_region]), axis=0)
    names = []
    for b in range(int(body.max(initial=-1)) + 1):  # a loop over bodies
        own = np.unique(prefix[pairs[pairs[:, 0] == b, 1]])
        names.append(str(own[0]) if own.size == 1 else "")
    return [
        name if name and names.count(name) == 1 else f"body {b}" for b, name in enumerate(names)
    ]


def validated_bodies(mesh: Mesh) -> Mesh:
    """``mesh`` (built with ``validate=False``) checked as the union of its bodies: each
    body (:func:`body_of_cells`) a valid mesh of its own, no body inside another. Where the
    bodies touch their points may coincide, which one mesh's checks refuse.

    Raises
    ------
    MeshError
        Naming the body (by its number) and the fault.
    """
    body = body_of_cells(mesh)
    bodies = []
    point_body = np.full(mesh.n_points, -1)
    point_body[mesh.cells.ravel()] = np.repeat(body, 3)
    for b in range(int(body.max(initial=-1)) + 1):  # a loop over bodies
        cells = mesh.cells[body == b]
        used = np.unique(cells)
        index = np.full(mesh.n_points, -1)
        index[used] = np.arange(used.size)
        mine = point_body[mesh.boundary[:, 0]] == b
        parts, part = np.unique(mesh.boundary_part[mine], return_inverse=True)
        regions, region = np.unique(mesh.cell_region[body == b], return_inverse=True)
        try:
            bodies.append(
                Mesh(
                    mesh.points[used],
                    index[cells],
                    index[mesh.boundary[mine]],
                    part,
                    [mesh.part_names[p] for p in parts],
                    cell_region=region,
                    region_names=[mesh.region_names[r] for r in regions],
                )
            )
        except MeshError as err:
            raise MeshError(f"body {b}: {err}") from None
    _check_apart([f"{b}" for b in range(len(bodies))], bodies)
    return mesh
