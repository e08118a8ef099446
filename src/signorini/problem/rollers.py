"""What the Dirichlet and Roller parts hold at each P2 node (docs/method.md, *Rollers and
components*).

A Dirichlet part, or a roller on a part along x or y, holds Cartesian components of ``u``.
A roller on an oblique straight part or on a curved part holds ``u(z)·n_z = value`` at each
node ``z`` of the part, ``n_z`` the outward unit normal there
(:func:`~signorini.problem.normals.node_normals`: the part's normal on a straight part, the
curve's exact normal where the mesh carries one, else the normalised mean of the facets'
normals at a vertex). Per node the held directions combine:

- one roller direction alone: the node is a *roller node*; the assembly gives it the frame
  ``u = Q y``, ``Q = [n t]``, and holds the DOF ``y_0 = u·n``;
- a roller direction and another independent one (a second roller part's normal, or a
  Cartesian component held by a Dirichlet part or an axis roller): both components are
  held, at ``u = A⁻¹ b`` (rows of ``A`` the two directions, ``b`` their values), and the node
  is a Dirichlet node;
- a roller direction parallel to another held one is the same condition; where conditions
  overlap the later part wins along the direction it holds (:func:`held_nodes`), the rule
  of two Dirichlet parts at a node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fem.space import P2Space
from ..mesh.geometry import facet_normals
from ..mesh.mesh import Mesh
from .fields import ProblemError, evaluate_field
from .normals import node_normals, straight_normal

__all__ = ["MAX_ROLLER_TURN", "HeldNodes", "check_roller_part", "held_nodes", "roller_normals"]

#: a roller part without a curve normal may turn by at most this angle (radians, 30°) at a
#: vertex between two of its edges: beyond it the mean of the two edges' normals is no
#: normal of the body (at a corner the two sides' conditions hold both components)
MAX_ROLLER_TURN = np.pi / 6
#: two held directions at a node with ``|n × m|`` below this are one direction
PARALLEL = 1e-8


def roller_normals(mesh: Mesh, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The P2 nodes ``[start, end, midpoint]`` of roller part ``name``'s facets (edges in
    2D) ``(e, 3)`` and the outward unit normal at each ``(e, 3, 2)``
    (:func:`~.normals.node_normals`)."""
    facets = mesh.part_facets(name)
    ab = mesh.oriented_boundary(facets)
    # 2D: a facet is an edge, its P2 node the edge's (n_points + edge index)
    nodes = np.column_stack([ab, mesh.n_points + facets])
    points = np.concatenate(
        [mesh.points[ab], mesh.curved_midpoints[facets][:, None, :]], axis=1
    )  # (e, 3, 2)
    _, chord = facet_normals(mesh.points[ab])
    normals = node_normals(
        mesh, name, nodes, points, chord, straight=straight_normal(mesh, name), what="roller part"
    )
    return nodes, normals


def check_roller_part(mesh: Mesh, name: str) -> None:
    """Refuse a roller part whose normal is not defined at a vertex: a corner of the part
    (two of its facets, edges in 2D, turning by more than :data:`MAX_ROLLER_TURN`) where no
    curve gives the normal.

    Raises
    ------
    ProblemError
        Naming the part, the vertex and the angle.
    """
    curve = mesh.curves[mesh.part_index(name)]
    if straight_normal(mesh, name) is not None or (curve is not None and curve.has_normal):
        return
    ab = mesh.oriented_boundary(mesh.part_facets(name))
    _, chord = facet_normals(mesh.points[ab])
    total = np.zeros((mesh.n_points, 2))
    count = np.zeros(mesh.n_points)
    np.add.at(total, ab.ravel(), np.repeat(chord, 2, axis=0))
    np.add.at(count, ab.ravel(), 1.0)
    inner = np.flatnonzero(count == 2)
    half = np.clip(np.hypot(*total[inner].T) / 2.0, -1.0, 1.0)
    turn = 2.0 * np.arccos(half)
    bad = np.flatnonzero(turn > MAX_ROLLER_TURN)
    if bad.size:
        i = bad[np.argmax(turn[bad])]
        x = mesh.points[inner[i]]
        raise ProblemError(
            f"Roller on part {name!r}: the part turns by {np.degrees(turn[i]):.3g}° at the "
            f"vertex ({x[0]:.12g}, {x[1]:.12g}) (more than {np.degrees(MAX_ROLLER_TURN):.0f}°; "
            f"{bad.size} such vertex(es)), where its normal is not defined. Split the part at "
            "the corner into two parts, each with its roller (the corner node then holds both "
            "normal components), or give the part a curve that has a normal (Mesh.with_curve)"
        )


@dataclass(frozen=True)
class HeldNodes:
    """What the Dirichlet and Roller parts hold at the P2 nodes of a space.

    Attributes
    ----------
    components : (n_nodes, 2) bool array
        The Cartesian components held: by Dirichlet parts and axis rollers, and both at a
        node held along two independent directions (a Dirichlet node).
    values : (n_nodes, 2) float array or None
        The held Cartesian values (0 where free); ``None`` when not asked for.
    roller_nodes : (m,) int array
        The nodes held along one oblique direction only (sorted).
    roller_normal : (m, 2) float array
        That direction, the roller part's outward unit normal at the node.
    roller_value : (m,) float array
        The held ``u·n``.
    """

    components: np.ndarray
    values: np.ndarray | None
    roller_nodes: np.ndarray
    roller_normal: np.ndarray
    roller_value: np.ndarray

    @property
    def n_held(self) -> int:
        """The number of held scalar DOFs (one per roller node)."""
        return int(self.components.sum()) + self.roller_nodes.size


def held_nodes(problem, space: P2Space, *, values: bool = True) -> HeldNodes:
    """The held components and roller directions of ``problem`` (a
    :class:`~signorini.problem.problem.ContactProblem`) at the nodes of ``space``.

    Where conditions overlap, the later part (in the order of ``problem.conditions``) wins
    along the direction it holds, as a node on two Dirichlet parts takes the later part's
    value in each component that part holds: a roller after a part holding both components
    moves the node to ``v n + (u_D·t) t``; of two parallel directions the later value
    stands. So a model rotated as a whole holds the rotated values. ``values=False`` skips
    evaluating the prescribed values.

    Raises
    ------
    ProblemError
        If a node is held by rollers along more than two directions.
    """
    d = space.mesh.dim
    comp = np.zeros((space.n_nodes, d), dtype=bool)
    order = np.full((space.n_nodes, d), -1)  # the last part holding each component
    val = np.zeros((space.n_nodes, d)) if values else None
    rank = {name: i for i, name in enumerate(problem.conditions)}
    for name, cond in problem.held.items():  # a loop over parts
        nodes = space.part_nodes([name])
        held = np.resize(np.asarray(cond.components), d)  # a function: all d components
        comp[nodes] |= held
        order[nodes[:, None], np.flatnonzero(held)[None, :]] = rank[name]
        if values:
            v = evaluate_field(
                cond.field(),
                space.node_points[nodes],
                f"the Dirichlet value of part {name!r}",
                shape=(d,),
                bounded=True,
            )
            val[nodes[:, None], np.flatnonzero(held)[None, :]] = v[:, held]
    if d == 3:  # the oblique and curved rollers of a tetrahedral mesh (docs/method.md)
        from .rollers3d import held_rows_3d

        return held_rows_3d(problem, space, comp, val)
    node, normal, value, part = _roller_rows(problem, space.mesh)
    if node.size == 0:
        return HeldNodes(comp, val, np.zeros(0, np.int64), np.zeros((0, d)), np.zeros(0))
    k = np.array([rank[name] for name in problem.rollers])[part]
    # a node's rows along one line are one condition: the later part's value
    same = node[1:] == node[:-1]
    cross = normal[1:, 0] * normal[:-1, 1] - normal[1:, 1] * normal[:-1, 0]
    drop = np.concatenate([same & (np.abs(cross) <= PARALLEL), [False]])  # the earlier row
    node, normal, value, k = (a[~drop] for a in (node, normal, value, k))
    count = np.bincount(node, minlength=space.n_nodes)[node]
    if (count > 2).any():
        z = node[np.argmax(count)]
        raise ProblemError(
            f"the node at {tuple(space.node_points[z].tolist())} is held by rollers along more "
            "than two directions"
        )
    pair = np.flatnonzero(np.concatenate([node[1:] == node[:-1], [False]]))  # first of two
    single = np.ones(node.size, dtype=bool)
    single[pair] = single[pair + 1] = False
    k_c = comp[node].sum(axis=1)
    later = k > order[node].max(axis=1)
    # beside both components held: a later roller moves the node along its normal
    both = np.flatnonzero(single & (k_c == 2) & later)
    if values and both.size:
        n, t = normal[both], normal[both] @ np.array([[0.0, 1.0], [-1.0, 0.0]])
        u_t = np.einsum("kc,kc->k", val[node[both]], t)
        val[node[both]] = value[both, None] * n + u_t[:, None] * t
    # beside one component held along the roller's normal: the later value stands
    one = np.flatnonzero(single & (k_c == 1))
    c = np.argmax(comp[node[one]], axis=1)
    along = np.abs(normal[one, 1 - c]) <= PARALLEL
    if values:
        i = one[along & later[one]]
        ci = c[along & later[one]]
        val[node[i], ci] = value[i] * np.sign(normal[i, ci])
    # two independent directions: the node is held in both components, u = A⁻¹ b
    mixed, cm = one[~along], c[~along]
    full = np.concatenate([node[pair], node[mixed]])
    comp[full] = True
    if values and full.size:
        A = np.stack(
            [
                np.concatenate([normal[pair], np.eye(2)[cm]]),
                np.concatenate([normal[pair + 1], normal[mixed]]),
            ],
            axis=1,
        )  # (f, 2, 2)
        b = np.stack(
            [
                np.concatenate([value[pair], val[node[mixed], cm]]),
                np.concatenate([value[pair + 1], value[mixed]]),
            ],
            axis=1,
        )
        val[full] = np.linalg.solve(A, b[..., None])[..., 0]
    alone = np.flatnonzero(single & (k_c == 0))
    return HeldNodes(comp, val, node[alone], normal[alone], value[alone])


def _roller_rows(problem, mesh: Mesh) -> tuple[np.ndarray, ...]:
    """One row per (P2 node, roller part): node, normal, value and the part's index in
    ``problem.rollers``, sorted by node (then by the parts' order)."""
    parts = list(problem.rollers)
    if not parts:
        return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64)
    nodes, normals, values, index = [], [], [], []
    for i, name in enumerate(parts):  # a loop over parts
        en, n = roller_normals(mesh, name)
        z, first = np.unique(en.ravel(), return_index=True)
        nodes.append(z)
        normals.append(n.reshape(-1, 2)[first])
        values.append(np.full(z.size, float(problem.rollers[name].value)))
        index.append(np.full(z.size, i))
    node = np.concatenate(nodes)
    order = np.argsort(node, kind="stable")
    return tuple(np.concatenate(a)[order] for a in (nodes, normals, values, index))
