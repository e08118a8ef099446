"""Tetrahedral meshes from files read through meshio (e.g. Gmsh ``.msh``):
:func:`~signorini.mesh.gmsh.read_mesh` dispatches here when a file holds tetrahedra.

- Cells: ``tetra`` or ``tetra10`` blocks (meshio lists ``tetra10`` nodes in VTK's order, the
  edges of :data:`~signorini.mesh.reference.TETRAHEDRON`); their physical volume groups are
  the cell regions (``"region<tag>"`` for an unnamed one, ``"body"`` for cells in none).
- Boundary parts: ``triangle`` or ``triangle6`` blocks in physical surface groups, named after
  the groups (``"part<tag>"`` for an unnamed one; tag 0, Gmsh's mark for *no* group, names
  none). Every boundary face must be in one (:meth:`Mesh.from_arrays`).
- A triangle that is not a face of a tetrahedron is a 2D cell beside the 3D ones: refused,
  naming its group. Line and vertex elements are ignored.
- Second order: a ``tetra10`` or ``triangle6`` midpoint off its edge's chord (beyond
  :data:`~signorini.mesh.gmsh.STRAIGHT_TOL` times the mesh's size) is allowed only on the
  edges of a part that the caller gives an exact surface (``surfaces``), and must lie on it
  (within ``SURFACE_RTOL`` times the mesh's diameter); the part then carries the surface
  (:meth:`Mesh.with_curve`), which places refinement's and the P2 space's edge nodes.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .gmsh import STRAIGHT_TOL, _check_finite
from .mesh import Mesh, MeshError
from .reference import TETRAHEDRON, TRIANGLE
from .regions import DEFAULT_REGION
from .surfaces import Surface
from .topology import entity_keys, find_rows

__all__ = ["SURFACE_RTOL", "read_tetrahedra"]

#: A second-order midpoint of a part carrying a surface lies on it within this times the
#: mesh's diameter (as :meth:`Mesh.with_curve` asks of the vertices).
SURFACE_RTOL = 1e-8

_TETRA = (TETRAHEDRON.vtk_name, TETRAHEDRON.vtk_p2_name)
_TRIANGLES = (TRIANGLE.vtk_name, TRIANGLE.vtk_p2_name)


def _names(m: object, dim: int) -> dict[int, str]:
    """Physical group names of dimension ``dim`` by tag (meshio's ``field_data``)."""
    data = m.field_data or {}  # type: ignore[attr-defined]
    return {int(v[0]): k for k, v in data.items() if len(v) > 1 and v[1] == dim}


def read_tetrahedra(
    path: Path,
    m: object,
    parts: Sequence[str] | None = None,
    surfaces: Mapping[str, Surface] | None = None,
) -> Mesh:
    """The tetrahedral mesh of the meshio mesh ``m`` read from ``path`` (module docstring).

    Parameters
    ----------
    path : Path
        The file, for messages.
    m : meshio.Mesh
    parts : sequence of str, optional
        The parts to keep (default: every named surface group).
    surfaces : mapping part name -> Surface, optional
        The exact surfaces of curved parts.

    Raises
    ------
    MeshError
        Naming the file and the fault: non-finite nodes, no physical surface groups, a
        triangle that is no face of a tetrahedron (2D and 3D cells mixed), a missing part,
        a midpoint off its chord on an edge of no curved part, or off its part's surface.
    """
    blocks = [(i, b) for i, b in enumerate(m.cells) if b.type in _TETRA]  # type: ignore[attr-defined]
    cells = np.concatenate([b.data[:, :4] for _, b in blocks]).astype(np.int64)
    xyz = np.asarray(m.points, dtype=np.float64)  # type: ignore[attr-defined]
    _check_finite(path, xyz)
    if xyz.shape[1] != 3:
        raise MeshError(f"{path}: tetrahedra need points with three coordinates")
    used = np.unique(cells)
    renumber = np.full(len(xyz), -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    points, cells = xyz[used], renumber[cells]
    tags = m.cell_data.get("gmsh:physical")  # type: ignore[attr-defined]
    groups = _surface_groups(path, m, tags, renumber, cells)
    if parts is not None:
        missing = [p for p in parts if p not in groups]
        if missing:
            raise MeshError(f"{path} has no boundary group(s) {missing}; it has {sorted(groups)}")
        groups = {p: groups[p] for p in parts}
    regions = None
    if tags is not None:
        volume = np.concatenate([np.asarray(tags[i]).reshape(-1) for i, _ in blocks])
        if volume.any():
            names = _names(m, 3)
            tag, index = np.unique(volume.astype(int), return_inverse=True)
            label = [DEFAULT_REGION if t == 0 else names.get(int(t), f"region{t}") for t in tag]
            regions = np.asarray(label, dtype=object)[index.reshape(-1)].astype(str)
    try:
        mesh = Mesh.from_arrays(points, cells, groups, regions=regions)
        return _with_surfaces(mesh, m, renumber, dict(surfaces or {}))
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def _surface_groups(
    path: Path, m: object, tags: list | None, renumber: np.ndarray, cells: np.ndarray
) -> dict[str, np.ndarray]:
    """The boundary faces ``(k, 3)`` (new numbering) of each named physical surface group;
    a triangle that is no face of a tetrahedron is refused."""
    names = _names(m, 2)
    faces = cells[:, TETRAHEDRON.facets].reshape(-1, 3)
    groups: dict[str, list[np.ndarray]] = {}
    for i, block in enumerate(m.cells):  # type: ignore[attr-defined]
        if block.type not in _TRIANGLES or tags is None:
            continue
        for tag in np.unique(tags[i]):  # a loop over the block's groups
            if tag == 0:
                continue
            name = names.get(int(tag), f"part{int(tag)}")
            tri = renumber[block.data[tags[i] == tag][:, :3]]
            _, found = find_rows(faces, np.where(tri < 0, 0, tri), max(len(renumber), 1))
            stray = (tri < 0).any(1) | ~found
            if stray.any():
                raise MeshError(
                    f"{path} mixes 2D and 3D cells: {int(stray.sum())} triangle(s) of group "
                    f"{name!r} are not faces of any tetrahedron (first: file nodes "
                    f"{(block.data[tags[i] == tag][np.argmax(stray), :3] + 1).tolist()}); a "
                    "3D mesh's triangles must be its boundary faces"
                )
            groups.setdefault(name, []).append(tri)
    if not groups:
        raise MeshError(
            f"{path} has no tagged boundary faces (physical groups); the boundary parts cannot "
            "be named: put the boundary surfaces in physical surface groups (Gmsh: Physical "
            "Surface)"
        )
    return {k: np.concatenate(v) for k, v in groups.items()}


def _given_midpoints(m: object, renumber: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The vertex pairs ``(k, 2)`` (new numbering) and midpoints ``(k, 3)`` of every edge of
    the ``tetra10`` and ``triangle6`` elements (repeats included)."""
    pairs, mids = [np.zeros((0, 2), dtype=np.int64)], [np.zeros((0, 3))]
    for block in m.cells:  # type: ignore[attr-defined]
        if block.type == TETRAHEDRON.vtk_p2_name:
            local = TETRAHEDRON.edge_nodes
        elif block.type == TRIANGLE.vtk_p2_name:
            local = TRIANGLE.edge_nodes
        else:
            continue
        nodes = block.data[:, local].reshape(-1, 3)
        pairs.append(renumber[nodes[:, :2]])
        mids.append(np.asarray(m.points, dtype=np.float64)[nodes[:, 2]])  # type: ignore[attr-defined]
    pairs, mids = np.concatenate(pairs), np.concatenate(mids)
    keep = (pairs >= 0).all(1)
    return pairs[keep], mids[keep]


def _with_surfaces(mesh: Mesh, m: object, renumber: np.ndarray, surfaces: dict) -> Mesh:
    """``mesh`` with each part of ``surfaces`` carrying its surface, after checking that every
    second-order midpoint off its chord is on an edge of such a part and on its surface."""
    unknown = sorted(set(surfaces) - set(mesh.part_names))
    if unknown:
        raise MeshError(f"surfaces for part(s) {unknown}, which the mesh does not have")
    for name, surface in surfaces.items():
        mesh = mesh.with_curve(name, surface)
    pairs, mids = _given_midpoints(m, renumber)
    if not len(pairs):
        return mesh
    key = entity_keys(mesh.edges, mesh.n_points)
    edge = np.minimum(np.searchsorted(key, entity_keys(pairs, mesh.n_points)), key.size - 1)
    diameter = float(np.linalg.norm(np.ptp(mesh.points, axis=0)))
    scale = max(diameter, float(np.abs(mesh.points).max()))
    chord = np.linalg.norm(mids - mesh.edge_midpoints[edge], axis=1)
    carried = np.zeros(mesh.n_edges, dtype=bool)
    for name in surfaces:  # a loop over parts
        carried[mesh.part_edge_indices(mesh.part_index(name))] = True
    off = np.flatnonzero((chord > STRAIGHT_TOL * scale) & ~carried[edge])
    if off.size:
        e = mesh.edges[edge[off[0]]]
        raise MeshError(
            f"{off.size} second-order midpoint(s) lie off their edge's chord on no part with "
            f"a surface (first: edge {e.tolist()} from {mesh.points[e[0]].tolist()} to "
            f"{mesh.points[e[1]].tolist()}, midpoint {mids[off[0]].tolist()}, "
            f"{chord[off[0]]:.3g} off): give the curved part its exact surface, "
            "read_mesh(path, surfaces={part: Sphere(...)})"
        )
    for name, surface in surfaces.items():  # a loop over parts
        mine = np.isin(edge, mesh.part_edge_indices(mesh.part_index(name)))
        own = np.flatnonzero(mine & (chord > STRAIGHT_TOL * scale))  # straight files pass
        gap = np.linalg.norm(surface.project(mids[own]) - mids[own], axis=1)
        if np.any(gap > SURFACE_RTOL * diameter):
            k = own[int(np.argmax(gap))]
            raise MeshError(
                f"a second-order midpoint {mids[k].tolist()} of part {name!r} lies "
                f"{gap.max():.3g} off {surface!r}, more than {SURFACE_RTOL} * diameter"
            )
    return mesh
