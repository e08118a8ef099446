"""Node frames: the ``d`` DOFs of a contact node in its constraint frame ``[n t_1 … t_{d−1}]``
(a normal, then a basis of the tangent plane: ``ContactSet.tangent (k, d − 1, d)``, the
frictional problem's tangential DOFs ``(m, d − 1)``). The kernels here are the ``d = 2`` ones.

A node ``z`` with one constraint has a unit direction ``n = (n1, n2)`` and the tangent
``t_1 = t = (-n2, n1)``. With interleaved DOFs (``dof = d * node + component``; ``d = 2``, the size
``Q.shape[-1]`` of a frame), the Cartesian values ``u = (x[2z], x[2z + 1])`` and the frame
values ``(u.n, u.t)`` are related by the 2 x 2 block ``Q_z = [n t]``: ``u = Q_z (u.n, u.t)``.
``Q`` is block diagonal with ``Q_z`` at the listed nodes and the identity elsewhere, so the
constraint ``u(z).n <= gap`` of docs/method.md, *The continuous problem* becomes a bound on
the single DOF ``2z`` of the rotated system ``Q^T K Q y = Q^T F``.

A corner node with two constraints along independent directions ``n, m`` takes the frame
``Q_z = A_z^{-1}``, ``A_z`` the matrix with rows ``n`` and ``m``: then ``y = (u.n, u.m)`` and
both constraints bound one DOF each; ``Q^T K Q`` is still symmetric, and the multipliers
``Q^T (F - K u)`` are the two constraints' nodal forces (docs/method.md, *Contact
directions*). Every function here takes either unit directions ``(m, 2)`` (rotations) or
general frames ``(m, 2, 2)``.

:func:`rotate_frames` forms ``Q^T K Q`` directly on the CSR values: a stiffness matrix with
interleaved DOFs has a 2 x 2 node-block pattern (rows ``2z`` and ``2z + 1`` store the same
columns, and columns ``2z``, ``2z + 1`` sit next to each other in every row), so the product
only mixes pairs of stored values.

:func:`rotate_frames` checks its input unless told not to (the assembly of a validated problem
passes ``validate=False``); :func:`to_frames` and :func:`to_cartesian` trust theirs.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..algebra.sparse import as_csr, concatenated_ranges, csr_row_indices
from ..fem.space import node_dofs

__all__ = ["frame_matrices", "rotate_frames", "to_cartesian", "to_frames"]


def frame_matrices(frames: np.ndarray) -> np.ndarray:
    """The blocks ``Q_z (m, 2, 2)`` of unit directions ``(m, 2)`` (``[n t]``) or of frames
    ``(m, 2, 2)`` (returned as they are)."""
    frames = np.asarray(frames, dtype=np.float64)
    if frames.ndim == 3:
        return frames
    n1, n2 = frames[:, 0], frames[:, 1]
    return np.stack([np.stack([n1, -n2], axis=-1), np.stack([n2, n1], axis=-1)], axis=1)


def _checked_frames(
    nodes: np.ndarray, frames: np.ndarray, n_dofs: int
) -> tuple[np.ndarray, np.ndarray]:
    """Validate ``nodes (k,)`` and unit directions ``(k, 2)`` or invertible frames
    ``(k, 2, 2)``; return them as int64 / float64."""
    if n_dofs % 2:
        raise ValueError(f"interleaved 2D DOFs need an even size, got {n_dofs}")
    nodes = np.asarray(nodes)
    if nodes.ndim != 1 or not (nodes.size == 0 or np.issubdtype(nodes.dtype, np.integer)):
        raise ValueError(f"nodes must be a 1D integer array, got dtype {nodes.dtype}")
    nodes = nodes.astype(np.int64)
    n_nodes = n_dofs // 2
    if nodes.size and (nodes.min() < 0 or nodes.max() >= n_nodes):
        raise ValueError(
            f"nodes must lie in [0, {n_nodes}), got range [{nodes.min()}, {nodes.max()}]"
        )
    if np.unique(nodes).size != nodes.size:
        raise ValueError("nodes has repeated entries")
    frames = np.asarray(frames, dtype=np.float64)
    if frames.shape not in ((nodes.size, 2), (nodes.size, 2, 2)):
        raise ValueError(
            f"normals must have shape ({nodes.size}, 2) (unit directions) or ({nodes.size}, 2, "
            f"2) (frames), got {frames.shape}"
        )
    if not np.isfinite(frames).all():
        raise ValueError("normals has non-finite entries")
    if frames.ndim == 2:
        length = np.hypot(frames[:, 0], frames[:, 1])
        if nodes.size and np.abs(length - 1.0).max() > 1e-10:
            k = int(np.argmax(np.abs(length - 1.0)))
            raise ValueError(
                f"normals must be unit vectors; normals[{k}] has length {length[k]:.6g}"
            )
    elif nodes.size:
        det = np.abs(np.linalg.det(frames))
        scale = np.abs(frames).max(axis=(1, 2)) ** 2
        if (det <= 1e-12 * scale).any():
            k = int(np.argmin(det / np.maximum(scale, 1e-300)))
            raise ValueError(
                f"normals: the frame normals[{k}] is singular (determinant {det[k]:.3g})"
            )
    return nodes, frames


def _transform_pairs(
    first: np.ndarray, second: np.ndarray, Q: np.ndarray, values: np.ndarray
) -> None:
    """In place: ``(v[first], v[second]) <- Q^T (v[first], v[second])`` for blocks
    ``Q (k, 2, 2)`` broadcast against the values."""
    v1 = values[first]
    v2 = values[second]
    shape = (-1,) + (1,) * (values.ndim - 1)
    q00, q01 = Q[:, 0, 0].reshape(shape), Q[:, 0, 1].reshape(shape)
    q10, q11 = Q[:, 1, 0].reshape(shape), Q[:, 1, 1].reshape(shape)
    values[first] = q00 * v1 + q10 * v2
    values[second] = q01 * v1 + q11 * v2


def to_frames(x: np.ndarray, nodes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Cartesian DOF values to frame values at the listed nodes: ``Q^{-1} x``.

    Parameters
    ----------
    x : (n_dofs,) or (n_dofs, k) float array
        Interleaved Cartesian values.
    nodes : (m,) int array
        Nodes to transform (distinct).
    normals : (m, 2) or (m, 2, 2) float array
        Unit direction at each node (a rotation ``Q_z = [n t]``), or the frames ``Q_z``.

    Returns
    -------
    (n_dofs,) or (n_dofs, k) float array
        For directions ``y[2z] = u(z).n``, ``y[2z + 1] = u(z).t`` with ``t = (-n2, n1)``; for
        frames ``(y[2z], y[2z + 1]) = Q_z^{-1} u(z)``; other DOFs copied.
    """
    y = np.array(x, dtype=np.float64)
    nodes = np.asarray(nodes, dtype=np.int64)
    normals = np.asarray(normals, dtype=np.float64)
    # a rotation's inverse is its transpose; a general frame's is computed
    Q = frame_matrices(normals)
    M = Q if normals.ndim == 2 else np.linalg.inv(Q).transpose(0, 2, 1)
    _transform_pairs(*node_dofs(nodes, Q.shape[-1]).T, M, y)
    return y


def to_cartesian(y: np.ndarray, nodes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Frame values at the listed nodes back to Cartesian values: ``Q y``.

    Parameters
    ----------
    y : (n_dofs,) or (n_dofs, k) float array
    nodes : (m,) int array
    normals : (m, 2) or (m, 2, 2) float array
        As for :func:`to_frames`.

    Returns
    -------
    (n_dofs,) or (n_dofs, k) float array
        ``x[2z : 2z + 2] = Q_z (y[2z], y[2z + 1])`` (``y[2z] n + y[2z + 1] t`` for a
        direction); other DOFs copied.
    """
    x = np.array(y, dtype=np.float64)
    nodes = np.asarray(nodes, dtype=np.int64)
    Q = frame_matrices(normals)
    _transform_pairs(*node_dofs(nodes, Q.shape[-1]).T, Q.transpose(0, 2, 1), x)
    return x


def _row_pairs(indptr: np.ndarray, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions ``pos0``, ``pos1`` of the stored entries of rows ``2z`` and ``2z + 1`` of each
    node, paired entry by entry, and the length of row ``2z`` per node."""
    start0, start1 = indptr[2 * nodes], indptr[2 * nodes + 1]
    length = start1 - start0
    pos0 = concatenated_ranges(start0, length)
    return pos0, pos0 + np.repeat(length, length), length


def _column_entries(
    K: sp.csr_matrix, which_node: np.ndarray, pos0: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The positions of the stored entries in column ``2z`` of each node ``z`` of
    ``which_node`` (its index there, -1 elsewhere) and those indices, for a ``K`` with a
    symmetric pattern: only the rows of the DOFs that rows ``2z`` (stored at ``pos0``) couple
    with store such a column, so only they are read (a few rows near the constrained
    boundary instead of every entry of ``K``); the positions come in increasing order, as a
    scan of every entry gives them."""
    rows = np.unique(K.indices[pos0])
    start = K.indptr[rows]
    positions = concatenated_ranges(start, K.indptr[rows + 1] - start)
    columns = K.indices[positions]
    col_node = which_node[columns >> 1]
    hit = (col_node >= 0) & (columns % 2 == 0)
    return positions[hit], col_node[hit]


def _check_node_blocks(
    K: sp.csr_matrix, nodes: np.ndarray, first: np.ndarray, n_column_entries: int
) -> None:
    """Raise unless ``K`` has a 2 x 2 node-block pattern at ``nodes``: rows ``2z``, ``2z + 1``
    store the same columns, and in every row column ``2z`` (stored at ``first``) is followed by
    column ``2z + 1``."""
    indptr, indices = K.indptr, K.indices
    length = indptr[2 * nodes + 1] - indptr[2 * nodes]
    bad = np.flatnonzero(length != indptr[2 * nodes + 2] - indptr[2 * nodes + 1])
    if bad.size == 0:
        pos0, pos1, length = _row_pairs(indptr, nodes)
        mismatch = indices[pos0] != indices[pos1]
        if mismatch.any():
            bad = np.unique(np.repeat(np.arange(nodes.size), length)[mismatch])
    if bad.size:
        raise ValueError(
            f"K has no 2x2 node-block pattern: rows 2z, 2z+1 of node {nodes[bad[0]]} store "
            "different columns"
        )
    second = np.minimum(first + 1, K.nnz - 1)
    rows = csr_row_indices(K)
    ok = (first + 1 < K.nnz) & (indices[second] == indices[first] + 1)
    ok &= rows[second] == rows[first]
    if not ok.all() or 2 * first.size != n_column_entries:
        raise ValueError(
            "K has no 2x2 node-block pattern: columns 2z and 2z+1 of a rotated node are not "
            "stored side by side in every row"
        )


def rotate_frames(
    K: sp.spmatrix,
    F: np.ndarray,
    nodes: np.ndarray,
    normals: np.ndarray,
    *,
    copy: bool = True,
    validate: bool = True,
) -> tuple[sp.csr_matrix, np.ndarray]:
    """Transform a system ``K x = F`` into node frames: ``(Q^T K Q, Q^T F)``.

    Works on the CSR values only (no sparse product): the column rotation mixes the two
    adjacent stored values of columns ``2z``, ``2z + 1`` in every row, and the row rotation
    mixes rows ``2z`` and ``2z + 1`` entry by entry, which store the same columns.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n_dofs, n_dofs)
        With a 2 x 2 node-block pattern at the listed nodes.
    F : (n_dofs,) float array
    nodes : (m,) int array
        Nodes to rotate (distinct).
    normals : (m, 2) or (m, 2, 2) float array
        Unit direction ``n`` at each node (the tangent is ``t = (-n2, n1)``), or general
        invertible frames ``Q_z`` (a corner node's two constraint directions).
    copy : bool
        If False and ``K`` is canonical float64 CSR and ``F`` a float64 array, both are
        overwritten and returned.
    validate : bool
        Check ``K`` (square, finite, canonical CSR), ``F``, the nodes and normals, and the
        node-block pattern. The assembly passes False: its stiffness matrix has the pattern by
        construction (:func:`signorini.fem.stiffness.assemble_stiffness`) and its nodes and
        normals come from a validated problem.

    Returns
    -------
    K_rot : scipy.sparse.csr_matrix, shape (n_dofs, n_dofs)
        Same pattern as ``K``.
    F_rot : (n_dofs,) float array

    Raises
    ------
    ValueError
        If ``validate``: on bad shapes or normals, or if the pattern is not node-blocked at a
        listed node.
    """
    if validate:
        K = as_csr(K, "K")
        if np.shape(F) != (K.shape[0],):
            raise ValueError(f"F must have shape ({K.shape[0]},), got {np.shape(F)}")
        nodes, normals = _checked_frames(nodes, normals, K.shape[0])
    else:
        nodes = np.asarray(nodes, dtype=np.int64)
    Q = frame_matrices(normals)
    if copy:
        K = K.copy()
    F_rot = np.array(F, dtype=np.float64) if copy else np.asarray(F, dtype=np.float64)

    # Column rotation: in every row, column 2z is stored and followed by column 2z + 1.
    which_node = np.full(K.shape[0] // 2, -1, dtype=np.int64)
    which_node[nodes] = np.arange(nodes.size)
    # Row rotation: rows 2z and 2z + 1 store the same columns, paired entry by entry.
    pos0, pos1, length = _row_pairs(K.indptr, nodes)
    if validate or not np.diff(K.indptr).all():  # any row may store a column 2z
        col_node = which_node[K.indices >> 1]
        first = np.flatnonzero((col_node >= 0) & (K.indices % 2 == 0))
        if validate:
            _check_node_blocks(K, nodes, first, np.count_nonzero(col_node >= 0))
        col_node = col_node[first]
    else:  # an assembled matrix, whole: its pattern is symmetric
        first, col_node = _column_entries(K, which_node, pos0)
    data = K.data
    _transform_pairs(first, first + 1, Q[col_node], data)
    _transform_pairs(pos0, pos1, np.repeat(Q, length, axis=0), data)
    _transform_pairs(*node_dofs(nodes, Q.shape[-1]).T, Q, F_rot)
    return K, F_rot
