"""Built-in structured meshes."""

from __future__ import annotations

import numpy as np

from .mesh import Mesh, MeshError

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
    return Mesh.from_arrays(points, cells, parts)
