"""The terms of the residual estimator (paper, Section 5, (5.1), and η8 with friction), one
function each.

Every term function takes arrays and returns the paper's integrals, one per cell (η1), per facet
(η2–η5, η7; an edge in 2D) or per facet node (η6, η8); the distributing helpers turn them into node
contributions ``η_{k,p}²`` and cell shares. :func:`signorini.estimator.residual.estimate` is the
table that calls them; docs/method.md, *Estimator*, states the choices.

====  ===========================  ================================================
term  function                     integral
====  ===========================  ================================================
η1    :func:`interior_residual`    ``‖f + div σ(u_h)‖²_T`` per cell
η2    :func:`stress_jump`          ``‖⟦σ(u_h)⟧‖²_F`` per interior facet
η3    :func:`neumann_residual`     ``‖σ(u_h)n − g‖²_F`` per Neumann facet
η4    :func:`tangential_stress`    ``‖σ_t(u_h) [+ p_t,h]‖²_F`` per contact facet
η5    :func:`normal_stress`        ``‖σ_nn(u_h) [+ p_h]‖²_F`` per contact facet
η6    :func:`complementarity`      ``s_p ∫_{γ̃_p} (ψ − u_h·n)⁺ φ_p`` per facet node
η7    :func:`penetration`          share of ``‖(u_h·n − ψ)⁺‖²_{H^{1/2}(Γ_C)}``
η8    :func:`friction_work`        ``∫_{γ̃_p} (max(b_h, |p_t,h|)|u_t| − p_t,h u_t)``
                                   per facet node
====  ===========================  ================================================

The functions carry the names of what they measure; ``estimate`` files their results under
the term names ``"eta_1"`` … ``"eta_8"`` (``eta2…`` names elsewhere are squared indicators).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..fem.element import P2
from .h_half_norm import hhalf_norm2_positive_part
from .thirds import friction_work_thirds, third_integrals
from .traction import direction_field, facet_traction

__all__ = [
    "FacetSet",
    "TermShares",
    "facet_traction",
    "interior_residual",
    "stress_jump",
    "neumann_residual",
    "node_mesh_size",
    "tangential_stress",
    "normal_stress",
    "complementarity",
    "penetration",
    "friction_work",
    "direction_field",
    "boundary_cell_shares",
    "spread_cell_integrals",
    "spread_facet_integrals",
    "spread_node_parts",
    "third_integrals",
]


class FacetSet(NamedTuple):
    """The facets a term integrates over (edges in 2D).

    Attributes
    ----------
    index : (k,) int array
        Mesh facet numbers.
    nodes : (k, 3) int array
        P2 nodes of each facet: its two vertices, then its midpoint (P1: the two vertices).
    cells : (k, 2) int array
        The facet's cells (``facet2cell`` rows, ``-1`` outside the domain).
    measure : (k,) float array
        The facets' measures ``|F|`` (lengths in 2D).
    """

    index: np.ndarray
    nodes: np.ndarray
    cells: np.ndarray
    measure: np.ndarray


class TermShares(NamedTuple):
    """One term's contributions: ``node (n_nodes,)`` the ``η_{k,p}²`` (``None`` for the
    global η7) and ``cell (n_cells,)`` each cell's share, summing to ``η_k²``."""

    node: np.ndarray | None
    cell: np.ndarray


# --------------------------------------------------------------------------- distribution


def spread_cell_integrals(R: np.ndarray, cell_nodes: np.ndarray, h_p: np.ndarray) -> TermShares:
    """Cell integrals ``R_T`` enter ``η_{k,p}²`` with weight ``h_p²`` for each node p of T.

    Parameters
    ----------
    R : (n_cells,) float array
    cell_nodes : (n_cells, 6) int array
        (``(n_cells, 3)`` for P1)
    h_p : (n_nodes,) float array
        Node mesh sizes, zero at Dirichlet nodes.

    Returns
    -------
    TermShares
        ``node = h_p² Σ_{T ∋ p} R_T``, ``cell = R_T Σ_{p ∈ T} h_p²``.
    """
    k = cell_nodes.shape[1]
    node = h_p**2 * np.bincount(cell_nodes.ravel(), weights=np.repeat(R, k), minlength=h_p.size)
    return TermShares(node, R * (h_p[cell_nodes] ** 2).sum(axis=1))


def spread_facet_integrals(
    facets: FacetSet, J: np.ndarray, h_p: np.ndarray, n_cells: int
) -> TermShares:
    """Facet integrals ``J_F`` enter ``η_{k,p}²`` with weight ``h_p`` for each node p of F.

    Each facet's total ``Σ_{p ∈ F} h_p J_F`` is split equally between its cells.

    Parameters
    ----------
    facets : FacetSet
    J : (k,) float array
    h_p : (n_nodes,) float array
        Node mesh sizes, zero at Dirichlet nodes.
    n_cells : int

    Returns
    -------
    TermShares
    """
    node_part = h_p[facets.nodes] * J[:, None]
    node = np.bincount(facets.nodes.ravel(), weights=node_part.ravel(), minlength=h_p.size)
    total = node_part.sum(axis=1)
    c0, c1 = facets.cells[:, 0], facets.cells[:, 1]
    two = c1 >= 0
    cell = np.bincount(c0, weights=np.where(two, 0.5, 1.0) * total, minlength=n_cells)
    cell += np.bincount(c1[two], weights=0.5 * total[two], minlength=n_cells)
    return TermShares(node, cell)


def spread_node_parts(
    facets: FacetSet, parts: np.ndarray, n_nodes: int, n_cells: int
) -> TermShares:
    """Per-node parts ``(k, 3)`` of boundary facets to their nodes, each facet's total to its
    cell.

    Parameters
    ----------
    facets : FacetSet
        Boundary facets (one cell each); ``parts`` columns follow ``facets.nodes``.
    parts : (k, 3) float array
    n_nodes, n_cells : int

    Returns
    -------
    TermShares
    """
    node = np.bincount(facets.nodes.ravel(), weights=parts.ravel(), minlength=n_nodes)
    return TermShares(node, boundary_cell_shares(facets, parts.sum(axis=1), n_cells))


def boundary_cell_shares(facets: FacetSet, values: np.ndarray, n_cells: int) -> np.ndarray:
    """Values ``(k,)`` of boundary facets to their cells: ``(n_cells,)``."""
    return np.bincount(facets.cells[:, 0], weights=values, minlength=n_cells)


def _point_weights(w: np.ndarray, measure: np.ndarray) -> np.ndarray:
    """``(k, q)`` quadrature weights along facets: ``w`` times the facet measure ``(k,)`` or
    times ``|x'(t)|`` at each point ``(k, q)``."""
    return w * (measure[:, None] if np.ndim(measure) == 1 else measure)


def _per_item(a: np.ndarray | None, ndim: int) -> np.ndarray | None:
    """``a`` without its point axis (axis 1) where that has length 1: a value constant on
    each cell or edge (:mod:`signorini.fem.mapping` gives such arrays, ``(k, 1, ...)``), so
    that it is used in the per-cell or per-edge form; ``ndim`` is the per-point rank."""
    if a is None or np.ndim(a) != ndim or np.shape(a)[1] != 1:
        return a
    return a[:, 0]


# --------------------------------------------------------------------------- the terms


def interior_residual(
    area: np.ndarray,
    div_sigma: np.ndarray,
    f: np.ndarray | None = None,
    w: np.ndarray | None = None,
) -> np.ndarray:
    """``R_T = ‖f + div σ(u_h)‖²_T`` per cell (η1).

    Parameters
    ----------
    area : (n_cells,) float array
        Cell areas; ``(n_cells, q)``: ``det J / 2`` at the points of ``w`` on cells whose
        Jacobian varies (:meth:`signorini.fem.mapping.IsoparametricCells.jacobians`).
    div_sigma : (n_cells, 2) float array
        ``div σ(u_h)``, constant on each cell; ``(n_cells, q, 2)`` at the points of ``w``.
    f : (n_cells, q, 2) float array, optional
        The body force at the quadrature points; ``None`` for ``f = 0``.
    w : (q,) float array, optional
        Quadrature weights on the reference triangle (summing to 1/2).

    Returns
    -------
    (n_cells,) float array
    """
    area, div_sigma = _per_item(area, 2), _per_item(div_sigma, 3)
    if np.ndim(area) == 1 and div_sigma.ndim == 2:
        if f is None:
            return area * (div_sigma**2).sum(axis=1)
        r = f + div_sigma[:, None, :]
        return 2 * area * np.einsum("q,mqc,mqc->m", w, r, r)
    r = div_sigma if div_sigma.ndim == 3 else div_sigma[:, None, :]
    if f is not None:
        r = f + r
    r = np.broadcast_to(r, (len(r), len(w), r.shape[-1]))
    a = np.broadcast_to(area if np.ndim(area) == 2 else area[:, None], r.shape[:2])
    return 2 * np.einsum("q,mq,mqc,mqc->m", w, a, r, r)


def stress_jump(
    traction_0: np.ndarray, traction_1: np.ndarray, w: np.ndarray, measure: np.ndarray
) -> np.ndarray:
    """``‖⟦σ(u_h)⟧‖²_F`` per interior facet (η2, an edge in 2D).

    Parameters
    ----------
    traction_0, traction_1 : (k, q, 2) float arrays
        ``σ(u_h) n`` from each of the facet's cells with its own outward normal, at the same
        points (so the jump is their sum).
    w : (q,) float array
        Weights on [0, 1].
    measure : (k,) float array
    """
    jump = traction_0 + traction_1
    return measure * np.einsum("q,eqi,eqi->e", w, jump, jump)


def neumann_residual(residual: np.ndarray, w: np.ndarray, measure: np.ndarray) -> np.ndarray:
    """``‖σ(u_h) n − g‖²_F`` per Neumann facet (η3), from ``residual (k, q, 2)`` at the
    points of the weights ``w (q,)``; ``measure (k,)``, or ``|x'(t)|`` at each point ``(k, q)``
    on a quadratic facet."""
    measure = _per_item(measure, 2)
    if np.ndim(measure) == 2:
        return np.einsum("eq,eqi,eqi->e", _point_weights(w, measure), residual, residual)
    return measure * np.einsum("q,eqi,eqi->e", w, residual, residual)


def tangential_stress(
    traction: np.ndarray,
    normal: np.ndarray,
    w: np.ndarray,
    measure: np.ndarray,
    t: np.ndarray | None = None,
    friction: np.ndarray | None = None,
) -> np.ndarray:
    """``‖σ_t(u_h)‖²_F`` per contact facet (η4), or ``‖σ_t(u_h) + p_t,h‖²_F`` with friction.

    Parameters
    ----------
    traction : (k, q, 2) float array
        ``σ(u_h) n`` at the points of ``w``.
    normal : (k, 2) float array
        The contact part's outward unit normal, or ``(k, q, 2)`` the direction the traction
        is split along at each point (:func:`direction_field`).
    w : (q,) float array
    measure : (k,) float array
        Facet measures h_F = |F| (edge lengths in 2D); ``|x'(t)|`` at each point ``(k, q)``
        on a quadratic facet.
    t : (q,) float array, optional
        The quadrature points on [0, 1] (needed with ``friction``).
    friction : (k, 3) float array, optional
        The nodal friction stresses ``p_t,z = Λ_t,z / w_z`` at ``[start, end, midpoint]``
        (0 at Dirichlet nodes); ``p_t,h`` is their quadratic interpolant, and the residual
        is the scalar ``σ(u_h) n · τ + p_t,h`` with ``τ = (−d_y, d_x)`` for the direction d
        (docs/method.md, *Estimator*, "With friction"). ``None`` without friction.
    """
    measure, normal = _per_item(measure, 2), _per_item(normal, 3)
    if normal.ndim == 2 and np.ndim(measure) == 2:
        normal = np.broadcast_to(normal[:, None, :], traction.shape)
    if friction is not None:
        d = normal if normal.ndim == 3 else np.broadcast_to(normal[:, None, :], traction.shape)
        residual = traction[..., 1] * d[..., 0] - traction[..., 0] * d[..., 1]
        residual = residual + friction @ P2.facet.basis(t).T
        return (_point_weights(w, measure) * residual**2).sum(axis=1)
    if normal.ndim == 3:
        snn = np.einsum("eqi,eqi->eq", traction, normal)
        st = traction - snn[..., None] * normal
        return np.einsum("eq,eqi,eqi->e", _point_weights(w, measure), st, st)
    snn = np.einsum("eqi,ei->eq", traction, normal)
    st = traction - snn[..., None] * normal[:, None, :]
    return measure * np.einsum("q,eqi,eqi->e", w, st, st)


def normal_stress(
    traction: np.ndarray,
    normal: np.ndarray,
    t: np.ndarray,
    w: np.ndarray,
    measure: np.ndarray,
    pressure: np.ndarray | None = None,
) -> np.ndarray:
    """``‖σ_nn(u_h)‖²_F`` (``paper``) or ``‖σ_nn(u_h) + p_h‖²_F`` (``consistent``) (η5).

    Parameters
    ----------
    traction : (k, q, 2) float array
        ``σ(u_h) n`` at the points ``t``.
    normal : (k, 2) float array
        Or ``(k, q, 2)``, the direction at each point (:func:`direction_field`).
    t, w : (q,) float arrays
        Quadrature points and weights on [0, 1], in the edge's counter-clockwise direction.
    measure : (k,) float array
        ``(k, q)``: ``|x'(t)|`` at each point of a quadratic edge.
    pressure : (k, 3) float array, optional
        The nodal pressures ``p_z`` at ``[start, end, midpoint]`` (0 at Dirichlet nodes);
        ``p_h`` is their quadratic interpolant. ``None`` for the ``paper`` variant.
    """
    measure, normal = _per_item(measure, 2), _per_item(normal, 3)
    if normal.ndim == 3:
        snn = np.einsum("eqi,eqi->eq", traction, normal)
    else:
        snn = np.einsum("eqi,ei->eq", traction, normal)
    if pressure is not None:
        snn = snn + pressure @ P2.facet.basis(t).T
    if normal.ndim == 3 or np.ndim(measure) == 2:
        return (_point_weights(w, measure) * snn**2).sum(axis=1)
    return measure * (w * snn**2).sum(axis=1)


def complementarity(
    gap: np.ndarray,
    density: np.ndarray,
    measure: np.ndarray,
    points: np.ndarray | None = None,
    pieces: tuple = P2.facet.hat_pieces,
) -> np.ndarray:
    """``s_p d_p`` with ``d_p = ∫_{γ̃_p} (ψ − u_h·n)⁺ φ_p``, per contact facet node (η6).

    Parameters
    ----------
    gap : (k, 3) float array
        ``u_h·n − ψ_h`` at ``[start, end, midpoint]``.
    density : (k, 3) float array
        ``s_p`` at the same nodes where p is a semi-contact node, else 0.
    measure : (k,) float array or StraightFacets or QuadraticFacets
        Facet measures h_F = |F| (edge lengths in 2D), or the facets' geometry
        (:mod:`signorini.fem.mapping`).
    points : (k, 3, 2) float array, optional
        Node points ``[start, end, midpoint]`` of quadratic edges: integrate along them
        (:func:`third_integrals`).
    pieces : tuple, optional
        The element's γ̃_p and hats (:attr:`~signorini.fem.facet_element.FacetElement.hat_pieces`):
        P2's thirds (default), P1's halves.

    Returns
    -------
    (k, 3) float array
        Each node's part from this facet.
    """
    return density * third_integrals(-gap, measure, points, pieces)


def friction_work(
    slip: np.ndarray,
    friction: np.ndarray,
    bound: np.ndarray,
    measure: np.ndarray,
    points: np.ndarray | None = None,
    parts: tuple = P2.facet.node_parts,
) -> np.ndarray:
    """``∫_{γ̃_p} (max(b_h, |p_t,h|) |u_t| − p_t,h u_t) ds`` per contact facet node (η8): the
    defect of the friction work ``p_t u_t = s |u_t|`` of the tangential law (docs/method.md,
    *Estimator*, "With friction").

    Parameters
    ----------
    slip : (k, 3) float array
        ``u_h·t_z`` (minus the reference slip) at ``[start, end, midpoint]``.
    friction : (k, 3) float array
        The nodal friction stresses ``p_t,z`` at the same nodes (0 at Dirichlet nodes).
    bound : (k, 3) float array
        The nodal slip bounds ``b_z`` (Tresca ``s_z / w_z``, Coulomb ``F p_z``; 0 at
        Dirichlet nodes and on frictionless parts).
    measure : (k,) float array or StraightFacets or QuadraticFacets
        Facet measures h_F = |F| (edge lengths in 2D), or the facets' geometry
        (:mod:`signorini.fem.mapping`).
    points : (k, 3, 2) float array, optional
        Node points of quadratic edges: integrate along them.

    Returns
    -------
    (k, 3) float array
        The facet's integrals over the thirds of its start, end and midpoint nodes.
    """
    return friction_work_thirds(slip, friction, bound, measure, points, parts)


def penetration(
    x0: np.ndarray, x1: np.ndarray, gap: np.ndarray, scale: float | None = None
) -> np.ndarray:
    """Each contact facet's share of ``η7² = ‖(u_h·n − ψ_h)⁺‖²_{H^{1/2}(Γ_C)}``.

    Parameters
    ----------
    x0, x1 : (k, 2) float arrays
        Start and end points of the contact facets (edges).
    gap : (k, 3) float array
        ``u_h·n − ψ_h`` at ``[start, end, midpoint]``.
    scale : float, optional
        The displacement's size, ``max|u_h|``: where two contact parts meet, their gaps may
        differ by its round-off (default: ``max|gap|`` only).

    Returns
    -------
    (k,) float array

    Notes
    -----
    The norm only depends on differences of points, so Γ_C is first moved next to the
    origin (by its lower-left bounding-box corner): far from the origin (a mesh shifted by
    1e9) the distances ``|x − y|`` of the quadrature points would otherwise lose 9 digits.
    """
    origin = x0.min(axis=0) if len(x0) else np.zeros(2)
    _, share = hhalf_norm2_positive_part(x0 - origin, x1 - origin, gap, validate=False, scale=scale)
    return share


def node_mesh_size(
    h: np.ndarray, cell_nodes: np.ndarray, dirichlet_nodes: np.ndarray, n_nodes: int
) -> np.ndarray:
    """``h_p = max_{T ∋ p} h_T`` ``(n_nodes,)``, zero at Dirichlet nodes (they carry no term)."""
    # node by node over its cells: the node-cell incidence in CSC form, one maximum per column
    # (np.maximum.at took 0.1 s at 1.2M unknowns on some meshes' h_T, this 0.03 s on all)
    m, k = cell_nodes.shape
    incidence = sp.csr_matrix(
        (np.repeat(h, k), cell_nodes.ravel(), np.arange(0, m * k + 1, k)), shape=(m, n_nodes)
    ).tocsc()
    h_p = np.zeros(n_nodes)
    has_cells = np.diff(incidence.indptr) > 0
    h_p[has_cells] = np.maximum.reduceat(incidence.data, incidence.indptr[:-1][has_cells])
    h_p[dirichlet_nodes] = 0.0
    return h_p
