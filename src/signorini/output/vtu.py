"""Discrete solutions as quadratic-triangle VTU files (ParaView), the ``.pvd`` collections of
a run's levels, and the description of every field (``fields.md``), all written atomically.

:data:`POINT_FIELDS` and :data:`CELL_FIELDS` are the one list of the fields: the writer
fills them and ``fields.md`` describes them (a field added to the writer is added there).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..mesh.bodies import body_of_cells
from .files import atomic_write, replacing

__all__ = [
    "CELL_FIELDS",
    "POINT_FIELDS",
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
#: Cell data of a level's VTU file (the eta2 fields with an estimate): name -> meaning.
CELL_FIELDS: dict[str, str] = {
    "region": "the cell's material region, an index into the mesh's region names "
    "(mesh.region_names; 0 where the mesh has one region)",
    "body": "with several bodies (a union mesh), the cell's body: 0, 1, … in the union's "
    "order (not written for one body)",
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
    return Path(path)


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


def write_fields(path: str | os.PathLike) -> Path:
    """Write the description of the VTU files' fields as Markdown (``fields.md``)."""
    lines = [
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
    ]
    return atomic_write(path, ("\n".join(lines) + "\n").encode())
