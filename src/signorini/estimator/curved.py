"""The estimator's integrals on isoparametric cells and quadratic edges (docs/method.md,
*Estimator*, "On curved boundaries").

On a mesh with curved boundary parts, :func:`signorini.estimator.residual.estimate` computes
every term with the affine formulas first and then replaces the integrals of the few cells
and edges where those are not the estimator of the discrete solution:

- η1 on the isoparametric cells: ``∫_T |f + div σ(u_h)|²`` with ``u_h = û ∘ x⁻¹``, its
  exact second derivatives through the quadratic map (:func:`signorini.fem.iso.field_derivatives`)
  at the points of the cell rule, weighted by ``det J``;
- η2 on the edges of isoparametric cells: ``σ(u_h)`` from the curved side through the map
  (those edges are straight, so the points and the normal are the affine ones);
- η3, η4, η5 on the boundary edges of isoparametric cells: the edge is the quadratic
  ``x(t)`` through its three nodes, with its own unit normal ``n(t)`` and ``|x'(t)|`` at
  each quadrature point (on a straight edge of such a cell these are the chord's); η4 and
  η5 split the traction along the constraint direction field, the normalised quadratic
  interpolant of the nodal n_z;
- η6 on contact edges of curved parts: ``d_p`` integrated with ``|x'(t)|``.

η7 stays on the chords (docs/method.md). The cost is proportional to the number of
isoparametric cells and their edges; on a mesh without them :func:`curved_cells` returns
``None`` and nothing else here runs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..contact.solution import ContactResult
from ..fem import iso
from ..fem.material import Material, stress
from ..fem.p2 import edge_reference_points
from ..fem.quadrature import triangle_rule
from ..fem.space import P2Space
from ..mesh.mesh import Mesh
from ..problem.fields import evaluate_field
from ..problem.problem import ContactProblem
from .terms import (
    EdgeSet,
    direction_field,
    neumann_residual,
    normal_stress,
    tangential_stress,
)

__all__ = [
    "CurvedCells",
    "curved_cells",
    "div_stress",
    "neumann_integrals",
    "contact_integrals",
    "edge_node_points",
]

#: local nodes ``[start, end, midpoint]`` of local edge k = 0, 1, 2 of a P2 cell
_EDGE_NODES = np.array([[0, 1, 3], [1, 2, 4], [2, 0, 5]])


@dataclass(frozen=True)
class CurvedCells:
    """The isoparametric cells of a discrete solution, with what the estimator needs there.

    Attributes
    ----------
    cells : (m,) int array
        The isoparametric cells (sorted).
    nodes : (m, 6, 2) float array
        Their node points.
    u : (m, 12) float array
        ``u_h``'s interleaved local coefficients.
    slot : (n_cells,) int array
        Row of each cell in ``cells``, ``-1`` for affine cells.
    material : Material
    unit : float
        The stress unit σ₀ the estimator divides stresses by.
    xi, w : (q, 2), (q,) float arrays
        The cell rule (the one η1 uses on affine cells).
    """

    cells: np.ndarray
    nodes: np.ndarray
    u: np.ndarray
    slot: np.ndarray
    material: Material
    unit: float
    xi: np.ndarray
    w: np.ndarray

    def points(self) -> np.ndarray:
        """``(m, q, 2)`` the images ``x(ξ_q)`` of the cell rule's points."""
        return iso.geometry(self.nodes, self.xi)[0]

    def interior_residual(self, f: np.ndarray | None) -> np.ndarray:
        """``∫_T |f + div σ(u_h)|² dx`` ``(m,)`` (η1), with ``f (m, q, 2)`` already in the stress
        unit at :meth:`points` (``None`` for ``f = 0``)."""
        _, _, det = iso.geometry(self.nodes, self.xi)
        _, hess = iso.field_derivatives(self.nodes, self.u, self.xi)
        r = div_stress(hess, self.material) / self.unit
        if f is not None:
            r = r + f
        return np.einsum("q,mq,mqc,mqc->m", self.w, det, r, r)

    def traction(
        self, cell: np.ndarray, k: np.ndarray, t: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``σ(u_h) n`` along local edge ``k`` of isoparametric ``cell`` at parameters ``t``
        (counter-clockwise around the cell), in the stress unit, with the quadratic edge.

        Returns
        -------
        traction, x : (e, q, 2) float arrays
        speed : (e, q) float array
            ``|x'(t)|``.
        normal : (e, q, 2) float array
            The edge's outward unit normal at each point.
        """
        s = self.slot[cell]
        nodes = self.nodes[s[:, None], _EDGE_NODES[k]]  # (e, 3, 2)
        x, speed, normal = iso.edge_geometry(nodes[:, :2], nodes[:, 2], t)
        grad, _ = iso.field_derivatives(self.nodes[s], self.u[s], edge_reference_points(k, t))
        sig = stress(self.material, grad) / self.unit
        return np.einsum("eqij,eqj->eqi", sig, normal), x, speed, normal

    def mixed_traction(
        self,
        affine: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
        cell: np.ndarray,
        k: np.ndarray,
        t: np.ndarray,
    ) -> np.ndarray:
        """``σ(u_h) n`` ``(e, q, 2)`` of any cells: ``affine(cell, k, t)``, replaced on the
        isoparametric ones (the interior edges of the jump term are straight, so the points
        and normals agree)."""
        out = affine(cell, k, t)
        on = self.slot[cell] >= 0
        if on.any():
            out[on] = self.traction(cell[on], k[on], t)[0]
        return out


def curved_cells(result: ContactResult, unit: float, degree: int) -> CurvedCells | None:
    """The isoparametric cells of ``result`` (:attr:`signorini.fem.space.P2Space.curved`),
    ``None`` on a mesh without them; ``degree`` is the cell rule's."""
    space = result.space
    if space.curved is None:
        return None
    cells, nodes = space.curved
    slot = np.full(space.mesh.n_cells, -1)
    slot[cells] = np.arange(cells.size)
    u = np.asarray(result.u)[space.cell_nodes[cells]].reshape(cells.size, 12)
    xi, w = triangle_rule(degree)
    return CurvedCells(cells, nodes, u, slot, result.problem.material, unit, xi, w)


def div_stress(hess: np.ndarray, material: Material) -> np.ndarray:
    """``div σ(u_h)`` ``(..., 2)`` from the Hessian ``(..., 2, 2, 2)`` of u_h:
    ``μ Δu_i + (λ + μ) ∂_i div u``."""
    lap = hess[..., 0, 0] + hess[..., 1, 1]
    grad_div = hess[..., 0, 0, :] + hess[..., 1, 1, :]
    return material.mu * lap + (material.lam + material.mu) * grad_div


def boundary_rows(curved: CurvedCells, edges: EdgeSet) -> np.ndarray:
    """Rows of boundary ``edges`` whose cell is isoparametric."""
    return np.flatnonzero(curved.slot[edges.cells[:, 0]] >= 0)


def neumann_integrals(
    curved: CurvedCells,
    problem: ContactProblem,
    mesh: Mesh,
    edges: EdgeSet,
    t: np.ndarray,
    w: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``‖σ(u_h) n − g‖²_e`` (η3) on the Neumann edges of isoparametric cells, along the
    quadratic edge: rows into ``edges`` (the Neumann edges part after part) and values."""
    sizes = [mesh.part_edges(name).size for name in problem.neumann_parts]
    part = np.repeat(np.arange(len(sizes)), sizes)
    rows = boundary_rows(curved, edges)
    values = np.zeros(rows.size)
    for i, name in enumerate(problem.neumann_parts):  # a loop over parts
        sel = np.flatnonzero(part[rows] == i)
        if sel.size == 0:
            continue
        e = edges.index[rows[sel]]
        sn, x, speed, normal = curved.traction(mesh.edge2cell[e, 0], mesh.edge_local[e, 0], t)
        cond = problem.conditions[name]
        if not cond.is_zero:
            what = f"the traction of Neumann part {name!r}"
            sn = sn - evaluate_field(cond.field(), x, what, normal=normal) / curved.unit
        values[sel] = neumann_residual(sn, w, speed)
    return rows, values


def contact_integrals(
    curved: CurvedCells,
    mesh: Mesh,
    edges: EdgeSet,
    t: np.ndarray,
    w: np.ndarray,
    pressure: np.ndarray | None,
    direction: np.ndarray,
    friction: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``‖σ_t(u_h) [+ p_t,h]‖²_e`` (η4; ``friction (k, 3)`` the nodal friction stresses, or
    ``None``) and ``‖σ_nn(u_h) [+ p_h]‖²_e`` (η5) on the contact edges of
    isoparametric cells: the traction ``σ(u_h) n(t)`` with the normal of the quadratic edge
    at each point, split along the constraint direction field (:func:`direction_field` of
    the nodal ``direction (k, 3, 2)``), integrated with ``|x'(t)|``. Returns rows into
    ``edges`` and the two arrays of values."""
    rows = boundary_rows(curved, edges)
    e = edges.index[rows]
    sn, _, speed, _ = curved.traction(mesh.edge2cell[e, 0], mesh.edge_local[e, 0], t)
    d = direction_field(direction[rows], t)
    p = None if pressure is None else pressure[rows]
    f = None if friction is None else friction[rows]
    return rows, tangential_stress(sn, d, w, speed, t, f), normal_stress(sn, d, t, w, speed, p)


def edge_node_points(space: P2Space, edges: EdgeSet) -> tuple[np.ndarray, np.ndarray]:
    """Rows of contact ``edges`` on curved parts and their node points ``(r, 3, 2)``
    ``[start, end, midpoint]`` (for η6 along the quadratic edge)."""
    rows = np.flatnonzero(np.isin(edges.index, iso.curved_edges(space.mesh)))
    return rows, space.node_points[edges.nodes[rows]]
