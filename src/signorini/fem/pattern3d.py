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
* ``first, column, pair, mirror``: the node-block CSR of the whole matrix (both triangles,
  sorted columns), each block the summed upper pair ``pair`` or, below the diagonal
  (``mirror``), its transpose, so the matrix is symmetric bit for bit; and ``indptr``, the
  scalar rows' starts (3 × 3 blocks: row ``3 z + i`` holds row ``i`` of node row ``z``'s
  blocks).

Assembly is then ``summed = sums @ blocks`` and :meth:`NodePattern.laid_out`, the CSR's data
and indices from the summed blocks (the indices' array allocated before the element blocks,
so that the data can reuse their freed memory), written chunk of node rows by chunk through
SciPy's BSR -> CSR loop: no sort and no ``(nnz,)``
array kept in the pattern, so the first assembly on a mesh faults in less memory
(:func:`signorini.fem.stiffness3d.assemble_stiffness_3d`). :func:`pattern_of` keeps the
pattern of a cell-node array as long as that array lives (the space's ``cell_dofs`` is cached
on the space, so its pattern lives with the space) and rebuilds it if the array's values
changed.
"""

from __future__ import annotations

import weakref
from collections.abc import Iterator
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
    first, column : int arrays
        The node-block CSR pattern ``(n_nodes, n_nodes)``: both triangles, sorted columns.
    pair : (n_blocks,) int array
        Each block's upper pair.
    mirror : (n_blocks,) bool array
        The blocks below the diagonal: the transpose of their pair's block.
    indptr : (3 n_nodes + 1,) int array
        The scalar CSR's row starts, ``9 first[z] + 3 i deg z`` for row ``3 z + i``.
    """

    n_nodes: int
    cell_nodes: np.ndarray
    select: np.ndarray
    sums: sp.csr_matrix
    first: np.ndarray
    column: np.ndarray
    pair: np.ndarray
    mirror: np.ndarray
    indptr: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """The scalar matrix's shape, ``(3 n_nodes, 3 n_nodes)``."""
        return 3 * self.n_nodes, 3 * self.n_nodes

    def _row_chunks(self) -> Iterator[tuple[int, int, int, int]]:
        """Chunks ``(r0, r1, f0, f1)`` of node rows and their blocks, about ``_BLOCKS`` each."""
        first = self.first
        cuts = np.searchsorted(first, np.arange(0, first[-1], _BLOCKS), side="right") - 1
        cuts = np.append(np.unique(cuts), self.n_nodes)
        for r0, r1 in zip(cuts[:-1].tolist(), cuts[1:].tolist(), strict=True):
            yield r0, r1, int(first[r0]), int(first[r1])

    def _scalar(self, values: np.ndarray, r0: int, r1: int, f0: int, f1: int) -> sp.csr_matrix:
        """The scalar CSR rows ``3 r0 … 3 r1 - 1`` of the node blocks ``values (k, 3, 3)`` of
        blocks ``f0 … f1 - 1``, by SciPy's BSR -> CSR loop."""
        starts = self.first[r0 : r1 + 1] - f0
        bsr = sp.bsr_matrix(
            (values, self.column[f0:f1], starts), shape=(3 * (r1 - r0), 3 * self.n_nodes)
        )
        return bsr.tocsr()

    def scalar_indices(self) -> np.ndarray:
        """The scalar CSR's column indices ``(nnz,)`` (a new array), sorted in each row: the
        node blocks' columns ``3 w + j``, written chunk of node rows by chunk."""
        indices = np.empty(9 * int(self.first[-1]), dtype=self.indptr.dtype)
        for r0, r1, f0, f1 in self._row_chunks():
            values = np.zeros((f1 - f0, 3, 3), dtype=np.int8)
            indices[9 * f0 : 9 * f1] = self._scalar(values, r0, r1, f0, f1).indices
        return indices

    def laid_out(self, summed: np.ndarray, indices: np.ndarray | None = None) -> np.ndarray:
        """The scalar CSR's data ``(nnz,)`` (a new array, in the order of
        :meth:`scalar_indices`) of the summed upper blocks ``summed (n_upper, 9)``: each node
        block its pair's, transposed below the diagonal, chunk of node rows by chunk (the
        temporaries stay in the cache).

        Parameters
        ----------
        summed : (n_upper, 9) float array
        indices : (nnz,) int array, optional
            Receives :meth:`scalar_indices` in the same pass (allocated by the caller before
            the element blocks, so that the data can reuse their freed memory).

        Returns
        -------
        (nnz,) float64 array
        """
        blocks = summed.reshape(-1, 3, 3)
        data = np.empty(9 * int(self.first[-1]))
        for r0, r1, f0, f1 in self._row_chunks():
            values = np.take(blocks, self.pair[f0:f1], axis=0)  # (k, 3, 3): the pair's block
            mirror = self.mirror[f0:f1, None, None]
            values = np.where(mirror, values.transpose(0, 2, 1), values)  # or its transpose
            csr = self._scalar(values, r0, r1, f0, f1)
            data[9 * f0 : 9 * f1] = csr.data
            if indices is not None:
                indices[9 * f0 : 9 * f1] = csr.indices
        return data


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


#: node blocks per chunk of :meth:`NodePattern.laid_out`: its temporaries stay in the cache
_BLOCKS = 1 << 15


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
    # its own index arrays: eliminate_zeros compacts them in place, and SciPy shares the
    # arrays it is handed where their index type is already its own (int64 beyond 2³¹)
    strict = sp.csr_matrix((np.where(lo != hi, -p1, 0), hi.copy(), start.copy()), upper.shape)
    strict.eliminate_zeros()
    both = upper + strict.T.tocsr()
    first = both.indptr.astype(np.int64)
    column, mirror = both.indices.astype(index), both.data < 0
    pair = (np.abs(both.data) - 1).astype(index)
    deg = np.diff(first)
    indptr = np.empty(3 * n_nodes + 1, dtype=index)
    indptr[:-1] = (9 * first[:-1, None] + 3 * deg[:, None] * np.arange(3)).reshape(-1)
    indptr[-1] = 9 * first[-1]
    for a in (z, select, first, column, pair, mirror, indptr):
        a.setflags(write=False)
    return NodePattern(int(n_nodes), z, select, sums, first, column, pair, mirror, indptr)


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
