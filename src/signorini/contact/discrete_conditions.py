"""The conditions of a :class:`~signorini.problem.problem.ContactProblem` resolved once on the
nodes of one space: what the Dirichlet and Roller parts hold, the gaps ψ and obstacle
directions of the contact parts, the contact pairs and the free rigid motions, as plain
arrays (docs/method.md, *Rollers and components*, *Contact directions*, *Two bodies*,
*Force control*).

:func:`~.system.assemble` calls :func:`discrete_conditions` once; every helper below it
(the contact set, its refusals, the held DOFs, the rollers' DOFs, force control) reads the
record instead of the problem. Every user function of the boundary conditions (Dirichlet
values, gap functions, obstacle shapes) is evaluated here, at the nodes where the discrete
problem needs it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..algebra.friction.laws import FrictionLaw
from ..fem.space import LagrangeSpace
from ..mesh.bodies import body_of_cells
from ..problem.conditions import Contact, Roller
from ..problem.fields import ProblemError, evaluate_field
from ..problem.normals import straight_normal
from ..problem.obstacle_base import Obstacle
from ..problem.problem import ContactProblem
from ..problem.rigid import motion_field
from ..problem.rollers import HeldNodes, held_nodes

__all__ = ["DiscreteConditions", "discrete_conditions"]


@dataclass(frozen=True)
class DiscreteConditions:
    """The boundary conditions and free rigid motions of a problem at the nodes of a space.

    Per node of the space (``n_nodes``), per contact part (``n_c``, in the problem's order)
    and per node of a contact part (``g``: the nodes of each part's facets, part after
    part, sorted within a part).

    Attributes
    ----------
    held : HeldNodes
        What the Dirichlet and Roller parts hold at each node
        (:func:`~signorini.problem.rollers.held_nodes`): the held Cartesian components
        ``(n_nodes, 2)`` and their values u_D ``(n_nodes, 2)``, the roller nodes held along
        one oblique direction, that direction and the held ``u·n``.
    held_parts : tuple of str
        The Dirichlet and Roller parts, in the problem's order.
    held_part : (n_nodes,) int array
        Index into ``held_parts`` of the later such part through each node, ``-1`` off
        them (the part a message names).
    axis_normal : (n_nodes, 2) float array
        At the nodes of a roller along an axis, its outward unit normal ``± e_c`` (the
        first such roller through the node), 0 elsewhere: the roller holds ``u_c``.
    contact_parts : tuple of str
        The contact parts Γ_C, in the problem's order.
    straight_normal : (n_c, 2) float array
        The outward unit normal of each straight contact part with a gap function, its
        directions' one value; NaN for the others (their directions are per node).
    obstacles : tuple of Obstacle or None
        Each part's obstacle shape (``Contact(obstacle=...)``), None for a gap function;
        named in messages (its values at the nodes are ``gap`` and ``obstacle_direction``).
    obstacle_motion : (n_c, 2) float array
        The prescribed rigid displacement of each part's obstacle
        (:meth:`~signorini.problem.obstacle_base.Obstacle.moved`; 0 for a gap function).
    gap_nodes : (g,) int array
        The nodes of each contact part's facets.
    gap_part : (g,) int array
        Index into ``contact_parts`` of each.
    gap : (g,) float array
        ψ(z) there, the gap function's value or the shape's signed distance along its
        direction; NaN on the slave of a contact pair (its mortar gap is the coupling's).
    obstacle_direction : (g, 2) float array
        A shape's unit normal pointing into it at its surface point closest to the node;
        NaN on the other parts (their direction is the body's normal, or the pair's).
    friction : tuple of FrictionLaw or None
        The friction law of each contact part (``None``: frictionless).
    pairs : mapping slave part -> master part
        The contact pairs between bodies (docs/method.md, *Two bodies*).
    rigid_motions : (k, 3) float array
        The free rigid motions (:attr:`~signorini.problem.problem.ContactProblem.rigid_motions`).
    rigid_field : (k, n_nodes, 2) float array
        Each free rigid motion at the nodes, zero off its own body where the problem has
        contact pairs (docs/method.md, *Force control*).
    """

    held: HeldNodes
    held_parts: tuple[str, ...]
    held_part: np.ndarray
    axis_normal: np.ndarray
    contact_parts: tuple[str, ...]
    straight_normal: np.ndarray
    obstacles: tuple[Obstacle | None, ...]
    obstacle_motion: np.ndarray
    gap_nodes: np.ndarray
    gap_part: np.ndarray
    gap: np.ndarray
    obstacle_direction: np.ndarray
    friction: tuple[FrictionLaw | None, ...]
    pairs: Mapping[str, str]
    rigid_motions: np.ndarray
    rigid_field: np.ndarray

    @property
    def is_shape(self) -> np.ndarray:
        """``(n_c,)`` bool: whether each contact part's obstacle is a shape."""
        return np.array([o is not None for o in self.obstacles], dtype=bool)

    @property
    def dirichlet_nodes(self) -> np.ndarray:
        """``(n_D,)`` the nodes whose both components are held (sorted)."""
        return np.flatnonzero(self.held.components.all(axis=1))

    def straight(self, i: int) -> np.ndarray | None:
        """``(2,)`` the straight normal of contact part ``i``, or None."""
        n = self.straight_normal[i]
        return None if np.isnan(n).any() else n


def discrete_conditions(problem: ContactProblem, space: LagrangeSpace) -> DiscreteConditions:
    """Resolve the conditions of ``problem`` on the nodes of ``space`` (see
    :class:`DiscreteConditions`).

    Raises
    ------
    ProblemError
        If a node is held by rollers along more than two directions, or a Dirichlet value,
        a gap function or an obstacle shape does not give finite numbers (naming the part).
    """
    held = held_nodes(problem, space)
    held_parts = tuple(problem.dirichlet_parts)
    held_part = np.full(space.n_nodes, -1, dtype=np.int64)
    for i, name in enumerate(held_parts):  # a loop over parts: the later one wins
        held_part[space.part_nodes([name])] = i
    axis_normal = np.zeros((space.n_nodes, 2))
    for name in reversed(problem.held):  # a loop over parts: the first one wins
        if isinstance(problem.conditions[name], Roller):
            n = straight_normal(space.mesh, name)
            c = int(np.argmax(np.abs(n)))
            axis_normal[space.part_nodes([name])] = np.eye(2)[c] * np.sign(n[c])
    parts = tuple(problem.contact_parts)
    conditions: list[Contact] = [problem.conditions[p] for p in parts]
    straight = np.full((len(parts), 2), np.nan)
    for i, name in enumerate(parts):  # a loop over parts
        if name in problem.contact_normals:
            straight[i] = problem.contact_normals[name]
    motion = np.zeros((len(parts), 2))
    for i, cond in enumerate(conditions):  # a loop over parts
        if cond.obstacle is not None:
            motion[i] = cond.obstacle.displacement
    gap_nodes, gap, direction = _gaps(space, parts, conditions, problem.pairs)
    return DiscreteConditions(
        held=held,
        held_parts=held_parts,
        held_part=held_part,
        axis_normal=axis_normal,
        contact_parts=parts,
        straight_normal=straight,
        obstacles=tuple(c.obstacle for c in conditions),
        obstacle_motion=motion,
        gap_nodes=np.concatenate(gap_nodes or [np.zeros(0, np.int64)]),
        gap_part=np.repeat(np.arange(len(parts)), [z.size for z in gap_nodes]).astype(np.int64),
        gap=np.concatenate(gap or [np.zeros(0)]),
        obstacle_direction=np.concatenate(direction or [np.zeros((0, 2))]),
        friction=tuple(c.friction for c in conditions),
        pairs=dict(problem.pairs),
        rigid_motions=problem.rigid_motions,
        rigid_field=_rigid_field(problem.rigid_motions, problem.rigid_parts, space),
    )


def _gaps(space: LagrangeSpace, parts: tuple, conditions: list, pairs: Mapping) -> tuple:
    """Per contact part: the nodes of its facets (sorted), ψ and a shape's direction there
    (NaN where the part has none: a gap function's direction, a slave's mortar data)."""
    nodes, gaps, directions = [], [], []
    for name, cond in zip(parts, conditions, strict=True):  # a loop over parts
        z = np.unique(space.facet_nodes(space.mesh.part_facets(name)))
        x = space.node_points[z]
        psi, n = np.full(z.size, np.nan), np.full((z.size, 2), np.nan)
        if name in pairs:
            pass
        elif cond.obstacle is not None:
            try:
                psi, n = cond.obstacle.gap_and_direction(x)
            except ValueError as err:
                raise ProblemError(f"the obstacle of contact part {name!r}: {err}") from err
            except Exception as err:  # a shape of one's own that raises
                raise ProblemError(
                    f"the obstacle {cond.obstacle!r} of contact part {name!r} raised "
                    f"{type(err).__name__} in gap_and_direction: {err}"
                ) from err
        else:
            what = f"the gap function of contact part {name!r}"
            psi = evaluate_field(cond.gap_field(), x, what, shape=(), bounded=True)
        nodes.append(z)
        gaps.append(psi)
        directions.append(n)
    return nodes, gaps, directions


def _rigid_field(motions: np.ndarray, parts: tuple, space: LagrangeSpace) -> np.ndarray:
    """``(k, n_nodes, 2)`` the free rigid motions ``motions (k, 3)`` at the nodes of
    ``space``, each zero off its body where ``parts`` names a part of it (with contact pairs:
    :attr:`~signorini.problem.problem.ContactProblem.rigid_parts`)."""
    if not motions.size:
        return np.zeros((0, space.n_nodes, 2))
    mesh = space.mesh
    r = motion_field(mesh, motions, space.node_points)
    if not parts:
        return r
    cell_body = body_of_cells(mesh)
    node_body = np.zeros(space.n_nodes, dtype=np.int64)
    node_body[space.cell_nodes.ravel()] = np.repeat(cell_body, space.cell_nodes.shape[1])
    first_cell = [mesh.facet2cell[mesh.part_facets(p)[0], 0] for p in parts]
    return r * (node_body[None, :] == cell_body[first_cell][:, None])[..., None]
