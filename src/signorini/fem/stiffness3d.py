"""The stiffness matrix of 3D linear elasticity, ``a(w, v) = ∫_Ω σ(w) : ε(v) dx`` with the
isotropic Hooke's law ``σ = λ tr(ε) I + 2 μ ε`` (the paper's (2.1) in three dimensions), for
P2 tetrahedra (:mod:`signorini.fem.p2_tet`, 30 DOFs per cell).

Element matrices
----------------
One integrand for every geometry (:mod:`signorini.fem.mapping3d`): with ``G_q (m, 10, 3)``
the physical basis gradients and ``W_q = w_q det J(ξ_q)`` at the points of the rule,

    B[a, i, b, j] = Σ_q W_q ∂_i φ_a ∂_j φ_b,
    K[(a, i), (b, j)] = λ B[a, i, b, j] + μ B[a, j, b, i] + μ δ_ij Σ_k B[a, k, b, k],

formed by elementwise products and sums over the points in turn (a loop over quadrature
points, never over cells): each cell's matrix depends on that cell's data alone, bit for bit,
whatever cells are computed beside it (the property :mod:`signorini.fem.fixed_order` gives
the 2D products). On affine cells the integrand is of degree 2 and the four-point rule makes
it exact; on the quadratic maps of isoparametric cells the degree-4 rule (degree 2k − 2 + 2
of the numerator, as in 2D).

Assembly
--------
The ``(m, 30, 30)`` matrices are 3 × 3 node blocks in interleaved DOF order
(``3 node + component``, :mod:`signorini.fem.dofs`); one COO → CSR conversion sums them
(int32 indices while they fit), sorted indices, the node-block pattern (rows ``3z … 3z + 2``
share their columns). The complex packing of the 2D assembly is a d = 2 trick and is not
used here.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .mapping import CellMap
from .mapping3d import AffineTetrahedra, IsoparametricTetrahedra, TetrahedronMap
from .material import CellMaterials, Material, lame_parameters, on_cells
from .quadrature import tetrahedron_rule

__all__ = ["assemble_stiffness_3d", "element_stiffness_3d"]

#: cells per chunk of the element matrices (bounds the temporaries at ~30 MB)
_CHUNK = 4096

_Tetrahedra = AffineTetrahedra | IsoparametricTetrahedra


def _per_cell(value: float | np.ndarray, rows: slice) -> float | np.ndarray:
    """A scalar, or the rows ``rows`` of an ``(m,)`` array shaped ``(k, 1, 1, 1, 1)``."""
    if np.ndim(value) == 0:
        return value
    return np.asarray(value)[rows, None, None, None, None]


def element_stiffness_3d(
    cells: _Tetrahedra,
    material: Material | CellMaterials,
    degree: int | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Element stiffness matrices of a group of tetrahedra, ``(m, 30, 30)``.

    ``K[c, 3 a + i, 3 b + j] = a(φ_b e_j, φ_a e_i)`` on cell ``c`` (module docstring).

    Parameters
    ----------
    cells : AffineTetrahedra or IsoparametricTetrahedra
        The group (:mod:`signorini.fem.mapping3d`); for raw vertices ``(m, 4, 3)`` wrap them
        as ``AffineTetrahedra(vertices)``.
    material : Material or CellMaterials
        The 3D law (:func:`~signorini.fem.material.lame_parameters` with ``dim = 3``); a
        :class:`CellMaterials` of the group's cells in its order.
    degree : int, optional
        The rule's degree, ``2 * cells.order`` by default (exact on affine cells).
    out : (m, 30, 30) float array, optional
        Receives the result.

    Returns
    -------
    (m, 30, 30) float64 array
        Symmetric positive semidefinite, six zero eigenvalues (the rigid motions).
    """
    lam, mu = lame_parameters(material, 3)
    degree = 2 * cells.order if degree is None else degree
    xi, w = tetrahedron_rule(degree)
    m = len(cells)
    out = np.empty((m, 30, 30)) if out is None else out
    view = out.reshape(m, 10, 3, 10, 3)
    eye = np.eye(3)[None, None, :, None, :]
    for start in range(0, m, _CHUNK):  # chunks of cells bound the temporaries
        rows = slice(start, min(start + _CHUNK, m))
        part = cells.rows(np.arange(rows.start, rows.stop))
        G = part.basis_gradients(xi)  # (k, q, 10, 3)
        W = part.measure(w, xi)  # (k, q)
        B = np.zeros((G.shape[0], 10, 3, 10, 3))
        for q in range(G.shape[1]):  # a loop over quadrature points
            Gw = W[:, q, None, None] * G[:, q]
            B += Gw[:, :, :, None, None] * G[:, q, None, None, :, :]
        dot = B[:, :, 0, :, 0] + B[:, :, 1, :, 1] + B[:, :, 2, :, 2]  # ∫ ∇φ_a · ∇φ_b
        mu_k = _per_cell(mu, rows)
        K = view[rows]
        np.multiply(_per_cell(lam, rows), B, out=K)
        K += mu_k * B.transpose(0, 1, 4, 3, 2)
        K += mu_k * (dot[:, :, None, :, None] * eye)
    return out


def _cell_nodes(cell_dofs: np.ndarray) -> np.ndarray:
    """The nodes ``(m, 10)`` of interleaved cell DOFs ``(m, 30)``."""
    return np.asarray(cell_dofs)[:, 0::3] // 3


def assemble_stiffness_3d(
    cells: CellMap | np.ndarray,
    cell_dofs: np.ndarray,
    n_dofs: int,
    material: Material | CellMaterials,
) -> sp.csr_matrix:
    """Global stiffness matrix ``(n_dofs, n_dofs)`` of 3D elasticity on P2 tetrahedra.

    Parameters
    ----------
    cells : TetrahedronMap or (m, 4, 3) float array
        The cells' geometry (``space.mapping``: affine and isoparametric groups), or the
        vertices of straight, positively oriented tetrahedra.
    cell_dofs : (m, 30) int array
        Interleaved global DOFs, ``cell_dofs[:, 3 a + c] = 3 node_a + c``.
    n_dofs : int
    material : Material or CellMaterials

    Returns
    -------
    scipy.sparse.csr_matrix
        Symmetric, sorted indices, the 3 × 3 node-block pattern.
    """
    mapping = cells if isinstance(cells, CellMap) else TetrahedronMap(cells)
    dofs = np.asarray(cell_dofs)
    m = mapping.n_cells
    blocks = np.empty((m, 30, 30))
    order = []
    start = 0
    for g in mapping.groups:  # group after group into one array, the cells in that order
        element_stiffness_3d(g, on_cells(material, g.cells), out=blocks[start : start + len(g)])
        order.append(np.arange(m)[g.cells])
        start += len(g)
    if len(mapping.groups) > 1:
        dofs = dofs[np.concatenate(order)]
    idx = np.int32 if max(m * 900, n_dofs) < np.iinfo(np.int32).max else np.int64
    d = dofs.astype(idx, copy=False)
    rows = np.broadcast_to(d[:, :, None], (m, 30, 30)).reshape(-1)
    cols = np.broadcast_to(d[:, None, :], (m, 30, 30)).reshape(-1)
    K = sp.csr_matrix((blocks.reshape(-1), (rows, cols)), shape=(n_dofs, n_dofs))
    K.sum_duplicates()
    return K
