"""The dual mortar coupling of one contact pair between two bodies in three dimensions: the
dual basis of the transformed quadratic face basis, the mortar matrices D and M and the
weighted gap (docs/method.md, *Two bodies in three dimensions: the dual mortar coupling on
faces*).

On the slave part's P2 faces the trace basis is first transformed (contact condition (b),
:mod:`.face_basis`): ``φ̃_v = φ_v + α Σ_{e ∋ v} φ_e``, ``φ̃_e = (1 − 2α) φ_e`` on every side e
of the slave part, so that every ``∫_F φ̃_z > 0`` (the plain vertex functions integrate to
zero on a flat face and have no dual). Per slave face F, with its local ``T_F (6, 6)``,

    M_F = ∫_F φ̃ φ̃ᵀ,   D_F = diag ∫_F φ̃,   ψ = D_F M_F⁻¹ φ̃,   ∫_F ψ_a φ̃_b = δ_ab (D_F)_aa.

The global ψ_j sums its faces' pieces; ``D_jj = ∫_Γs φ̃_j`` and ``M_jk = ∫_Γs ψ_j (φ_k ∘ π)``
over the integration cells of :mod:`.mortar3d_segments` (π the projection along the slave
face's normal; the master keeps its plain P2 basis). All integrals are taken on the straight
(vertex) triangles of both parts, with the geometry's midpoints at the chords' midpoints:
exact on flat interfaces (the integrands are polynomials of degree 4 on each cell), a
geometry error of the order of the faces' curvature on curved ones. Reference
configuration, small sliding.

References
----------
A. Popp, B. I. Wohlmuth, M. W. Gee, W. A. Wall, *Dual quadratic mortar finite element
methods for 3D finite deformation contact*, SIAM J. Sci. Comput. 34 (2012).
B. I. Wohlmuth, *A mortar finite element method using dual spaces for the Lagrange
multiplier*, SIAM J. Numer. Anal. 38 (2000).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.p2 import basis_barycentric
from ..fem.quadrature import triangle_rule
from ..mesh.bodies import body_of_cells
from ..problem.fields import ProblemError
from ..problem.normals import face_node_normals
from .face_basis import DEFAULT_ALPHA
from .mortar3d_segments import Segments, plane_frames, segments
from .mortar_checks import COVERAGE_TOL

__all__ = [
    "MORTAR_DEGREE",
    "RIM_COVERAGE",
    "MortarCoupling3D",
    "dual_coefficients",
    "face_duals",
    "face_transform",
    "mortar_coupling_3d",
    "plane_barycentric",
]

#: the triangle rule's degree on the integration cells and the slave faces: ψ_j (φ_k ∘ π)
#: and φ̃_a φ̃_b are polynomials of degree 4 there (π affine on each cell)
MORTAR_DEGREE = 4

#: a slave node whose ψ_j reaches the slave part's rim (a face with a vertex on another
#: boundary part, e.g. a symmetry plane) may miss this share of its coverage: the master's
#: edge on a plane the slave's edge also lies on, projected along a face normal that is
#: not in that plane, leaves a sliver of width gap · |n_S · e_plane| (docs/method.md, *Two
#: bodies in three dimensions*, "Rims"); such rows are scaled to coverage 1
RIM_COVERAGE = 0.05

#: the midpoint and the two ends of the sides (a, b), (b, c), (c, a) of a 6-node face
_SIDES = np.array([[3, 0, 1], [4, 1, 2], [5, 2, 0]])


def face_transform(alpha: float) -> np.ndarray:
    """``T_F (6, 6)``: the transformed basis on one face, ``φ̃ = T_F φ`` (rows the new
    functions, columns the P2 ones, local order vertices then the sides' midpoints):
    ``T_vv = 1``, ``T_ve = α`` for the two sides at v, ``T_ee = 1 − 2α``."""
    T = np.eye(6)
    for e, a, b in _SIDES:  # the three sides of a face
        T[e, e] = 1.0 - 2.0 * alpha
        T[a, e] = T[b, e] = alpha
    return T


def plane_barycentric(triangles: np.ndarray, x: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """Barycentric coordinates ``(c, q, 3)`` of the points ``x (c, q, 3)`` in the
    triangles ``(c, 3, 3)`` after projecting both into the planes of ``frame (c, 2, 3)``
    (two orthonormal in-plane directions): along the planes' normal, so for a master face
    they are those of the point's projection π onto it."""
    o = triangles[:, 0]
    J = np.einsum("cdx,ckx->cdk", frame, triangles[:, 1:] - o[:, None])  # (c, 2, 2)
    r = np.einsum("cdx,cqx->cqd", frame, x - o[:, None])
    lam = np.einsum("cij,cqj->cqi", np.linalg.inv(J), r)
    return np.concatenate([1.0 - lam.sum(axis=2, keepdims=True), lam], axis=2)


def dual_coefficients(mass: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``A_F = D_F M_F⁻¹`` ``(f, 6, 6)`` of the local masses ``M_F (f, 6, 6)`` (symmetric,
    positive definite) and weights ``D_F (f, 6)``: the dual basis ``ψ_a = Σ_b (A_F)_ab φ̃_b``
    with ``∫_F ψ_a φ̃_b = δ_ab (D_F)_a``."""
    # A = D M⁻¹ with M symmetric: Aᵀ = M⁻¹ D
    return np.swapaxes(np.linalg.solve(mass, weight[:, :, None] * np.eye(6)), 1, 2)


def face_duals(triangles: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Per slave face (straight triangles ``(f, 3, 3)``) the weights ``D_F (f, 6)`` and the
    dual coefficients ``A_F (f, 6, 6)`` of the transformed basis."""
    s, w = triangle_rule(MORTAR_DEGREE)
    T = face_transform(alpha)
    phi = basis_barycentric(np.column_stack([1.0 - s.sum(axis=1), s])) @ T.T  # (q, 6): φ̃
    area = 0.5 * np.linalg.norm(
        np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]), axis=1
    )
    ws = 2.0 * area[:, None] * w  # (f, q)
    mass = np.einsum("fq,qa,qb->fab", ws, phi, phi)
    weight = ws @ phi
    return weight, dual_coefficients(mass, weight)


@dataclass(frozen=True)
class MortarCoupling3D:
    """The mortar data of one contact pair on faces (docs/method.md, *Two bodies in three
    dimensions*).

    Attributes
    ----------
    slave, master : str
        The boundary parts.
    alpha : float
        The transformed basis's α on the slave.
    slave_nodes : (s,) int array
        Sorted P2 nodes of the slave part's faces.
    slave_faces : (f, 6) int array
        The slave faces' nodes (vertices in outward order, then the sides' midpoints).
    normal : (s, 3) float array
        The constraint directions n_j: the slave body's outward unit normal at the node.
    D : (s,) float array
        ``D_jj = ∫_Γs φ̃_j`` (positive).
    M : (s, n_nodes) scipy.sparse.csr_matrix
        ``M_jk = ∫_Γs ψ_j (φ_k ∘ π)``, columns the global master nodes.
    weighted_gap : (s,) float array
        ``g̃_j = n_j · (Σ_k M_jk x_k − D_jj x_j)`` (straight-face geometry): ``≥ 0`` open.
    coverage : (s,) float array
        ``Σ_k M_jk / D_jj``: 1 where ψ_j's support lies wholly over the master.
    cells : Segments
        The integration cells (slave and master faces as rows of the parts' face lists).
    """

    slave: str
    master: str
    alpha: float
    slave_nodes: np.ndarray
    slave_faces: np.ndarray
    normal: np.ndarray
    D: np.ndarray
    M: sp.csr_matrix
    weighted_gap: np.ndarray
    coverage: np.ndarray
    cells: Segments


def _check_parts(space, slave: str, master: str, pair: str) -> None:
    """Refuse unknown parts, one part twice, a shared node and self contact."""
    mesh = space.mesh
    for role, name in (("slave", slave), ("master", master)):
        if name not in mesh.part_names:
            raise ProblemError(
                f"{pair}: the {role} {name!r} is not a boundary part; the parts are "
                f"{list(mesh.part_names)}"
            )
    if slave == master:
        raise ProblemError(f"{pair}: the slave and the master must be two different parts")
    if np.intersect1d(space.part_nodes([slave]), space.part_nodes([master])).size:
        raise ProblemError(f"{pair}: the parts share nodes; a pair joins two bodies' parts")
    body = body_of_cells(mesh)
    owners = []
    for role, name in (("slave", slave), ("master", master)):
        owner = np.unique(body[mesh.facet2cell[mesh.part_facets(name), 0]])
        if owner.size > 1:
            raise ProblemError(f"{pair}: the {role} part {name!r} runs over several bodies")
        owners.append(int(owner[0]))
    if owners[0] == owners[1]:
        raise ProblemError(
            f"{pair}: both parts lie on one body: self contact is not modelled (in small "
            "deformation a body does not reach its own boundary); a pair joins two bodies"
        )


def _straight_points(space, faces: np.ndarray) -> np.ndarray:
    """The node points with the faces' midpoints put at their sides' chord midpoints (the
    straight-face geometry of the coupling)."""
    x = np.array(space.node_points, dtype=np.float64)
    for e, a, b in _SIDES:  # the three sides of a face
        x[faces[:, e]] = 0.5 * (x[faces[:, a]] + x[faces[:, b]])
    return x


def mortar_coupling_3d(
    space, slave: str, master: str, *, alpha: float = DEFAULT_ALPHA
) -> MortarCoupling3D:
    """The dual mortar coupling of the pair ``slave`` → ``master`` on a P2 tetrahedral
    space (two bodies: components of the mesh).

    Raises
    ------
    ProblemError
        Naming the pair: an unknown part, the same part twice, a shared node, both parts on
        one body (self contact), a part over two bodies, no overlap of the slave with the
        master along the slave's normals.
    ValueError
        For α outside ``(0, 1/2)`` (the dual basis needs positive weights ``∫ φ̃``).
    """
    pair = f"contact pair (slave {slave!r}, master {master!r})"
    if not 0.0 < alpha < 0.5:
        raise ValueError(
            f"{pair}: the dual basis on P2 faces needs 0 < face_alpha < 1/2 (positive "
            f"weights ∫ φ̃), got {alpha!r}"
        )
    _check_parts(space, slave, master, pair)
    mesh = space.mesh
    sf = space.facet_nodes(mesh.part_facets(slave))
    mf = space.facet_nodes(mesh.part_facets(master))
    x = _straight_points(space, np.vstack([sf, mf]))
    s_tri, m_tri = x[sf[:, :3]], x[mf[:, :3]]
    cells = segments(s_tri, m_tri)
    if cells.slave.size == 0:
        raise ProblemError(
            f"{pair}: no part of the slave lies over the master along its normals (the parts "
            "do not face each other)"
        )
    weight, coef = face_duals(s_tri, alpha)
    slave_nodes, index = np.unique(sf, return_inverse=True)
    index = index.reshape(sf.shape)
    D = np.bincount(index.ravel(), weights=weight.ravel(), minlength=slave_nodes.size)
    entries = _cell_entries(cells, s_tri, m_tri, coef, face_transform(alpha))
    rows = np.broadcast_to(index[cells.slave][:, :, None], entries.shape)
    cols = np.broadcast_to(mf[cells.master][:, None, :], entries.shape)
    M = sp.coo_matrix(
        (entries.ravel(), (rows.ravel(), cols.ravel())), shape=(slave_nodes.size, space.n_nodes)
    ).tocsr()
    M = _rim_scaled(space, slave, M, D, slave_nodes, index)
    normal = face_node_normals(space, slave, slave_nodes)
    gap = np.einsum("sc,sc->s", _gap_vectors(space, sf, M, D, slave_nodes, alpha), normal)
    coverage = np.asarray(M.sum(axis=1)).ravel() / D
    return MortarCoupling3D(
        slave, master, float(alpha), slave_nodes, sf, normal, D, M, gap, coverage, cells
    )


def _cell_entries(cells: Segments, s_tri, m_tri, coef, T) -> np.ndarray:
    """``(c, 6, 6)`` ``∫_cell ψ_a (φ_b ∘ π)`` of the integration cells: ψ of the cell's slave
    face (``coef (f, 6, 6)`` on ``φ̃ = T φ``), φ of its master face at the projected point."""
    s, w = triangle_rule(MORTAR_DEGREE)
    p = cells.points
    x = p[:, :1] + np.einsum("qk,ckx->cqx", s, p[:, 1:] - p[:, :1])  # (c, q, 3)
    ws = 2.0 * cells.area[:, None] * w
    _, frame = plane_frames(s_tri[cells.slave])
    in_plane = frame[:, :2]
    ls = plane_barycentric(s_tri[cells.slave], x, in_plane)
    lm = plane_barycentric(m_tri[cells.master], x, in_plane)
    psi = np.einsum("cqb,cab->cqa", basis_barycentric(ls) @ T.T, coef[cells.slave])
    return np.einsum("cq,cqa,cqb->cab", ws, psi, basis_barycentric(lm))


def _rim_scaled(space, slave: str, M: sp.csr_matrix, D, slave_nodes, index) -> sp.csr_matrix:
    """``M`` with the rows of the rim nodes (:data:`RIM_COVERAGE`) whose coverage
    ``Σ_k M_jk / D_jj`` is within ``RIM_COVERAGE`` of 1 scaled to coverage 1: the constant
    is transferred exactly again (the patch test, equal and opposite resultants), at a
    change of ``M`` of the order of the sliver. Rows within ``COVERAGE_TOL`` of 1 (a flat
    interface) or beyond ``RIM_COVERAGE`` (refused by the contact set as large sliding) stay
    as they are."""
    mesh = space.mesh
    others = [p for p in mesh.part_names if p != slave]
    rim = np.isin(slave_nodes, space.part_nodes(others))
    vertex_on_rim = rim[index[:, :3]].any(axis=1)  # faces touching the rim
    near = np.zeros(slave_nodes.size, dtype=bool)
    near[index[vertex_on_rim].ravel()] = True
    coverage = np.asarray(M.sum(axis=1)).ravel() / D
    off = np.abs(coverage - 1.0)
    scale = np.where(near & (off > COVERAGE_TOL) & (off <= RIM_COVERAGE), 1.0 / coverage, 1.0)
    return sp.csr_matrix(sp.diags(scale) @ M)


def _gap_vectors(space, faces, M: sp.csr_matrix, D, slave_nodes, alpha: float) -> np.ndarray:
    """``(s, 3)`` ``Σ_k M_jk x_k − D_jj x̃_j``: the ψ_j-weighted distance vector from the slave
    to the master of the isoparametric (curved) P2 surfaces, x the node points (midpoints on
    a carried surface), ``x̃`` the slave's coordinates in the transformed basis
    (``∫ ψ_j x_s = D_jj x̃_j``); on straight faces the chords' midpoints, ``x̃ = x``."""
    x = np.asarray(space.node_points, dtype=np.float64)
    xt = x.copy()
    for e, a, b in _SIDES:  # the three sides of a face
        xt[faces[:, e]] = (x[faces[:, e]] - alpha * (x[faces[:, a]] + x[faces[:, b]])) / (
            1.0 - 2.0 * alpha
        )
    return M @ x - D[:, None] * xt[slave_nodes]
