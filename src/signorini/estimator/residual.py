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
==== =========================================================== =====================

γ_{p,I}, γ_{p,N}, γ_{p,C} are the interior, Neumann and contact edges that contain p (as a
vertex or as their midpoint): the only edges where the P2 basis function ψ_p is not zero.
γ̃_p is made of the thirds of the contact edges that belong to p (outer thirds to the end
vertices, the middle third to the midpoint). On contact edges ψ is replaced by its P2
interpolant, so that (u_h·n − ψ) is a quadratic on each edge (exact for gaps that are
piecewise quadratic with kinks at nodes, as in Example 6.2).

Every node term is a sum of cell or edge integrals; each cell receives its share (edge terms
split equally between the edge's cells), so the element indicators sum exactly to η_h².
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact.contact_set import SEMI_CONTACT
from ..contact.solution import ContactResult
from ..fem.material import stress
from ..fem.p2 import REFERENCE_NODES, edge_basis, field_gradients, physical_points
from ..fem.postprocess import div_stress
from ..fem.quadrature import line_rule, triangle_rule
from ..mesh.geometry import segment_normals
from ..problem.conditions import Neumann
from ..problem.fields import evaluate_field
from .hhalf import hhalf_norm2_positive_part

__all__ = ["Estimate", "estimate", "ETA5_VARIANTS", "third_integrals"]

ETA5_VARIANTS = ("consistent", "paper")
N_TERMS = 7
#: line quadrature degree for the Neumann residual with non-polynomial data g
NEUMANN_DEGREE = 15


@dataclass(frozen=True)
class Estimate:
    """Estimator contributions of one discrete solution.

    Attributes
    ----------
    eta2_cell : (7, n_cells) float array
        Share of each cell in η_k², k = 1..7 (row k−1). Sums to η_k².
    eta2_node : (6, n_nodes) float array
        Node contributions η_{k,p}², k = 1..6, as the paper writes them (zero at Dirichlet
        nodes and where a term does not apply). η7 is global.
    eta5 : str
        The η5 variant used.
    """

    eta2_cell: np.ndarray
    eta2_node: np.ndarray
    eta5: str

    @property
    def eta2_terms(self) -> np.ndarray:
        """``(7,)`` the squared contributions η_k²."""
        return self.eta2_cell.sum(axis=1)

    @property
    def eta_terms(self) -> np.ndarray:
        """``(7,)`` the contributions η_k."""
        return np.sqrt(self.eta2_terms)

    @property
    def eta2(self) -> np.ndarray:
        """``(n_cells,)`` element indicators η_T² for marking."""
        return self.eta2_cell.sum(axis=0)

    @property
    def eta(self) -> float:
        """The total estimator η_h = (Σ_k η_k²)^{1/2} (5.1)."""
        return float(np.sqrt(self.eta2_cell.sum()))

    def as_dict(self) -> dict[str, float]:
        """``{"eta": η_h, "eta1": η1, …, "eta7": η7}``."""
        out = {"eta": self.eta}
        out.update({f"eta{k + 1}": float(v) for k, v in enumerate(self.eta_terms)})
        return out


def estimate(result: ContactResult, eta5: str = "consistent") -> Estimate:
    """Compute η_h and all its contributions for a discrete solution (paper, Section 5).

    Parameters
    ----------
    result : ContactResult
        The discrete solution.
    eta5 : {"consistent", "paper"}
        ``"paper"`` is η5 as printed (the full normal stress on Γ_C); ``"consistent"``
        balances it by the discrete pressure, ``σ_nn(u_h) + p_h`` (docs/method.md, *Estimator*).
    """
    if eta5 not in ETA5_VARIANTS:
        raise ValueError(f"eta5 must be one of {ETA5_VARIANTS}, got {eta5!r}")
    problem, space, mesh = result.problem, result.space, result.mesh
    material = problem.material
    n_nodes, n_cells = space.n_nodes, mesh.n_cells
    cell_nodes = space.cell_nodes
    V = space.vertices
    u_cell = space.cell_values(result.u)

    free = np.ones(n_nodes, dtype=bool)
    free[result.dirichlet_nodes] = False
    h_p = np.zeros(n_nodes)
    np.maximum.at(h_p, cell_nodes.ravel(), np.repeat(mesh.h, 6))
    h_p = np.where(free, h_p, 0.0)  # Dirichlet nodes carry no term

    eta2_cell = np.zeros((N_TERMS, n_cells))
    eta2_node = np.zeros((N_TERMS - 1, n_nodes))

    # ---- η1: interior residual f + div σ(u_h)
    divs = div_stress(V, u_cell, material)  # (m, 2), constant on each cell
    if problem.body_force is None:
        R = mesh.area * (divs**2).sum(axis=1)
    else:
        xi, w = triangle_rule(8)
        x = physical_points(V, xi)
        r = evaluate_field(problem.body_force, x, "body_force") + divs[:, None, :]
        R = 2 * mesh.area * np.einsum("q,mqc,mqc->m", w, r, r)
    eta2_cell[0] = R * (h_p[cell_nodes] ** 2).sum(axis=1)
    eta2_node[0] = h_p**2 * np.bincount(
        cell_nodes.ravel(), weights=np.repeat(R, 6), minlength=n_nodes
    )

    # ---- stresses on edges: σ(u_h) is linear on each cell, known from its vertex values
    sig_v = stress(material, field_gradients(V, u_cell, REFERENCE_NODES[:3]))  # (m, 3, 2, 2)
    edges, e2c = mesh.edges, mesh.edge2cell
    n_points = mesh.n_points
    local = mesh.edge_local  # (n_edges, 2)
    t, wt = line_rule(7)

    def traction(cell: np.ndarray, k: np.ndarray, tt: np.ndarray) -> np.ndarray:
        """σ(u_h) n at parameters ``tt`` along local edge k of ``cell`` (its own direction)."""
        s0 = sig_v[cell, k]
        s1 = sig_v[cell, (k + 1) % 3]
        sig = (1 - tt)[None, :, None, None] * s0[:, None] + tt[None, :, None, None] * s1[:, None]
        _, n = segment_normals(
            mesh.points[mesh.cells[cell, k]], mesh.points[mesh.cells[cell, (k + 1) % 3]]
        )
        return np.einsum("eqij,ej->eqi", sig, n)

    def edge_nodes_of(e: np.ndarray) -> np.ndarray:
        return np.column_stack([edges[e], n_points + e])

    def add_edge_term(term: int, e: np.ndarray, J: np.ndarray, nodes: np.ndarray) -> None:
        """Edge integral J_e enters η_{term,p}² with weight h_p for each node p of e."""
        hp = h_p[nodes]  # (k, 3), zero at Dirichlet nodes
        node_part = hp * J[:, None]
        np.add.at(eta2_node[term], nodes.ravel(), node_part.ravel())
        total = node_part.sum(axis=1)
        c0, c1 = e2c[e, 0], e2c[e, 1]
        two = c1 >= 0
        np.add.at(eta2_cell[term], c0, np.where(two, 0.5, 1.0) * total)
        np.add.at(eta2_cell[term], c1[two], 0.5 * total[two])

    # ---- η2: stress jumps on interior edges
    inner = np.flatnonzero(e2c[:, 1] >= 0)
    jump = traction(e2c[inner, 0], local[inner, 0], t) + traction(
        e2c[inner, 1], local[inner, 1], 1 - t
    )
    J2 = mesh.edge_length[inner] * np.einsum("q,eqi,eqi->e", wt, jump, jump)
    add_edge_term(1, inner, J2, edge_nodes_of(inner))

    # ---- η3: Neumann residual σ(u_h) n − g (g is any function: a finer rule than for the
    # polynomial edge terms, so that quadrature stays far below the residual itself)
    tn, wn = line_rule(NEUMANN_DEGREE)
    for name in problem.neumann_parts:
        cond: Neumann = problem.conditions[name]
        e = mesh.part_edges(name)
        sn = traction(e2c[e, 0], local[e, 0], tn)
        if not cond.is_zero:
            ab = mesh.cells[e2c[e, 0][:, None], (local[e, 0][:, None] + [0, 1]) % 3]
            a, b = mesh.points[ab[:, 0]], mesh.points[ab[:, 1]]
            x = a[:, None] + tn[None, :, None] * (b - a)[:, None]
            _, n = segment_normals(a, b)
            g = cond.field()
            sn = sn - evaluate_field(
                lambda y, n=n, g=g: g(y, n[:, None, :]), x, f"the traction of part {name!r}"
            )
        J3 = mesh.edge_length[e] * np.einsum("q,eqi,eqi->e", wn, sn, sn)
        add_edge_term(2, e, J3, edge_nodes_of(e))

    # ---- η4, η5: tangential and normal stress on Γ_C
    cs = result.contact
    if cs.edges.size:
        e = cs.edges
        nodes = edge_nodes_of(e)
        sn = traction(e2c[e, 0], local[e, 0], t)
        nrm = cs.edge_normal
        snn = np.einsum("eqi,ei->eq", sn, nrm)
        st = sn - snn[..., None] * nrm[:, None, :]
        length = mesh.edge_length[e]
        add_edge_term(3, e, length * np.einsum("q,eqi,eqi->e", wt, st, st), nodes)
        if eta5 == "consistent":
            loc = cs.edge_local
            p_nodes = np.where(loc >= 0, result.pressure[np.maximum(loc, 0)], 0.0)
            # the contact set's edge nodes are [start, end, midpoint] along the cell's direction
            snn = snn + p_nodes @ edge_basis(t).T
        add_edge_term(4, e, length * (wt * snn**2).sum(axis=1), nodes)

        # ---- η6: s_p d_p on semi-contact nodes
        wgap = cs.edge_normal_gap(result.u)  # u·n − ψ_h at [start, end, mid]
        thirds = third_integrals(-wgap, length)  # ∫ (ψ − u·n)⁺ φ_p over p's third
        loc = cs.edge_local
        semi = np.zeros(cs.size, dtype=bool)
        semi[result.classes == SEMI_CONTACT] = True
        use = (loc >= 0) & semi[np.maximum(loc, 0)]
        s = np.where(use, result.density[np.maximum(loc, 0)], 0.0)
        part6 = s * thirds
        np.add.at(eta2_node[5], cs.edge_nodes.ravel(), part6.ravel())
        np.add.at(eta2_cell[5], e2c[e, 0], part6.sum(axis=1))

        # ---- η7: H^{1/2}(Γ_C) norm of the penetration (u_h·n − ψ)⁺
        x0 = mesh.points[cs.edge_nodes[:, 0]]
        x1 = mesh.points[cs.edge_nodes[:, 1]]
        _, share = hhalf_norm2_positive_part(x0, x1, wgap[:, [0, 2, 1]])
        np.add.at(eta2_cell[6], e2c[e, 0], share)

    return Estimate(eta2_cell=eta2_cell, eta2_node=eta2_node, eta5=eta5)


def third_integrals(v: np.ndarray, length: np.ndarray) -> np.ndarray:
    """∫ v⁺ φ_p over the thirds γ̃_p of each edge (docs/method.md, *Estimator*, paper (4.12)).

    Parameters
    ----------
    v : (k, 3) float array
        A quadratic on each edge, by its values at ``[start, end, midpoint]``.
    length : (k,) float array

    Returns
    -------
    (k, 3) float array
        ``[∫_{start third} v⁺ φ_start, ∫_{end third} v⁺ φ_end, ∫_{middle third} v⁺ φ_mid]``
        where φ are the half-edge hats of Q^h (3.6).
    """
    v = np.asarray(v, dtype=np.float64)
    a, b, m = v[:, 0], v[:, 1], v[:, 2]
    # v(t) = c0 + c1 t + c2 t² on t ∈ [0, 1]
    c0, c1, c2 = a, -3 * a - b + 4 * m, 2 * a + 2 * b - 4 * m
    # sub-intervals where φ is linear: [0,1/3]: φ_start = 1 − 2t; [2/3,1]: φ_end = 2t − 1;
    # [1/3,1/2]: φ_mid = 2t; [1/2,2/3]: φ_mid = 2 − 2t
    pieces = [
        (0.0, 1 / 3, 0, (1.0, -2.0)),
        (2 / 3, 1.0, 1, (-1.0, 2.0)),
        (1 / 3, 0.5, 2, (0.0, 2.0)),
        (0.5, 2 / 3, 2, (2.0, -2.0)),
    ]
    gt, gw = np.polynomial.legendre.leggauss(3)  # exact for degree 5 ≥ 3 (quadratic × linear)
    roots = _roots_in_unit(c0, c1, c2)  # (k, 2), NaN where none
    out = np.zeros(v.shape)
    for lo, hi, col, (p0, p1) in pieces:
        r = np.where(np.isnan(roots), lo, np.clip(roots, lo, hi))
        bounds = np.sort(np.column_stack([np.full(len(v), lo), r, np.full(len(v), hi)]), axis=1)
        for j in range(3):
            x0, x1 = bounds[:, j], bounds[:, j + 1]
            half = 0.5 * (x1 - x0)
            tq = 0.5 * (x0 + x1)[:, None] + half[:, None] * gt[None, :]
            vq = c0[:, None] + c1[:, None] * tq + c2[:, None] * tq**2
            phi = p0 + p1 * tq
            out[:, col] += half * (gw * np.maximum(vq, 0.0) * phi).sum(axis=1)
    return out * np.asarray(length)[:, None]


def _roots_in_unit(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray) -> np.ndarray:
    """Real roots in (0, 1) of ``c0 + c1 t + c2 t²`` per row, ``(k, 2)``, NaN where absent."""
    k = c0.size
    out = np.full((k, 2), np.nan)
    scale = np.maximum.reduce([np.abs(c0), np.abs(c1), np.abs(c2)])
    quad = np.abs(c2) > 1e-14 * np.maximum(scale, 1e-300)
    disc = c1**2 - 4 * c2 * c0
    ok = quad & (disc >= 0)
    sq = np.sqrt(np.where(ok, disc, 0.0))
    # numerically stable pair of roots
    qq = -0.5 * (c1 + np.copysign(sq, c1))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(ok, qq / np.where(quad, c2, 1.0), np.nan)
        r2 = np.where(ok & (qq != 0), c0 / np.where(qq != 0, qq, 1.0), np.nan)
        lin = ~quad & (np.abs(c1) > 0)
        r_lin = np.where(lin, -c0 / np.where(lin, c1, 1.0), np.nan)
    out[:, 0] = np.where(quad, r1, r_lin)
    out[:, 1] = np.where(quad, r2, np.nan)
    out[(out <= 0) | (out >= 1)] = np.nan
    return out
