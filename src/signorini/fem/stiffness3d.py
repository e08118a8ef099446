"""The stiffness matrix of 3D linear elasticity, ``a(w, v) = ∫_Ω σ(w) : ε(v) dx`` with the
isotropic Hooke's law ``σ = λ tr(ε) I + 2 μ ε`` (the paper's (2.1) in three dimensions), for
P2 tetrahedra (:mod:`signorini.fem.p2_tet`, 30 DOFs per cell).

Element matrices
----------------
One integrand for every geometry (:mod:`signorini.fem.mapping3d`). With the physical
gradients ``∇φ_a = J⁻ᵀ ∇̂φ_a`` and the weights ``w_p det J(ξ_p)`` of the rule,

    B_ij[a, b] = ∫ ∂_i φ_a ∂_j φ_b = Σ_p Σ_kl P_p[ij, kl] R_p[kl, ab],
    P_p[ij, kl] = det J J⁻ᵀ[i, k] J⁻ᵀ[j, l] at ξ_p,   R_p[kl, ab] = w_p ∂_k φ̂_a ∂_l φ̂_b,
    K[(a, i), (b, j)] = λ B_ij[a, b] + μ B_ji[a, b] + μ δ_ij Σ_k B_kk[a, b],

with ``B_ji = B_ijᵀ`` (in a, b), so only ``i ≤ j`` are formed and ``K[(b, j), (a, i)]`` is
copied from ``K[(a, i), (b, j)]``. Where ``J`` is constant (affine cells) ``P`` has one point
and ``R`` is summed over the rule first, ``(9, 100)``: one product of the ``(6 m, 9)``
factors with it per chunk of cells, :func:`~signorini.fem.fixed_order.rows_times` (no BLAS),
so each cell's matrix depends on that cell's data alone, bit for bit, whatever cells are
computed beside it. On affine cells the integrand is of degree 2 and the four-point rule
makes it exact; on the quadratic maps of isoparametric cells ``P`` varies and the degree-4
rule is used (as in 2D).

Assembly
--------
The element matrices are 3 × 3 node blocks (DOFs ``3 node + component``,
:mod:`signorini.fem.dofs`), ``(m, 10, 10, 3, 3)`` (:func:`node_blocks`). The sum over cells
sorts the ``m · 100`` node pairs once (:func:`_assemble_node_blocks`) and adds each pair's
blocks in one sparse product with the 0/1 matrix of the sort's runs; the summed blocks are a
BSR matrix (blocksize 3) as they stand, converted to CSR once: sorted indices, the
node-block pattern (rows ``3z … 3z + 2`` share their columns), int32 indices while they fit.
A scalar COO → CSR conversion would sort the 900 entries of each cell instead of its 100
node pairs; the complex packing of the 2D assembly is a d = 2 trick and is not used.

Measured on a shared two-core machine (``benchmarks/assembly3d.py``, Kuhn cube): 0.30–0.52 ×
10⁶ unknowns per second of wall time from 1.5 × 10⁴ to 3.5 × 10⁵ unknowns, 24–38 times
scikit-fem's ``asm`` on the same mesh in the same run; at 1.1 × 10⁵ unknowns 0.12 s of CPU
for the element matrices and 0.15 s for the sum (the sort of the node pairs the largest
part, 0.27 s of 0.55 at 3.5 × 10⁵). The issue's 0.5 × 10⁶ is reached on small meshes only.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from . import p2_tet
from .fixed_order import rows_times
from .mapping import CellMap
from .mapping3d import AffineTetrahedra, IsoparametricTetrahedra, TetrahedronMap
from .material import CellMaterials, Material, lame_parameters, on_cells
from .quadrature import tetrahedron_rule

__all__ = ["assemble_stiffness_3d", "element_stiffness_3d"]

#: cells per chunk of the element matrices: the temporaries stay in the cache (measured:
#: 4096 took twice as long)
_CHUNK = 256

_Tetrahedra = AffineTetrahedra | IsoparametricTetrahedra

#: the block components ``i <= j`` that are computed (the others are their transposes)
_UPPER = tuple((i, j) for i in range(3) for j in range(i, 3))


def _per_cell(value: float | np.ndarray, rows: slice) -> float | np.ndarray:
    """A scalar, or the rows ``rows`` of an ``(m,)`` array shaped ``(k, 1, 1)``."""
    if np.ndim(value) == 0:
        return value
    return np.asarray(value)[rows, None, None]


@lru_cache(maxsize=16)
def _reference_products(degree: int, per_point: bool) -> np.ndarray:
    """``R[(p, k, l), (a, b)] = w_p ∂_k φ̂_a(ξ_p) ∂_l φ̂_b(ξ_p)`` on the reference tetrahedron
    for the points of the degree-``degree`` rule, ``(q · 9, 100)``; summed over the points,
    ``(9, 100)``, unless ``per_point`` (Jacobians that vary from point to point)."""
    xi, w = tetrahedron_rule(degree)
    g = p2_tet.grad_basis(xi)
    R = np.einsum("q,qak,qbl->qklab", w, g, g)
    R = R.reshape(len(w) * 9, 100) if per_point else R.sum(axis=0).reshape(9, 100)
    R.setflags(write=False)
    return R


def node_blocks(
    cells: _Tetrahedra,
    material: Material | CellMaterials,
    degree: int | None = None,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Element stiffness of a group of tetrahedra as node blocks, ``(m, 10, 10, 3, 3)``:
    ``[c, a, b, i, j] = a(φ_b e_j, φ_a e_i)`` on cell ``c`` (module docstring), the layout the
    assembly sums (the nine entries of a node pair's block together).

    Parameters
    ----------
    cells : AffineTetrahedra or IsoparametricTetrahedra
        The group (:mod:`signorini.fem.mapping3d`).
    material : Material or CellMaterials
        The 3D law (:func:`~signorini.fem.material.lame_parameters`, ``dim = 3``); a
        :class:`CellMaterials` of the group's cells in its order.
    degree : int, optional
        The rule's degree, ``2 * cells.order`` by default (exact on affine cells).
    out : (m, 10, 10, 3, 3) float array, optional
        Receives the result.

    Returns
    -------
    (m, 10, 10, 3, 3) float64 array
    """
    lam, mu = lame_parameters(material, 3)
    degree = 2 * cells.order if degree is None else degree
    xi, w = tetrahedron_rule(degree)
    m = len(cells)
    out = np.empty((m, 10, 10, 3, 3)) if out is None else out
    J, det = cells.jacobians(xi)  # (m, p, 3, 3), p = 1 (affine) or q
    jit = cells.inverse_transpose(xi)
    R = _reference_products(degree, det.shape[1] > 1)  # (p · 9, 100)
    for start in range(0, m, _CHUNK):  # chunks of cells bound the temporaries
        rows = slice(start, min(start + _CHUNK, m))
        # P[c, (i, j), p, k, l] = det J J⁻ᵀ[i, k] J⁻ᵀ[j, l] at point p, for i <= j
        d, t = det[rows], jit[rows]
        P = np.empty((len(d), len(_UPPER), d.shape[1], 3, 3))
        for u, (i, j) in enumerate(_UPPER):
            np.multiply(t[:, :, i, :, None], t[:, :, j, None, :], out=P[:, u])
            P[:, u] *= d[:, :, None, None]
        B = rows_times(P.reshape(-1, R.shape[0]), R).reshape(len(d), len(_UPPER), 10, 10)
        B = {ij: B[:, u] for u, ij in enumerate(_UPPER)}
        lam_k, mu_k = _per_cell(lam, rows), _per_cell(mu, rows)
        trace = mu_k * (B[0, 0] + B[1, 1] + B[2, 2])  # μ ∫ ∇φ_a · ∇φ_b
        for i, j in _UPPER:
            K = out[rows, :, :, i, j]
            np.multiply(lam_k, B[i, j], out=K)
            K += mu_k * np.swapaxes(B[i, j], -1, -2)
            if i == j:
                K += trace
            else:  # K[(b, j), (a, i)] = K[(a, i), (b, j)]: the symmetric block
                out[rows, :, :, j, i] = np.swapaxes(K, -1, -2)
    return out


def element_stiffness_3d(
    cells: _Tetrahedra, material: Material | CellMaterials, degree: int | None = None
) -> np.ndarray:
    """Element stiffness matrices of a group of tetrahedra, ``(m, 30, 30)`` in interleaved
    local DOF order: ``K[c, 3 a + i, 3 b + j] = a(φ_b e_j, φ_a e_i)`` on cell ``c``
    (:func:`node_blocks`, laid out by DOF).

    Parameters
    ----------
    cells : AffineTetrahedra or IsoparametricTetrahedra
        For raw vertices ``(m, 4, 3)``: ``AffineTetrahedra(vertices)``.
    material : Material or CellMaterials
    degree : int, optional

    Returns
    -------
    (m, 30, 30) float64 array
        Symmetric positive semidefinite, six zero eigenvalues (the rigid motions).
    """
    blocks = node_blocks(cells, material, degree)
    return blocks.transpose(0, 1, 3, 2, 4).reshape(-1, 30, 30)


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
    nodes = _cell_nodes(cell_dofs)
    m = mapping.n_cells
    blocks = np.empty((m, 10, 10, 3, 3))
    order = []
    start = 0
    for g in mapping.groups:  # group after group into one array, the cells in that order
        rows = slice(start, start + len(g))
        node_blocks(g, on_cells(material, g.cells), out=blocks[rows])
        order.append(np.arange(m)[g.cells])
        start += len(g)
    if len(mapping.groups) > 1:
        nodes = nodes[np.concatenate(order)]
    return _assemble_node_blocks(nodes, int(n_dofs) // 3, blocks)


def _assemble_node_blocks(
    cell_nodes: np.ndarray, n_nodes: int, blocks: np.ndarray
) -> sp.csr_matrix:
    """Sum per-cell 3 × 3 node blocks into a CSR matrix with the node-block pattern.

    The ``(m, 10, 10)`` node pairs ``(z_a, z_b)`` of the cells are sorted once by their key
    ``z_a n_nodes + z_b`` (a stable sort: the duplicates of a pair stay in cell order); the
    pattern is the distinct keys, and the summation is one product ``S @ blocks`` with the
    0/1 matrix ``S (n_pairs, m · 100)`` whose row p holds the sorted run of pair p (its CSR
    arrays are the sort's run starts and order, built without a conversion): SciPy's loop
    reads each block's nine entries where they lie and adds them in cell order. The summed
    blocks, in the sort's order, are a BSR matrix as they stand (block row z, its columns
    sorted), and SciPy's BSR → CSR loop lays them out (row ``3 z + i`` holds row ``i`` of node
    ``z``'s blocks).

    Parameters
    ----------
    cell_nodes : (m, 10) int array
    n_nodes : int
    blocks : (m, 10, 10, 3, 3) float array
        :func:`node_blocks` of the cells, in the order of ``cell_nodes``.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (3 n_nodes, 3 n_nodes)
        Sorted indices; a full 3 × 3 block for every coupled node pair.
    """
    z = np.asarray(cell_nodes, dtype=np.int64)
    key = (z[:, :, None] * n_nodes + z[:, None, :]).reshape(-1)
    order = np.argsort(key, kind="stable")
    key = key[order]
    new = np.empty(key.size + 1, dtype=bool)
    new[0] = new[-1] = True
    np.not_equal(key[1:], key[:-1], out=new[1:-1])
    run = np.flatnonzero(new)  # run p of equal keys: order[run[p] : run[p + 1]]
    start = run[:-1]
    runs = np.int32 if key.size < 2**31 else np.int64
    S = sp.csr_matrix(
        (np.ones(key.size), order.astype(runs), run.astype(runs)),
        shape=(start.size, key.size),
        copy=False,
    )
    summed = S @ np.ascontiguousarray(blocks).reshape(-1, 9)  # (n_pairs, 9)
    row, col = np.divmod(key[start], n_nodes)
    first = np.zeros(n_nodes + 1, dtype=np.int64)  # the block rows' starts
    np.cumsum(np.bincount(row, minlength=n_nodes), out=first[1:])
    index = np.int32 if summed.size < 2**31 else np.int64
    bsr = sp.bsr_matrix(
        (summed.reshape(-1, 3, 3), col.astype(index), first.astype(index)),
        shape=(3 * n_nodes, 3 * n_nodes),
        copy=False,
    )
    out = bsr.tocsr()  # SciPy's loop lays each block row out as three CSR rows
    out.has_sorted_indices = True
    return out
