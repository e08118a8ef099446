"""Stresses of a discrete displacement ``u_h``: ``sigma(u_h)`` in cells, tractions
``sigma(u_h) n`` on edges, and ``div sigma(u_h)`` (the quantities of the residual estimator,
paper Section 5).

Arrays are vectorized over cells: ``vertices (m, 3, 2)`` counter-clockwise and
``u_cell (m, 12)`` the interleaved local coefficients ``u[cell_dofs]``.
"""

from __future__ import annotations

import numpy as np

from ..mesh.geometry import facet_normals
from ..mesh.reference import TRIANGLE
from . import iso, p2
from .mapping import CellMap
from .material import CellMaterials, Material, _per_cell, on_cells, stress, stress_zz

__all__ = [
    "cell_stress",
    "div_stress",
    "facet_traction",
    "nodal_stress",
    "stress_divergence",
    "traction",
]


def cell_stress(
    vertices: CellMap | np.ndarray,
    u_cell: np.ndarray,
    material: Material | CellMaterials,
    xi: np.ndarray,
) -> np.ndarray:
    """Stress ``sigma(u_h)`` at reference points of each cell.

    Parameters
    ----------
    vertices : CellMap or ndarray of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`: through the
        quadratic map on isoparametric cells), or the vertices of straight cells.
    u_cell : ndarray of float, shape (m, 12)
        Interleaved local coefficients.
    material : Material
    xi : ndarray of float, shape (q, 2) or (m, q, 2)
        Reference points, shared or per cell.

    Returns
    -------
    ndarray of float64, shape (m, q, 2, 2)
    """
    if isinstance(vertices, CellMap):
        u, xi = np.asarray(u_cell, dtype=np.float64), np.asarray(xi, dtype=np.float64)

        def group_stress(g):
            points = xi if xi.ndim == 2 else xi[g.cells]
            return stress(on_cells(material, g.cells), g.field_gradients(u[g.cells], points))

        return vertices.per_cell(group_stress)
    return stress(material, p2.field_gradients(vertices, u_cell, xi))


def traction(
    vertices: CellMap | np.ndarray,
    u_cell: np.ndarray,
    material: Material | CellMaterials,
    xi: np.ndarray,
    normal: np.ndarray,
) -> np.ndarray:
    """Traction ``sigma(u_h) n`` at reference points of each cell.

    Parameters
    ----------
    vertices : CellMap or ndarray of float, shape (m, 3, 2)
        As for :func:`cell_stress`.
    u_cell : ndarray of float, shape (m, 12)
    material : Material
    xi : ndarray of float, shape (q, 2) or (m, q, 2)
        Reference points, shared or per cell.
    normal : ndarray of float, shape (m, 2), (m, q, 2) or (2,)
        Normal vectors (not normalised here).

    Returns
    -------
    ndarray of float64, shape (m, q, 2)
        ``(sigma n)_i = sum_j sigma_ij n_j``.
    """
    sig = cell_stress(vertices, u_cell, material, xi)
    nrm = np.asarray(normal, dtype=np.float64)
    if nrm.ndim == 2:
        nrm = nrm[:, None, :]
    return np.einsum("mqij,mqj->mqi", sig, np.broadcast_to(nrm, sig.shape[:-1]))


def facet_traction(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    material: Material | CellMaterials,
    local_facet: np.ndarray,
    t: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Traction ``sigma(u_h) n`` along one local facet (an edge in 2D) of each cell, ``n``
    outward.

    Local facet ``k`` runs from local vertex ``k`` to ``k + 1`` mod 3
    (``TRIANGLE.facets[k]``, :mod:`signorini.mesh.reference`); ``t`` is the parameter along
    it (0 at the start).  The neighbour across an interior facet traverses it the other
    way: evaluate it at ``1 - t`` to get the same physical points (its normal is the
    opposite one), e.g. for the jump
    ``[[sigma n]] = sigma_1 n_1 + sigma_2 n_2``.

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
    u_cell : ndarray of float, shape (m, 12)
    material : Material
    local_facet : ndarray of int, shape (m,)
        Which local facet of each cell, in {0, 1, 2} (e.g. :attr:`Mesh.facet_local`).
    t : ndarray of float, shape (q,)
        Parameters in [0, 1] along the facet.

    Returns
    -------
    traction : ndarray of float64, shape (m, q, 2)
    normal : ndarray of float64, shape (m, 2)
        Outward unit normals of those facets.
    """
    v = np.asarray(vertices, dtype=np.float64)
    lf = np.asarray(local_facet)
    xi = p2.edge_reference_points(lf, t)
    rows = np.arange(v.shape[0])
    _, normal = facet_normals(v[rows[:, None], TRIANGLE.facets[lf]])
    return traction(v, u_cell, material, xi, normal), normal


def div_stress(
    vertices: np.ndarray, u_cell: np.ndarray, material: Material | CellMaterials
) -> np.ndarray:
    """``div sigma(u_h)`` on each cell (constant for P2 on straight triangles).

    ``(div sigma)_i = mu Laplace u_i + (lam + mu) d_i div u``, from the constant
    Hessian of ``u_h``; this enters the interior residual ``f + div sigma(u_h)``
    of the estimator (term eta_1 of Section 5).

    Parameters
    ----------
    vertices : ndarray of float, shape (m, 3, 2)
    u_cell : ndarray of float, shape (m, 12)
    material : Material

    Returns
    -------
    ndarray of float64, shape (m, 2)
    """
    return stress_divergence(p2.field_hessian(vertices, u_cell), material)


def stress_divergence(hess: np.ndarray, material: Material | CellMaterials) -> np.ndarray:
    """``div sigma(u)`` ``(..., 2)`` from the Hessian ``(..., 2, 2, 2)`` of ``u``,
    ``hess[..., i, j, k] = d^2 u_i / d x_j d x_k`` (e.g. through a cell's map,
    :meth:`signorini.fem.mapping.IsoparametricCells.field_hessians`):
    ``mu Laplace u_i + (lam + mu) d_i div u`` (``lam_eff`` in plane stress; a
    :class:`~signorini.fem.material.CellMaterials` of the leading axis' cells)."""
    lap = hess[..., 0, 0] + hess[..., 1, 1]
    grad_div = hess[..., 0, 0, :] + hess[..., 1, 1, :]
    mu = _per_cell(material.mu, lap.ndim)
    return mu * lap + (_per_cell(material.lam_eff, lap.ndim) + mu) * grad_div


def nodal_stress(space, u: np.ndarray, material: Material | CellMaterials) -> np.ndarray:
    """The stress of the displacement ``u (n_nodes, 2)`` of ``space`` (P2 or P1) at its nodes,
    averaged over the cells sharing each node.

    Each cell gives σ(u_h) at its six nodes (the gradient of its P2 displacement on its own
    map, curved cells included, with the cell's own material); a node's value is the mean of
    the values of its cells. On a linear-elastic field with continuous σ of degree ≤ 1 (a
    patch test) this is exact; at a node on an interface between two materials it is the
    mean of the two sides' values (σ jumps there).

    Parameters
    ----------
    space : P2Space
    u : (n_nodes, 2) float array
    material : Material or CellMaterials
        One material, or one per cell of ``space.mesh``.

    Returns
    -------
    (n_nodes, 3, 3) float array
        σ with σ_zz from the material (:func:`~signorini.fem.material.stress_zz`: λ tr ε in
        plane strain, 0 in plane stress). On a tetrahedral mesh (``u (n_nodes, 3)``) the
        3D stress, :func:`~signorini.fem.elasticity3d.nodal_stress_3d`.
    """
    if space.mesh.dim == 3:
        from .elasticity3d import nodal_stress_3d  # the 3D module builds on this package

        return nodal_stress_3d(space, material, u)
    nodes = space.cell_nodes  # (m, n_local): 6 for P2, 3 for P1
    m, k = nodes.shape
    u_cell = space.field_coefficients(u)  # (m, 12): a P1 field as the P2 field it is
    xi = space.element.reference_nodes
    grad, _ = iso.field_derivatives(space.cell_map_nodes, u_cell, xi)
    sig = np.zeros((m, k, 3, 3))
    sig[..., :2, :2] = stress(material, grad)
    sig[..., 2, 2] = stress_zz(material, grad)
    count = np.bincount(nodes.ravel(), minlength=space.n_nodes).astype(np.float64)
    flat = sig.reshape(m * k, 9)
    mean = np.column_stack(
        [np.bincount(nodes.ravel(), weights=flat[:, j], minlength=space.n_nodes) for j in range(9)]
    )
    return (mean / np.maximum(count, 1.0)[:, None]).reshape(-1, 3, 3)
