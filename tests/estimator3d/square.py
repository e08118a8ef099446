"""The unit square {z = 0} as P2 faces: n × n squares, each cut into two triangles."""

from __future__ import annotations

import numpy as np

from signorini.fem.p2 import REFERENCE_NODES


def square_faces(n: int) -> np.ndarray:
    """``(2 n², 6, 3)`` the P2 nodes of the faces (vertices counter-clockwise, then the side
    midpoints in the P2 order)."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    o = np.stack([i.ravel(), j.ravel()], axis=1) / n
    h = 1.0 / n
    lower = np.stack([o, o + [h, 0], o + [h, h]], axis=1)
    upper = np.stack([o, o + [h, h], o + [0, h]], axis=1)
    tri = np.concatenate([lower, upper])  # (k, 3, 2)
    nodes = tri[:, :1] + np.einsum("ak,fki->fai", REFERENCE_NODES, tri[:, 1:] - tri[:, :1])
    return np.concatenate([nodes, np.zeros(nodes.shape[:2] + (1,))], axis=2)


def quadratic_at(c, points):
    """The quadratic with monomial coefficients ``c`` in (x, y) at ``points (..., 3)``."""
    x, y = points[..., 0], points[..., 1]
    return c[0] + c[1] * x + c[2] * y + c[3] * x * x + c[4] * x * y + c[5] * y * y
