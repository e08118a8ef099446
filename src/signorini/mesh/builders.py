"""Built-in structured meshes."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh, MeshError
from .regions import RegionSpec

__all__ = ["rectangle"]

_PATTERNS = ("unionjack", "right", "left", "crossed")


def rectangle(
    x0: float = 0.0,
    x1: float = 1.0,
    y0: float = 0.0,
    y1: float = 1.0,
    nx: int = 4,
    ny: int = 4,
    pattern: str = "unionjack",
    *,
    regions: RegionSpec | None = None,
) -> Mesh:
    """Structured triangulation of the rectangle ``[x0, x1] × [y0, y1]``.

    Boundary parts are named ``"bottom"``, ``"right"``, ``"top"`` and ``"left"``.

    Parameters
    ----------
    nx, ny : int
        Number of squares (rectangles) in each direction.
    pattern : {"unionjack", "right", "left", "crossed"}
        ``"unionjack"`` alternates the diagonals so the mesh is symmetric about the
        rectangle's centre lines when ``nx`` and ``ny`` are even; ``"right"`` / ``"left"``
        use one diagonal direction; ``"crossed"`` splits each square into four triangles
        through its centre.
    regions : mapping region name -> selector, or array, optional
        The cells' regions, e.g. ``{"coating": lambda x: x[:, 1] > 0.9, "base": lambda x:
        x[:, 1] < 0.9}`` with selectors of the cell centroids ``x (n, 2)``, as for
        :meth:`Mesh.from_arrays`; one region ``"body"`` by default.
    """
    if not (np.isfinite([x0, x1, y0, y1]).all() and x1 > x0 and y1 > y0):
        raise MeshError(f"rectangle needs x0 < x1 and y0 < y1, got [{x0}, {x1}] x [{y0}, {y1}]")
    if int(nx) != nx or int(ny) != ny or nx < 1 or ny < 1:
        raise MeshError(f"nx and ny must be positive integers, got {nx}, {ny}")
    if pattern not in _PATTERNS:
        raise MeshError(f"unknown pattern {pattern!r}; choose one of {_PATTERNS}")
    nx, ny = int(nx), int(ny)
    xs = np.linspace(x0, x1, nx + 1)
    ys = np.linspace(y0, y1, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    points = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    i, j = i.ravel(), j.ravel()
    a = j * (nx + 1) + i  # lower left
    b = a + 1  # lower right
    c = a + nx + 2  # upper right
    d = a + nx + 1  # upper left
    if pattern == "crossed":
        centre = np.column_stack([xs[i] + 0.5 * (xs[1] - xs[0]), ys[j] + 0.5 * (ys[1] - ys[0])])
        m = len(points) + np.arange(len(a))
        points = np.vstack([points, centre])
        cells = np.concatenate(
            [np.column_stack(t) for t in ((a, b, m), (b, c, m), (c, d, m), (d, a, m))]
        )
    else:
        if pattern == "right":
            flip = np.zeros(len(a), dtype=bool)
        elif pattern == "left":
            flip = np.ones(len(a), dtype=bool)
        else:  # union jack: diagonals point towards the centre of the rectangle
            flip = (i < nx / 2) == (j < ny / 2)
            flip = ~flip
        # diagonal a-c (no flip) or b-d (flip)
        t1 = np.where(flip[:, None], np.column_stack([a, b, d]), np.column_stack([a, b, c]))
        t2 = np.where(flip[:, None], np.column_stack([b, c, d]), np.column_stack([a, c, d]))
        cells = np.concatenate([t1, t2])
    tol = 1e-12 * max(x1 - x0, y1 - y0)
    parts = {
        "bottom": lambda x: np.abs(x[:, 1] - y0) < tol,
        "right": lambda x: np.abs(x[:, 0] - x1) < tol,
        "top": lambda x: np.abs(x[:, 1] - y1) < tol,
        "left": lambda x: np.abs(x[:, 0] - x0) < tol,
    }
    return Mesh.from_arrays(points, cells, parts, regions=regions)


def half_disc(
    radius: float = 1.0,
    rings: int = 4,
    *,
    h_bottom: float | None = None,
    grading: float = 0.5,
) -> Mesh:
    """The half-disc of radius ``R`` below its flat side: centre ``(0, R)``, the arc touching
    ``y = 0`` at the origin (the *bottom point*), the flat side on ``y = R``.

    Boundary parts: ``"top"`` (the flat side, a straight segment from ``(−R, R)`` to
    ``(R, R)``) and ``"arc"``, which carries ``Circle((0, R), R)``
    (:meth:`Mesh.with_curve`), so refinement puts new boundary points on the circle and the
    cells along it are isoparametric (docs/method.md, *Curved boundaries*).

    The coarse mesh is polar about the centre: ``rings`` half-rings of radii ``j R / rings``,
    half-ring ``j`` split into ``3 j`` equal angles (``3 rings²`` cells, all angles between
    about 30° and 90°); with ``rings`` even, the bottom point is a vertex and the mesh is
    mirror-symmetric about ``x = 0``. With ``h_bottom``, cells are then bisected by newest
    vertex bisection until every cell's diameter ``h_T`` is at most
    ``max(h_bottom, grading · d_T)``, ``d_T`` the distance from the cell's nearest vertex to
    the bottom point: a mesh graded towards the point where contact starts.

    Parameters
    ----------
    radius : float
        ``R`` (length units), positive.
    rings : int
        Number of half-rings of the coarse mesh, at least 1.
    h_bottom : float, optional
        Largest cell diameter at the bottom point (length units); no grading when omitted.
    grading : float
        Growth of the cell size with the distance from the bottom point (``h_T ≤ grading ·
        d_T`` away from it), positive.

    Returns
    -------
    Mesh
        Counter-clockwise, valid cells; the arc's vertices lie on the circle to round-off.

    Raises
    ------
    MeshError
        For a radius, ``rings``, ``h_bottom`` or ``grading`` out of range, naming it.
    """
    from .curves import Circle
    from .refine import refine_nvb

    if not (np.isfinite(radius) and radius > 0):
        raise MeshError(f"half_disc: radius must be a positive number, got {radius!r}")
    if int(rings) != rings or rings < 1:
        raise MeshError(f"half_disc: rings must be a positive integer, got {rings!r}")
    if h_bottom is not None and not (np.isfinite(h_bottom) and h_bottom > 0):
        raise MeshError(f"half_disc: h_bottom must be a positive number, got {h_bottom!r}")
    if not (np.isfinite(grading) and grading > 0):
        raise MeshError(f"half_disc: grading must be a positive number, got {grading!r}")
    radius, rings = float(radius), int(rings)
    points, cells = _polar_half_disc(rings)
    points = np.array([0.0, 1.0]) + points  # centre (0, 1), bottom point at the origin
    tol = 1e-9
    mesh = Mesh.from_arrays(
        radius * points,
        cells,
        {
            "top": lambda x: np.abs(x[:, 1] - radius) < tol * radius,
            "arc": lambda x: np.abs(x[:, 1] - radius) >= tol * radius,
        },
    ).with_curve("arc", Circle((0.0, radius), radius))
    if h_bottom is None:
        return mesh
    while True:  # a loop over refinement rounds: O(log(R / h_bottom)) of them
        distance = np.hypot(*mesh.points[mesh.cells].transpose(2, 0, 1)).min(axis=1)
        marked = mesh.h > np.maximum(h_bottom, grading * distance)
        if not marked.any():
            return mesh
        mesh = refine_nvb(mesh, marked).mesh


def _polar_half_disc(rings: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and cells of the unit half-disc ``r ≤ 1, π ≤ θ ≤ 2π`` about the origin.

    Point 0 is the centre; half-ring ``j = 1 … rings`` holds ``3 j + 1`` points at the angles
    ``π (1 + k / (3 j))``, ``k = 0 … 3 j``. The strip between half-rings ``j − 1`` and ``j``
    gets one triangle per segment of either half-ring: the segments taken in the order of
    their midpoint angles, each joined to the node of the other half-ring reached so far.
    """
    counts = 3 * np.arange(rings + 1) + 1  # points per half-ring; half-ring 0 is the centre
    counts[0] = 1
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    j = np.repeat(np.arange(rings + 1), counts)
    k = np.arange(j.size) - first[j]
    # angle from the bottom, in half-turns: sin is odd, so the points are mirror-symmetric
    # and the bottom point (s = 0) and the ends on the flat side (s = ±1/2) are exact
    s = k / np.maximum(3 * j, 1) - 0.5
    y = np.where(np.abs(s) == 0.5, 0.0, -np.cos(np.pi * s))
    points = np.column_stack([j * np.sin(np.pi * s), j * y]) / rings
    return points, ring_cells(first, 3)


def ring_cells(first: np.ndarray, per_ring: int) -> np.ndarray:
    """The cells of a polar mesh of rings about a centre (point 0): ring ``j = 1 …`` has
    ``per_ring · j + 1`` points from index ``first[j]`` on (``first`` of length rings + 1).

    The strip between rings ``j − 1`` and ``j`` gets one triangle per segment of either ring:
    the segments taken in the order of their midpoint angles, each joined to the node of the
    other ring reached so far (counter-clockwise for angles increasing with the index).

    Returns
    -------
    (n_cells, 3) int array
    """
    cells = []
    for ring in range(1, len(first)):  # a loop over rings (a few tens at most)
        n_in, n_out = per_ring * (ring - 1), per_ring * ring
        mid_in = (np.arange(n_in) + 0.5) / max(n_in, 1)
        mid_out = (np.arange(n_out) + 0.5) / n_out
        is_out = np.concatenate([np.zeros(n_in, bool), np.ones(n_out, bool)])
        order = np.argsort(np.concatenate([mid_in, mid_out]), kind="stable")
        is_out = is_out[order]
        # nodes of each ring reached before each segment
        seen_out = np.cumsum(is_out) - is_out
        seen_in = np.cumsum(~is_out) - ~is_out
        a, b = first[ring - 1], first[ring]
        inner = np.where(n_in > 0, a + seen_in, a)
        cells.append(
            np.where(
                is_out[:, None],
                np.column_stack([b + seen_out, b + seen_out + 1, inner]),
                np.column_stack([a + seen_in, b + seen_out, a + seen_in + 1]),
            )
        )
    return np.concatenate(cells)
