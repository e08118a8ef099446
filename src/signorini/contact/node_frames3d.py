"""Node frames in three dimensions: the DOFs of a contact node in its frame ``[n t_1 t_2]``
(docs/method.md, *Three dimensions: contact on faces*, "The frames").

With interleaved DOFs (``3 node + component``) the Cartesian values ``u(z)`` and the frame
values ``y_z`` of a node are related by a 3 × 3 block ``Q_z``: ``u(z) = Q_z y_z``; ``Q`` is
block diagonal with ``Q_z`` at the listed nodes and the identity elsewhere, and the system
``K u = F`` becomes ``Qᵀ K Q y = Qᵀ F``, where each constraint bounds one DOF.

- A node with one constraint direction ``n`` takes the rotation ``Q_z = [n t_1 t_2]``, the
  orthonormal completion of :func:`tangent_completion` (right-handed, ``y = (u·n, u·t_1,
  u·t_2)``).
- A node with two or three rows (contact directions of several parts, held Cartesian
  directions) takes ``Q_z = A_z^{-1}``, ``A_z`` the matrix of those rows, completed by the unit
  ``n × m`` when there are two: ``y = A_z u``, each row bounds or holds one DOF, and the
  multipliers ``Qᵀ (F − K u)`` are the rows' nodal forces (the 2D corners' frame).

The completion is the branch-free construction of Duff et al. (J. Computer Graphics
Techniques 6(1), 2017) about a *pole* axis ``e_k``: continuous in ``n`` except on the great
circle ``n_k = 0``, where the sign of ``n_k`` switches branch (``n_k = 0`` counts as positive:
deterministic). A contact part takes the pole of its mean normal's largest component, so its
frames are continuous unless its normals turn by more than about 90°; on a flat part normal to
``± e_k`` the tangents are ``± e_{k+1}``, ``± e_{k+2}``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..fem.dofs import node_dofs
from ..problem.fields import ProblemError
from ..problem.rollers import HeldNodes

__all__ = [
    "HeldFrames",
    "frame_operator",
    "held_frames",
    "row_frames",
    "rotate_frames_3d",
    "tangent_completion",
    "to_cartesian_3d",
    "to_frames_3d",
]


def tangent_completion(normals: np.ndarray, pole: np.ndarray | int = 2) -> np.ndarray:
    """The rotations ``Q_z = [n t_1 t_2] (m, 3, 3)`` (columns) of unit normals ``(m, 3)``.

    About the pole ``e_k`` (``k`` per node or one for all), in the coordinates cyclically
    shifted so that ``k`` comes last, ``(a, b, c)``: ``s = sign(c)`` (``+1`` at ``c = 0``),
    ``h = −1/(s + c)``, ``g = a b h``; ``t_1 = (1 + s a² h, s g, −s a)``,
    ``t_2 = (g, s + b² h, −b)``; then shifted back. ``n · (t_1 × t_2) = 1``.

    Parameters
    ----------
    normals : (m, 3) float array
        Unit vectors.
    pole : int or (m,) int array
        The pole axis of each node, in {0, 1, 2}.

    Returns
    -------
    (m, 3, 3) float array
    """
    n = np.asarray(normals, dtype=np.float64)
    k = np.broadcast_to(np.asarray(pole, dtype=np.int64), n.shape[:1])
    order = (k[:, None] + np.array([1, 2, 3])) % 3  # (m, 3): the coordinates (a, b, c)
    a, b, c = np.take_along_axis(n, order, axis=1).T
    s = np.where(c >= 0, 1.0, -1.0)
    h = -1.0 / (s + c)
    g = a * b * h
    t1 = np.stack([1 + s * a * a * h, s * g, -s * a], axis=1)
    t2 = np.stack([g, s + b * b * h, -b], axis=1)
    Q = np.empty(n.shape + (3,))
    Q[:, :, 0] = n
    rows = np.arange(n.shape[0])[:, None]
    Q[rows, order, 1] = t1
    Q[rows, order, 2] = t2
    return Q


def row_frames(rows: np.ndarray, count: np.ndarray, pole: np.ndarray) -> np.ndarray:
    """The frames ``Q_z (m, 3, 3)`` of nodes with ``count (m,)`` rows ``rows (m, 3, 3)``
    (row ``j < count`` used): the rotation of :func:`tangent_completion` for one row (a unit
    direction), ``A_z^{-1}`` otherwise (two rows completed by their unit cross product).

    Parameters
    ----------
    rows : (m, 3, 3) float array
        Each node's unit rows (directions), the first ``count`` meaningful.
    count : (m,) int array
        1, 2 or 3.
    pole : (m,) int array
        The completion's pole per node (:func:`tangent_completion`).

    Returns
    -------
    (m, 3, 3) float array
    """
    rows = np.array(rows, dtype=np.float64)
    Q = np.empty_like(rows)
    one = count == 1
    Q[one] = tangent_completion(rows[one, 0], pole[one])
    two = count == 2
    third = np.cross(rows[two, 0], rows[two, 1])
    rows[two, 2] = third / np.linalg.norm(third, axis=1)[:, None]
    many = ~one
    Q[many] = np.linalg.inv(rows[many])
    return Q


def frame_operator(n_dofs: int, nodes: np.ndarray, frames: np.ndarray) -> sp.csr_matrix:
    """``Q (n_dofs, n_dofs)``: the blocks ``frames (m, 3, 3)`` at the DOFs of ``nodes (m,)``
    (distinct), the identity elsewhere."""
    nodes = np.asarray(nodes, dtype=np.int64)
    dofs = node_dofs(nodes, 3)  # (m, 3)
    other = np.setdiff1d(np.arange(n_dofs), dofs.ravel())
    rows = np.concatenate([np.repeat(dofs, 3, axis=1).ravel(), other])
    cols = np.concatenate([np.tile(dofs, (1, 3)).ravel(), other])
    values = np.concatenate([np.asarray(frames, dtype=np.float64).ravel(), np.ones(other.size)])
    return sp.csr_matrix((values, (rows, cols)), shape=(n_dofs, n_dofs))


def rotate_frames_3d(
    K: sp.spmatrix, F: np.ndarray, nodes: np.ndarray, frames: np.ndarray
) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(Qᵀ K Q, Qᵀ F)`` for the frames ``(m, 3, 3)`` at ``nodes (m,)``
    (:func:`frame_operator`).

    Parameters
    ----------
    K : sparse matrix, shape (n_dofs, n_dofs)
    F : (n_dofs,) float array
    nodes : (m,) int array
    frames : (m, 3, 3) float array

    Returns
    -------
    K_rot : csr_matrix, shape (n_dofs, n_dofs)
    F_rot : (n_dofs,) float array
    """
    Q = frame_operator(K.shape[0], nodes, frames)
    return (Q.T @ K @ Q).tocsr(), Q.T @ np.asarray(F, dtype=np.float64)


def to_frames_3d(x: np.ndarray, nodes: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """Cartesian values ``x (n_dofs,)`` to frame values ``Q^{-1} x`` at ``nodes``."""
    y = np.array(x, dtype=np.float64)
    dofs = node_dofs(np.asarray(nodes, dtype=np.int64), 3)
    y[dofs] = np.linalg.solve(frames, y[dofs][..., None])[..., 0]
    return y


def to_cartesian_3d(y: np.ndarray, nodes: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """Frame values ``y (n_dofs,)`` to Cartesian values ``Q y`` at ``nodes``."""
    x = np.array(y, dtype=np.float64)
    dofs = node_dofs(np.asarray(nodes, dtype=np.int64), 3)
    x[dofs] = np.einsum("mij,mj->mi", frames, x[dofs])
    return x


@dataclass(frozen=True)
class HeldFrames:
    """The frames of the nodes with constraint rows or roller rows, and the held DOFs.

    Attributes
    ----------
    frame_nodes : (m,) int array
        The nodes in a frame (sorted); ``frames (m, 3, 3)`` their ``Q_z``.
    frames : (m, 3, 3) float array
    row_dof : (k,) int array
        The frame DOF ``3 z + j`` each constraint row bounds.
    held_dofs : (n_h,) int array
        The held DOFs: frame DOFs of held axes and roller rows at the frame nodes, Cartesian
        DOFs elsewhere; ``held_values (n_h,)`` their values.
    held_values : (n_h,) float array
    roller_dof : (r,) int array
        The frame DOF each roller row holds (``held.roller_nodes`` order).
    """

    frame_nodes: np.ndarray
    frames: np.ndarray
    row_dof: np.ndarray
    held_dofs: np.ndarray
    held_values: np.ndarray
    roller_dof: np.ndarray


def held_frames(
    points: np.ndarray,
    row_node: np.ndarray,
    row_direction: np.ndarray,
    row_pole: np.ndarray,
    held: HeldNodes,
) -> HeldFrames:
    """The frames ``Q_z = A_z^{-1}`` (one row: the rotation of :func:`tangent_completion`)
    of the nodes with constraint rows or roller rows, the rows of ``A_z`` in the order
    constraint rows, held Cartesian axes ``e_c``, roller normals (docs/method.md, *Three
    dimensions: contact on faces*, "The frames"; *Three dimensions: rollers, force
    control, regions*).

    Parameters
    ----------
    points : (n_nodes, 3) float array
        The nodes' coordinates (for messages).
    row_node : (k,) int array
        The constraint rows' nodes, sorted.
    row_direction : (k, 3) float array
        Their unit directions.
    row_pole : (k,) int array
        The completion's pole of each row's node (its part's).
    held : HeldNodes
        The held Cartesian components and values ``(n_nodes, 3)`` and the roller rows
        (:func:`~signorini.problem.rollers3d.held_rows_3d`).

    Raises
    ------
    ProblemError
        For a node with more than three rows and held directions, or dependent ones.
    """
    comp, values = held.components, held.values
    rn = held.roller_nodes
    frame_nodes = np.union1d(row_node, rn).astype(np.int64)
    m, k = frame_nodes.size, row_node.size
    at_row = np.searchsorted(frame_nodes, row_node)
    at_roller = np.searchsorted(frame_nodes, rn)
    n_rows = np.bincount(at_row, minlength=m)
    n_held = comp[frame_nodes].sum(axis=1)
    total = n_rows + n_held + np.bincount(at_roller, minlength=m)
    if (total > 3).any():
        z = int(frame_nodes[np.argmax(total)])
        raise ProblemError(
            f"node {z} at {points[z].tolist()} has {int(total.max())} constraint "
            "and held directions (at most 3): contact parts and held components meet there"
        )
    rows = np.zeros((m, 3, 3))
    j = np.arange(k) - np.searchsorted(row_node, row_node)  # each row's index at its node
    rows[at_row, j] = row_direction
    position = np.cumsum(comp[frame_nodes], axis=1) - 1 + n_rows[:, None]  # held axes' slots
    f, c = np.nonzero(comp[frame_nodes])
    rows[f, position[f, c], c] = 1.0
    slot = n_rows[at_roller] + n_held[at_roller] + np.arange(rn.size) - np.searchsorted(rn, rn)
    rows[at_roller, slot] = held.roller_normal
    pole = np.argmax(np.abs(rows[:, 0]), axis=1)
    pole[at_row] = row_pole
    try:
        Q = row_frames(rows, total, pole)
    except np.linalg.LinAlgError:
        Q = np.full(rows.shape, np.nan)
    if not np.isfinite(Q).all():
        raise ProblemError(
            "the constraint and held directions at a contact or roller node are dependent (a "
            "contact direction along a held axis beside another part's)"
        )
    rotated = np.zeros(comp.shape[0], dtype=bool)
    rotated[frame_nodes] = True
    cartesian = np.flatnonzero((comp & ~rotated[:, None]).ravel())
    held_dofs = np.concatenate([3 * frame_nodes[f] + position[f, c], 3 * rn + slot, cartesian])
    held_values = np.concatenate(
        [values[frame_nodes[f], c], held.roller_value, values.reshape(-1)[cartesian]]
    )
    return HeldFrames(frame_nodes, Q, 3 * row_node + j, held_dofs, held_values, 3 * rn + slot)
