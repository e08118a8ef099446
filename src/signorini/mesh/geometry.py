"""Geometry of straight segments and triangles: lengths, unit normals, signed areas.

The one place where an edge's normal is computed. For a segment traversed from ``a`` to
``b`` the normal is the right-hand one, ``(d_y, −d_x) / |d|`` with ``d = b − a``: it points
out of a counter-clockwise cell whose local edge runs from ``a`` to ``b``, so it is the
outward normal of every boundary edge taken in its cell's counter-clockwise order.
"""

from __future__ import annotations

import numpy as np

from .reference import TRIANGLE

__all__ = ["min_angle", "segment_normals", "signed_area"]


def segment_normals(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lengths and right-hand unit normals of the segments ``a → b``.

    Parameters
    ----------
    a, b : (..., 2) float arrays
        Start and end points.

    Returns
    -------
    length : (...) float array
    normal : (..., 2) float array
        ``(d_y, −d_x) / |d|``, ``d = b − a``; outward for a counter-clockwise cell.
    """
    d = np.asarray(b, dtype=np.float64) - np.asarray(a, dtype=np.float64)
    length = np.hypot(d[..., 0], d[..., 1])
    normal = np.stack([d[..., 1], -d[..., 0]], axis=-1) / length[..., None]
    return length, normal


def signed_area(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Signed areas of triangles, positive for counter-clockwise ones.

    Parameters
    ----------
    points : (n_points, 2) float array
    cells : (n_cells, 3) int array

    Returns
    -------
    (n_cells,) float array
    """
    p0, p1, p2 = (points[cells[:, k]] for k in range(3))
    d1, d2 = p1 - p0, p2 - p0
    return 0.5 * (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def min_angle(points: np.ndarray, cells: np.ndarray) -> float:
    """Smallest interior angle (radians) of the triangles ``cells (n_cells, 3)``."""
    p = points[cells]
    angles = []
    for k in range(3):  # at vertex k: edge k leaves it, edge k - 1 arrives
        (_, b), (c, _) = TRIANGLE.edges[k], TRIANGLE.edges[k - 1]
        u = p[:, b] - p[:, k]
        v = p[:, c] - p[:, k]
        cos = (u * v).sum(1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        angles.append(np.arccos(np.clip(cos, -1.0, 1.0)))
    return float(np.min(angles))
