"""Discrete solutions as quadratic-triangle VTU files (ParaView), the ``.pvd`` collections of
a run's levels, and the description of every field (``fields.md``), all written atomically.

:data:`POINT_FIELDS`, :data:`CELL_FIELDS` and :data:`NAME_FIELDS` (the field data naming
the regions and bodies) are the one list of the fields: the writer fills them and
``fields.md`` describes them (a field added to the writer is added there).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from ..mesh.bodies import body_names, body_of_cells
from ..mesh.mesh import Mesh
from .files import atomic_write, replacing
from .vtu3d import fields_lines_3d, write_vtu_3d

__all__ = [
    "CELL_FIELDS",
    "NAME_FIELDS",
    "POINT_FIELDS",
    "name_fields",
    "von_mises",
    "write_fields",
    "write_pvd",
    "write_vtu",
]

#: Point data of a level's VTU file: name -> meaning (units are the problem's).
POINT_FIELDS: dict[str, str] = {
    "displacement": "u_h at the node (3 components, z = 0, for ParaView's Warp By Vector)",
    "stress": "the Cauchy stress of u_h at the node, 6 components in VTK's symmetric-tensor "
    "order (xx, yy, zz, xy, yz, xz), yz = xz = 0: σ_xx, σ_yy, σ_xy of Hooke's law (2.1) "
    "from the P2 displacement, averaged over the cells that share the node (one value per "
    "cell at its own nodes: exact where σ is continuous and polynomial of degree ≤ 1); σ_zz "
    "= λ(σ_xx + σ_yy)/(2(λ + μ)) in plane strain, 0 in plane stress",
    "von_mises": "von Mises stress sqrt(((σ_xx−σ_yy)² + (σ_yy−σ_zz)² + (σ_zz−σ_xx)²)/2 + "
    "3σ_xy²) of the nodal stress, σ_zz included",
    "pressure": "on Γ_C the consistent nodal pressure p_z = Λ_z / w_z (0 elsewhere); on the "
    "master part of a contact pair between two bodies the transferred pressure "
    "Σ_j T_jk Λ_j / w_k (docs/method.md, *Two bodies*)",
    "contact_force": "on Γ_C the nodal contact force Λ_z (force per unit thickness; 0 elsewhere)",
    "tangential_pressure": "on Γ_C the consistent friction stress p_t,z = Λ_t,z / w_z along "
    "t_z = (−n_y, n_x); 0 without friction",
    "contact_traction": "on Γ_C the obstacle's traction on the body, −p_z n_z − p_t,z t_z "
    "(3 components); on a pair's master the slave's consistent traction on it",
    "active": "1 where u·n_z = ψ is imposed (the node is in contact), else 0",
    "contact_class": "0 no contact, 1 semi, 2 full contact (the estimator's classes), −1 off Γ_C",
    "contact_state": "0 inactive, 1 stick, 2 slip (a frictionless node in contact slips), −1 "
    "off Γ_C",
}
#: Field data of a level's VTU file (one Int32 value each; ParaView's Information panel and
#: the spreadsheet's Field Data list them, meshio.read returns them as ``field_data``).
NAME_FIELDS: dict[str, str] = {
    "region:<name>": "the index, in the `region` cell field, of the region named after the colon",
    "body:<name>": "the number, in the `body` cell field, of the body named after the colon "
    "(with several bodies)",
}
#: Cell data of a level's VTU file (the eta2 fields with an estimate): name -> meaning.
CELL_FIELDS: dict[str, str] = {
    "region": "the cell's material region, an index into the mesh's region names "
    "(mesh.region_names; 0 where the mesh has one region): the field data `region:<name>` "
    "holds each name's index, and *Regions and bodies* below lists them",
    "body": "with several bodies (a union mesh), the cell's body: 0, 1, … in the union's "
    "order (not written for one body): the field data `body:<name>` holds each body's "
    "number, and *Regions and bodies* below lists them",
    "eta2": "the squared element indicator η_T² (the sum of the contributions)",
    "eta2_k": "the squared contribution η_k,T² of term k = 1, 2, … (docs/method.md, "
    "*Estimator*): one field per term",
}


def von_mises(sig: np.ndarray) -> np.ndarray:
    """von Mises stress of ``(n, 3, 3)`` stress tensors."""
    sxx, syy, szz = sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2]
    sxy, syz, sxz = sig[:, 0, 1], sig[:, 1, 2], sig[:, 0, 2]
    return np.sqrt(
        0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
        + 3.0 * (sxy**2 + syz**2 + sxz**2)
    )


def write_vtu(path: str | os.PathLike, result, estimate=None) -> Path:
    """Write a discrete solution as a VTU file of quadratic triangles (P2; ``triangle`` cells
    for P1, the element's :attr:`~signorini.fem.element.Element.vtk_cell`).

    The point fields are :data:`POINT_FIELDS`, the cell fields (with an estimate)
    :data:`CELL_FIELDS`. At a corner node with two constraints the contact scalars are the
    larger of the two, the tangential pressure and the traction their sums.

    Parameters
    ----------
    path : path of the ``.vtu`` file
    result : ContactResult
    estimate : Estimate, optional
    """
    if result.space.mesh.dim == 3:  # quadratic tetrahedra
        return write_vtu_3d(path, result, von_mises)
    import meshio

    space, cs = result.space, result.contact
    n = space.n_nodes
    points = np.column_stack([space.node_points, np.zeros(n)])
    disp = np.column_stack([result.u, np.zeros(n)])
    pressure = np.zeros(n)
    force = np.zeros(n)
    active = np.zeros(n, dtype=np.int32)
    klass = np.full(n, -1, dtype=np.int32)
    state = np.full(n, -1, dtype=np.int32)
    tangential = np.zeros(n)
    traction = np.zeros((n, 3))
    pressure[cs.nodes] = -np.inf  # a corner node's two constraints: the larger value
    force[cs.nodes] = -np.inf
    np.maximum.at(pressure, cs.nodes, result.pressure)
    np.maximum.at(force, cs.nodes, result.contact_force)
    np.maximum.at(active, cs.nodes, result.active.astype(np.int32))
    np.maximum.at(klass, cs.nodes, result.classes.astype(np.int32))
    np.maximum.at(state, cs.nodes, result.state.astype(np.int32))
    p_t = result.tangential_pressure
    np.add.at(tangential, cs.nodes, p_t)
    t = cs.tangent[:, 0]
    np.add.at(traction[:, :2], cs.nodes, -result.pressure[:, None] * cs.normal - p_t[:, None] * t)
    masters, master_traction, master_pressure = result.master_side  # empty for one body
    pressure[masters] = master_pressure
    traction[masters, :2] = master_traction
    sig = result.nodal_stress  # (n_nodes, 3, 3): ContactResult.nodal_stress
    # VTK's symmetric tensor order: xx, yy, zz, xy, yz, xz
    voigt = np.column_stack(
        [sig[:, 0, 0], sig[:, 1, 1], sig[:, 2, 2], sig[:, 0, 1], sig[:, 1, 2], sig[:, 0, 2]]
    )
    # cell fields: one array per field, in the cells' order (each one in CELL_FIELDS)
    cell_data = {"region": [space.mesh.cell_region.astype(np.int32)]}  # into mesh.region_names
    body = body_of_cells(space.mesh)
    if body.max(initial=0) > 0:
        cell_data["body"] = [body.astype(np.int32)]
    if estimate is not None:
        cell_data["eta2"] = [estimate.eta2]
        for k in range(estimate.eta2_cell.shape[0]):
            cell_data[f"eta2_{k + 1}"] = [estimate.eta2_cell[k]]
    mesh = meshio.Mesh(
        points,
        [(space.element.vtk_cell, space.cell_nodes)],
        point_data={
            "displacement": disp,
            "stress": voigt,
            "von_mises": von_mises(sig),
            "pressure": pressure,
            "contact_force": force,
            "tangential_pressure": tangential,
            "contact_traction": traction,
            "active": active,
            "contact_class": klass,
            "contact_state": state,
        },
        cell_data=cell_data,
    )
    with replacing(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
        _append_field_data(tmp, name_fields(space.mesh, body))
    return Path(path)


def name_fields(mesh: Mesh, body: np.ndarray | None = None) -> dict[str, int]:
    """The field data of :data:`NAME_FIELDS`: ``region:<name>`` -> the region's index, and
    with several bodies ``body:<name>`` -> the body's number (in its ``body`` cell field;
    ``body``: the mesh's :func:`~signorini.mesh.bodies.body_of_cells` where known)."""
    fields = {f"region:{name}": k for k, name in enumerate(mesh.region_names)}
    names = body_names(mesh, body)
    if len(names) > 1:
        fields.update({f"body:{name}": b for b, name in enumerate(names)})
    return fields


_GRID_END = b"</UnstructuredGrid>\n</VTKFile>\n"


def _append_field_data(path: Path, fields: dict[str, int]) -> None:
    """Add ``fields`` as the VTK field data of the VTU file at ``path`` (meshio's VTU writer
    writes none): a ``FieldData`` element after the piece, where VTK's reader finds it as
    well as before, appended in place without rewriting the file."""
    arrays = "".join(
        f'<DataArray type="Int32" Name={quoteattr(name)} NumberOfTuples="1" '
        f'format="ascii">{value}</DataArray>\n'
        for name, value in fields.items()
    )
    with open(path, "r+b") as f:
        f.seek(-len(_GRID_END), os.SEEK_END)
        end = f.tell()
        if f.read() != _GRID_END:
            raise RuntimeError(f"{path}: meshio's VTU file does not end as expected")
        f.seek(end)
        f.write(b"<FieldData>\n" + arrays.encode() + b"</FieldData>\n" + _GRID_END)


def write_pvd(folder: str | os.PathLike, levels: Sequence[tuple[int, int]]) -> list[Path]:
    """Write ``levels.pvd`` (time = level index) and ``levels_ndof.pvd`` (time = N_dof): the
    ``level_NNN.vtu`` files of ``levels`` as ParaView collections, so that the time slider
    steps through the levels (and a plot over time is against N_dof in the second).

    Parameters
    ----------
    folder : the run folder
    levels : sequence of (level, ndof)
    """
    folder = Path(folder)
    written = []
    for name, key in (("levels.pvd", 0), ("levels_ndof.pvd", 1)):
        rows = "".join(
            f'    <DataSet timestep="{entry[key]}" part="0" file="level_{entry[0]:03d}.vtu"/>\n'
            for entry in levels
        )
        text = (
            '<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            "  <Collection>\n" + rows + "  </Collection>\n</VTKFile>\n"
        )
        written.append(atomic_write(folder / name, text.encode()))
    return written


def write_fields(path: str | os.PathLike, mesh: Mesh | None = None) -> Path:
    """Write the description of the VTU files' fields as Markdown (``fields.md``); with the
    run's ``mesh``, which region index and which body number is which name (the same on
    every level: refinement keeps the regions, and the bodies' order is the union's); a
    tetrahedral ``mesh``'s files are described by :func:`~.vtu3d.fields_lines_3d`."""
    three = mesh is not None and mesh.dim == 3
    lines = (
        fields_lines_3d()
        if three
        else [
            "# Fields of the level_NNN.vtu files",
            "",
            "Quadratic triangles (VTK_QUADRATIC_TRIANGLE: 3 vertices, then the midpoints of "
            "v0-v1, v1-v2, v2-v0); linear triangles (VTK_TRIANGLE) in a run with --element P1. "
            "`levels.pvd` collects the levels with the level index as "
            "time, `levels_ndof.pvd` with N_dof as time. Units are those of the problem's data.",
            "",
            "## Point data",
            "",
            "| field | meaning |",
            "|---|---|",
            *(f"| `{name}` | {text} |" for name, text in POINT_FIELDS.items()),
            "",
            "## Cell data",
            "",
            "| field | meaning |",
            "|---|---|",
            *(f"| `{name}` | {text} |" for name, text in CELL_FIELDS.items()),
            "",
            "## Field data",
            "",
            "| field | meaning |",
            "|---|---|",
            *(f"| `{name}` | {text} |" for name, text in NAME_FIELDS.items()),
        ]
    )
    if mesh is not None:
        lines += ["", "## Regions and bodies", "", "| `region` | region name |", "|---|---|"]
        lines += [f"| {k} | `{name}` |" for k, name in enumerate(mesh.region_names)]
        names = body_names(mesh)
        if len(names) > 1:
            lines += ["", "| `body` | body name |", "|---|---|"]
            lines += [f"| {b} | `{name}` |" for b, name in enumerate(names)]
    return atomic_write(path, ("\n".join(lines) + "\n").encode())
