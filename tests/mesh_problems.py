"""Small meshes given as arrays, for the tests of :mod:`signorini.mesh` and of code on meshes.

- ``SQUARE_P``, ``SQUARE_C``: the unit square split along its diagonal 0-2;
- :func:`square4`, :func:`hexfan`, :func:`jittered_delaunay`: hand-made and Delaunay meshes
  (``HAND_MESHES`` maps a name to each);
- ``ALL``: the part specification that puts every boundary edge in one part ``"all"``;
- :func:`affine_copy`: the image of a mesh under an orientation-preserving affine map.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from signorini.mesh.mesh import Mesh


def everything(x: np.ndarray) -> np.ndarray:
    return np.ones(x.shape[:-1], dtype=bool)


ALL = {"all": everything}

# unit square split along its diagonal 0-2
SQUARE_P = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
SQUARE_C = np.array([[0, 1, 2], [0, 2, 3]])


def square4() -> tuple[np.ndarray, np.ndarray]:
    """Unit square cut into four triangles through its centre."""
    p = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]], dtype=float)
    c = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    return p, c


def hexfan() -> tuple[np.ndarray, np.ndarray]:
    """Regular hexagon fanned around its centre, with one more triangle on a side."""
    t = np.arange(6) * np.pi / 3
    p = np.vstack([[0.0, 0.0], np.column_stack([np.cos(t), np.sin(t)]), [[1.5, 0.8]]])
    c = [[0, 1 + k, 1 + (k + 1) % 6] for k in range(6)] + [[1, 7, 2]]
    return p, np.array(c)


def jittered_delaunay(n: int = 7, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Delaunay triangulation (scipy) of a jittered grid on the unit square, made CCW."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, n)
    x, y = np.meshgrid(s, s)
    p = np.column_stack([x.ravel(), y.ravel()])
    inner = (p > 0).all(1) & (p < 1).all(1)
    p[inner] += rng.uniform(-0.3, 0.3, size=(inner.sum(), 2)) / (n - 1)
    c = Delaunay(p).simplices.astype(np.int64)
    d1, d2 = p[c[:, 1]] - p[c[:, 0]], p[c[:, 2]] - p[c[:, 0]]
    cw = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] < 0
    c[cw] = c[cw][:, [0, 2, 1]]
    return p, c


HAND_MESHES = {
    "square2": lambda: (SQUARE_P, SQUARE_C),
    "square4": square4,
    "hexfan": hexfan,
    "delaunay": jittered_delaunay,
}


def affine_copy(mesh: Mesh, matrix: np.ndarray, shift: np.ndarray) -> Mesh:
    """The image of ``mesh`` under ``x -> matrix @ x + shift``, parts given as edge lists."""
    assert np.linalg.det(matrix) > 0
    points = mesh.points @ np.asarray(matrix).T + shift
    parts = {name: mesh.facets[mesh.part_facets(name)] for name in mesh.part_names}
    return Mesh.from_arrays(points, mesh.cells, parts)
