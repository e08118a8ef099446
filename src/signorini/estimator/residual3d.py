"""ESTIMATE on P2 tetrahedra: the residual estimator η_h of the paper's (5.1) in three
dimensions, the same :class:`~signorini.estimator.residual.Estimate` as in 2D
(docs/method.md, *Three dimensions: the estimator on tetrahedra and faces*).

For every P2 node p that is not a Dirichlet node, ``h_p = max_{T ∋ p} h_T`` (h_T the
longest edge of the tetrahedron):

==== ============================================================ ==========================
η1   ``h_p² ‖f + div σ(u_h)‖²_{ω_p}``                                every cell of ω_p
η2   ``h_p ‖⟦σ(u_h) n⟧‖²_F``                                        interior faces F ∋ p
η3   ``h_p ‖σ(u_h)n − g‖²_F``; on rollers the tangential part of     Neumann, roller faces,
     σ(u_h)n, on parts holding some components the free ones; on     the master faces of pairs
     the master faces of pairs ``g = g_h``, the consistent master
     traction (:mod:`.master_faces3d`)
η4   ``h_p ‖σ_t(u_h)‖²_F``, σ_t the tangent part of σ(u_h)n          contact faces
     (of ``σ(u_h)n + p_t,h`` with friction)
η5   ``h_p ‖d·σ(u_h)n + p_h‖²_F`` (``consistent``) or without p_h    contact faces
η6   ``s_p d_p``, ``d_p = ∫_{γ̃_p} (ψ_h − u_h·n)⁺ φ_p``             semi-contact nodes
η7   the guaranteed bound G of ``‖(u_h·n − ψ_h)⁺‖_{H^{1/2}(Γ_C)}``   global
η8   ``∫ (max(b_h, ‖p_t,h‖) ‖u_t‖ − p_t,h·u_t) φ_p`` with friction   contact faces
     (:mod:`.friction_faces3d`; 0 without)
==== ============================================================ ==========================

A face F "contains" p when p is one of its six P2 nodes (where the P2 function of p does not
vanish on F). d is the constraint direction field on Γ_C (:func:`.faces3d.direction_field_3d`),
p_h the P2 interpolant of the nodal pressure on each face, γ̃_p the support of the hat φ_p of
the once-refined face and s_p = Λ̃_p / m_p (:mod:`.contact_faces3d`, which integrates η4 … η7).
Each integral is taken once per cell or face through its own geometry (affine or
isoparametric tetrahedra, flat or quadratic faces, :mod:`signorini.fem.mapping3d`), the
kernels of :mod:`.terms` turn them into node contributions and cell shares as in 2D, so the
element indicators sum to η_h² exactly.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..contact.solution import ContactResult
from ..fem.elasticity3d import stress_divergence_3d
from ..fem.mapping3d import FlatFaces
from ..fem.material import CellMaterials, Material, on_cells
from ..fem.quadrature import tetrahedron_rule, triangle_rule
from ..fem.space3d import P2TetSpace
from ..problem.conditions import Dirichlet, Roller
from ..problem.fields import evaluate_field
from .contact_faces3d import PRESSURE_3D, contact_terms
from .faces3d import TetStress, face_geometry
from .master_faces3d import master_tractions
from .names import TERMS
from .owned import OwnPart, per_cell_of
from .residual import NODE_TERMS, Estimate
from .terms import (
    FacetSet,
    TermShares,
    boundary_cell_shares,
    interior_residual,
    neumann_residual,
    node_mesh_size,
    spread_cell_integrals,
    spread_facet_integrals,
    spread_node_parts,
)

__all__ = ["CELL_DEGREE_3D", "FACE_DEGREE", "NEUMANN_DEGREE_3D", "Estimate3D", "estimate_3d"]

#: tetrahedron rule for η1 with a body force (14 points; f is smooth data)
CELL_DEGREE_3D = 5
#: triangle rule on the faces for η2, η4, η5: σ(u_h) is linear on a straight cell, p_h
#: quadratic, so the squares are of degree 4 on flat faces; one more for quadratic faces
FACE_DEGREE = 5
#: triangle rule for η3 with data g that is not a polynomial: finer, so that quadrature stays
#: far below the residual itself
NEUMANN_DEGREE_3D = 10


def estimate_3d(
    result: ContactResult,
    eta5_variant: str = "consistent",
    pressure: str = PRESSURE_3D,
    own: OwnPart | None = None,
) -> Estimate:
    """η_h and its contributions for a 3D discrete solution (P2 tetrahedra); called by
    :func:`~signorini.estimator.residual.estimate` on a tetrahedral mesh (which checks
    ``eta5_variant``).

    Parameters
    ----------
    result : ContactResult
    eta5_variant : {"consistent", "paper"}
    pressure : {"transformed", "recovered"}
        The nodal pressure the consistent η5 balances σ_nn with
        (:func:`~.contact_faces3d.eta5_pressure`; default :data:`~.contact_faces3d.PRESSURE_3D`).
    own : OwnPart, optional
        This rank's part on a run of several ranks (:func:`~.owned.own_part`; default every
        cell and face): η1 on its cells, η2 and η3 on the faces whose first cell is its own,
        η4 … η7 on every contact face (Γ_C's data is replicated) kept on its own faces; the
        integrals are summed over the ranks before they are spread, as in 2D
        (docs/parallel.md, *The estimator on several ranks*).

    Returns
    -------
    Estimate
        ``eta2_cell (8, n_cells)``, ``eta2_node (7, n_nodes)`` as in 2D (η8 = 0 without
        friction).
    """
    problem, space, mesh = result.problem, result.space, result.mesh
    n_nodes, n_cells = space.n_nodes, mesh.n_cells
    h_p = node_mesh_size(mesh.h, space.cell_nodes, result.dirichlet_nodes, n_nodes)
    material = problem.material_on(mesh)
    stresses = TetStress(space, result.u, material)
    unit = stresses.unit
    s, w = triangle_rule(FACE_DEGREE)

    mine = None if own is None else own.cells  # None: every cell and face (one process)
    R = _cell_residuals(result, material, stresses, mine)
    inner = _face_set(space, np.flatnonzero(mesh.facet2cell[:, 1] >= 0))
    J2 = _on_own_faces(inner, own, lambda faces: _jumps(space, stresses, faces, s, w))
    boundary, J3 = _traction_residuals(result, stresses, own)
    master = master_tractions(result, stresses, s, w)  # pairs: η3 on the master faces too
    if master is not None:
        boundary = FacetSet(*map(np.concatenate, zip(boundary, master[0], strict=True)))
        J3 = np.concatenate([J3, master[1]])
    contact = contact_terms(result, stresses, eta5_variant, s, w, pressure)
    if own is not None:  # each integral from the one rank that owns it, summed over the ranks
        if contact is None:
            R, J2, J3 = own.sum([R, J2, J3])
        else:
            keep = own.facets(contact.faces.cells)
            J4, J5, eta7 = (np.where(keep, a, 0.0) for a in (contact.J4, contact.J5, contact.eta7))
            parts6 = np.where(keep[:, None], contact.parts6, 0.0)
            R, J2, J3, J4, J5, parts6, eta7 = own.sum([R, J2, J3, J4, J5, parts6, eta7])
            contact = contact._replace(J4=J4, J5=J5, parts6=parts6, eta7=eta7)
            if contact.parts8 is not None:
                parts8 = own.sum([np.where(keep[:, None], contact.parts8, 0.0)])[0]
                contact = contact._replace(parts8=parts8)

    def on_faces(faces: FacetSet, J: np.ndarray) -> TermShares:
        return spread_facet_integrals(faces, J, h_p, n_cells)

    zero = TermShares(np.zeros(n_nodes), np.zeros(n_cells))
    shares = {
        "eta_1": spread_cell_integrals(R, space.cell_nodes, h_p),
        "eta_2": on_faces(inner, J2),
        "eta_3": on_faces(boundary, J3),
        "eta_4": zero,
        "eta_5": zero,
        "eta_6": zero,
        "eta_7": TermShares(None, np.zeros(n_cells)),
        "eta_8": zero,
    }
    if contact is not None:
        faces = contact.faces
        shares["eta_4"] = on_faces(faces, contact.J4)
        shares["eta_5"] = on_faces(faces, contact.J5)
        shares["eta_6"] = spread_node_parts(faces, contact.parts6, n_nodes, n_cells)
        shares["eta_7"] = TermShares(None, boundary_cell_shares(faces, contact.eta7, n_cells))
        if contact.parts8 is not None:  # friction (docs/method.md, η4 and η8 on faces)
            shares["eta_8"] = spread_node_parts(faces, contact.parts8, n_nodes, n_cells)
    oscillation = 0.0 if contact is None else float(np.sqrt(contact.oscillation.sum() * unit))
    return Estimate3D(
        eta2_cell=np.stack([shares[name].cell for name in TERMS]),
        eta2_node=np.stack([shares[name].node for name in NODE_TERMS]),
        eta5_variant=eta5_variant,
        unit=unit,
        obstacle_oscillation=oscillation,
    )


@dataclass(frozen=True)
class Estimate3D(Estimate):
    """The :class:`~signorini.estimator.residual.Estimate` of a 3D solution, and beside it
    (not in η_h) the obstacle's interpolation term ``osc_ψ = (Σ_F |∫_F λ̃_h (ψ − ψ_h)|)^{1/2}``
    of the reliability bound (:func:`~.contact_faces3d.obstacle_oscillation`; the unit of η6;
    0 without contact and where ψ is piecewise quadratic on the faces)."""

    obstacle_oscillation: float = 0.0


def _face_set(space: P2TetSpace, e: np.ndarray) -> FacetSet:
    """Mesh faces ``e`` with their six nodes (the first cell's face order), cells, areas."""
    mesh = space.mesh
    return FacetSet(e, space.mesh_facet_nodes(e), mesh.facet2cell[e], mesh.facet_measure[e])


def _on_own_faces(
    faces: FacetSet, own: OwnPart | None, integrals: Callable[[FacetSet], np.ndarray]
) -> np.ndarray:
    """``integrals(faces)`` ``(k,)``; with this rank's part ``own`` on the faces it
    integrates only (:meth:`~.owned.OwnPart.facets`), zero on the others."""
    if own is None:
        return integrals(faces)
    keep = np.flatnonzero(own.facets(faces.cells))
    J = np.zeros(faces.index.size)
    own = FacetSet(faces.index[keep], faces.nodes[keep], faces.cells[keep], faces.measure[keep])
    J[keep] = integrals(own)
    return J


def _cell_residuals(
    result: ContactResult,
    material: Material | CellMaterials,
    stresses: TetStress,
    mine: np.ndarray | None = None,
) -> np.ndarray:
    """η1's ``‖f + div σ(u_h)‖²_T`` ``(n_cells,)`` in the stress unit: div σ(u_h) from the
    Hessians through each cell's map (constant on affine cells), f at the points of the
    degree-``CELL_DEGREE_3D`` rule. :func:`~.terms.interior_residual` reads a rule whose
    weights sum to 1/2 and the cells' ``det J / 2``: the tetrahedron's weights (summing to
    1/6) enter times 3 and ``det J / 6`` (the volume) as its measure, the same sums. With
    this rank's cells ``mine`` on those only (zero on the others)."""
    problem, cells, unit = result.problem, result.space.mapping, stresses.unit
    xi, w = tetrahedron_rule(CELL_DEGREE_3D)
    f = None
    if problem.body_force is not None:
        f = evaluate_field(problem.body_force, cells.points(xi), "body_force", shape=(3,)) / unit

    def residual(g) -> np.ndarray:
        hess = g.field_hessians(stresses.u_cell[g.cells], xi)
        div = stress_divergence_3d(hess, on_cells(material, g.cells)) / unit
        volume = g.jacobians(xi)[1] / 6.0
        return interior_residual(volume, div, None if f is None else f[g.cells], 3.0 * w)

    if mine is None:
        return cells.per_cell(residual)
    subset = np.flatnonzero(mine)
    R = np.zeros(result.mesh.n_cells)
    R[subset] = per_cell_of(cells, subset, lambda g, rows: residual(g))
    return R


def _traction(stresses: TetStress, cells: np.ndarray, nodes: np.ndarray, s, geometry):
    """``σ(u_h) n (k, q, 3)`` of ``cells`` on their faces (nodes ``(k, 6)``, outward normals
    of ``geometry``) at the points ``s``."""
    sigma = stresses.at_faces(cells, nodes[:, :3], s)
    n = np.broadcast_to(geometry.normals(s), sigma.shape[:2] + (3,))
    return (sigma @ n[..., None])[..., 0]


def _jumps(space, stresses: TetStress, faces: FacetSet, s, w) -> np.ndarray:
    """η2's ``‖⟦σ(u_h) n⟧‖²_F`` on interior faces: both cells at the same points, the jump
    ``(σ₀ − σ₁) n₀`` with the first cell's outward normal. On a flat face between two affine
    cells the jump is linear and is integrated exactly from its vertex values
    (:func:`linear_square`); by the rule ``(s, w)`` elsewhere (:func:`_jumps_by_rule`)."""
    J = np.zeros(faces.index.size)
    for rows, geometry in face_geometry(space, faces.nodes):
        nodes, cells = faces.nodes[rows], faces.cells[rows]
        if isinstance(geometry, FlatFaces):
            linear = _affine(space, cells).all(axis=1)
            sub = np.flatnonzero(linear)
            if sub.size:
                n = geometry.normals()[sub]  # (r, 1, 3)
                v = nodes[sub, :3]
                jump = stresses.at_vertices(cells[sub, 0], v)
                jump -= stresses.at_vertices(cells[sub, 1], v)
                J[np.arange(J.size)[rows][sub]] = linear_square(
                    (jump @ n[:, :, :, None])[..., 0], geometry.area[sub]
                )
            rest = np.flatnonzero(~linear)
            if rest.size == 0:
                continue
            rows, geometry = np.arange(J.size)[rows][rest], FlatFaces(geometry.corners[rest])
            nodes, cells = faces.nodes[rows], faces.cells[rows]
        J[rows] = _jumps_by_rule(stresses, cells, nodes, geometry, s, w)
    return J


def _jumps_by_rule(stresses: TetStress, cells, nodes, geometry, s, w) -> np.ndarray:
    """η2's ``‖⟦σ(u_h) n⟧‖²_F`` by the triangle rule ``(s, w)`` through each cell's map."""
    jump = _traction(stresses, cells[:, 0], nodes, s, geometry)
    jump -= _traction(stresses, cells[:, 1], nodes, s, geometry)
    return neumann_residual(jump, w, geometry.speeds(s))


def _affine(space: P2TetSpace, cells: np.ndarray) -> np.ndarray:
    """Whether each of ``cells`` (any shape) is affine (σ(u_h) linear on it)."""
    mapping = space.mapping
    if len(mapping.groups) == 1:
        return np.full(cells.shape, mapping.groups[0].order == 1)
    return mapping.group[cells] == 0


def linear_square(values: np.ndarray, area: np.ndarray) -> np.ndarray:
    """``∫_F |r|²`` of linear fields ``r`` on triangles from their vertex values ``values
    (k, 3, c)``: ``|F| / 12 (Σ_i |r_i|² + |Σ_i r_i|²)``, the exact mass matrix of the
    barycentric coordinates ``|F| / 12 (I + 1 1ᵀ)`` (docs/method.md, *Three dimensions: the
    estimator at speed*)."""
    total = values.sum(axis=1)
    return (
        area
        / 12.0
        * (np.einsum("kjc,kjc->k", values, values) + np.einsum("kc,kc->k", total, total))
    )


def _traction_residuals(
    result: ContactResult, stresses: TetStress, own: OwnPart | None = None
) -> tuple[FacetSet, np.ndarray]:
    """η3's faces and ``‖r‖²_F`` on each, part after part: ``r = σ(u_h)n − g`` on Neumann parts
    (g at the points and with the normals of each face's geometry), the tangential part of
    σ(u_h)n on rollers, the free components of σ(u_h)n on Dirichlet parts that hold some
    (docs/method.md, *Rollers and components*). With this rank's part ``own``, on the faces
    it integrates only (zero on the others)."""
    problem, space, mesh = result.problem, result.space, result.mesh
    s, w = triangle_rule(NEUMANN_DEGREE_3D)
    index, values = [], []
    for name, cond in problem.conditions.items():  # a loop over parts
        if isinstance(cond, Dirichlet) and all(cond.components):
            continue
        if not isinstance(cond, Dirichlet | Roller) and name not in problem.neumann_parts:
            continue
        e = mesh.part_facets(name)
        J = _on_own_faces(
            _face_set(space, e),
            own,
            lambda faces, c=cond, n=name: _part_tractions(stresses, faces, c, n, s, w),
        )
        index.append(e)
        values.append(J)
    e = np.concatenate(index) if index else np.zeros(0, np.int64)
    return _face_set(space, e), (np.concatenate(values) if values else np.zeros(0))


def _part_tractions(
    stresses: TetStress, faces: FacetSet, cond: object, name: str, s: np.ndarray, w: np.ndarray
) -> np.ndarray:
    """η3's ``‖r‖²_F`` on the faces ``faces`` of the part ``name`` with condition ``cond``
    (:func:`_traction_residuals`)."""
    J = np.zeros(faces.index.size)
    for rows, geometry in face_geometry(stresses.space, faces.nodes):
        sn = _traction(stresses, faces.cells[rows, 0], faces.nodes[rows], s, geometry)
        n = np.broadcast_to(geometry.normals(s), sn.shape)
        if isinstance(cond, Roller):
            sn = sn - np.einsum("kqc,kqc->kq", sn, n)[..., None] * n
        elif isinstance(cond, Dirichlet):
            sn = sn * ~np.asarray(cond.components)
        elif not cond.is_zero:
            what = f"the traction of Neumann part {name!r}"
            g = evaluate_field(cond.field(), geometry.points(s), what, shape=(3,), normal=n)
            sn = sn - g / stresses.unit
        J[rows] = neumann_residual(sn, w, geometry.speeds(s))
    return J
