"""Built-in tetrahedral meshes: a box in a Kuhn (Freudenthal) split, the eighth ball of the
Hertz sphere's symmetric model and a quarter-cylinder segment, their curved faces carrying a
:mod:`~signorini.mesh.surfaces` surface.

The Kuhn split cuts each cube of a grid into the six tetrahedra along its main diagonal
``x0 → x0 + (1, 1, 1) h``: for a permutation ``σ`` of the axes the tetrahedron
``(x0, x0 + e_σ1, x0 + e_σ1 + e_σ2, x0 + e_σ1 + e_σ2 + e_σ3)`` (a *Kuhn path*). Every cube is
split alike, so the split is a translation-invariant, conforming mesh whose cells are all
congruent (dihedral angles 45°, 60°, 90°), and it meets the initial condition of
tagged-simplex bisection (Maubach, Traxler, Stevenson) as it is. The cells of odd ``σ`` have
negative orientation along the path and are listed with their vertices 1 and 2 swapped
(:mod:`signorini.mesh.tetrahedra`): a cell's Kuhn path is ``cells[c]`` for even ``σ`` and
``cells[c, [0, 2, 1, 3]]`` for odd ``σ`` (:func:`kuhn_paths`).

References
----------
Kuhn, H. W. (1960). Some combinatorial lemmas in topology. *IBM J. Res. Dev.* 4, 518–524.
Freudenthal, H. (1942). Simplizialzerlegungen von beschränkter Flachheit. *Ann. Math.* 43.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

from .mesh import Mesh, MeshError
from .reference import TETRAHEDRON
from .regions import RegionSpec
from .topology import boundary_facets

__all__ = ["BOX_PARTS", "box", "kuhn_grid", "kuhn_paths"]

#: The six faces of a box, as parts: ``x0``/``x1`` at the lower/upper x, and so on.
BOX_PARTS = ("x0", "x1", "y0", "y1", "z0", "z1")

#: The six permutations of the axes, the even ones first (``σ`` of the Kuhn path).
_SIGMA = np.array(list(permutations(range(3))))[[0, 3, 4, 1, 2, 5]]
_ODD = np.array([False, False, False, True, True, True])


def _counts(n: tuple[int, ...]) -> tuple[int, ...]:
    if len(n) != 3 or any(int(k) != k or k < 1 for k in n):
        raise MeshError(f"box: nx, ny, nz must be positive integers, got {n}")
    return tuple(int(k) for k in n)


def kuhn_grid(nx: int, ny: int, nz: int) -> tuple[np.ndarray, np.ndarray]:
    """The grid indices ``(n_points, 3)`` int of the vertices (vertex ``i + (nx + 1) (j +
    (ny + 1) k)`` at ``(i, j, k)``) and the positively oriented Kuhn cells ``(6 nx ny nz,
    4)`` of the grid of cubes ``nx × ny × nz`` (module docstring), cell ``6 c + s`` the
    ``s``-th permutation of cube ``c``."""
    nx, ny, nz = _counts((nx, ny, nz))
    shape = np.array([nx + 1, ny + 1, nz + 1])
    k, j, i = np.meshgrid(np.arange(nz + 1), np.arange(ny + 1), np.arange(nx + 1), indexing="ij")
    grid = np.column_stack([i.ravel(), j.ravel(), k.ravel()])
    stride = np.array([1, shape[0], shape[0] * shape[1]])
    ck, cj, ci = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    corner = np.column_stack([ci.ravel(), cj.ravel(), ck.ravel()]) @ stride  # (n_cubes,)
    step = stride[_SIGMA]  # (6, 3): the index steps along each Kuhn path
    path = np.concatenate([np.zeros((6, 1), np.int64), np.cumsum(step, axis=1)], axis=1)
    path[_ODD] = path[_ODD][:, [0, 2, 1, 3]]  # positive orientation
    cells = (corner[:, None, None] + path[None]).reshape(-1, 4)
    return grid, cells


def kuhn_paths(cells: np.ndarray) -> np.ndarray:
    """The Kuhn paths ``(n_cells, 4)`` of the cells of :func:`kuhn_grid` (and of
    :func:`box`, :func:`eighth_ball`, :func:`quarter_cylinder`, whose cells keep its order):
    the tagged vertex order ``x0 … x3`` of bisection's initial condition."""
    odd = np.tile(_ODD, cells.shape[0] // 6)
    out = np.array(cells, dtype=np.int64)
    out[odd] = out[odd][:, [0, 2, 1, 3]]
    return out


def _face_parts(grid: np.ndarray, faces: np.ndarray, n: np.ndarray) -> dict[str, np.ndarray]:
    """The boundary faces ``(k, 3)`` of each of the six sides of the grid, exactly by the
    vertices' grid indices (no floating-point selectors)."""
    g = grid[faces]  # (n_b, 3, 3)
    parts = {}
    for axis in range(3):  # a loop over the three axes
        parts[BOX_PARTS[2 * axis]] = faces[(g[:, :, axis] == 0).all(1)]
        parts[BOX_PARTS[2 * axis + 1]] = faces[(g[:, :, axis] == n[axis]).all(1)]
    return parts


def box(
    nx: int,
    ny: int,
    nz: int,
    *,
    lower: tuple[float, float, float] = (0.0, 0.0, 0.0),
    upper: tuple[float, float, float] = (1.0, 1.0, 1.0),
    regions: RegionSpec | None = None,
) -> Mesh:
    """The box ``[lower, upper]`` cut into ``nx × ny × nz`` cubes (cuboids) of six Kuhn
    tetrahedra each (module docstring).

    Boundary parts, named after the coordinate and the side: ``"x0"`` (``x = lower[0]``),
    ``"x1"`` (``x = upper[0]``), ``"y0"``, ``"y1"``, ``"z0"`` (the bottom), ``"z1"`` (the
    top) (:data:`BOX_PARTS`).

    Parameters
    ----------
    nx, ny, nz : int
        Number of cuboids in each direction, positive.
    lower, upper : (3,) float
        Opposite corners, ``lower < upper`` in each coordinate.
    regions : mapping region name -> selector, or array, optional
        As for :meth:`Mesh.from_arrays`, with selectors of the cell centroids ``x (n, 3)``.

    Returns
    -------
    Mesh
        ``(nx + 1)(ny + 1)(nz + 1)`` points, ``6 nx ny nz`` positively oriented cells, their
        vertex order the Kuhn paths' up to the swap of :func:`kuhn_paths`.

    Raises
    ------
    MeshError
        For counts or corners out of range.
    """
    lo, hi = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    if (
        lo.shape != (3,)
        or hi.shape != (3,)
        or not (np.isfinite([lo, hi]).all() and (hi > lo).all())
    ):
        raise MeshError(f"box needs lower < upper, two points (x, y, z); got {lower}, {upper}")
    n = np.array(_counts((nx, ny, nz)))
    grid, cells = kuhn_grid(*n)
    points = lo + (hi - lo) * (grid / n)
    parts = _face_parts(grid, boundary_facets(cells, TETRAHEDRON.facets), n)
    return Mesh.from_arrays(points, cells, parts, regions=regions)
