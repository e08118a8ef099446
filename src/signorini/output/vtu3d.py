"""3D solutions as VTU files of quadratic tetrahedra (docs/method.md, *Three dimensions:
solving elasticity*): ``tetra10`` cells (VTK_QUADRATIC_TETRA, 24) with their boundary faces
as ``triangle6`` cells (VTK_QUADRATIC_TRIANGLE, 22) carrying their part, so that ParaView's
threshold on ``part`` shows a boundary part.

The node order is VTK's, the one ParaView expects: the four vertices, then the edge nodes
of the edges 01, 12, 20, 03, 13, 23 (:data:`~signorini.mesh.reference.TETRAHEDRON`'s edge
order, the space's own numbering); a face's three vertices in outward order, then its edges
ab, bc, ca (:meth:`~signorini.fem.space3d.P2TetSpace.facet_nodes`). :func:`write_vtu_3d` is
what :func:`~.vtu.write_vtu` writes for a tetrahedral mesh.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .files import replacing

__all__ = ["CELL_FIELDS_3D", "POINT_FIELDS_3D", "write_vtu_3d"]

#: Point data of a 3D level's VTU file: name -> meaning (units are the problem's).
POINT_FIELDS_3D: dict[str, str] = {
    "displacement": "u_h at the node (3 components)",
    "stress": "the Cauchy stress of u_h at the node, 6 components in VTK's symmetric-tensor "
    "order (xx, yy, zz, xy, yz, xz), averaged over the cells that share the node",
    "von_mises": "von Mises stress of the nodal stress",
}
#: Cell data of a 3D level's VTU file: name -> meaning (-1 where it does not apply).
CELL_FIELDS_3D: dict[str, str] = {
    "region": "a tetrahedron's material region (index into mesh.region_names); -1 on faces",
    "part": "a boundary face's part (index into mesh.part_names); -1 on tetrahedra",
}


def write_vtu_3d(
    path: str | os.PathLike, result, mises: Callable[[np.ndarray], np.ndarray]
) -> Path:
    """Write the 3D solution ``result`` (a ContactResult on a tetrahedral mesh) as a VTU file
    of ``tetra10`` cells and ``triangle6`` boundary faces; the fields are
    :data:`POINT_FIELDS_3D` and :data:`CELL_FIELDS_3D`.

    Parameters
    ----------
    path : path of the ``.vtu`` file
    result : ContactResult
        ``result.u (n_nodes, 3)`` on ``result.space`` (a P2TetSpace).
    mises : callable
        The von Mises stress ``(n,)`` of stress tensors ``(n, 3, 3)`` (:func:`~.vtu.von_mises`).
    """
    import meshio

    space, mesh = result.space, result.mesh
    sigma = result.nodal_stress  # (n_nodes, 3, 3): fem.elasticity3d.nodal_stress_3d
    voigt = sigma.reshape(-1, 9)[:, [0, 4, 8, 1, 5, 2]]  # xx, yy, zz, xy, yz, xz
    faces = space.facet_nodes(mesh.boundary_facet)
    n_cells, n_faces = mesh.n_cells, faces.shape[0]
    data = meshio.Mesh(
        space.node_points,
        [("tetra10", space.cell_nodes), ("triangle6", faces)],
        point_data={"displacement": result.u, "stress": voigt, "von_mises": mises(sigma)},
        cell_data={
            "region": [mesh.cell_region.astype(np.int32), np.full(n_faces, -1, np.int32)],
            "part": [np.full(n_cells, -1, np.int32), mesh.boundary_part.astype(np.int32)],
        },
    )
    with replacing(path) as tmp:
        meshio.write(tmp, data, file_format="vtu")
    return Path(path)
