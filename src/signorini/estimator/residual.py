"""ESTIMATE: the residual a posteriori error estimator η_h of the paper (Section 5, (5.1)).

For every non-Dirichlet P2 node p (docs/method.md, *Estimator*), with ``h_p = max_{T ∈ ω_p} h_T``:

==== =========================================================== =====================
η1   ``h_p² ‖f + div σ(u_h)‖²_{ω_p}``                               all free nodes
η2   ``h_p ‖⟦σ(u_h)⟧‖²_{γ_{p,I}}``                                  all free nodes
η3   ``h_p ‖σ(u_h)n − g‖²_{γ_{p,N}}``                               Neumann nodes
η4   ``h_p ‖σ_t(u_h)‖²_{γ_{p,C}}``                                  contact nodes
η5   ``h_p ‖σ_nn(u_h)‖²`` (``paper``) or                            contact nodes
     ``h_p ‖σ_nn(u_h) + p_h‖²`` (``consistent``) on ``γ_{p,C}``
η6   ``s_p d_p``, ``d_p = ∫_{γ̃_p} (ψ − u_h·n)⁺ φ_p ds``            semi-contact nodes
η7   ``‖(u_h·n − ψ)⁺‖²_{H^{1/2}(Γ_C)}``                              global
η8   ``∫_{γ̃_p} (max(b_h, |p_t,h|) |u_t| − p_t,h u_t) ds``            contact nodes
==== =========================================================== =====================

With Tresca or Coulomb friction η4 becomes ``h_p ‖σ_t(u_h) + p_t,h‖²_{γ_{p,C}}`` (p_t,h the
quadratic interpolant of the nodal friction stresses) and η8, the defect of the friction work,
is added; without friction both are the frictionless values exactly (η8 = 0;
docs/method.md, *Estimator*, "With friction").

γ_{p,I}, γ_{p,N}, γ_{p,C} are the interior, Neumann and contact facets (edges in 2D) that contain p
(as a vertex or as their midpoint): the only facets where the P2 basis function ψ_p is not zero.
γ̃_p is made of the thirds of the contact facets that belong to p (outer thirds to the end vertices,
the middle third to the midpoint). On contact facets ψ is replaced by its P2 interpolant, so that
(u_h·n − ψ) is a quadratic on each facet (exact for gaps that are piecewise quadratic with kinks at
nodes, as in Example 6.2). A P1 solution is estimated by the same terms on its P2 form, the pieces
γ̃_p and the facet layout taken from its facet element (docs/method.md, *P1 elements and their
estimator*).

Each term is one function of :mod:`signorini.estimator.terms` (arrays in, integrals out):
η1 ``interior_residual``, η2 ``stress_jump``, η3 ``neumann_residual``,
η4 ``tangential_stress``, η5 ``normal_stress``, η6 ``complementarity``,
η7 ``penetration``, η8 ``friction_work``; :func:`estimate` is the table that feeds them, by
name. Every node term is a sum of cell or facet integrals; each cell receives its share (facet
terms split equally between the facet's cells, ``terms.spread_facet_integrals``), so the
element indicators sum exactly to η_h².

Each integral is taken once, through the geometry of its cell or facet
(:mod:`signorini.fem.mapping`, :func:`geometry`): the closed forms of straight cells where
the Jacobian is constant, the quadratic maps of the isoparametric cells along curved parts
and their quadratic facets elsewhere; η4, η5 split the traction along the constraint direction
field where n_z is not the facet's normal (docs/method.md, *Estimator*, "On curved
boundaries").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algebra.ranks import SERIAL, Ranks
from ..contact.partition import Partition
from ..contact.solution import ContactResult
from ..fem.mapping import CellMap
from ..fem.material import CellMaterials, Material, on_cells
from ..fem.postprocess import stress_divergence
from ..fem.quadrature import line_rule, triangle_rule
from ..fem.space import LagrangeSpace
from ..problem.fields import evaluate_field
from ..problem.problem import ContactProblem
from .contact_facets import contact_node_parts, contact_stress, facet_pressure, semi_contact_density
from .friction_facets import friction_facets
from .held import further_traction_facets
from .names import TERMS
from .owned import OwnPart, own_part, per_cell_of
from .terms import (
    FacetSet,
    TermShares,
    boundary_cell_shares,
    interior_residual,
    neumann_residual,
    node_mesh_size,
    penetration,
    spread_cell_integrals,
    spread_facet_integrals,
    spread_node_parts,
    stress_jump,
)
from .traction import CellStress, vertex_stress

__all__ = [
    "ETA5_VARIANTS",
    "NODE_TERMS",
    "TERMS",
    "Estimate",
    "estimate",
    "contact_stress",
    "geometry",
    "stress_unit",
]

#: the variants of η5 (docs/method.md, *Estimator*); the first is the default
ETA5_VARIANTS = ("consistent", "paper")
#: the terms with node contributions (all but the global η7), the rows of ``Estimate.eta2_node``
NODE_TERMS = tuple(name for name in TERMS if name != "eta_7")
#: line quadrature degree for the polynomial facet terms η2, η4, η5 (σ(u_h) is linear)
EDGE_DEGREE = 7
#: line quadrature degree for the Neumann residual with non-polynomial data g: finer, so
#: that quadrature stays far below the residual itself
NEUMANN_DEGREE = 15
#: triangle quadrature degree for η1 with a body force
CELL_DEGREE = 8
#: stresses of magnitude inside this range are squared as they are (``Estimate.unit`` = 1);
#: outside it the estimator divides them by a power of 4 first, so that no square overflows
#: or underflows (docs/method.md, *Estimator*, "Units")
STRESS_RANGE = (2.0**-256, 2.0**256)
#: power of the stress unit in each term's square, in the order of ``TERMS``: η1² … η5² are
#: squares of stresses (times lengths), η6² = s_p d_p is a stress times a length² times a
#: displacement, η7² a squared displacement, η8² (stress × displacement × length) as η6²
UNIT_POWER = (2, 2, 2, 2, 2, 1, 0, 1)


@dataclass(frozen=True)
class Estimate:
    """Estimator contributions of one discrete solution.

    Consistent units: if E is in MPa and lengths in mm (so displacements are in mm), η1 …
    η5 are in MPa·mm (stress × length), η6 in MPa^{1/2}·mm (η6² = s_p d_p: stress × length²),
    η7 in mm (a displacement; its square is ‖v‖²_{L²} (mm³) plus the H^{1/2} seminorm
    (mm²), so η7 is not homogeneous in length alone), and η8 as η6 (η8² = ∫ p_t u_t ds:
    stress × length²). η_h adds the squares as the paper does; η8 = 0 without friction.

    Attributes
    ----------
    eta2_cell : (8, n_cells) float array
        Share of each cell in η_k² / unit^{a_k}, k = 1..8 (rows in the order of ``TERMS``,
        ``a = UNIT_POWER = (2, 2, 2, 2, 2, 1, 0, 1)``). Each row sums to η_k² / unit^{a_k};
        with ``unit = 1`` (every ordinary problem) these are the squares themselves.
    eta2_node : (7, n_nodes) float array
        Node contributions η_{k,p}² / unit^{a_k} of the terms ``NODE_TERMS`` (η1 … η6, η8), as
        the paper writes them (zero at Dirichlet nodes and where a term does not apply). η7
        is global.
    eta5_variant : str
        The η5 variant used (one of ``ETA5_VARIANTS``).
    unit : float
        The stress unit σ₀ the squares were taken in: 1 when max|σ(u_h)| lies in
        ``STRESS_RANGE``, else the largest power of 4 not above it (so that scaling by it and by
        its square root is exact in floating point).
    """

    eta2_cell: np.ndarray
    eta2_node: np.ndarray
    eta5_variant: str
    unit: float = 1.0

    @property
    def _exponents(self) -> tuple[np.ndarray, int]:
        """``a_k e`` with ``unit = 2^e`` (row k times ``2^{a_k e}`` is η_k²), and ``r`` with
        ``max_k η_k ≤ 2^r`` (0 when ``unit = 1``): the power of two η_T² and η_h² are
        taken relative to, so that neither overflows nor underflows."""
        e = int(np.frexp(self.unit)[1]) - 1
        power = np.array(UNIT_POWER) * e
        if e == 0:
            return power, 0
        top = float(self.eta_terms.max())
        return power, int(np.frexp(top)[1]) if top > 0 else 0

    @property
    def eta2_terms(self) -> np.ndarray:
        """``(8,)`` the squared contributions η_k² (they overflow to inf when ``unit`` is
        beyond about 1e154; :attr:`eta_terms` does not)."""
        return np.ldexp(self.eta2_cell.sum(axis=1), self._exponents[0])

    @property
    def eta_terms(self) -> np.ndarray:
        """``(8,)`` the contributions η_k."""
        power = (np.frexp(self.unit)[1] - 1) * np.array(UNIT_POWER) // 2
        return np.ldexp(np.sqrt(self.eta2_cell.sum(axis=1)), power)

    @property
    def eta2(self) -> np.ndarray:
        """``(n_cells,)`` element indicators η_T² for marking: the squares themselves when
        ``unit = 1``, else η_T² / 4^r with ``max_k η_k ≤ 2^r`` (marking needs only their
        ratios)."""
        power, r = self._exponents
        return np.ldexp(self.eta2_cell, (power - 2 * r)[:, None]).sum(axis=0)

    @property
    def eta(self) -> float:
        """The total estimator η_h = (Σ_k η_k²)^{1/2} (5.1)."""
        power, r = self._exponents
        total = np.ldexp(self.eta2_cell, (power - 2 * r)[:, None]).sum()
        return float(np.ldexp(np.sqrt(total), r))

    def as_dict(self) -> dict[str, float]:
        """``{"eta": η_h, "eta_1": η1, …, "eta_8": η8}``, the names of the history columns."""
        out = {"eta": self.eta}
        out.update({name: float(v) for name, v in zip(TERMS, self.eta_terms, strict=True)})
        return out


def estimate(
    result: ContactResult,
    eta5_variant: str = ETA5_VARIANTS[0],
    *,
    ranks: Ranks = SERIAL,
    partition: Partition | None = None,
) -> Estimate:
    """Compute η_h and all its contributions for a discrete solution (paper, Section 5); on
    tetrahedra :func:`~.residual3d.estimate_3d`.

    Parameters
    ----------
    result : ContactResult
        The discrete solution.
    eta5_variant : {"consistent", "paper"}
        ``"paper"`` is η5 as printed (the full normal stress on Γ_C); ``"consistent"``
        balances it by the discrete pressure, ``σ_nn(u_h) + p_h`` (docs/method.md, *Estimator*).
        With friction η4 is ``‖σ_t(u_h) + p_t,h‖`` in both variants.
    ranks : Ranks, optional
        The processes of a run on several MPI ranks (:mod:`signorini.algebra.ranks`; default
        one process): each integrates its own cells and facets, and the integrals are summed
        over them (:mod:`signorini.estimator.owned`); every rank returns the serial estimate.
    partition : Partition, optional
        Which cells are this rank's (:func:`signorini.contact.partition.partition`, built
        from ``result.space`` and ``ranks`` when not given).

    Returns
    -------
    Estimate

    Raises
    ------
    ValueError
        For an unknown ``eta5_variant``, or ``ranks`` or ``partition`` that do not fit
        (:func:`~signorini.estimator.owned.own_part`).
    """
    if eta5_variant not in ETA5_VARIANTS:
        raise ValueError(f"eta5_variant must be one of {ETA5_VARIANTS}, got {eta5_variant!r}")
    own = own_part(result, ranks, partition)  # None: one process, every cell and facet
    if result.mesh.dim == 3:  # tetrahedra: the 3D table (it imports this module)
        from .residual3d import estimate_3d

        return estimate_3d(result, eta5_variant, own=own)
    problem, space, mesh, cs = result.problem, result.space, result.mesh, result.contact
    n_nodes, n_cells = space.n_nodes, mesh.n_cells
    element = space.element  # P2, or P1 read as the P2 field it is (docs/method.md, *P1 ...*)
    on_facet = element.facet.facet_values  # contact facets' nodal data: [start, end, midpoint]
    h_p = node_mesh_size(mesh.h, space.cell_nodes, result.dirichlet_nodes, n_nodes)
    cells, quadratic_facets = geometry(space)

    # what the terms integrate: the residual in the cells, σ(u_h) n on the facets, the gap
    # every stress-like input (σ(u_h), div σ(u_h), f, g, p_z, s_z) is divided by the stress
    # unit σ₀ (a power of 4, 1 for ordinary stresses): exact, and no square overflows;
    # Estimate puts σ₀ back (docs/method.md, *Estimator*, "Units")
    material = problem.material_on(mesh)  # each cell's own where regions differ
    stresses = _cell_stress(result, cells, material, own)
    unit, u_cell = stresses.unit, stresses.u_cell
    t, w = line_rule(EDGE_DEGREE)
    inner = _facet_set(space, np.flatnonzero(mesh.facet2cell[:, 1] >= 0))
    t_n, w_n = line_rule(NEUMANN_DEGREE)
    # pairs' masters (the slave's traction) and rollers (their free traction) join η3: held.py
    further, J3_further = further_traction_facets(result, stresses, t_n, w_n, unit)
    neumann = _facet_set(
        space, np.concatenate([_part_facets(mesh, problem.neumann_parts), further])
    )
    contact = FacetSet(
        cs.facets, cs.facet_nodes, mesh.facet2cell[cs.facets], mesh.facet_measure[cs.facets]
    )
    pressure = on_facet(facet_pressure(result)) / unit if eta5_variant == "consistent" else None
    friction = friction_facets(result, unit)  # None without friction
    if friction is not None:
        friction = type(friction)(*(on_facet(v) for v in friction))
    p_t = None if friction is None else friction.friction
    gap = on_facet(cs.facet_normal_gap(result.u))  # u_h·n − ψ_h at [start, end, midpoint]
    density = on_facet(semi_contact_density(result)) / unit
    x0, x1 = mesh.points[cs.facet_nodes[:, 0]], mesh.points[cs.facet_nodes[:, 1]]
    eta7_shares = penetration(x0, x1, gap, scale=float(np.abs(result.u).max(initial=0.0)))

    # each integral once per cell or facet, through its own geometry (docs/method.md,
    # *Estimator*, "On curved boundaries"); on several ranks, the rank's own (owned.py)
    R = _interior_residual(problem, material, cells, u_cell, unit, own)
    J2 = _stress_jumps(mesh, stresses, inner, t, w, own)
    J3 = np.concatenate([_neumann_integrals(problem, mesh, stresses, t_n, w_n, unit), J3_further])
    direction = on_facet(cs.facet_direction)
    # the contact terms on every contact facet, on every rank (Γ_C's data is replicated)
    every = stresses.everywhere
    J4, J5 = contact_stress(every, mesh, contact, cs.facet_normal, direction, t, w, pressure, p_t)
    curved = np.isin(cs.facets, quadratic_facets)
    parts6, parts8 = contact_node_parts(result, gap, density, friction, curved)
    if own is not None:  # each integral from the one rank that owns it, summed over the ranks
        mine = own.facets(contact.cells)
        J4, J5, eta7_shares = (np.where(mine, a, 0.0) for a in (J4, J5, eta7_shares))
        parts6, parts8 = (np.where(mine[:, None], a, 0.0) for a in (parts6, parts8))
        R, J2, J3, J4, J5, parts6, parts8, eta7_shares = own.sum(
            [R, J2, J3, J4, J5, parts6, parts8, eta7_shares]
        )

    def on_facets(facets: FacetSet, J: np.ndarray) -> TermShares:
        return spread_facet_integrals(facets, J, h_p, n_cells)

    shares = {
        "eta_1": spread_cell_integrals(R, space.cell_nodes, h_p),
        "eta_2": on_facets(inner, J2),
        "eta_3": on_facets(neumann, J3),
        "eta_4": on_facets(contact, J4),
        "eta_5": on_facets(contact, J5),
        "eta_6": spread_node_parts(contact, parts6, n_nodes, n_cells),
        "eta_7": TermShares(None, boundary_cell_shares(contact, eta7_shares, n_cells)),
        "eta_8": spread_node_parts(contact, parts8, n_nodes, n_cells),
    }
    return Estimate(
        eta2_cell=np.stack([shares[name].cell for name in TERMS]),
        eta2_node=np.stack([shares[name].node for name in NODE_TERMS]),
        eta5_variant=eta5_variant,
        unit=unit,
    )


# --------------------------------------------------------------------------- inputs of the terms


def stress_unit(sigma_max: float) -> float:
    """The stress unit σ₀ the estimator squares stresses in: 1 if ``sigma_max`` lies in
    ``STRESS_RANGE`` (or is 0 or not finite), else the largest power of 4 not above ``sigma_max``.

    Dividing by a power of 4 is exact, and so is multiplying η_k by its square root, so
    η_k are the same numbers as without scaling wherever those do not overflow or underflow.
    """
    lo, hi = STRESS_RANGE
    if not np.isfinite(sigma_max) or sigma_max == 0.0 or lo <= sigma_max <= hi:
        return 1.0
    return float(np.ldexp(1.0, 2 * int(np.floor(np.log2(sigma_max) / 2))))


def geometry(space: LagrangeSpace) -> tuple[CellMap, np.ndarray]:
    """The cells' maps (:attr:`~signorini.fem.space.P2Space.mapping`) and the boundary facets
    that are quadratics (those on parts carrying a curve other than a line; none in a P1
    space): the geometry every term integrates on."""
    return space.mapping, space.curved_facets


def _cell_stress(
    result: ContactResult, cells: CellMap, material: Material | CellMaterials, own: OwnPart | None
) -> CellStress:
    """σ(u_h) of ``result`` in its stress unit (:func:`stress_unit` of max|σ(u_h)|) on every
    cell; with ``own`` on the cells its rank's terms read (``OwnPart.stressed_cells``, the
    other rows zero), the maximum taken over the ranks."""
    space, mesh = result.space, result.mesh
    if own is None:
        u_cell = space.field_coefficients(result.u)
        sigma = vertex_stress(cells, u_cell, material)
        unit = stress_unit(float(np.abs(sigma).max(initial=0.0)))
        return CellStress(cells, mesh.points, mesh.cells, u_cell, material, sigma / unit, unit)
    stressed = own.stressed_cells(mesh.facet2cell, result.contact.facets)
    u_cell = np.zeros((mesh.n_cells, 12))
    values = np.asarray(result.u).reshape(-1)[space.cell_dofs[stressed]]  # as cell_values
    u_cell[stressed] = space.element.cell_coefficients(values)
    sigma = vertex_stress(cells, u_cell, material, stressed)
    unit = stress_unit(own.ranks.max(float(np.abs(sigma[stressed]).max(initial=0.0))))
    if unit != 1.0:
        sigma[stressed] /= unit
    return CellStress(cells, mesh.points, mesh.cells, u_cell, material, sigma, unit, own.cells)


def _interior_residual(
    problem: ContactProblem,
    material: Material | CellMaterials,
    cells: CellMap,
    u_cell: np.ndarray,
    unit: float,
    own: OwnPart | None = None,
) -> np.ndarray:
    """η1's ``‖f + div σ(u_h)‖²_T`` ``(n_cells,)``: div σ(u_h) from the Hessian of u_h through
    each cell's map (constant on affine cells), f at the points of the degree-``CELL_DEGREE``
    rule (called once, at the points of the maps), both in the stress unit; each cell with its
    own material. With ``own``, on its cells only (zero on the others)."""
    xi, w = triangle_rule(CELL_DEGREE)
    subset = None if own is None else np.flatnonzero(own.cells)
    f = None
    if problem.body_force is not None and (subset is None or subset.size):
        if subset is None:
            points = cells.points(xi)
        else:
            points = per_cell_of(cells, subset, lambda g, _: g.points(xi), (len(xi), 2))
        f = evaluate_field(problem.body_force, points, "body_force") / unit

    def residual(g, f_g) -> np.ndarray:
        hess = g.field_hessians(u_cell[g.cells], xi)
        div = stress_divergence(hess, on_cells(material, g.cells)) / unit
        return interior_residual(0.5 * g.jacobians(xi)[1], div, f_g, w)

    if subset is None:
        return cells.per_cell(lambda g: residual(g, None if f is None else f[g.cells]))
    R = np.zeros(cells.n_cells)
    R[subset] = per_cell_of(
        cells, subset, lambda g, rows: residual(g, None if f is None else f[rows])
    )
    return R


def _stress_jumps(
    mesh, stresses: CellStress, inner: FacetSet, t: np.ndarray, w: np.ndarray, own: OwnPart | None
) -> np.ndarray:
    """η2's ``‖⟦σ(u_h)⟧‖²_F`` on the interior facets ``inner``; with ``own`` on its facets
    only (zero on the others)."""
    if own is None:
        return stress_jump(
            *_from_both_sides(mesh, stresses.traction, inner.index, t), w, inner.measure
        )
    J = np.zeros(inner.index.size)
    mine = np.flatnonzero(own.facets(inner.cells))
    jump = _from_both_sides(mesh, stresses.traction, inner.index[mine], t)
    J[mine] = stress_jump(*jump, w, inner.measure[mine])
    return J


def _neumann_integrals(
    problem: ContactProblem, mesh, stresses: CellStress, t: np.ndarray, w: np.ndarray, unit: float
) -> np.ndarray:
    """η3's ``‖σ(u_h) n − g‖²_F`` on the Neumann facets (part after part), g (divided by the
    stress unit) at the points and with the normals of each facet's geometry."""
    out = []
    for name in problem.neumann_parts:
        cond = problem.conditions[name]
        e = mesh.part_facets(name)
        values = np.zeros(e.size)
        for rows, sn, facets in stresses.on_facets(
            mesh.facet2cell[e, 0], mesh.facet_local[e, 0], t
        ):
            if not cond.is_zero:
                what = f"the traction of Neumann part {name!r}"
                g = evaluate_field(cond.field(), facets.points(t), what, normal=facets.normals(t))
                sn = sn - g / unit
            values[rows] = neumann_residual(sn, w, facets.speeds(t))
        out.append(values)
    return np.concatenate(out) if out else np.zeros(0)


def _part_facets(mesh, names) -> np.ndarray:
    """Mesh facets of the named boundary parts, part after part."""
    return np.concatenate([mesh.part_facets(p) for p in names] or [np.zeros(0, np.int64)])


def _facet_set(space: LagrangeSpace, e: np.ndarray) -> FacetSet:
    """Mesh facets ``e`` with their nodes ``[vertex, vertex, midpoint]`` (P1: the two
    vertices), cells and measures."""
    mesh = space.mesh
    return FacetSet(e, space.mesh_facet_nodes(e), mesh.facet2cell[e], mesh.facet_measure[e])


def _from_both_sides(mesh, traction, e: np.ndarray, t: np.ndarray):
    """σ(u_h) n of both cells of interior facets ``e`` at the same points, each with its
    outward normal (the second cell runs the facet the other way)."""
    c, k = mesh.facet2cell[e], mesh.facet_local[e]
    return traction(c[:, 0], k[:, 0], t), traction(c[:, 1], k[:, 1], 1 - t)
