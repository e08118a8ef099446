"""The stiffness matrix of plane-strain elasticity, ``a(w, v) = int_Omega sigma(w) : eps(v)``,
for the P2 element (the paper's) or P1 (:mod:`signorini.fem.element`).

Arrays are vectorized over cells: ``vertices (m, 3, 2)`` is ``points[cells]``
(counter-clockwise), ``cell_dofs (m, 12)`` the interleaved global DOFs,
``cell_dofs[:, d a + c] = d * node_a + c`` (``d = 2`` components a node) in the local node
order of :mod:`signorini.fem.p2`.

Assembly
--------
The stiffness matrix is assembled at the level of nodes: every pair of nodes that share a
cell gets one full 2x2 block. The two entries of each block row are packed into one complex
number, SciPy's COO -> CSR conversion sums the duplicates of the resulting (scalar row, node
column) matrix, and its data, viewed as float64, are the scalar CSR data. The result has
sorted indices and a node-block pattern: rows ``2 z`` and ``2 z + 1`` have identical column
patterns, and columns ``2 w``, ``2 w + 1`` are adjacent (explicit zeros kept). At 1.6 M
unknowns this takes less memory and time than converting the 144 scalar entries per cell
directly, or sorting node pairs with ``np.unique``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ..mesh.reference import TRIANGLE
from . import p2
from .element import ELEMENTS, P2, Element
from .fixed_order import rows_times
from .mapping import AffineCells, CellMap, Cells
from .material import CellMaterials, Material, on_cells
from .quadrature import triangle_rule

__all__ = ["assemble_stiffness", "element_blocks", "element_stiffness"]

# The components per node, ``d`` (``space.n_components`` of a triangle mesh): the node blocks
# are ``d x d``; the complex packing of :func:`_assemble_node_blocks` is the d = 2 branch.
_D = TRIANGLE.dim


# On a straight triangle, grad phi_a = J^{-T} ghat_a with ghat_a linear, so
#   B_ab[i, j] = int d_i phi_a d_j phi_b = sum_{kl} P[ij, kl] R[kl, ab],
#   P[ij, kl] = det J * Jit[i, k] * Jit[j, l],  R[kl, ab] = int_ref ghat_a[k] ghat_b[l]
# (R exact with the degree-2 rule), and
#   K[(a, i), (b, j)] = lam B_ab[i, j] + mu B_ab[j, i] + mu delta_ij tr B_ab.
# K is linear in the 16 numbers P, which satisfy P[ij, kl] = P[ji, lk]; the 10
# independent ones are gathered per cell and K = P10 @ KREF (one product, fixed_order.rows_times).
_P_PAIRS = [
    ((i, j, k, l), (j, i, l, k))
    for i in range(2)
    for j in range(2)
    for k in range(2)
    for l in range(2)  # noqa: E741
    if (i, j, k, l) <= (j, i, l, k)
]


@lru_cache(maxsize=32)
def _stiffness_basis(
    lam: float,
    mu: float,
    dof_order: bool,
    degree: int = 2,
    per_point: bool = False,
    element: str = "P2",
) -> np.ndarray:
    """Matrix (10, 144) mapping the 10 geometric factors to K, with ``R`` summed over the
    points of the degree-``degree`` rule; ``(q * 10, 144)``, one block per point, if
    ``per_point`` (for Jacobians that vary from point to point).

    The 144 columns (``(2 n)²`` for an element of ``n`` local nodes: 36 for P1) are in
    node-block layout (a, b, i, j), or in interleaved DOF layout (a, i, b, j) if ``dof_order``.
    """
    xi, w = triangle_rule(degree)
    g = ELEMENTS[element].grad_basis(xi)
    n = g.shape[1]
    if per_point:
        R = np.einsum("q,qak,qbl->qklab", w, g, g)  # (q, 2, 2, 6, 6)
    else:
        R = np.einsum("q,qak,qbl->klab", w, g, g)[None]  # (1, 2, 2, 6, 6)
    full = np.zeros((R.shape[0], 2, 2, 2, 2, n, n, 2, 2))
    for i in range(2):
        for j in range(2):
            for k in range(2):
                for l in range(2):  # noqa: E741
                    r = R[:, k, l]
                    full[:, i, j, k, l, :, :, i, j] += lam * r
                    full[:, i, j, k, l, :, :, j, i] += mu * r
                    if i == j:
                        full[:, i, j, k, l, :, :, 0, 0] += mu * r
                        full[:, i, j, k, l, :, :, 1, 1] += mu * r
    out = np.empty((R.shape[0], len(_P_PAIRS), 4 * n * n))
    for s, (p, q) in enumerate(_P_PAIRS):
        blk = (
            full[(slice(None),) + p]
            if p == q
            else full[(slice(None),) + p] + full[(slice(None),) + q]
        )
        out[:, s] = (blk.transpose(0, 1, 3, 2, 4) if dof_order else blk).reshape(R.shape[0], -1)
    out = out.reshape(-1, 4 * n * n)
    out.setflags(write=False)
    return out


def _geometric_factors(J: np.ndarray, det: np.ndarray) -> np.ndarray:
    """The 10 independent ``det J * Jit[i, k] * Jit[j, l]`` of Jacobians ``J (m, 2, 2)`` with
    determinants ``det (m,)``, shape (m, 10)."""
    jit = p2.inverse_transpose(J, det)
    out = np.empty((J.shape[0], len(_P_PAIRS)))
    for s, ((i, j, k, el), _) in enumerate(_P_PAIRS):
        np.multiply(jit[:, i, k], jit[:, j, el], out=out[:, s])
    out *= det[:, None]
    return out


def element_blocks(
    cells: Cells,
    material: Material | CellMaterials,
    degree: int | None = None,
    dof_order: bool = False,
    out: np.ndarray | None = None,
    element: Element = P2,
) -> np.ndarray:
    """Element stiffness of a group of cells (:mod:`signorini.fem.mapping`), shape
    ``(m, 144)`` (``(m, 36)`` for P1): ``[c, a, b, i, j] = a(phi_b e_j, phi_a e_i)`` on cell
    ``c`` in node-block layout, or ``(a, i, b, j)`` if ``dof_order``, for the basis of
    ``element``.

    One integrand for every geometry: ``K = sum_q P(x_q) R_q`` with the 10 geometric factors
    ``P = det J * Jit (x) Jit`` at the points of the rule and ``R_q`` the reference gradients'
    products there. Where the Jacobian is constant on each cell (affine cells) ``P`` has one
    point and ``R`` is summed over the rule first (one product with a (10, 144) matrix,
    :func:`~signorini.fem.fixed_order.rows_times`: no BLAS, so a cell's block depends on that
    cell alone).

    ``degree`` defaults to ``2 * cells.order``: the degree of the integrand's numerator
    ``(cof J grad phi_a) . C (cof J grad phi_b)``, exact on affine cells (degree 2); on the
    quadratic maps of isoparametric cells (degree 4) the rational remainder is far below the
    discretisation error (Ciarlet-Raviart: degree 2k - 2 suffices for the optimal rate).
    ``out (m, 144)``, if given, receives the result. With a :class:`CellMaterials` of the
    group's cells, one product per material on its rows.
    """
    degree = 2 * cells.order if degree is None else degree
    xi, _ = triangle_rule(degree)
    J, det = cells.jacobians(xi)  # (m, p, 2, 2), p = 1 (constant) or q
    m, n_p = det.shape
    fac = _geometric_factors(J.reshape(-1, 2, 2), det.reshape(-1)).reshape(m, -1)
    name = element.name
    if isinstance(material, CellMaterials):
        out = np.empty((m, 4 * element.n_local**2)) if out is None else out
        for k, mat in enumerate(material.materials):  # a loop over materials, not cells
            rows = np.flatnonzero(material.index == k)
            if rows.size:
                basis = _stiffness_basis(mat.lam_eff, mat.mu, dof_order, degree, n_p > 1, name)
                out[rows] = rows_times(fac[rows], basis)
        return out
    basis = _stiffness_basis(material.lam_eff, material.mu, dof_order, degree, n_p > 1, name)
    return rows_times(fac, basis, out=out)


def element_stiffness(vertices: np.ndarray, material: Material) -> np.ndarray:
    """P2 element stiffness matrices of plane-strain elasticity.

    ``K[c, 2 a + i, 2 b + j] = a(phi_b e_j, phi_a e_i)`` on cell ``c``, i.e. the
    local matrix of ``a(u, v) = int sigma(u) : eps(v)`` (Section 2 of the paper).
    The integrand is a polynomial of degree 2 on a straight triangle; the
    degree-2 rule makes the result exact.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    material : Material

    Returns
    -------
    ndarray of float64, shape (m, 12, 12)
        Symmetric positive semidefinite matrices, interleaved local DOF order
        ``2 * local_node + component``.
    """
    return element_blocks(AffineCells(vertices), material, dof_order=True).reshape(-1, 12, 12)


def _assemble_node_blocks(
    cell_nodes: np.ndarray, n_nodes: int, blocks: np.ndarray, rows: np.ndarray | None = None
) -> sp.csr_matrix:
    """Assemble per-cell 2x2 node blocks into a scalar CSR with node-block pattern.

    Each row ``(b_i0, b_i1)`` of a 2x2 block is packed into one complex number
    ``b_i0 + 1j b_i1``, and the complex matrix with rows ``2 z + i`` (scalar rows)
    and columns ``w`` (nodes) is built by SciPy's COO -> CSR conversion, which
    sums duplicates.  Viewed as float64, its data are exactly the scalar CSR data
    with columns ``2 w, 2 w + 1``; so every coupled node pair gets its full 2x2
    block, with no further copy of the values.

    Parameters
    ----------
    cell_nodes : ndarray of int, shape (m, k)
        Global node numbers of the ``k`` local nodes of each cell.
    n_nodes : int
    blocks : ndarray of float64, shape (m, k, k, 2, 2), C-contiguous
        ``blocks[c, a, b, i, j]`` is added to entry ``(2 z_a + i, 2 z_b + j)``.
    rows : ndarray of bool, shape (n_nodes,), optional
        The nodes whose two rows are kept (the others are emptied after the conversion):
        ``cell_nodes`` must then hold every cell with a kept node, in the order of the whole
        assembly, so that each kept row is summed from the same terms in the same order.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (2 n_nodes, 2 n_nodes)
        Sorted indices; full 2x2 block for every coupled node pair.
    """
    m, k = cell_nodes.shape
    n_dofs = 2 * n_nodes
    n_entries = 2 * m * k * k
    idx = np.int32 if max(n_entries, n_dofs) < np.iinfo(np.int32).max // 2 else np.int64
    nodes = cell_nodes.astype(idx, copy=False)
    packed = np.ascontiguousarray(blocks, dtype=np.float64).reshape(-1, 2)
    packed = packed.view(np.complex128).reshape(-1)  # (c, a, b, i): b_i0 + 1j b_i1
    row = np.empty((m, k, k, 2), dtype=idx)
    row[..., 0] = 2 * nodes[:, :, None]
    row[..., 1] = row[..., 0] + 1
    cols = np.broadcast_to(nodes[:, None, :, None], (m, k, k, 2)).reshape(-1)
    half = sp.csr_matrix((packed, (row.reshape(-1), cols)), shape=(n_dofs, n_nodes))
    del row, cols
    half.sum_duplicates()  # canonical: summed duplicates, sorted indices
    if not half.has_sorted_indices:
        half.sort_indices()
    if rows is not None:  # the kept rows, each summed from all its cells' terms
        length = np.diff(half.indptr)
        keep = np.repeat(np.repeat(rows, 2), length)
        indptr = np.zeros_like(half.indptr)
        np.cumsum(np.where(np.repeat(rows, 2), length, 0), out=indptr[1:])
        half = sp.csr_matrix(
            (half.data[: half.nnz][keep], half.indices[keep], indptr), shape=half.shape
        )
    indices = np.empty((half.nnz, 2), dtype=half.indices.dtype)
    np.multiply(half.indices, 2, out=indices[:, 0])
    np.add(indices[:, 0], 1, out=indices[:, 1])
    indptr = 2 * half.indptr
    data = _summed_values(half)
    del half
    out = sp.csr_matrix((data, indices.reshape(-1), indptr), shape=(n_dofs, n_dofs), copy=False)
    out.has_sorted_indices = True
    return out


def _summed_values(half: sp.csr_matrix) -> np.ndarray:
    """``half``'s values as float64 in a buffer of their own size (K would keep 1.5 x its data):
    SciPy's COO -> CSR conversion sums in a COO-sized buffer, ``half.data`` a view of its start,
    shrunk here in place (``realloc``, no copy) where it can be, else copied."""
    data, buffer, nnz = half.data, half.data.base, half.nnz
    layout = (data.dtype, 1, nnz, data.ctypes.data)
    if (
        not isinstance(buffer, np.ndarray)
        or not buffer.flags.owndata
        or layout != (buffer.dtype, buffer.ndim, data.size, buffer.ctypes.data)
    ):
        return data[:nnz].view(np.float64).copy()
    half.data = data = None  # no view of the buffer may outlive the resize
    buffer.resize(nnz, refcheck=False)
    return buffer.view(np.float64)


def _checked_input(
    vertices: np.ndarray, cell_dofs: np.ndarray, n_dofs: int, material: Material, width: int = 12
) -> tuple[np.ndarray, int]:
    """Validate the raw arrays of :func:`assemble_stiffness`; return the cell nodes and
    ``n_dofs``."""
    try:
        n = int(n_dofs)
    except (TypeError, ValueError):
        raise ValueError(f"n_dofs must be a non-negative integer, got {n_dofs!r}") from None
    if n < 0 or n != n_dofs:
        raise ValueError(f"n_dofs must be a non-negative integer, got {n_dofs!r}")
    if n % _D:
        raise ValueError(f"n_dofs must be even (two components per node), got {n}")
    if not isinstance(material, Material | CellMaterials):
        raise ValueError(f"material must be a Material, got {type(material).__name__}")
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 3 or v.shape[1:] != (3, 2):
        raise ValueError(f"vertices must have shape (n_cells, 3, 2), got {v.shape}")
    if not np.all(np.isfinite(v)):
        bad = np.flatnonzero(~np.isfinite(v).all(axis=(1, 2)))
        raise ValueError(f"vertices of {bad.size} cell(s) are not finite (first: cell {bad[0]})")
    _, det = p2.jacobian(v)
    if not np.all(det > 0.0):
        bad = np.flatnonzero(~(det > 0.0))
        raise ValueError(
            f"{bad.size} cell(s) have a non-positive Jacobian determinant "
            f"(clockwise or degenerate; first: cell {bad[0]}, det = {det[bad[0]]:.3e})"
        )
    d = np.asarray(cell_dofs)
    if d.ndim != 2 or d.shape[1] != width:
        raise ValueError(f"cell_dofs must have shape (n, {width}), got {d.shape}")
    if d.shape[0] != v.shape[0]:
        raise ValueError(f"cell_dofs has {d.shape[0]} rows but there are {v.shape[0]} cells")
    if d.size and not np.issubdtype(d.dtype, np.integer):
        raise ValueError(f"cell_dofs must be an integer array, got dtype {d.dtype}")
    if d.size and (d.min() < 0 or d.max() >= n):
        raise ValueError(
            f"cell_dofs out of range: values in [{d.min()}, {d.max()}] but n_dofs = {n}"
        )
    ev, od = d[:, 0::_D], d[:, 1::_D]
    if np.any(ev % _D) or np.any(od != ev + 1):
        raise ValueError(
            "cell_dofs must be interleaved: cell_dofs[:, 2a] = 2 * node_a and "
            "cell_dofs[:, 2a + 1] = 2 * node_a + 1"
        )
    return ev.astype(np.int64, copy=False) // _D, n


def assemble_stiffness(
    cells: CellMap | np.ndarray,
    cell_dofs: np.ndarray,
    n_dofs: int,
    material: Material | CellMaterials,
    *,
    validate: bool = True,
    element: Element = P2,
    rows: np.ndarray | None = None,
) -> sp.csr_matrix:
    """Global stiffness matrix of ``a(u, v) = int sigma(u) : eps(v)``, or some of its rows.

    Parameters
    ----------
    cells : CellMap or array_like of float, shape (m, 3, 2)
        The cells' geometry (:attr:`~signorini.fem.space.P2Space.mapping`: affine cells and
        the isoparametric ones along curved parts, each integrated by :func:`element_blocks`),
        or the vertices of straight cells, counter-clockwise.
    cell_dofs : array_like of int, shape (m, 12)
        Interleaved global DOFs (``2 * node + component``); ``(m, 6)`` for P1.
    n_dofs : int
        Number of global DOFs (even: two per node).
    material : Material or CellMaterials
        One material, or one per cell (:class:`~signorini.fem.material.CellMaterials`).
    validate : bool, optional
        Check the arrays (shapes, finite counter-clockwise cells, interleaved DOFs in
        range). The assembly of a :class:`~signorini.fem.space.P2Space`, whose arrays are
        right by construction, skips it.
    element : Element, optional
        The element of the DOFs (:data:`~signorini.fem.element.P2`, the default, or
        :data:`~signorini.fem.element.P1`).
    rows : (n_dofs,) bool array, optional
        The rows to assemble (both DOFs of a node together): the rows a rank of a run on
        several MPI ranks owns (docs/parallel.md, *What is distributed*). Only the cells with
        a node of these rows are integrated, and the other rows are left empty; the rows
        assembled are bit for bit those of the whole matrix (the same cells, in the same
        order, so that SciPy sums each entry's terms in the same order). Default: every row.

    Returns
    -------
    scipy.sparse.csr_matrix of float64, shape (n_dofs, n_dofs)
        Symmetric, both triangles stored, sorted indices, node-block pattern:
        each pair of nodes sharing a cell has its full 2x2 block stored
        (explicit zeros kept), so rows ``2 z`` and ``2 z + 1`` have identical
        column patterns and columns ``2 w``, ``2 w + 1`` are adjacent. With ``rows``, the
        rows not asked for have no stored entry.

    Raises
    ------
    ValueError
        If ``validate``: on inconsistent shapes, out-of-range or non-interleaved DOFs, odd
        ``n_dofs``, badly oriented or non-finite cells, a material that is not a
        :class:`Material`, or ``rows`` not an ``(n_dofs,)`` bool array that takes both DOFs
        of a node or neither.
    """
    mapping = cells if isinstance(cells, CellMap) else None
    if validate:
        vertices = mapping.groups[0].vertices if mapping is not None else cells
        if mapping is not None and len(mapping.groups) > 1:
            vertices = mapping.per_cell(lambda g: g.vertices)
        nodes, n = _checked_input(vertices, cell_dofs, n_dofs, material, _D * element.n_local)
        if rows is not None:
            _check_rows(rows, n)
    else:
        nodes = np.asarray(cell_dofs, dtype=np.int64)[:, 0::_D] // _D
        n = int(n_dofs)
    if mapping is None:
        mapping = CellMap(cells)
    if rows is not None:
        kept = np.asarray(rows, dtype=bool)[0::_D]
        blocks, nodes = _row_blocks(mapping, nodes, material, element, kept[nodes].any(axis=1))
        k = element.n_local
        return _assemble_node_blocks(nodes, n // _D, blocks.reshape(-1, k, k, _D, _D), kept)
    if len(mapping.groups) == 1:
        g = mapping.groups[0]
        blocks = element_blocks(g, on_cells(material, g.cells), element=element)
    else:  # group after group into one array (no scatter), the cells' nodes in that order
        blocks = np.empty((mapping.n_cells, 4 * element.n_local**2))
        start = 0
        for g in mapping.groups:
            rows = blocks[start : start + len(g)]
            element_blocks(g, on_cells(material, g.cells), out=rows, element=element)
            start += len(g)
        nodes = nodes[np.concatenate([g.cells for g in mapping.groups])]
    k = element.n_local
    return _assemble_node_blocks(nodes, n // _D, blocks.reshape(-1, k, k, _D, _D))


def _check_rows(rows: object, n_dofs: int) -> None:
    """Refuse ``rows`` unless it is an ``(n_dofs,)`` bool array with ``rows[2z] ==
    rows[2z + 1]``."""
    r = np.asarray(rows)
    if r.dtype != np.bool_ or r.shape != (n_dofs,):
        raise ValueError(f"rows must be a bool array of shape ({n_dofs},), got {r.dtype} {r.shape}")
    split = np.flatnonzero(r[0::_D] != r[1::_D])
    if split.size:
        raise ValueError(
            f"rows must take both DOFs of a node or neither; node {split[0]} has one "
            f"({split.size} such nodes)"
        )


def _row_blocks(
    mapping: CellMap,
    nodes: np.ndarray,
    material: Material | CellMaterials,
    element: Element,
    cells: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The element blocks ``(e, 4 k²)`` of the cells ``cells (n_cells,) bool`` and their
    nodes ``(e, k)``, group after group in the order of the whole assembly.

    Each block equals the whole assembly's bit for bit, whatever other cells are computed
    beside it: :func:`element_blocks` forms every cell's block from that cell's data alone
    (elementwise operations and :func:`~signorini.fem.fixed_order.rows_times`, no BLAS).
    """
    work = []  # (group's rows computed, their materials, their cells' rows in the mesh)
    for g in mapping.groups:
        index = np.arange(mapping.n_cells)[g.cells]  # the group's cells, in its order
        slot = np.flatnonzero(cells[index])
        if slot.size:
            work.append((g.rows(slot), on_cells(on_cells(material, g.cells), slot), index[slot]))
    blocks = np.empty((sum(len(w[2]) for w in work), 4 * element.n_local**2))
    start = 0
    for group, mat, index in work:  # into one array (no copy), as the whole assembly does
        element_blocks(group, mat, out=blocks[start : start + len(index)], element=element)
        start += len(index)
    return blocks, nodes[np.concatenate([w[2] for w in work])] if work else nodes[:0]
