"""What the Dirichlet and Roller parts hold at the P2 nodes of a tetrahedral mesh
(docs/method.md, *Three dimensions: rollers, force control, regions*).

A Dirichlet part and a roller on a plane normal to an axis hold Cartesian components (as in
2D). A roller on an oblique plane or on a curved part (the sphere of ``eighth_ball``, the
cylinder of ``quarter_cylinder``) holds ``u(z)·n_z = value`` at every P2 node z of its faces,
``n_z`` the body's outward unit normal there (:func:`~.normals.face_node_normals`: the
surface's exact normal on a part carrying one, else the mean of the faces' normals). Per node
the held directions combine, in the order Cartesian components first, then the rollers in the
problem's order:

- a roller direction in the span of the directions held already at the node (within
  :data:`~.rollers.PARALLEL`) adds nothing: the node already holds it (a symmetry plane's
  roller beside a clamped part);
- three independent directions hold the node in every component, at ``u = A⁻¹ b`` (rows of
  ``A`` the directions, ``b`` their values): a Dirichlet node;
- otherwise the node keeps its Cartesian components and gets one *roller row* per oblique
  direction (:attr:`~.rollers.HeldNodes.roller_nodes` lists a node once per row); the
  assembly gives it the frame of its rows (:func:`~signorini.contact.node_frames3d.
  held_frames`) and holds their DOFs.
"""

from __future__ import annotations

import numpy as np

from ..mesh.geometry import facet_normals
from .fields import ProblemError
from .normals import face_node_normals
from .rollers import MAX_ROLLER_TURN, PARALLEL, HeldNodes

__all__ = [
    "check_roller_part_3d",
    "held_basis",
    "held_rows_3d",
    "roller_rows_3d",
    "span_residual",
]


def span_residual(basis: np.ndarray, count: np.ndarray, n: np.ndarray) -> np.ndarray:
    """``(j, 3)`` the part of the unit vectors ``n (j, 3)`` orthogonal to the first
    ``count (j,)`` rows of the orthonormal ``basis (j, 3, 3)``."""
    live = np.arange(3)[None, :] < count[:, None]  # (j, 3)
    coefficients = np.einsum("jrc,jc->jr", basis, n) * live
    return n - np.einsum("jr,jrc->jc", coefficients, basis)


def _axes(held: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The held Cartesian axes ``held (j, 3)`` as orthonormal rows ``(j, 3, 3)`` (the first
    ``count (j,)`` of each) and their count."""
    basis = np.zeros(held.shape + (3,))
    r, c = np.nonzero(held)
    basis[r, np.cumsum(held, axis=1)[r, c] - 1, c] = 1.0
    return basis, held.sum(axis=1)


def check_roller_part_3d(space, name: str) -> None:
    """Refuse a roller part of a tetrahedral mesh whose normal is not defined at a node: a
    crease (a face of the part more than :data:`~.rollers.MAX_ROLLER_TURN` away from the mean
    normal at one of its nodes) where no surface gives the normal.

    Raises
    ------
    ProblemError
        Naming the part, the node and the angle.
    """
    mesh = space.mesh
    surface = mesh.curves[mesh.part_index(name)]
    if surface is not None and getattr(surface, "has_normal", False):
        return
    nodes = space.facet_nodes(mesh.part_facets(name))
    _, normal = facet_normals(mesh.points[nodes[:, :3]])
    z = np.unique(nodes)
    mean = face_node_normals(space, name, z)
    at = mean[np.searchsorted(z, nodes)]  # (f, 6, 3)
    cos = np.clip(np.einsum("fjc,fc->fj", at, normal), -1.0, 1.0)
    turn = np.arccos(cos)
    if turn.max(initial=0.0) > MAX_ROLLER_TURN:
        f, j = np.unravel_index(np.argmax(turn), turn.shape)
        x = space.node_points[nodes[f, j]]
        raise ProblemError(
            f"Roller on part {name!r}: at the node {tuple(np.round(x, 12).tolist())} a face of "
            f"the part turns by {np.degrees(turn[f, j]):.3g}° from the mean normal (more than "
            f"{np.degrees(MAX_ROLLER_TURN):.0f}°), where the part's normal is not defined. "
            "Split the part at the crease into parts, each with its roller, or give it a "
            "surface (Mesh.with_curve)"
        )


def roller_rows_3d(problem, space) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One row per (P2 node, oblique or curved roller part): node, outward unit normal
    ``(j, 3)`` and the held ``u·n``, sorted by node (then by the parts' order)."""
    nodes, normals, values = [np.zeros(0, np.int64)], [np.zeros((0, 3))], [np.zeros(0)]
    for name, cond in problem.rollers.items():  # a loop over parts
        z = np.unique(space.facet_nodes(space.mesh.part_facets(name)))
        nodes.append(z)
        normals.append(face_node_normals(space, name, z))
        values.append(np.full(z.size, float(cond.value)))
    node = np.concatenate(nodes)
    order = np.argsort(node, kind="stable")
    return node[order], np.concatenate(normals)[order], np.concatenate(values)[order]


def held_rows_3d(problem, space, comp: np.ndarray, val: np.ndarray | None) -> HeldNodes:
    """Combine the Cartesian components ``comp (n_nodes, 3)`` (values ``val``) held by the
    Dirichlet parts and axis rollers with the oblique and curved rollers of ``problem`` (a
    :class:`~.problem.ContactProblem` on a tetrahedral mesh) at the nodes of ``space``
    (module docstring).

    Raises
    ------
    ProblemError
        If a roller part has a crease (:func:`check_roller_part_3d`).
    """
    for name in problem.rollers:  # a loop over parts
        check_roller_part_3d(space, name)
    node, normal, value = roller_rows_3d(problem, space)
    if node.size == 0:
        return HeldNodes(comp, val, node, normal, value)
    basis, count = _axes(comp[node])  # the held directions so far at each row's node
    start = np.searchsorted(node, node)  # the first row of each row's node
    rank = np.arange(node.size) - start
    keep = np.zeros(node.size, dtype=bool)
    for j in range(int(rank.max()) + 1):  # a loop over the roller parts meeting at a node
        rows = np.flatnonzero(rank == j)
        first = start[rows]
        residual = span_residual(basis[first], count[first], normal[rows])
        size = np.linalg.norm(residual, axis=1)
        new = size > PARALLEL
        keep[rows[new]] = True
        f = first[new]
        basis[f, np.minimum(count[f], 2)] = residual[new] / size[new, None]
        count[f] += 1
    full_node = np.unique(node[keep & (count[start] >= 3)])
    if full_node.size:
        _hold_fully(full_node, node[keep], normal[keep], value[keep], comp, val)
    alone = keep & ~np.isin(node, full_node)
    return HeldNodes(comp, val, node[alone], normal[alone], value[alone])


def _hold_fully(full, node, normal, value, comp, val) -> None:
    """Hold the nodes ``full`` in every component (in place): ``u = A⁻¹ b`` from their held
    axes and roller rows (``node, normal, value``, three independent directions a node)."""
    A = np.zeros((full.size, 3, 3))
    b = np.zeros((full.size, 3))
    held = comp[full]
    f, c = np.nonzero(held)
    slot = np.cumsum(held, axis=1) - 1
    A[f, slot[f, c], c] = 1.0
    if val is not None:
        b[f, slot[f, c]] = val[full[f], c]
    on = np.isin(node, full)
    i = np.searchsorted(full, node[on])
    position = held.sum(axis=1)[i] + (np.arange(on.sum()) - np.searchsorted(node[on], node[on]))
    A[i, position] = normal[on]
    b[i, position] = value[on]
    comp[full] = True
    if val is not None:
        val[full] = np.linalg.solve(A, b[..., None])[..., 0]


def held_basis(comp: np.ndarray, node: np.ndarray, normal: np.ndarray) -> tuple[np.ndarray, ...]:
    """An orthonormal basis of the directions held at the nodes of the roller rows ``node
    (j,)`` (sorted), ``normal (j, 3)`` (independent, as :func:`held_rows_3d` keeps them)
    beside the Cartesian axes ``comp (n_nodes, 3)``: the distinct nodes ``(u,)``, their bases
    ``(u, 3, 3)`` (rows) and the number of rows ``(u,)``."""
    nodes, first = np.unique(node, return_index=True)
    basis, count = _axes(comp[nodes])
    rank = np.arange(node.size) - first[np.searchsorted(nodes, node)]
    for j in range(int(rank.max(initial=-1)) + 1):  # a loop over the roller rows of a node
        rows = np.flatnonzero(rank == j)
        i = np.searchsorted(nodes, node[rows])
        residual = span_residual(basis[i], count[i], normal[rows])
        basis[i, np.minimum(count[i], 2)] = residual / np.linalg.norm(residual, axis=1)[:, None]
        count[i] += 1
    return nodes, basis, count
