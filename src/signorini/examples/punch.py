"""A rigid punch with rounded corners pressed into a block held against a rigid wall.

The block [0, W] × [0, H] (plane strain) stands on a clamped base (u = 0 on y = 0), its left
side free. A rigid flat punch with rounded corners covers the top from x = x_p to beyond the
block's right side and is pressed a depth d into it; the block's right side rests against a
rigid wall x ≥ W. Both obstacles are shapes (docs/method.md, *Obstacles as shapes*): the
punch a :class:`~signorini.problem.obstacles.Polyline` with corner radius r, the wall a
:class:`~signorini.problem.obstacles.HalfPlane`. The two contact parts, ``"top"`` and
``"right"``, meet at the corner (W, H): pushed down, the block bulges sideways into the wall,
so near the corner both are in contact and the corner node carries two constraints, one
against each obstacle.

The pressure under the punch is bounded at its rounded corner (a sharp corner would give the
1/√distance singularity of a flat punch) and peaks there; refinement concentrates at the end
of the contact zone under the rounded corner, and along the wall where contact ends.
"""

from __future__ import annotations

from ..fem.material import Material
from ..mesh.builders import rectangle
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from ..problem.obstacles import HalfPlane, Polyline

__all__ = ["punch"]


def punch(
    width: float = 2.0,
    height: float = 1.0,
    edge: float = 1.0,
    radius: float = 0.2,
    depth: float = 0.01,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    nx: int = 8,
) -> ContactProblem:
    """The punch problem: a block pressed by a rounded rigid punch, held by a wall.

    Defaults: W = 2, H = 1, the punch's left side at x_p = 1 with corner radius r = 0.2,
    pressed d = 0.01 into the top, E = 1, ν = 0.3 (consistent units).

    Parameters
    ----------
    width, height : float
        W and H, the block's size (length units).
    edge : float
        x_p, where the punch's flat bottom would begin without the rounding (0 < x_p < W).
    radius : float
        r, the radius of the punch's corners (length units).
    depth : float
        d, how far the punch's bottom lies below the block's top (y = H − d).
    young, poisson : float
        E (stress units) and ν of the block.
    nx : int
        The initial mesh: ``nx × nx/2`` squares with "union jack" diagonals (``rectangle``).

    Returns
    -------
    ContactProblem
        Named ``"punch"``; parts ``"bottom"`` (Dirichlet 0), ``"left"`` (free), ``"top"``
        (contact with the punch) and ``"right"`` (contact with the wall).
    """
    bottom = height - depth
    reach = 2.0 * width - edge  # the punch ends beyond the wall, centred on it
    tool = Polyline(
        [(edge, height + 1.0), (edge, bottom), (reach, bottom), (reach, height + 1.0)],
        radius=radius,
    )
    return ContactProblem(
        mesh=rectangle(0.0, width, 0.0, height, nx=nx, ny=max(nx // 2, 1)),
        material=Material.from_young(young, poisson),
        conditions={
            "bottom": Dirichlet((0.0, 0.0)),
            "left": Neumann((0.0, 0.0)),
            "top": Contact(obstacle=tool),
            "right": Contact(obstacle=HalfPlane((width, 0.0), (-1.0, 0.0))),
        },
        name="punch",
    )
