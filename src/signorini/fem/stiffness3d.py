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
copied from ``K[(a, i), (b, j)]``. As ``R_p[lk, ba] = R_p[kl, ab]``, ``B_ijᵀ`` is the product
of ``P_p[ij, lk]`` with ``R_p``, so the law is applied to the factors before the product:
``K_ij = Σ_p Q_p[ij] R_p`` with ``Q_p[ij, kl] = λ P_p[ij, kl] + μ P_p[ij, lk] + μ δ_ij Σ_m
P_p[mm, kl]``. Where ``J`` is constant (affine cells) ``P`` has one point and ``R`` is summed
over the rule first, ``(9, 100)``: one product of the ``(6 m, 9)`` factors ``Q`` with it per
chunk of cells, :func:`~signorini.fem.fixed_order.rows_times` (no BLAS),
so each cell's matrix depends on that cell's data alone, bit for bit, whatever cells are
computed beside it. On affine cells the integrand is of degree 2 and the four-point rule
makes it exact; on the quadratic maps of isoparametric cells ``P`` varies and the degree-4
rule is used (as in 2D).

Assembly
--------
The element matrices are 3 × 3 node blocks (DOFs ``3 node + component``,
:mod:`signorini.fem.dofs`), ``(m, 10, 10, 3, 3)`` (:func:`node_blocks`), formed chunk by
chunk component by component (``(9, k, 10, 10)``, contiguous writes). The matrix is symmetric,
so the assembly keeps only each cell's 55 *upper* node pairs (the global row the smaller
node, :func:`upper_blocks`) and sums them in cell order with one sparse product through the
mesh's node-pair pattern (:mod:`signorini.fem.pattern3d`: built at the first assembly on a
mesh, one stable sort of the ``55 m`` pair keys, and kept while the space's DOF array
lives); the sums are laid out as the CSR data and indices chunk of node rows by chunk
(:meth:`~signorini.fem.pattern3d.NodePattern.laid_out`), the lower triangle mirrored from the
upper one, so the matrix is symmetric bit for bit. The result has sorted indices, the
node-block pattern (rows ``3z … 3z + 2`` share their columns) and int32 indices while they
fit; the complex packing of the 2D assembly is a d = 2 trick and is not used.

Measured on a shared two-core machine (``benchmarks/assembly3d.py``, Kuhn cube, best of
three, NGSolve on one thread and scikit-fem on the same mesh in the same run): again on the
same mesh 0.61–0.82 × 10⁶ unknowns per second from 1.5 × 10⁴ to 1.07 × 10⁶ unknowns, 2.2–4.1
times faster than NGSolve; the first assembly on a mesh (its pattern built) 0.41–0.50 × 10⁶
to 3.5 × 10⁵ unknowns, 1.1–3.9 times NGSolve's and 31–81 times scikit-fem's, 0.14 × 10⁶ at
1.07 × 10⁶ (its memory faulted in). Of a warm assembly the element matrices are about half.
Since the pattern keeps no nnz-sized array (the CSR laid out per assembly), the cold assembly
at 1.07 × 10⁶ faults in 0.66 GB less and took 5.5–6.1 s instead of 8.4–9.7 s (one call in a
fresh process, alternated with the previous code), the warm one about 25 % more CPU
(docs/method.md, *The kept pattern without nnz-sized arrays*).
"""

from __future__ import annotations

from collections.abc import Iterator
from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from . import p2_tet
from .fixed_order import rows_times
from .mapping import CellMap
from .mapping3d import AffineTetrahedra, IsoparametricTetrahedra, TetrahedronMap
from .material import CellMaterials, Material, lame_parameters, on_cells
from .pattern3d import pattern_of
from .quadrature import tetrahedron_rule

__all__ = ["assemble_stiffness_3d", "element_stiffness_3d"]

#: cells per chunk of the element matrices: the temporaries stay in the cache (measured:
#: 4096 took twice as long)
_CHUNK = 256

_Tetrahedra = AffineTetrahedra | IsoparametricTetrahedra

#: the block components ``i <= j`` that are computed (the others are their transposes)
_UPPER = tuple((i, j) for i in range(3) for j in range(i, 3))


def _per_cell(value: float | np.ndarray, rows: slice) -> float | np.ndarray:
    """A scalar, or the rows ``rows`` of an ``(m,)`` array shaped ``(k, 1, 1, 1)``."""
    if np.ndim(value) == 0:
        return value
    return np.asarray(value)[rows, None, None, None]


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


def _chunks(
    cells: _Tetrahedra, material: Material | CellMaterials, degree: int | None
) -> Iterator[tuple[slice, np.ndarray]]:
    """The node blocks of the cells chunk by chunk, ``(rows, K (9, k, 10, 10))`` with
    ``K[3 i + j, c, a, b] = a(φ_b e_j, φ_a e_i)`` on cell ``rows[c]`` (module docstring), in
    one scratch array reused from chunk to chunk; each cell's blocks from its own data alone.
    """
    lam, mu = lame_parameters(material, 3)
    degree = 2 * cells.order if degree is None else degree
    xi, w = tetrahedron_rule(degree)
    m = len(cells)
    J, det = cells.jacobians(xi)  # (m, p, 3, 3), p = 1 (affine) or q
    jit = cells.inverse_transpose(xi)
    R = _reference_products(degree, det.shape[1] > 1)  # (p · 9, 100)
    scratch = np.empty((9, min(_CHUNK, m), 10, 10))
    products = np.empty((len(_UPPER), min(_CHUNK, m), 100))
    for start in range(0, m, _CHUNK):  # chunks of cells bound the temporaries
        rows = slice(start, min(start + _CHUNK, m))
        d, t = det[rows], jit[rows]
        K = scratch[:, : len(d)]
        # P[(i, j), c, p, k, l] = det J J⁻ᵀ[i, k] J⁻ᵀ[j, l] at point p, for i <= j
        P = np.empty((len(_UPPER), len(d), d.shape[1], 3, 3))
        for u, (i, j) in enumerate(_UPPER):
            np.multiply(t[:, :, i, :, None], t[:, :, j, None, :], out=P[u])
            P[u] *= d[:, :, None, None]
        # K_ij = Q_ij R with Q_ij[kl] = λ P_ij[kl] + μ P_ij[lk] + δ_ij μ Σ_m P_mm[kl]
        # (B_ijᵀ = P_ijᵀ R, the reference products being symmetric under (k, a) <-> (l, b))
        lam_k, mu_k = _per_cell(lam, rows), _per_cell(mu, rows)
        Q = lam_k * P + mu_k * np.swapaxes(P, -1, -2)
        trace = mu_k * (P[0] + P[_UPPER.index((1, 1))] + P[_UPPER.index((2, 2))])
        for u, (i, j) in enumerate(_UPPER):
            if i == j:
                Q[u] += trace
        B = rows_times(Q.reshape(-1, R.shape[0]), R, out=products[:, : len(d)].reshape(-1, 100))
        B = B.reshape(len(_UPPER), len(d), 10, 10)
        for u, (i, j) in enumerate(_UPPER):
            K[3 * i + j] = B[u]
            if i != j:  # K[(b, j), (a, i)] = K[(a, i), (b, j)]: the symmetric block
                K[3 * j + i] = np.swapaxes(B[u], -1, -2)
        yield rows, K


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
    out = np.empty((len(cells), 10, 10, 3, 3)) if out is None else out
    for rows, K in _chunks(cells, material, degree):
        out[rows] = K.reshape(3, 3, -1, 10, 10).transpose(2, 3, 4, 0, 1)
    return out


def upper_blocks(
    cells: _Tetrahedra,
    material: Material | CellMaterials,
    select: np.ndarray,
    out: np.ndarray,
    rows: np.ndarray | slice = slice(None),
) -> None:
    """The node blocks of the upper node pairs of a group of tetrahedra,
    ``out[rows[c], k] = node_blocks[c, a, b]`` with ``10 a + b = select[rows[c], k]``
    (:mod:`signorini.fem.pattern3d`), chunk by chunk (the whole ``(m, 10, 10, 3, 3)`` array
    is never formed).

    Parameters
    ----------
    cells : AffineTetrahedra or IsoparametricTetrahedra
    material : Material or CellMaterials
        Of the group's cells in its order.
    select : (n_cells, 55) int array
        The mesh's local upper pairs (``NodePattern.select``).
    out : (n_cells, 55, 9) float array
        Receives the group's rows.
    rows : (m,) int array or slice
        The group's cells in the mesh (``cells.cells``).
    """
    whole = isinstance(rows, slice) and rows == slice(None)
    index = None if whole else np.arange(len(select))[rows]
    for chunk, K in _chunks(cells, material, None):
        cell = chunk if whole else index[chunk]
        k = K.shape[1]
        flat = select[cell] + (100 * np.arange(k))[:, None]
        taken = np.take(K.reshape(9, -1), flat.reshape(-1), axis=1)  # (9, k · 55)
        if whole:  # straight into the rows of out
            np.copyto(out[cell].reshape(-1, 9), taken.T)
        else:
            out[cell] = taken.T.reshape(k, -1, 9)


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
    rows: np.ndarray | None = None,
) -> sp.csr_matrix:
    """Global stiffness matrix ``(n_dofs, n_dofs)`` of 3D elasticity on P2 tetrahedra, or
    some of its rows.

    The mesh's pattern (:func:`~signorini.fem.pattern3d.pattern_of`) is built at the first
    assembly with these ``cell_dofs`` and kept while the array lives; each assembly forms the
    blocks of the cells' upper node pairs (:func:`upper_blocks`), sums them in cell order
    (``pattern.sums @ blocks``) and lays the sums out as the CSR data, the lower triangle
    mirrored from the upper one.

    Parameters
    ----------
    cells : TetrahedronMap or (m, 4, 3) float array
        The cells' geometry (``space.mapping``: affine and isoparametric groups), or the
        vertices of straight, positively oriented tetrahedra.
    cell_dofs : (m, 30) int array
        Interleaved global DOFs, ``cell_dofs[:, 3 a + c] = 3 node_a + c``.
    n_dofs : int
    material : Material or CellMaterials
    rows : (n_dofs,) bool array, optional
        The rows to assemble (the three DOFs of a node together): the rows a rank of a run on
        several MPI ranks owns (docs/parallel.md, *A stiffness matrix split by rows*). Only
        the cells with a node of these rows are integrated, and their pattern is that of
        those cells (kept as the whole mesh's is); the other rows are left empty. Each kept
        row is the whole matrix's bit for bit: its node's pairs are summed over the same
        cells in the same order.

    Returns
    -------
    scipy.sparse.csr_matrix
        Symmetric bit for bit (without ``rows``), sorted indices, the 3 × 3 node-block
        pattern; with ``rows``, the rows not asked for have no stored entry.

    Raises
    ------
    ValueError
        If ``rows`` is not an ``(n_dofs,)`` bool array that takes the three DOFs of a node
        together.
    """
    mapping = cells if isinstance(cells, CellMap) else TetrahedronMap(cells)
    owner = cell_dofs if isinstance(cell_dofs, np.ndarray) else None
    nodes = _cell_nodes(cell_dofs)
    groups = [(g, g.cells) for g in mapping.groups]
    kept = None
    if rows is not None:
        kept = _node_rows(rows, int(n_dofs))
        touch = kept[nodes].any(axis=1)  # the cells whose matrices the rows need
        position = np.cumsum(touch) - 1  # a mesh cell's row among them
        every = np.arange(mapping.n_cells)
        groups = []
        for g in mapping.groups:  # each group's cells among them, in mesh order
            mine = every[g.cells]
            slot = np.flatnonzero(touch[mine])
            groups.append((g.rows(slot), position[mine[slot]]))
        nodes = nodes[touch]
    pattern = pattern_of(nodes, int(n_dofs) // 3, owner)
    # the indices' array before the blocks, so that the data can reuse the blocks' memory
    indices = np.empty(pattern.indptr[-1], dtype=pattern.indptr.dtype)
    blocks = np.empty((nodes.shape[0], pattern.select.shape[1], 9))
    for g, at in groups:  # each group into its cells' rows (mesh order)
        upper_blocks(g, on_cells(material, g.cells), pattern.select, blocks, at)
    summed = pattern.sums @ blocks.reshape(-1, 9)  # (n_upper, 9), each pair in cell order
    del blocks
    data = pattern.laid_out(summed, indices)
    del summed
    indptr = pattern.indptr
    if kept is not None:  # the kept rows' entries only
        data, indices, indptr = _rows_of(np.repeat(kept, 3), indptr, indices, data)
    out = sp.csr_matrix((data, indices, indptr.copy()), shape=pattern.shape, copy=False)
    out.has_sorted_indices = True
    return out


def _node_rows(rows: object, n_dofs: int) -> np.ndarray:
    """``(n_nodes,)`` bool of the DOF rows ``rows (n_dofs,) bool``; a ValueError unless it
    takes the three DOFs of every node together."""
    r = np.asarray(rows)
    if r.dtype != np.bool_ or r.shape != (n_dofs,) or n_dofs % 3:
        raise ValueError(f"rows must be a bool array of shape ({n_dofs},), got {r.dtype} {r.shape}")
    by_node = r.reshape(-1, 3)
    split = np.flatnonzero(by_node.any(axis=1) != by_node.all(axis=1))
    if split.size:
        raise ValueError(
            f"rows must take the three DOFs of a node or none; node {split[0]} has some "
            f"({split.size} such nodes)"
        )
    return by_node[:, 0].copy()


def _rows_of(
    keep: np.ndarray, indptr: np.ndarray, indices: np.ndarray, data: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The CSR arrays with only the rows ``keep (n,) bool`` stored, the others empty."""
    length = np.where(keep, np.diff(indptr), 0)
    entries = np.repeat(keep, np.diff(indptr))
    out = np.zeros_like(indptr)
    np.cumsum(length, out=out[1:])
    return data[entries], indices[entries], out
