"""3D solutions as VTU files of quadratic tetrahedra (docs/method.md, *Three dimensions:
solving elasticity*): ``tetra10`` cells (VTK_QUADRATIC_TETRA, 24) with their boundary faces
as ``triangle6`` cells (VTK_QUADRATIC_TRIANGLE, 22) carrying their part, so that ParaView's
threshold on ``part`` shows a boundary part.

The node order is VTK's, the one ParaView expects: the four vertices, then the edge nodes
of the edges 01, 12, 20, 03, 13, 23 (:data:`~signorini.mesh.reference.TETRAHEDRON`'s edge
order, the space's own numbering); a face's three vertices in outward order, then its edges
ab, bc, ca (:meth:`~signorini.fem.space3d.P2TetSpace.facet_nodes`). :func:`write_vtu_3d` is
what :func:`~.vtu.write_vtu` writes for a tetrahedral mesh.

With contact the nodes of Γ_C carry its fields (:data:`CONTACT_FIELDS_3D`: the contact
set's ``fields`` of the solution at the nodes, docs/method.md, *Three dimensions: contact
on faces*); on the ``triangle6`` faces of a contact part (threshold on ``part``) they show
Γ_C.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .files import replacing

__all__ = [
    "CELL_FIELDS_3D",
    "CONTACT_FIELDS_3D",
    "FRICTION_FIELDS_3D",
    "POINT_FIELDS_3D",
    "fields_lines_3d",
    "write_vtu_3d",
]

#: Point data of a 3D level's VTU file: name -> meaning (units are the problem's).
POINT_FIELDS_3D: dict[str, str] = {
    "displacement": "u_h at the node (3 components)",
    "stress": "the Cauchy stress of u_h at the node, 6 components in VTK's symmetric-tensor "
    "order (xx, yy, zz, xy, yz, xz), averaged over the cells that share the node",
    "von_mises": "von Mises stress of the nodal stress",
}
#: Point data of a 3D level's VTU file with contact: name -> (the solution's per-row field,
#: meaning). A node of several rows (contact parts meeting) takes the largest value of its rows.
CONTACT_FIELDS_3D: dict[str, tuple[str, str]] = {
    "gap": ("gap", "on Γ_C u_h·n_z − ψ(z): 0 in contact, negative off the obstacle (nan "
            "elsewhere)"),
    "contact_force": ("contact_force", "on Γ_C the nodal contact force Λ_z (3.17), force "
                      "units (0 elsewhere)"),
    "pressure": ("pressure", "on Γ_C the transformed basis's nodal pressure p̃_z = Λ̃_z / w̃_z "
                 "of condition (b) (nan for condition (a), whose P2 vertex weights vanish; "
                 "0 elsewhere)"),
    "recovered_pressure": ("recovered_pressure", "on Γ_C the P1-lumped recovered pressure "
                           "(T_½ Λ)_v / (T_½ w)_v at a vertex, the mean of its edge's ends at "
                           "a midpoint; exact for a constant pressure (0 elsewhere)"),
    "active": ("active", "1 where the node's constraint is in the final active set (the "
               "node is in contact), else 0"),
    "contact_normal": ("normal", "on Γ_C the constraint's unit direction n_z (3 "
                       "components; the first part's at a node of several; 0 elsewhere)"),
}  # fmt: skip
#: Point data of a 3D level's VTU file with friction (docs/method.md, *Friction in three
#: dimensions: the disc law*): name -> meaning. Written only when a contact part has a law.
FRICTION_FIELDS_3D: dict[str, str] = {
    "contact_state": "0 inactive (free), 1 stick, 2 slip (a frictionless node in contact "
    "slips), −1 off Γ_C",
    "slip_direction": "on Γ_C the unit direction Λ_t / ‖Λ_t‖ of a slipping node's friction "
    "force in Cartesian components (3; the slip increment is along it), 0 elsewhere",
}
#: Cell data of a 3D level's VTU file: name -> meaning (-1 where it does not apply).
CELL_FIELDS_3D: dict[str, str] = {
    "region": "a tetrahedron's material region (index into mesh.region_names); -1 on faces",
    "part": "a boundary face's part (index into mesh.part_names); -1 on tetrahedra",
}


def fields_lines_3d() -> list[str]:
    """The Markdown lines of ``fields.md`` that describe a 3D level's VTU file (the run's
    regions follow, :func:`~.vtu.write_fields`)."""

    def table(rows: dict[str, str]) -> list[str]:
        return ["| field | meaning |", "|---|---|", *(f"| `{k}` | {v} |" for k, v in rows.items())]

    contact = {name: text for name, (_, text) in CONTACT_FIELDS_3D.items()}
    return [
        "# Fields of the level_NNN.vtu files",
        "",
        "Quadratic tetrahedra (VTK_QUADRATIC_TETRA: 4 vertices, then the midpoints of the "
        "edges 01, 12, 20, 03, 13, 23) and their boundary faces as quadratic triangles "
        "(VTK_QUADRATIC_TRIANGLE: 3 vertices in outward order, then the midpoints of ab, bc, "
        "ca), which carry their part (threshold on `part` in ParaView to see one, e.g. Γ_C). "
        "`levels.pvd` collects the levels with the level index as time, `levels_ndof.pvd` "
        "with N_dof as time. Units are those of the problem's data.",
        "",
        "## Point data",
        "",
        *table(POINT_FIELDS_3D),
        "",
        "## Point data of Γ_C (runs with contact parts)",
        "",
        "One value per node of the contact parts' faces, from the constraint rows of the "
        "discrete contact condition (docs/method.md, *Three dimensions: contact on faces*); a "
        "node of several rows (contact parts meeting) takes the largest value of its rows.",
        "",
        *table(contact),
        "",
        "## Point data of Γ_C with friction (runs with a friction law)",
        "",
        *table(FRICTION_FIELDS_3D),
        "",
        "## Cell data",
        "",
        *table(CELL_FIELDS_3D),
    ]


def friction_fields_3d(result, n_nodes: int) -> dict[str, np.ndarray]:
    """:data:`FRICTION_FIELDS_3D` at the ``n_nodes`` nodes of a frictional 3D result: its
    rows' ``state`` and ``direction (k, 2)`` (in the node frame's ``[t_1 t_2]``) carried to
    Cartesian components by the frame ``[n t_1 t_2]`` of each row's node (a frictional node
    has one row, :func:`~signorini.contact.face_friction.face_friction`)."""
    cs = result.contact
    frames = cs.frames[np.searchsorted(cs.frame_nodes, cs.node)]  # (k, 3, 3), columns n t1 t2
    state = np.full(n_nodes, -1, dtype=np.int32)
    state[cs.node] = result.state.astype(np.int32)
    direction = np.zeros((n_nodes, 3))
    direction[cs.node] = np.einsum("kci,ki->kc", frames[:, :, 1:], result.direction)
    return {"contact_state": state, "slip_direction": direction}


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
        ``result.u (n_nodes, 3)`` on ``result.space`` (a P2TetSpace); with contact rows
        (``result.contact.size``) also ``result.contact.fields(u, force, active)``.
    mises : callable
        The von Mises stress ``(n,)`` of stress tensors ``(n, 3, 3)`` (:func:`~.vtu.von_mises`).
    """
    import meshio

    space, mesh = result.space, result.mesh
    sigma = result.nodal_stress  # (n_nodes, 3, 3): fem.elasticity3d.nodal_stress_3d
    voigt = sigma.reshape(-1, 9)[:, [0, 4, 8, 1, 5, 2]]  # xx, yy, zz, xy, yz, xz
    faces = space.facet_nodes(mesh.boundary_facet)
    n_cells, n_faces = mesh.n_cells, faces.shape[0]
    point_data = {"displacement": result.u, "stress": voigt, "von_mises": mises(sigma)}
    if result.contact.size:
        rows = result.contact.fields(result.u, result.contact_force, result.active)
        nodal = rows.at_nodes(space.n_nodes)
        point_data |= {name: nodal[key] for name, (key, _) in CONTACT_FIELDS_3D.items()}
        point_data["active"] = point_data["active"].astype(np.int32)
        if result.contact.has_friction:
            point_data |= friction_fields_3d(result, space.n_nodes)
    data = meshio.Mesh(
        space.node_points,
        [("tetra10", space.cell_nodes), ("triangle6", faces)],
        point_data=point_data,
        cell_data={
            "region": [mesh.cell_region.astype(np.int32), np.full(n_faces, -1, np.int32)],
            "part": [np.full(n_cells, -1, np.int32), mesh.boundary_part.astype(np.int32)],
        },
    )
    with replacing(path) as tmp:
        meshio.write(tmp, data, file_format="vtu")
    return Path(path)
