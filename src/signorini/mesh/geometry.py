"""Geometry of straight facets and simplices: facet measures and unit normals, signed
measures of cells.

The one place where a straight facet's normal is computed (:func:`facet_normals`), chosen
by the dimension:

- d = 2, a segment traversed from ``a`` to ``b``: the right-hand normal
  ``(d_y, −d_x) / |d|`` with ``d = b − a`` and ``|d|`` by ``np.hypot``. It points out of a
  counter-clockwise cell whose local edge runs from ``a`` to ``b``, so it is the outward
  normal of every boundary facet taken in its cell's counter-clockwise order.
- d = 3, a triangle ``(a, b, c)``: ``n = (b − a) × (c − a) / |…|``, the measure half the
  norm; outward for a face whose vertices run counter-clockwise seen from outside.

:func:`spanned_normals` is the kernel under it, also read where the spanning vectors are a
curve's tangent (a curved edge's line element and normal).
"""

from __future__ import annotations

import numpy as np

from .jacobians import affine_jacobian
from .reference import TRIANGLE

__all__ = ["facet_normals", "min_angle", "signed_area", "spanned_normals"]


def spanned_normals(spans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Norms and unit normals of the parallelotopes spanned by ``d − 1`` vectors in R^d.

    Parameters
    ----------
    spans : (..., d − 1, d) float array
        d = 2: one vector ``t`` (a segment's direction or a curve's tangent); d = 3: two
        vectors ``u, v``.

    Returns
    -------
    element : (...) float array
        d = 2: ``|t|`` (``np.hypot``); d = 3: ``|u × v|``.
    normal : (..., d) float array
        d = 2: ``(t_y, −t_x) / |t|``, the tangent turned clockwise; d = 3: ``u × v / |u × v|``.
    """
    spans = np.asarray(spans, dtype=np.float64)
    if spans.shape[-1] == 2:
        t = spans[..., 0, :]
        element = np.hypot(t[..., 0], t[..., 1])
        return element, np.stack([t[..., 1], -t[..., 0]], axis=-1) / element[..., None]
    n = np.cross(spans[..., 0, :], spans[..., 1, :])
    element = np.sqrt(np.einsum("...i,...i->...", n, n))
    return element, n / element[..., None]


def facet_normals(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Measures |F| and unit normals of straight facets given by their ``d`` vertices.

    Parameters
    ----------
    corners : (..., d, d) float array
        The facets' vertices in their cell's order (d = 2: ``(a, b)``; d = 3: ``(a, b, c)``).

    Returns
    -------
    measure : (...) float array
        d = 2: the length ``|b − a|``; d = 3: the area ``|(b − a) × (c − a)| / 2``.
    normal : (..., d) float array
        Outward for a positively oriented cell (module docstring).
    """
    corners = np.asarray(corners, dtype=np.float64)
    element, normal = spanned_normals(corners[..., 1:, :] - corners[..., :1, :])
    if corners.shape[-1] == 2:
        return element, normal
    return 0.5 * element, normal


def signed_area(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Signed measures ``det J / d!`` of simplices (areas of triangles, positive for
    counter-clockwise ones; volumes of tetrahedra).

    Parameters
    ----------
    points : (n_points, d) float array
    cells : (n_cells, d + 1) int array

    Returns
    -------
    (n_cells,) float array
    """
    _, det = affine_jacobian(points[cells])
    return 0.5 * det if points.shape[-1] == 2 else det / 6.0


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
