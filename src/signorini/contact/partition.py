"""Which rank owns which nodes and cells of a mesh, on a run of several MPI ranks
(docs/parallel.md, *What is distributed*).

The partition cuts the reverse Cuthill–McKee ordering of the mesh's vertex graph into ``size``
contiguous blocks of vertices: the ordering numbers the vertices level set after level set of
a breadth-first search, so a block is a band of the mesh, cut from the next by one level set.
Measured on Example 6.2's adaptive meshes (``python benchmarks/rows.py``, and the blocks of
METIS's nested dissection ordering, :mod:`.ordering`, for comparison): at 10⁶ unknowns it
takes 0.07 s against METIS's 1.5 s (more than the stiffness assembly of a rank), and the ranks
together compute 1.004, 1.010 and 1.029 times the cells of the serial assembly on 2, 3 and 8
ranks, against 1.003, 1.014 and 1.030 with METIS's blocks (on 32 ranks 1.119 against 1.081:
thin bands; a k-way partitioner would serve many ranks better). It needs no MKL and is the
same on every rank (SciPy's, single-threaded). An edge node (P2) and a cell go to the lowest
rank of their vertices: inside a block to the block's rank, on a cut to the first of the ranks
that meet there (the cut holds O(√n) of them, so the ranks keep about equal shares of nodes
and cells). The nodes that a contact pair's coupling joins (a slave node and the master nodes
of its mortar row, docs/method.md, *Two bodies*) go to one rank together: the change of basis
mixes their rows, and keeping them on one rank keeps every row of the system on one rank.

Rank r assembles the rows of the DOFs of its nodes; for that it computes the element matrices
of every cell with a node of its own (:attr:`Partition.row_cells`): its own cells and one
layer of its neighbours' (the ghost cells).
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, reverse_cuthill_mckee

from ..algebra.ranks import SERIAL, Ranks
from ..fem.space import LagrangeSpace
from .ordering import vertex_graph

__all__ = ["Partition", "partition"]


@dataclass(frozen=True)
class Partition:
    """The owner rank of every node and cell of one space, seen from one rank.

    Attributes
    ----------
    rank, size : int
        This rank and the number of ranks.
    node_owner : (n_nodes,) int array
        The rank that owns each node of the space (and the rows of its ``d`` DOFs).
    cell_owner : (n_cells,) int array
        The rank that owns each cell (its estimator terms).
    space : LagrangeSpace
    ranks : Ranks
        The ranks themselves, whose collectives sum what each computes from its rows
        (:meth:`~signorini.algebra.ranks.Ranks.sum`).
    """

    rank: int
    size: int
    node_owner: np.ndarray
    cell_owner: np.ndarray
    space: LagrangeSpace
    ranks: Ranks = SERIAL

    @property
    def owned_nodes(self) -> np.ndarray:
        """``(n_nodes,)`` bool: this rank's nodes."""
        return self.node_owner == self.rank

    @property
    def owned_dofs(self) -> np.ndarray:
        """``(n_dofs,)`` bool: the DOFs of this rank's nodes (interleaved, ``d node + k``)."""
        return np.repeat(self.owned_nodes, self.space.n_components)

    @property
    def owned_cells(self) -> np.ndarray:
        """``(n_cells,)`` bool: this rank's cells."""
        return self.cell_owner == self.rank

    @property
    def row_cells(self) -> np.ndarray:
        """``(n_cells,)`` bool: the cells with a node of this rank's, whose element matrices
        its rows need (its own cells and the ghost layer around them)."""
        return self.owned_nodes[self.space.cell_nodes].any(axis=1)

    def check_ranks(self, ranks: Ranks) -> None:
        """Refuse ``ranks`` other than this partition's (an assembly shared by rows handed to
        a solver on other processes), naming both."""
        if ranks.size != self.size or ranks.rank != self.rank:
            raise ValueError(
                f"assembled holds the stiffness rows of rank {self.rank} of {self.size}, but "
                f"the solver runs as rank {ranks.rank} of {ranks.size}: assemble with the "
                "solver's ranks (signorini.algebra.ranks.solver_ranks(solver))"
            )

    def own_rows(self, A: sp.csr_matrix) -> sp.csr_matrix:
        """``A (n_dofs, n_dofs)`` CSR with the rows of the other ranks' DOFs emptied (no
        stored entry), this rank's as they are."""
        keep = self.owned_dofs
        length = np.where(keep, np.diff(A.indptr), 0)
        entries = np.repeat(keep, np.diff(A.indptr))
        indptr = np.zeros(A.shape[0] + 1, dtype=A.indptr.dtype)
        np.cumsum(length, out=indptr[1:])
        out = sp.csr_matrix((A.data[entries], A.indices[entries], indptr), shape=A.shape)
        out.has_sorted_indices = A.has_sorted_indices
        return out


def partition(space: LagrangeSpace, ranks: Ranks, coupling: sp.spmatrix | None = None) -> Partition:
    """The partition of ``space``'s nodes and cells over ``ranks``.

    Parameters
    ----------
    space : LagrangeSpace
    ranks : Ranks
    coupling : (n_nodes, n_nodes) sparse matrix, optional
        Node pairs that must share a rank (a contact pair's mortar transfer).

    Returns
    -------
    Partition
        The same on every rank (computed from replicated data, deterministically; checked).

    Raises
    ------
    RuntimeError
        If the ranks computed different partitions.
    """
    mesh = space.mesh
    order = _vertex_order(mesh)
    vertex_owner = np.empty(mesh.n_points, dtype=np.int64)
    vertex_owner[order] = np.arange(mesh.n_points) * ranks.size // max(mesh.n_points, 1)
    node_owner = vertex_owner
    if space.n_nodes > mesh.n_points:  # P2: then the edge midpoints
        node_owner = np.concatenate([vertex_owner, vertex_owner[mesh.edges].min(axis=1)])
    if coupling is not None and ranks.size > 1:
        node_owner = _joined(node_owner, coupling)
    cell_owner = node_owner[mesh.cells].min(axis=1)  # a cell of a rank has a node of it
    if ranks.size > 1:  # the ranks must agree on it, or a row would be on two ranks or none
        check = float(zlib.crc32(node_owner.tobytes()))
        if ranks.max(check) != -ranks.max(-check):
            raise RuntimeError(
                "the ranks computed different partitions of the same mesh: run them with the "
                "same signorini, NumPy and SciPy"
            )
    return Partition(ranks.rank, ranks.size, node_owner, cell_owner, space, ranks)


def _vertex_order(mesh) -> np.ndarray:
    """The reverse Cuthill–McKee ordering of the vertex graph."""
    order = reverse_cuthill_mckee(vertex_graph(mesh), symmetric_mode=True)
    return np.asarray(order, dtype=np.int64)


def _joined(node_owner: np.ndarray, coupling: sp.spmatrix) -> np.ndarray:
    """``node_owner`` with every group of nodes that ``coupling`` joins given the owner of
    the group's first node."""
    n = node_owner.size
    c = sp.coo_matrix(coupling)
    graph = sp.csr_matrix((np.ones(c.nnz), (c.row, c.col)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(first, label, np.arange(n))
    return node_owner[first[label]]
