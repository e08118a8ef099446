"""``punch-3d``: a rigid flat punch with rounded edges pressed into a block held against a
rigid wall, the half of a symmetric model (docs/method.md, *Three dimensions: the paper's
examples*, "The punch in 3D"); the 2D ``punch`` (:mod:`.punch`) made three-dimensional.

The block [0, W] × [0, D] × [0, H] is the half y ≥ 0 of a block symmetric about y = 0:
rollers hold ``u_y = 0`` on ``"y0"``, the base ``"z0"`` is clamped, the faces ``"x0"`` and
``"y1"`` are free. The punch is a rigid box with rounded edges and corners (the points within
r of a box, :func:`rounded_box_distance`), its flat bottom at z = H − d, its footprint
``x ≥ x_p``, ``|y| ≤ y_p`` before the rounding, reaching beyond the block's side x = W: its
front edge ``x = x_p`` and its side edge ``y = y_p`` cross the top face, so the contact zone
under it ends along a straight rounded edge, a straight rounded side and the rounded corner
between them. The side ``"x1"`` rests against the rigid wall x ≥ W. Pushed down, the block
bulges sideways into the wall, so the two contact zones meet along the edge x = W, z = H, whose
nodes carry two constraints, one against each obstacle (three directions with the roller at
y = 0). Both obstacles are shapes: the punch a
:class:`~signorini.problem.obstacles3d.SignedDistance3D` with its exact gradient, the wall a
:class:`~signorini.problem.obstacles3d.HalfSpace`. No reference solution is known.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..fem.material import Material
from ..mesh.builders3d import box
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from ..problem.conditions import Roller
from ..problem.obstacles3d import HalfSpace, SignedDistance3D

__all__ = ["punch_3d", "rounded_box_distance"]


def rounded_box_distance(
    center: np.ndarray, half: np.ndarray, radius: float
) -> tuple[Callable, Callable]:
    """The signed distance to the box ``|x − center| ≤ half`` (componentwise) grown by
    ``radius`` (its edges and corners rounded), and its gradient.

    With ``q = |x − c| − h``: ``d(x) = |q⁺| + min(max_k q_k, 0) − r``, exact inside and
    outside; ``∇d = sign(x − c) q⁺ / |q⁺|`` outside the box, ``sign(x_k − c_k) e_k`` with
    ``k = argmax q`` inside it.

    Returns
    -------
    phi, grad : callable
        ``phi(x (n, 3)) -> (n,)`` and ``grad(x (n, 3)) -> (n, 3)``.
    """
    center = np.asarray(center, dtype=np.float64)
    half = np.asarray(half, dtype=np.float64)

    def parts(x):
        s = x - center
        q = np.abs(s) - half
        return s, q, np.maximum(q, 0.0)

    def phi(x):
        _, q, out = parts(x)
        return np.linalg.norm(out, axis=1) + np.minimum(q.max(axis=1), 0.0) - radius

    def grad(x):
        s, q, out = parts(x)
        length = np.linalg.norm(out, axis=1)
        outside = length > 0
        g = np.zeros_like(x)
        g[outside] = np.sign(s[outside]) * out[outside] / length[outside, None]
        k = np.argmax(q[~outside], axis=1)
        rows = np.flatnonzero(~outside)
        g[rows, k] = np.where(s[rows, k] < 0, -1.0, 1.0)
        return g

    return phi, grad


def punch_3d(
    width: float = 2.0,
    depth_y: float = 1.0,
    height: float = 1.0,
    edge: float = 1.0,
    side: float = 0.5,
    radius: float = 0.2,
    depth: float = 0.01,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    n: int = 4,
    face_alpha: float | None = None,
) -> ContactProblem:
    """The 3D punch problem: a block pressed by a rounded rigid punch, held by a wall.

    Defaults: W = 2, D = 1, H = 1, the punch's footprint ``x ≥ x_p = 1``, ``|y| ≤ y_p =
    0.5`` before the rounding, radius r = 0.2 of its edges, pressed d = 0.01 into the top,
    E = 1, ν = 0.3 (consistent units).

    Parameters
    ----------
    width, depth_y, height : float
        W, D and H, the block's size along x, y, z (length units).
    edge : float
        x_p, where the punch's footprint begins along x without the rounding (0 < x_p < W).
    side : float
        y_p, the half-width of the footprint along y without the rounding (0 < y_p < D).
    radius : float
        r, the radius of the punch's edges (length units, below x_p, y_p and W − x_p).
    depth : float
        d, how far the punch's bottom lies below the block's top (z = H − d).
    young, poisson : float
        E (stress units) and ν of the block.
    n : int
        The initial mesh: ``box(2n, n, n)`` Kuhn cubes of the block.
    face_alpha : float, optional
        The discrete contact condition of both parts (:class:`~signorini.problem.Contact`):
        None for (b), the transformed face basis with α = 1/5; 0 for (a), nodal constraints
        at all P2 nodes.

    Raises
    ------
    ValueError
        For a footprint or radius that does not fit the block (naming the arguments).

    Returns
    -------
    ContactProblem
        Named ``"punch-3d"``; parts ``"z0"`` (Dirichlet 0), ``"y0"`` (roller), ``"x0"``,
        ``"y1"`` (free), ``"z1"`` (contact with the punch), ``"x1"`` (contact with the wall).
    """
    if not (0 < edge < width and 0 < side < depth_y and 0 < radius < min(side, width - edge)):
        raise ValueError(
            f"punch_3d: need 0 < edge < width, 0 < side < depth_y and 0 < radius < min(side, "
            f"width - edge); got edge={edge}, side={side}, radius={radius}, width={width}, "
            f"depth_y={depth_y}"
        )
    reach = 2.0 * width - edge  # the punch ends beyond the wall, centred on it
    bottom = height - depth
    lower = np.array([edge + radius, -(side - radius), bottom + radius])
    upper = np.array([reach - radius, side - radius, height + 1.0])
    phi, grad = rounded_box_distance(0.5 * (lower + upper), 0.5 * (upper - lower), radius)
    tool = SignedDistance3D(phi, grad, scale=height)
    return ContactProblem(
        mesh=box(2 * n, n, n, upper=(width, depth_y, height)),
        material=Material.from_young(young, poisson),
        conditions={
            "z0": Dirichlet((0.0, 0.0, 0.0)),
            "y0": Roller(),
            "x0": Neumann((0.0, 0.0, 0.0)),
            "y1": Neumann((0.0, 0.0, 0.0)),
            "z1": Contact(obstacle=tool, face_alpha=face_alpha),
            "x1": Contact(
                obstacle=HalfSpace((width, 0.0, 0.0), (-1.0, 0.0, 0.0)), face_alpha=face_alpha
            ),
        },
        name="punch-3d",
    )
