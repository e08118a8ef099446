"""Quasi-static load paths: a sequence of problems on one mesh, solved step by step.

Coulomb friction is path-dependent: the state after a load path is not the static solution
of its last load. Each step is solved with the previous step's result (``solve(...,
previous=...)``), so that the friction law acts on the slip increment of the step and the
iteration starts from the previous states (docs/method.md, *Load paths*). A rigid obstacle
moved along the path (``shape.moved(d)`` in each step's problem) counts in the slip: the law
acts on the tangential displacement relative to the obstacle (docs/method.md, *Obstacle
motion*).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np

from ..algebra.backends.solvers import SolverFactory, SPDSolver
from ..mesh.mesh import Mesh
from ..problem.problem import ContactProblem
from .solution import ContactResult, solve

__all__ = ["check_path", "mesh_difference", "solve_path"]

log = logging.getLogger(__name__)


def solve_path(
    problems: Sequence[ContactProblem],
    mesh: Mesh | None = None,
    *,
    solver: SPDSolver | SolverFactory | None = None,
    max_iter: int = 50,
    u0: np.ndarray | None = None,
    element: str = "P2",
) -> list[ContactResult]:
    """Solve a prescribed load path: one problem per load step, each from the previous step.

    Parameters
    ----------
    problems : sequence of ContactProblem
        The load steps in order, e.g. ``[problem(t) for t in (0.5, 1.0)]`` with a function
        ``problem`` of the load parameter. They have the same contact parts and the same
        initial mesh (points and cells); only their data (Dirichlet values, loads, gaps,
        friction) differ.
    mesh : Mesh, optional
        The mesh of every step; defaults to the problems' initial mesh.
    solver : SolverFactory or SPDSolver, optional
        The linear solver of every step, as in :func:`~signorini.contact.solve`.
    max_iter : int
        Bound on the active set iterations of each step.
    u0 : (n_nodes, 2) float array, optional
        Warm start of the first step on ``mesh`` (as for :func:`~signorini.contact.solve`;
        e.g. the first step of a coarser mesh prolongated); the later steps start from the
        previous step.
    element : {"P2", "P1"}
        The finite element of every step (:func:`~signorini.contact.solve`).

    Returns
    -------
    list of ContactResult
        One per step; step 0 from the undeformed state (slip measured from 0), step ``i``
        with the law on the slip from step ``i − 1``.

    Raises
    ------
    ValueError
        If ``problems`` is empty or holds something else than problems, or two steps have
        different contact parts or initial meshes, including their boundary parts and curves
        (naming the step and what differs).
    """
    problems = check_path(problems)
    mesh = problems[0].mesh if mesh is None else mesh
    results: list[ContactResult] = []
    for i, problem in enumerate(problems):
        previous = results[-1] if results else None
        start = u0 if previous is None else None
        results.append(
            solve(
                problem,
                mesh,
                u0=start,
                previous=previous,
                solver=solver,
                max_iter=max_iter,
                element=element,
            )
        )
        log.info("load step %d of %d solved", i + 1, len(problems))
    return results


def check_path(problems: object) -> list[ContactProblem]:
    """The steps of a load path as a list, checked: problems on one initial mesh with one
    set of contact parts (a ``ValueError`` naming the step otherwise)."""
    if isinstance(problems, ContactProblem) or not isinstance(problems, Sequence):
        raise ValueError(
            f"problems must be a sequence of ContactProblem (one per load step), got "
            f"{type(problems).__name__}"
        )
    steps = list(problems)
    if not steps:
        raise ValueError("problems is empty: a load path has at least one step")
    for i, problem in enumerate(steps):
        if not isinstance(problem, ContactProblem):
            raise ValueError(
                f"problems[{i}] must be a ContactProblem, got {type(problem).__name__}"
            )
    first = steps[0]
    for i, problem in enumerate(steps[1:], start=1):
        if problem.contact_parts != first.contact_parts:
            raise ValueError(
                f"problems[{i}] has the contact parts {list(problem.contact_parts)}, "
                f"problems[0] {list(first.contact_parts)}: the steps of a load path share "
                "their contact parts"
            )
        a, b = problem.mesh, first.mesh
        if a is not b and (
            a.points.shape != b.points.shape
            or a.cells.shape != b.cells.shape
            or (a.points != b.points).any()
            or (a.cells != b.cells).any()
        ):
            raise ValueError(
                f"problems[{i}] is posed on another mesh than problems[0] ({a.n_cells} and "
                f"{b.n_cells} cells): the steps of a load path share one mesh"
            )
        difference = None if a is b else mesh_difference(a, b)
        if difference:
            raise ValueError(
                f"problems[{i}] is posed on the points and cells of problems[0] but {difference}"
                ": the steps of a load path share one mesh, with its parts and curves (every "
                "step is solved on the first step's mesh)"
            )
    return steps


#: two curves are the same on a part if their projections (and normals) of the part's edge
#: midpoints agree to this fraction of the mesh's extent (largest coordinate plus diameter)
SAME_CURVE_TOL = 1e-12


def mesh_difference(a: Mesh, b: Mesh) -> str | None:
    """What differs between two meshes with the same points and cells, or ``None``.

    Compared: the part of every boundary edge (by name), the curve attached to every part
    (by where it puts the part's edge midpoints: :meth:`~signorini.mesh.curves.Curve.project`
    and, where given, :meth:`~signorini.mesh.curves.Curve.normal`), and the cell regions if the
    meshes have them.
    """

    def labels(m: Mesh) -> np.ndarray:
        names = np.array([*m.part_names, ""], dtype=object)
        return names[m.facet_part]  # -1 (interior) -> ""

    la, lb = labels(a), labels(b)
    if set(a.part_names) != set(b.part_names):
        return f"has the parts {sorted(a.part_names)}, problems[0] {sorted(b.part_names)}"
    moved = np.flatnonzero(la != lb)
    if moved.size:
        e = moved[0]
        x = a.points[a.facets[e]]
        return (
            f"labels {moved.size} boundary edge(s) with other parts (the edge "
            f"({x[0, 0]:.12g}, {x[0, 1]:.12g})–({x[1, 0]:.12g}, {x[1, 1]:.12g}) is on part "
            f"{la[e]!r}, on problems[0] {lb[e]!r})"
        )
    extent = float(np.abs(a.points).max() + np.ptp(a.points, axis=0).max())
    for name in a.part_names:
        ca, cb = a.curves[a.part_index(name)], b.curves[b.part_index(name)]
        if ca is cb:
            continue
        if (ca is None) != (cb is None):
            which = "has a curve" if ca is not None else "has no curve"
            return f"{which} on part {name!r}, unlike problems[0]"
        x = a.edge_midpoints[a.part_facets(name)]
        same = np.abs(ca.project(x) - cb.project(x)).max() <= SAME_CURVE_TOL * extent
        if same and (ca.has_normal or cb.has_normal):
            same = ca.has_normal == cb.has_normal and np.allclose(
                ca.normal(x), cb.normal(x), rtol=0.0, atol=SAME_CURVE_TOL
            )
        if not same:
            return f"attaches another curve to part {name!r} ({ca!r}, problems[0] {cb!r})"
    ra, rb = getattr(a, "regions", None), getattr(b, "regions", None)
    if ra is not None and rb is not None and not np.array_equal(ra, rb):
        return "has other cell regions"
    return None
