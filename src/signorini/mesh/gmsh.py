"""Meshes from files: triangles and named boundary groups read through meshio (e.g. Gmsh)."""

from __future__ import annotations

import contextlib
import io as _io
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .mesh import Mesh, MeshError

__all__ = ["read_mesh"]


#: Relative spread of z (against the mesh's extent in x and y) below which z is constant.
FLAT_TOL = 1e-10


def read_mesh(path: str | os.PathLike, parts: Sequence[str] | None = None) -> Mesh:
    """Read a triangular mesh with named boundary parts from a file (e.g. Gmsh ``.msh``).

    Triangles (``triangle`` or ``triangle6``, whose vertices are used) make the cells; line
    elements tagged with physical groups make the boundary parts, named after the groups
    (``gmsh:physical`` / field data; a physical group without a name is called
    ``"part<tag>"``). Physical tag 0 is Gmsh's mark for an element in *no* physical group
    (written when all elements are saved): such lines name no part. The mesh must lie in a
    plane ``z = const``. Cells are oriented counter-clockwise (see
    :meth:`Mesh.from_arrays`) and each cell's longest edge becomes its refinement edge.

    Parameters
    ----------
    path : file readable by meshio
    parts : names of the parts to keep (default: all named line groups)

    Returns
    -------
    Mesh

    Raises
    ------
    MeshError
        If the file cannot be read as a mesh, has no triangles (e.g. only line groups were
        saved: add a physical surface group or save all elements), is not flat in the
        xy-plane, has no boundary lines in a physical group (every boundary edge must be in
        one), or lacks a requested part.
    """
    import meshio

    path = Path(path)
    if not path.is_file():
        raise MeshError(f"no mesh file at {path}")
    said = _io.StringIO()
    try:
        # meshio prints its diagnostics and calls sys.exit() on some foreign files
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):
            m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many types for foreign files
        detail = " ".join(said.getvalue().split()) if isinstance(exc, SystemExit) else exc
        raise MeshError(f"{path} is not a mesh file meshio can read: {detail}") from None
    tri = [(i, b) for i, b in enumerate(m.cells) if b.type in ("triangle", "triangle6")]
    if not tri:
        found = sorted({b.type for b in m.cells})
        hint = (
            ": only line elements were saved; add a physical surface group holding the "
            "triangles (Gmsh: Physical Surface) or save all elements (Gmsh: Mesh.SaveAll = 1)"
            if found and set(found) <= {"line", "line3", "vertex"}
            else ""
        )
        raise MeshError(f"{path} contains no triangles (it has {found or 'no cells'}){hint}")
    cells = np.concatenate([b.data[:, :3] for _, b in tri]).astype(np.int64)
    xyz = np.asarray(m.points, dtype=np.float64)
    # drop points that no triangle uses (e.g. geometry points), renumber
    used = np.unique(cells)
    renumber = np.full(len(xyz), -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    xyz, cells = xyz[used], renumber[cells]
    points = xyz[:, :2]
    if xyz.shape[1] > 2 and xyz.size:
        z = xyz[:, 2]
        extent = float(np.hypot(*np.ptp(points, axis=0)))
        if np.ptp(z) > FLAT_TOL * extent:
            raise MeshError(
                f"{path} is not flat in the xy-plane: z ranges over [{z.min():.6g}, "
                f"{z.max():.6g}]; a mesh must lie in a plane z = const (dropping z would "
                "distort it)"
            )
    tags = m.cell_data.get("gmsh:physical")
    names = {int(v[0]): k for k, v in (m.field_data or {}).items() if len(v) > 1 and v[1] == 1}
    groups: dict[str, list[np.ndarray]] = {}
    for i, block in enumerate(m.cells):
        if block.type not in ("line", "line3") or tags is None:
            continue
        for tag in np.unique(tags[i]):
            if tag == 0:  # in no physical group
                continue
            name = names.get(int(tag), f"part{int(tag)}")
            pairs = renumber[block.data[tags[i] == tag][:, :2]]
            if np.any(pairs < 0):
                raise MeshError(
                    f"boundary group {name!r} uses points that are not vertices of any triangle"
                )
            groups.setdefault(name, []).append(pairs)
    if not groups:
        raise MeshError(
            f"{path} has no tagged boundary lines (physical groups); the boundary "
            "parts cannot be named: put the boundary lines in physical line groups "
            "(Gmsh: Physical Curve)"
        )
    if parts is not None:
        missing = [p for p in parts if p not in groups]
        if missing:
            raise MeshError(f"{path} has no boundary group(s) {missing}; it has {sorted(groups)}")
        groups = {p: groups[p] for p in parts}
    try:
        return Mesh.from_arrays(points, cells, {k: np.concatenate(v) for k, v in groups.items()})
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None
