"""Hertz contact on a symmetric half-model: the quarter disc with a roller on its axis.

The half-disc of :mod:`.hertz` is symmetric about ``x = 0``; its right half, the quarter
disc ``x ≥ 0``, with a :class:`~signorini.problem.conditions.Roller` on the axis (``u_x = 0``,
no tangential traction), gives the same solution on half the unknowns (docs/method.md,
*Rollers and components*). Two loadings:

- displacement control, the flat top moved down by ``(0, −δ)`` (:func:`hertz_quarter`);
- force control, a traction ``(0, −P / (2R))`` on the top, so that the whole cylinder carries
  P (``P / 2`` on the quarter): the quarter is then held vertically by the contact alone
  (semi-coercive: docs/method.md, *Force control*).

The contact quantities of the quarter are those of the half-disc's right half, except at the
axis node, whose nodal force is half the whole's: the whole cylinder carries ``2 Σ Λ_z``.
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..mesh.builders import ring_cells
from ..mesh.curves import Circle
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Dirichlet, Neumann, Roller
from ..problem.obstacles import HalfPlane
from .hertz import DEPTH, hertz_solution

__all__ = ["hertz_quarter", "hertz_quarter_metrics", "mirrored_half_disc", "quarter_disc"]


def quarter_disc(radius: float = 1.0, rings: int = 4, *, h_bottom: float | None = None) -> Mesh:
    """The quarter disc ``x ≥ 0`` of the half-disc of :func:`~signorini.mesh.builders.
    half_disc` (centre ``(0, R)``, bottom point at the origin): parts ``"top"`` (y = R),
    ``"axis"`` (x = 0) and ``"arc"`` (carrying ``Circle((0, R), R)``).

    The coarse mesh is polar: quarter-ring ``j = 1 … rings`` of radius ``j R / rings`` in
    ``2 j`` equal angles; with ``h_bottom`` its cells are bisected (newest vertex bisection)
    until ``h_T ≤ max(h_bottom, d_T / 2)``, ``d_T`` the distance of the cell's nearest
    vertex from the bottom point, as :func:`~signorini.mesh.builders.half_disc` grades.
    """
    from ..mesh.refine import refine_nvb

    counts = 2 * np.arange(rings + 1) + 1
    counts[0] = 1
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    j = np.repeat(np.arange(rings + 1), counts)
    k = np.arange(j.size) - first[j]
    s = k / np.maximum(4 * j, 1)  # angle from the bottom in half-turns, 0 … 1/2
    x = np.where(s == 0.5, 1.0, np.sin(np.pi * s))
    y = np.where(s == 0.5, 0.0, -np.cos(np.pi * s))
    points = radius * (np.column_stack([j * x, j * y]) / rings + [0.0, 1.0])
    tol = 1e-9 * radius
    mesh = Mesh.from_arrays(
        points,
        ring_cells(first, 2),
        {
            "top": lambda x: np.abs(x[:, 1] - radius) < tol,
            "axis": lambda x: np.abs(x[:, 0]) < tol,
            "arc": lambda x: (np.abs(x[:, 1] - radius) >= tol) & (np.abs(x[:, 0]) >= tol),
        },
    ).with_curve("arc", Circle((0.0, radius), radius))
    if h_bottom is None:
        return mesh
    while True:  # a loop over refinement rounds: O(log(R / h_bottom)) of them
        distance = np.hypot(*mesh.points[mesh.cells].transpose(2, 0, 1)).min(axis=1)
        marked = mesh.h > np.maximum(h_bottom, 0.5 * distance)
        if not marked.any():
            return mesh
        mesh = refine_nvb(mesh, marked).mesh


def mirrored_half_disc(quarter: Mesh) -> tuple[Mesh, np.ndarray]:
    """The half-disc made of ``quarter`` and its mirror image in ``x = 0`` (exactly
    symmetric), with parts ``"top"`` and ``"arc"``; and for each vertex of ``quarter`` its
    index in the half-disc (the quarter's vertices come first, in their order)."""
    pts = quarter.points
    on_axis = np.abs(pts[:, 0]) <= 0.0
    mirror = np.flatnonzero(~on_axis)
    index = np.arange(len(pts))
    image = index.copy()
    image[mirror] = len(pts) + np.arange(mirror.size)
    points = np.vstack([pts, pts[mirror] * [-1.0, 1.0]])
    cells = np.vstack([quarter.cells, image[quarter.cells][:, ::-1]])
    radius = float(pts[:, 1].max())
    tol = 1e-9 * radius
    mesh = Mesh.from_arrays(
        points,
        cells,
        {
            "top": lambda x: np.abs(x[:, 1] - radius) < tol,
            "arc": lambda x: np.abs(x[:, 1] - radius) >= tol,
        },
    ).with_curve("arc", Circle((0.0, radius), radius))
    return mesh, index


def hertz_quarter(
    radius: float = 1.0,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    depth: float | None = None,
    force: float | None = None,
    rings: int = 4,
    h_bottom: float | None = None,
) -> ContactProblem:
    """The Hertz problem on the quarter disc ``x ≥ 0`` with a roller on the axis.

    Parameters
    ----------
    radius, young, poisson : float
        R, E and ν (consistent units).
    depth : float, optional
        δ, the downward displacement of the top (displacement control); default
        ``DEPTH * radius`` when ``force`` is not given.
    force : float, optional
        P, the total force per unit thickness on the whole cylinder (force control): the top
        carries the traction ``(0, −P / (2R))``, and the quarter is held vertically by the
        contact alone. Not with ``depth``.
    rings, h_bottom :
        The mesh, :func:`quarter_disc`.

    Returns
    -------
    ContactProblem
        Named ``"hertz-quarter"``; parts ``"top"``, ``"axis"`` (``Roller()``) and ``"arc"``
        (contact with the plane ``y = 0``).
    """
    if depth is not None and force is not None:
        raise ValueError("hertz_quarter: give depth (displacement control) or force, not both")
    if force is None:
        top = Dirichlet((0.0, -(DEPTH * radius if depth is None else depth)))
    else:
        top = Neumann((0.0, -force / (2.0 * radius)))
    return ContactProblem(
        mesh=quarter_disc(radius, rings, h_bottom=h_bottom),
        material=Material.from_young(young, poisson),
        conditions={
            "top": top,
            "axis": Roller(),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
        },
        name="hertz-quarter",
    )


def hertz_quarter_metrics(result: ContactResult) -> dict[str, float]:
    """Half-width a and peak pressure p0 of a quarter-disc solution, and their errors
    against Hertz for the whole cylinder's force ``P = 2 Σ Λ_z``.

    The quarter's nodal force at the axis node is half the whole's (its hat function is cut
    in half), so the whole's sums are twice the quarter's: ``P = 2 Σ Λ_z`` and the
    half-width ``2 √(Σ Λ_z x_z² / Σ Λ_z)`` is the same over the quarter; the pressure
    ``p_z = Λ_z / m_z`` is unchanged."""
    cs = result.contact
    lam = result.contact_force
    x = result.space.node_points[cs.nodes, 0]
    force = 2.0 * lam.sum()
    a = 2.0 * float(np.sqrt((lam * x**2).sum() / lam.sum()))
    p0 = float(result.pressure.max())
    radius = float(result.problem.mesh.points[:, 1].max())
    a_h, p0_h = hertz_solution(force, radius, result.problem.material)
    return {
        "force": float(force),
        "a": a,
        "p0": p0,
        "a_rel_error": a / a_h - 1.0,
        "p0_rel_error": p0 / p0_h - 1.0,
    }
