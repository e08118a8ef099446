"""A level of the loop as plain arrays, for the leaves that draw it (``plots.run_figures``):
they take arrays and part names, never the solver's objects, as :meth:`LevelRecord.row
<signorini.loop.record.LevelRecord.row>` gives the history writer a plain row."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..contact.solution import SLIP, STICK

if TYPE_CHECKING:
    from . import Level

__all__ = ["level_arrays"]


def level_arrays(level: Level) -> dict[str, Any]:
    """The mesh, displacement and contact quantities of ``level``, as plain arrays.

    Returns
    -------
    dict
        ``level`` (int); ``points (n, 2)``, ``cells (m, 3)`` of the level's mesh;
        ``displacement (n_nodes, 2)`` at the P2 nodes (vertices first); ``initial``, the
        problem's initial mesh, and ``parts``, the names of its ``"dirichlet"``,
        ``"neumann"`` and ``"contact"`` parts; per constraint (k of them)
        ``contact_points (k, 2)``, ``active (k,)``, ``pressure (k,)`` p_z, ``gap (k,)`` ψ(z)
        and ``normal (k, 2)`` n_z; with friction on some contact part also ``state (k,)`` as
        the labels ``"inactive"``, ``"stick"``, ``"slip"``, ``contact_displacement (k, 2)``
        and ``tangential_pressure (k,)`` p_t,z.
    """
    res = level.result
    mesh, problem, cs = res.mesh, res.problem, res.contact
    arrays = {
        "level": level.record.level,
        "points": mesh.points,
        "cells": mesh.cells,
        "displacement": res.u,
        "initial": problem.mesh,
        "parts": {
            "dirichlet": problem.dirichlet_parts,
            "neumann": problem.neumann_parts,
            "contact": problem.contact_parts,
        },
        "contact_points": res.space.node_points[cs.nodes],
        "active": res.active,
        "pressure": res.pressure,
        "gap": cs.gap,
        "normal": cs.normal,
    }
    if cs.has_friction:
        arrays["state"] = np.where(
            res.state == STICK, "stick", np.where(res.state == SLIP, "slip", "inactive")
        )
        arrays["contact_displacement"] = res.u[cs.nodes]
        arrays["tangential_pressure"] = res.tangential_pressure
    return arrays
