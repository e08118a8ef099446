"""The master side of contact pairs in the estimator (docs/method.md, *Two bodies*,
"Estimator").

A master part has no condition of its own: its traction is the one the slave exerts on it
through the pair. The slave's nodal contact forces ``f_j = −(Λ_j n_j + Λ_t,j t_j)`` are
carried to the master nodes by the mortar transfer, ``f_m = −T_dᵀ f``, and divided by the
master's basis integrals ``w_k = ∫_{Γ_m} φ_k ds``: the consistent master traction
``g_k = f_k / w_k`` (:attr:`~signorini.contact.ContactResult.master_side`), a P2 function
``g_h`` on the master part (as ``p_z = Λ_z / w_z`` on the slave). The master's facets then
enter η3 as Neumann facets with data ``g_h``: ``h_p ‖σ(u_h) n − g_h‖²``.
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.element import P2
from .terms import neumann_residual
from .traction import CellStress

__all__ = ["master_facets", "master_integrals"]


def master_facets(result: ContactResult) -> np.ndarray:
    """The mesh facets of the master parts of the problem's contact pairs, pair after pair."""
    mesh = result.mesh
    names = list(result.problem.pairs.values())
    return np.concatenate([mesh.part_facets(m) for m in names] or [np.zeros(0, np.int64)])


def master_integrals(
    result: ContactResult, stresses: CellStress, t: np.ndarray, w: np.ndarray, unit: float
) -> tuple[np.ndarray, np.ndarray]:
    """The master facets and η3's ``‖σ(u_h) n − g_h‖²_F`` on each, ``g_h`` the quadratic
    interpolant of the consistent master traction (divided by the stress unit ``unit``)."""
    mesh, space = result.mesh, result.space
    e = master_facets(result)
    values = np.zeros(e.size)
    if e.size == 0:
        return e, values
    nodes, traction, _ = result.master_side
    g = np.zeros((space.n_nodes, 2))
    g[nodes] = traction / unit
    # at [start, end, midpoint], counter-clockwise around the facet's cell as the traction's t
    g_nodes = g[space.facet_nodes(e)]
    phi = P2.facet.basis(t)  # (q, 3)
    for rows, sn, facets in stresses.on_facets(mesh.facet2cell[e, 0], mesh.facet_local[e, 0], t):
        g_h = np.einsum("qa,eac->eqc", phi, g_nodes[rows])
        values[rows] = neumann_residual(sn - g_h, w, facets.speeds(t))
    return e, values
