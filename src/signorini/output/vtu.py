"""Discrete solutions as quadratic-triangle VTU files (ParaView), written atomically."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .files import replacing

__all__ = ["write_vtu"]


def write_vtu(path: str | os.PathLike, result, estimate=None) -> Path:
    """Write a discrete solution as a quadratic-triangle VTU file.

    Point data: ``displacement`` (3 components, z = 0, for ParaView's "Warp By Vector"),
    and on Γ_C ``pressure`` (consistent nodal pressure p_z), ``contact_force`` (Λ_z),
    ``tangential_pressure`` (the consistent friction stress ``p_t,z = Λ_t,z / w_z`` along
    ``t_z = (−n_y, n_x)``; 0 without friction), ``contact_traction`` (``−p_z n_z − p_t,z t_z``,
    3 components: the obstacle's traction on the body as a vector), ``active`` (1 where
    u·n_z = ψ is imposed), ``contact_class`` (0 none, 1 semi, 2 full, −1 off Γ_C) and
    ``contact_state`` (0 inactive, 1 stick, 2 slip, −1 off Γ_C; a frictionless node in contact
    slips). At a corner node with two constraints the scalars are the larger of the two, the
    tangential pressure and the traction their sums. Cell data: ``region`` (the cell's region,
    an index into ``mesh.region_names``), ``eta2`` (element indicators)
    and ``eta2_k`` per contribution when an estimate is given.

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
    cell_data = {"region": [space.mesh.cell_region.astype(np.int32)]}  # into mesh.region_names
    if estimate is not None:
        cell_data["eta2"] = [estimate.eta2]
        for k in range(estimate.eta2_cell.shape[0]):
            cell_data[f"eta2_{k + 1}"] = [estimate.eta2_cell[k]]
    mesh = meshio.Mesh(
        points,
        [("triangle6", space.cell_nodes)],
        point_data={
            "displacement": disp,
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
