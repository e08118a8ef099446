"""The checks of a :class:`~signorini.problem.problem.ContactProblem` on a tetrahedral mesh
(docs/method.md, *Three dimensions: solving elasticity*, *Three dimensions: rollers, force
control, regions*).

A 3D problem holds Dirichlet parts (all or some of ``(u_x, u_y, u_z)``), rollers (on planes
normal to an axis one Cartesian component held, on oblique planes and curved parts the normal
component in node frames), Neumann parts and contact parts against a gap
function or a shape of space, along given directions or the body's normal (docs/method.md,
*Three dimensions: contact on faces*); a body may be held along some rigid motions by its
contact parts alone (force control). Contact pairs between bodies (docs/method.md, *Two
bodies in three dimensions*) stand alone (no obstacle parts beside them), with every body
held by its own parts. Friction, on obstacle parts and in pairs, is the disc law
(docs/method.md, *Friction in three dimensions*; *Two bodies in three dimensions:
friction*); plane shapes are refused here, before any work, and so are a 2D mesh's data
on a 3D mesh and the reverse.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..fem.space import space_of
from ..mesh.bodies import body_of_cells
from ..mesh.mesh import Mesh
from .conditions import Condition, Contact, Dirichlet, Neumann
from .fields import ProblemError
from .rigid3d import free_rigid_motions_3d
from .rollers3d import check_roller_part_3d

__all__ = ["check_dimension", "check_mesh_dimension", "check_problem_3d"]


def check_dimension(mesh: Mesh, conditions: Mapping[str, Condition]) -> None:
    """Refuse on a tetrahedral ``mesh`` what 3D contact does not build (pairs beside
    obstacles, plane shapes), and constant data with another number of components
    than the mesh has dimensions.

    Raises
    ------
    ProblemError
        Naming the contact part and what it asks for, or the part whose data have the wrong
        number of components.
    """
    if mesh.dim == 3:
        _check_contact_3d(conditions)
    for name, cond in conditions.items():  # a loop over parts
        if not isinstance(cond, Contact) or cond.normal is None:
            continue
        size = None if callable(cond.normal) else np.size(cond.normal)
        if mesh.dim == 2 and size != 2:
            raise ProblemError(
                f"contact part {name!r} gives normal={cond.normal!r} on a 2D mesh: give two "
                "numbers (n_x, n_y) (a direction field n(x) and three numbers are for 3D "
                "meshes)"
            )
        if mesh.dim == 3 and size == 2:
            raise ProblemError(
                f"contact part {name!r} gives normal={cond.normal!r} (2 numbers) on a 3D "
                "mesh: give three numbers or a function n(x) of points (n, 3) returning unit "
                "vectors (n, 3)"
            )
    alpha = [
        n for n, c in conditions.items() if isinstance(c, Contact) and c.face_alpha is not None
    ]
    if mesh.dim == 2 and alpha:
        raise ProblemError(
            f"contact part(s) {alpha} give face_alpha on a 2D mesh: the transformed face basis "
            "is the 3D contact condition on P2 faces"
        )
    for name, cond in conditions.items():  # a loop over parts
        if not isinstance(cond, Dirichlet | Neumann):
            continue
        value = cond.value if isinstance(cond, Dirichlet) else cond.traction
        if not callable(value) and np.size(value) != mesh.dim:
            raise ProblemError(
                f"the condition of part {name!r} gives {np.size(value)} components "
                f"{value!r} on a {mesh.dim}D mesh: give {mesh.dim}, "
                f"{('(x, y)', '(x, y, z)')[mesh.dim - 2]} (None for a free Dirichlet component)"
            )


def _check_contact_3d(conditions: Mapping[str, Condition]) -> None:
    """Refuse what 3D contact on faces does not build yet: a plane shape (dim 2) as the
    obstacle, pairs beside obstacle parts, a pair with condition (a) or an obstacle;
    and contact parts with different ``face_alpha``."""
    for name, cond in conditions.items():  # a loop over parts
        if not isinstance(cond, Contact):
            continue
        what = None
        if cond.master is not None and cond.face_alpha == 0:
            what = (
                "face_alpha=0 in a contact pair: the dual mortar basis on P2 faces needs the "
                "transformed basis (0 < face_alpha < 1/2; None for 1/5)"
            )
        elif cond.master is not None and (cond.obstacle is not None or cond.normal is not None):
            what = "a contact pair takes no obstacle and no normal (the bodies give them)"
        elif cond.obstacle is not None and cond.obstacle.dim != 3:
            what = (
                f"the obstacle {cond.obstacle!r} is a plane shape: use a shape of space "
                "(signorini.problem.obstacles3d: HalfSpace, Ball, Cylinder, SignedDistance3D)"
            )
        if what is not None:
            raise ProblemError(f"contact part {name!r} on a 3D (tetrahedral) mesh: {what}")
    kinds = {c.master is not None for c in conditions.values() if isinstance(c, Contact)}
    if len(kinds) > 1:
        raise ProblemError(
            "a 3D problem with contact pairs between bodies takes no contact parts against "
            "obstacles yet: state the pairs alone"
        )
    alphas = {c.face_alpha for c in conditions.values() if isinstance(c, Contact)}
    if len(alphas) > 1:
        raise ProblemError(
            f"the contact parts give different face_alpha {sorted(alphas, key=str)}: one "
            "discrete contact condition on all of Γ_C"
        )


def check_mesh_dimension(name: str, stated: Mesh, mesh: Mesh) -> None:
    """Refuse a ``mesh`` of another dimension than the mesh the problem ``name`` is
    ``stated`` on (a 2D problem handed a tetrahedral mesh, or the reverse).

    Raises
    ------
    TypeError
        For a ``mesh`` that is not a :class:`~signorini.mesh.mesh.Mesh` (a refinement's
        record, say: its ``.mesh`` is the mesh).
    ValueError
        Naming both dimensions.
    """
    if not isinstance(mesh, Mesh):
        hint = ": pass its .mesh" if isinstance(getattr(mesh, "mesh", None), Mesh) else ""
        raise TypeError(f"mesh must be a Mesh, got {type(mesh).__name__}{hint}")
    if mesh.dim != stated.dim:
        raise ValueError(
            f"the problem {name!r} is stated on a {stated.dim}D mesh and was handed a "
            f"{mesh.dim}D mesh: solve it on its own mesh or a refinement of it"
        )


def check_problem_3d(
    mesh: Mesh,
    held: Mapping[str, Dirichlet],
    rollers: Mapping[str, object],
    contact_parts: list[str],
    pairs: Mapping[str, str] | None = None,
) -> np.ndarray:
    """The checks of a 3D problem beyond the 2D ones that hold as they are, and its free
    rigid motions.

    Parameters
    ----------
    mesh : Mesh
        Tetrahedral.
    held : mapping part -> Dirichlet
        The Dirichlet parts and the axis rollers as Dirichlet conditions.
    rollers : mapping part -> Roller
        The rollers on oblique planes and curved parts (their normal components held in node
        frames, :mod:`.rollers3d`).
    contact_parts : list of str
    pairs : mapping slave part -> master part, optional
        The contact pairs: then every body must be held by its own parts.

    Returns
    -------
    (k, 6) float array
        The rigid motions the held components leave free, each held by a contact part
        (:func:`~.rigid3d.free_rigid_motions_3d`): the body is under force control along
        them.

    Raises
    ------
    ProblemError
        For a roller part with a crease (:func:`~.rollers3d.check_roller_part_3d`), or a
        rigid motion held by nothing (named).
    """
    space = space_of(mesh, "P2")
    for name in rollers:  # a loop over parts
        check_roller_part_3d(space, name)
    if pairs:
        return _held_bodies(space, held, rollers, pairs)
    return free_rigid_motions_3d(space, held, rollers, contact_parts)


def _held_bodies(space, held: Mapping, rollers: Mapping, pairs: Mapping[str, str]) -> np.ndarray:
    """With contact pairs (3D): no pair on one body (self contact), every body held in all
    its rigid motions by its own Dirichlet and Roller parts (force control across a pair is
    built in 2D only); no free motion."""
    mesh = space.mesh
    body = body_of_cells(mesh)
    part_body = {p: int(body[mesh.facet2cell[mesh.part_facets(p)[0], 0]]) for p in mesh.part_names}
    for slave, master in pairs.items():  # a loop over pairs
        if part_body[slave] == part_body[master]:
            raise ProblemError(
                f"the contact pair {slave!r} / {master!r}: both parts lie on one body: self "
                "contact is not modelled (in small deformation a body does not reach its own "
                "boundary); a pair joins parts of two bodies"
            )
    for b in range(int(body.max()) + 1):  # a loop over bodies
        own = [p for p in mesh.part_names if part_body[p] == b]
        try:
            free_rigid_motions_3d(
                space,
                {p: c for p, c in held.items() if p in own},
                {p: c for p, c in rollers.items() if p in own},
                [],
            )
        except ProblemError as err:
            raise ProblemError(
                f"the body with the parts {own} in a 3D problem with contact pairs "
                f"{dict(pairs)}: each body must be held in all its rigid motions by its own "
                f"Dirichlet and Roller parts (force control across a pair is built in 2D "
                f"only). {err}"
            ) from None
    return np.zeros((0, 6))
