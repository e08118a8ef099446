"""The node-pair pattern of the P2 stiffness matrix on a tetrahedral mesh, built once per mesh.

Two nodes are coupled when they share a cell (vertex–vertex along an edge, vertex–edge node
and edge node–edge node through a cell). The matrix is symmetric, so only the *upper* node
pairs ``z ≤ w`` are summed: each cell contributes its 55 local pairs ``{a, b}`` (``a ≤ b``
after ordering its ten nodes by their global numbers), the block of the local pair oriented
so that the global row is the smaller node, ``K_c[(a, ·), (b, ·)]`` with ``z_a ≤ z_b``. The
pattern holds

* ``select (m, 55)``: the local pair ``10 a + b`` of each cell's upper pairs, in the order of
  the cell's sorted nodes (:func:`numpy.triu_indices`);
* ``sums (n_upper, 55 m)``: the 0/1 matrix whose row ``p`` lists, in cell order, the cell
  pairs that add to upper pair ``p`` (one stable sort of the ``55 m`` keys ``z n + w``);
* ``indptr, indices, source``: the scalar CSR of the whole matrix (both triangles, 3 × 3
  node blocks, sorted indices) and, for each of its entries, its place in the summed upper
  blocks ``(n_upper, 9)``: ``9 p + 3 i + j`` above the diagonal and on it, ``9 p + 3 j + i``
  below it (the mirror), so the matrix is symmetric bit for bit.

Assembly is then ``data = (sums @ blocks)[source]``: no sort and no conversion per assembly
(:func:`signorini.fem.stiffness3d.assemble_stiffness_3d`). :func:`pattern_of` keeps the
pattern of a cell-node array as long as that array lives (the space's ``cell_dofs`` is
cached on the space, so its pattern lives with the space) and rebuilds it if the array's
values changed.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

__all__ = ["NodePattern", "node_pattern", "pattern_of"]

#: the local pairs ``a ≤ b`` of a cell's sorted nodes: 55 for the ten nodes of a P2 tetrahedron
_UPPER_A, _UPPER_B = np.triu_indices(10)


@dataclass(frozen=True, eq=False)
class NodePattern:
    """The upper node pairs of a mesh and the scalar CSR pattern of its stiffness matrix.

    Attributes
    ----------
    n_nodes : int
    cell_nodes : (m, 10) int array
        The cells' nodes it was built from (a copy).
    select : (m, 55) int8 array
        Local pair ``10 a + b`` (node blocks ``[c, a, b]``) of each cell's upper pairs.
    sums : scipy.sparse.csr_matrix, (n_upper, 55 m)
        Row ``p``: the cell pairs ``55 c + k`` of upper pair ``p`` in cell order.
    indptr, indices : int arrays
        The scalar CSR pattern ``(3 n_nodes, 3 n_nodes)``, sorted, node blocks full.
    source : (nnz,) int array
        Each CSR entry's index in the summed upper blocks, flattened ``(n_upper · 9,)``.
    """

    n_nodes: int
    cell_nodes: np.ndarray
    select: np.ndarray
    sums: sp.csr_matrix
    indptr: np.ndarray
    indices: np.ndarray
    source: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """The scalar matrix's shape, ``(3 n_nodes, 3 n_nodes)``."""
        return 3 * self.n_nodes, 3 * self.n_nodes


def _index_type(size: int) -> type:
    """int32 while ``size`` fits, else int64."""
    return np.int32 if size < 2**31 - 1 else np.int64


def _upper_sums(z: np.ndarray, n_nodes: int) -> tuple[np.ndarray, sp.csr_matrix, np.ndarray]:
    """The cells' local upper pairs ``(m, 55)``, the 0/1 summation matrix and the upper node
    pairs' keys ``z n + w`` (sorted) of cell nodes ``z (m, 10)``."""
    local = np.argsort(z, axis=1, kind="stable")  # the cell's nodes by global number
    s = np.take_along_axis(z, local, axis=1)
    select = (10 * local[:, _UPPER_A] + local[:, _UPPER_B]).astype(np.int8)
    key = (s[:, _UPPER_A] * n_nodes + s[:, _UPPER_B]).reshape(-1)
    order = np.argsort(key, kind="stable")  # the duplicates of a pair stay in cell order
    key = key[order]
    new = np.empty(key.size + 1, dtype=bool)
    new[0] = new[-1] = True
    np.not_equal(key[1:], key[:-1], out=new[1:-1])
    run = np.flatnonzero(new)  # run p of equal keys: order[run[p] : run[p + 1]]
    index = _index_type(key.size)
    sums = sp.csr_matrix(
        (np.ones(key.size), order.astype(index), run.astype(index)),
        shape=(run.size - 1, key.size),
        copy=False,
    )
    return select, sums, key[run[:-1]]


def node_pattern(cell_nodes: np.ndarray, n_nodes: int) -> NodePattern:
    """The pattern of the stiffness matrix of P2 tetrahedra with nodes ``cell_nodes``.

    Parameters
    ----------
    cell_nodes : (m, 10) int array
        Each cell's global nodes (distinct).
    n_nodes : int

    Returns
    -------
    NodePattern
    """
    z = np.array(cell_nodes, dtype=np.int64)  # a copy: the cache compares with it
    select, sums, key = _upper_sums(z, n_nodes)
    lo, hi = np.divmod(key, n_nodes)  # the upper pairs, sorted by (lo, hi)
    index = _index_type(max(9 * (2 * lo.size), 3 * n_nodes, 9 * lo.size))
    # both triangles, merged row by row by SciPy (sorted, no overlap): the upper pairs with
    # value p + 1, their mirrors (the strict ones transposed) with -(p + 1)
    start = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(lo, minlength=n_nodes), out=start[1:])
    p1 = np.arange(1, lo.size + 1, dtype=np.int64)
    upper = sp.csr_matrix((p1, hi, start), shape=(n_nodes, n_nodes), copy=False)
    strict = sp.csr_matrix((np.where(lo != hi, -p1, 0), hi, start), shape=upper.shape)
    strict.eliminate_zeros()
    both = upper + strict.T.tocsr()
    first, col = both.indptr, both.indices
    pair, mirror = np.abs(both.data) - 1, both.data < 0
    # each entry's source, 9 p + 3 i + j (3 j + i for a mirror), laid out by SciPy's BSR -> CSR
    # loop as the values will be: row 3 z + i holds row i of node row z's blocks
    mirrored = np.array([3 * j + i for i in range(3) for j in range(3)], dtype=index)
    entry = np.where(mirror[:, None], mirrored, np.arange(9, dtype=index))  # (n_blocks, 9)
    entry += (9 * pair).astype(index)[:, None]
    bsr = sp.bsr_matrix(
        (entry.reshape(-1, 3, 3), col, first),
        shape=(3 * n_nodes, 3 * n_nodes),
        copy=False,
    )
    csr = bsr.tocsr()
    source = csr.data
    indices, indptr = csr.indices.astype(index, copy=False), csr.indptr.astype(index, copy=False)
    for a in (z, select, indptr, indices, source):
        a.setflags(write=False)
    return NodePattern(int(n_nodes), z, select, sums, indptr, indices, source)


#: patterns by the identity of the cell-node array they were built for (while it lives)
_PATTERNS: dict[int, NodePattern] = {}


def pattern_of(
    cell_nodes: np.ndarray, n_nodes: int, owner: np.ndarray | None = None
) -> NodePattern:
    """:func:`node_pattern`, kept while ``owner`` (by default ``cell_nodes``) lives.

    Parameters
    ----------
    cell_nodes : (m, 10) int array
    n_nodes : int
    owner : array, optional
        The array whose life the pattern shares (the space's cached ``cell_dofs``, from which
        ``cell_nodes`` were taken). A kept pattern is used only if its nodes equal
        ``cell_nodes``; otherwise it is rebuilt.

    Returns
    -------
    NodePattern
    """
    owner = cell_nodes if owner is None else owner
    key = id(owner)
    kept = _PATTERNS.get(key)
    if kept is not None and kept.n_nodes == n_nodes and np.array_equal(kept.cell_nodes, cell_nodes):
        return kept
    pattern = node_pattern(cell_nodes, n_nodes)
    if kept is None:
        weakref.finalize(owner, _PATTERNS.pop, key, None)
    _PATTERNS[key] = pattern
    return pattern
