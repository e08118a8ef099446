"""The change of basis that makes the dual mortar constraint of two bodies nodal
(docs/method.md, *Two bodies*; Wohlmuth–Krause).

A constrained slave node ``j`` of a contact pair bounds its weighted gap,
``n_j·(D_jj u_j − Σ_k M_jk u_k) ≤ g̃_j``. With ``T_jk = M_jk / D_jj`` (zero outside the
constrained slave rows and the master columns) and the relative displacement
``ũ_j = u_j − P_j Σ_k T_jk u_k`` that is ``ũ_j·n_j ≤ g̃_j / D_jj``: a bound on one unknown
in the node's frame, as for a rigid obstacle. ``P_j`` is the identity where the node has a
friction law (its tangential unknown is then the relative slip the law acts on) and the
projection ``n_j n_jᵀ`` where it has none (its tangential unknown stays the slave's own
displacement, so a roller may hold it as at a rigid obstacle). The DOF transfer
``T_d = [P_j T_jk]`` has ``T_d² = 0`` (no master node is a slave node), so ``u = (I + T_d) ũ``
has the inverse ``ũ = (I − T_d) u``, and ``K̃ = (I + T_d)ᵀ K (I + T_d)``,
``F̃ = (I + T_d)ᵀ F`` stay symmetric positive definite: the active-set solver, its warm
starts, bordered updates and orderings, friction laws and every linear-solver backend take
them as they take one body's system.

The multiplier of constraint ``j`` is the slave's nodal contact force ``Λ_j`` along
``n_j`` (and the friction force along ``t_j``); the master's nodal forces are
``−T_dᵀ f`` of the slave's ``f``, so the two bodies' resultants are equal and opposite
wherever ``Σ_k M_jk = D_jj``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..algebra.sparse import concatenated_ranges
from ..fem.space import P2Space
from ..problem.fields import ProblemError
from .constraint_data import facet_weights
from .mortar import MortarCoupling

__all__ = [
    "PairTransfer",
    "master_forces",
    "master_traction",
    "mortar_transfer",
    "pair_transfer",
    "physical",
    "rows_read",
    "two_body_system",
]


def mortar_transfer(
    n_nodes: int, rows: np.ndarray, T: sp.csr_matrix, projection: np.ndarray
) -> sp.csr_matrix:
    """The DOF transfer ``T_d (2 n_nodes, 2 n_nodes)`` on interleaved DOFs (``2 node +
    component``) of the node transfer rows ``T (r, n_nodes)`` of the constrained slave nodes
    ``rows (r,)``, each with its ``projection (r, 2, 2)`` ``P_j``: block ``(j, k)`` is
    ``P_j T_jk``."""
    coo = sp.coo_matrix(T)
    block = coo.data[:, None, None] * projection[coo.row]  # (nnz, 2, 2)
    r = 2 * np.asarray(rows)[coo.row][:, None, None] + np.arange(2)[None, :, None]
    c = 2 * coo.col[:, None, None] + np.arange(2)[None, None, :]
    r, c = np.broadcast_arrays(r, c)
    return sp.csr_matrix((block.ravel(), (r.ravel(), c.ravel())), shape=(2 * n_nodes, 2 * n_nodes))


def two_body_system(
    K: sp.csr_matrix, F: np.ndarray, Td: sp.csr_matrix
) -> tuple[sp.csr_matrix, np.ndarray]:
    """``K̃ = (I + T_d)ᵀ K (I + T_d)`` and ``F̃ = (I + T_d)ᵀ F`` (Cartesian DOFs), with sorted
    indices and full 2 × 2 node blocks, as :func:`~.node_frames.rotate_frames` needs.

    Every product here is computed row by row, so a row of ``K̃`` is the same bit for bit
    whenever the rows of ``K`` it reads are (:func:`rows_read`): on a rank of several, ``K``
    holds those rows only, and the rows of ``K̃`` it needs are exact (the others are not:
    :meth:`~.partition.Partition.own_rows` drops them)."""
    KT = K @ Td
    correction = _full_blocks((KT + KT.T + Td.T @ KT).tocoo())  # rows near the interface
    return _add_rows(K.tocsr(), correction), F + Td.T @ F


def rows_read(cell_nodes: np.ndarray, Td: sp.csr_matrix, nodes: np.ndarray) -> np.ndarray:
    """``(n_nodes,) bool``: the nodes whose rows of ``K`` the rows of ``nodes (n_nodes,)
    bool`` of ``K̃ = (I + T_d)ᵀ K (I + T_d)`` read (:func:`two_body_system`), where
    ``nodes`` holds each slave node of ``T_d`` together with its master nodes (a rank's
    nodes, :func:`~.partition.partition`): ``nodes`` themselves, and every node that shares
    a cell (``cell_nodes (n_cells, k)``) with a slave node among them, as the term
    ``(K T_d)ᵀ`` of a master row reads the rows of the slave's neighbours."""
    filled = np.diff(Td.indptr)
    slaves = nodes & ((filled[0::2] + filled[1::2]) > 0)
    read = nodes.copy()
    read[cell_nodes[slaves[cell_nodes].any(axis=1)]] = True
    return read


def _add_rows(K: sp.csr_matrix, C: sp.csr_matrix) -> sp.csr_matrix:
    """``K + C`` for a ``C`` with few non-empty rows, keeping every entry either stores
    (explicit zeros too), indices sorted: only the rows ``C`` touches are merged; the
    others are moved as they are, by one deletion and one insertion of those rows' entries
    (two passes over ``K``'s arrays, no index array of its size)."""
    K.sort_indices()
    n = K.shape[0]
    touched = np.unique(np.repeat(np.arange(n), np.diff(C.indptr)))
    Ks, Cs = K[touched].tocoo(), C[touched].tocoo()
    M = sp.coo_matrix(
        (np.concatenate([Ks.data, Cs.data]),
         (np.concatenate([Ks.row, Cs.row]), np.concatenate([Ks.col, Cs.col]))),
        shape=(touched.size, K.shape[1]),
    ).tocsr()  # fmt: skip  # duplicates summed, explicit zeros kept, sorted
    start = K.indptr[touched]
    length = K.indptr[touched + 1] - start
    entries = concatenated_ranges(start, length)  # the touched rows' entries in K
    at = start - (np.cumsum(length) - length)  # each touched row's place in K without them
    merged = np.repeat(at, np.diff(M.indptr))
    data = np.insert(np.delete(K.data, entries), merged, M.data)
    indices = np.insert(np.delete(K.indices, entries), merged, M.indices)
    lengths = np.diff(K.indptr)
    lengths[touched] = np.diff(M.indptr)
    indptr = np.concatenate([[0], np.cumsum(lengths)])
    out = sp.csr_matrix((data, indices, indptr), shape=K.shape)
    out.has_sorted_indices = True
    return out


def _full_blocks(A: sp.coo_matrix) -> sp.csr_matrix:
    """``A`` in CSR with every 2 × 2 node block it touches stored whole (explicit zeros
    where a projected transfer ``n nᵀ`` left an entry out), indices sorted."""
    n = A.shape[0]
    keys = A.row.astype(np.int64) * n + A.col
    order = np.argsort(keys)
    keys, values = keys[order], A.data[order]
    blocks = np.unique((A.row // 2).astype(np.int64) * (n // 2) + A.col // 2)
    bi, bj = np.divmod(blocks, n // 2)
    rows = (2 * bi[:, None] + [0, 0, 1, 1]).ravel()
    cols = (2 * bj[:, None] + [0, 1, 0, 1]).ravel()
    want = np.sort(rows * n + cols)
    rows, cols = np.divmod(want, n)
    pos = np.minimum(np.searchsorted(keys, want), max(keys.size - 1, 0))
    data = np.where(keys[pos] == want, values[pos], 0.0) if keys.size else np.zeros(want.size)
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=n))])
    out = sp.csr_matrix((data, cols, indptr), shape=A.shape)  # rows, then columns, sorted
    out.has_sorted_indices = True
    return out


def physical(u_relative: np.ndarray, transfer: PairTransfer | None) -> np.ndarray:
    """``u = ũ + T_d ũ`` of nodal values ``(n_nodes, 2)``."""
    if transfer is None:
        return u_relative
    return u_relative + (transfer.dofs @ u_relative.ravel()).reshape(-1, 2)


def master_forces(
    Td: sp.csr_matrix, nodes: np.ndarray, force: np.ndarray, n_nodes: int
) -> np.ndarray:
    """``(n_nodes, 2)`` the nodal contact forces the slave constraints ``nodes (k,)`` with
    forces ``force (k, 2)`` (``Λ_j n_j``, plus any friction force) exert on the master:
    ``−T_dᵀ f``."""
    f = np.zeros((n_nodes, 2))
    np.add.at(f, nodes, force)
    return -(Td.T @ f.ravel()).reshape(-1, 2)


@dataclass(frozen=True)
class PairTransfer:
    """The mortar transfer of a problem's contact pairs.

    Attributes
    ----------
    nodes : (n_nodes, n_nodes) scipy.sparse CSR matrix
        ``T_jk = M_jk / D_jj`` on the constrained slave rows and the master columns.
    dofs : (n_dofs, n_dofs) scipy.sparse CSR matrix
        ``T_d``, blocks ``P_j T_jk`` on interleaved DOFs: the change of basis.
    masters : tuple of str
        The master parts, pair after pair.
    every_slave : (n_dofs, n_dofs) scipy.sparse CSR matrix
        Blocks ``T_jk I`` at every slave node, Dirichlet nodes included: the relative
        displacement ``u − T u`` along the whole slave part, which the estimator reads
        (:meth:`~.contact_set.ContactSet.facet_normal_gap`); at a constrained node its normal
        component is the basis unknown's.
    """

    nodes: sp.csr_matrix
    dofs: sp.csr_matrix
    masters: tuple[str, ...]
    every_slave: sp.csr_matrix


def master_traction(
    space: P2Space, transfer: PairTransfer, nodes: np.ndarray, force: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The master side of the pairs: the P2 nodes of the master parts ``(m,)``, the
    consistent traction the slaves exert there ``(m, 2)`` (nodal force of
    :func:`master_forces` over ``w_k = ∫_{Γ_m} φ_k ds``), and the transferred pressure
    ``(m,)`` ``Σ_j T_jk Λ_j / w_k``; ``nodes (k,)`` and ``force (k, 3)`` the slave
    constraints' nodes and their ``(f_x, f_y, Λ)`` (the force on the slave and the normal
    contact force)."""
    facets = np.concatenate([space.mesh.part_facets(m) for m in transfer.masters])
    facet_nodes = space.facet_nodes(facets)
    w = np.bincount(
        facet_nodes.ravel(), weights=facet_weights(space, facets, facet_nodes)[1].ravel(),
        minlength=space.n_nodes,
    )  # fmt: skip
    on = np.unique(facet_nodes)
    f = master_forces(transfer.dofs, nodes, force[:, :2], space.n_nodes)[on]
    lam = np.zeros(space.n_nodes)
    np.add.at(lam, nodes, force[:, 2])
    pressure = space.element.facet.pressure  # nodal force -> consistent stress
    return on, pressure(f, w[on, None]), pressure((transfer.nodes.T @ lam)[on], w[on])


def pair_transfer(
    space: P2Space,
    couplings: Mapping[str, MortarCoupling],
    rows: tuple,
    parts: tuple,
    masters: tuple[str, ...],
) -> PairTransfer | None:
    """The transfer of the contact pairs ``couplings {slave part: coupling}`` for the
    constraint rows ``rows = (nodes, part, second, normal, frictional)`` of a contact set
    with ``parts``, ``masters`` the master parts; ``None`` without pairs.

    Raises
    ------
    ProblemError
        If a constrained slave node is a corner (it lies on a second contact part), or a node
        is on the master side of one constraint and is itself constrained as a slave.
    """
    if not couplings:
        return None
    nodes, part, second, normal, frictional = rows
    Td = sp.csr_matrix((space.n_dofs, space.n_dofs))
    Tn = sp.csr_matrix((space.n_nodes, space.n_nodes))
    for name, c in couplings.items():  # a loop over contact pairs
        mine = np.flatnonzero(part == parts.index(name))
        corner = np.isin(nodes[mine], nodes[second]) | second[mine]
        if corner.any():
            z = nodes[mine][np.flatnonzero(corner)[0]]
            raise ProblemError(
                f"the node at {_point(space, z)} of contact part {name!r}, the slave of a "
                "pair, lies on a second contact part: a slave node carries one constraint "
                "(end the other part before it)"
            )
        loc = np.searchsorted(c.slave_nodes, nodes[mine])
        n = normal[mine]
        projection = np.where(
            frictional[mine, None, None], np.eye(2), n[:, :, None] * n[:, None, :]
        )
        T = sp.diags(1.0 / c.D[loc]) @ c.M[loc]
        Td = Td + mortar_transfer(space.n_nodes, nodes[mine], T, projection)
        Tn = Tn + sp.csr_matrix(
            (np.ones(mine.size), (nodes[mine], np.arange(mine.size))),
            shape=(space.n_nodes, mine.size),
        ) @ sp.csr_matrix(T)
    both = np.intersect1d(np.unique(Tn.indices), nodes)
    if both.size:
        raise ProblemError(
            f"the node at {_point(space, both[0])} is constrained as a slave node and lies on "
            "the master side of a contact pair: give the two pairs' parts no common node"
        )
    every = sp.csr_matrix((space.n_dofs, space.n_dofs))
    for c in couplings.values():  # a loop over contact pairs
        T = sp.diags(1.0 / c.D) @ c.M
        every = every + mortar_transfer(
            space.n_nodes, c.slave_nodes, T, np.broadcast_to(np.eye(2), (c.D.size, 2, 2))
        )
    return PairTransfer(Tn.tocsr(), Td.tocsr(), masters, every.tocsr())


def _point(space: P2Space, z: int) -> tuple:
    return tuple(np.round(space.node_points[z], 12).tolist())
