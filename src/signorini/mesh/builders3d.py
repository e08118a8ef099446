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

The curved meshes map a Kuhn grid of the unit cube (square) onto the eighth ball (quarter
disc) by :func:`round_corner`, which keeps the symmetry planes in place and the cells shape
regular: the smallest dihedral angle falls with ``n`` towards the smallest over the domain of
the Kuhn cells mapped by the map's Jacobian, above :data:`MIN_DIHEDRAL_BALL` (28°) for
:func:`eighth_ball` (45.0° at ``n = 1``, 39.5° at 2, 33.7° at 4, 30.9° at 8, 29.1° at 24;
the limit 28.6° at the rim ``x = 0``, ``y = z = 1``) and above
:data:`MIN_DIHEDRAL_CYLINDER` (20°) for :func:`quarter_cylinder` with its default ``nz``
(35.3°, 28.2°, 24.4°, 22.6°, 21.4° at the same ``n``; the limit 20.9° where the cylinder
meets the plane ``x = 0``); docs/method.md, *Three dimensions: bisection*.

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
from .surfaces import Cylinder, Sphere
from .topology import boundary_facets

__all__ = [
    "BOX_PARTS",
    "MIN_DIHEDRAL_BALL",
    "MIN_DIHEDRAL_CYLINDER",
    "box",
    "eighth_ball",
    "kuhn_grid",
    "kuhn_paths",
    "mirrored_box",
    "mirrored_kuhn_grid",
    "quarter_cylinder",
]

#: The six faces of a box, as parts: ``x0``/``x1`` at the lower/upper x, and so on.
BOX_PARTS = ("x0", "x1", "y0", "y1", "z0", "z1")

#: A lower bound (degrees) of the smallest dihedral angle of :func:`eighth_ball` at every
#: ``n`` (module docstring: the limit of large ``n`` is 28.6°).
MIN_DIHEDRAL_BALL = 28.0
#: The same for :func:`quarter_cylinder` with its default ``nz`` (the limit is 20.9°).
MIN_DIHEDRAL_CYLINDER = 20.0

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


def kuhn_paths(cells: np.ndarray, *, mirrored: bool = False) -> np.ndarray:
    """The Kuhn paths ``(n_cells, 4)`` of the cells of :func:`kuhn_grid` (and of
    :func:`box` and :func:`quarter_cylinder`, whose cells keep its order; of
    :func:`eighth_ball` with ``mirrored``, whose cells are its mirror image, all with their
    vertices 1 and 2 swapped): the tagged vertex order ``x0 … x3`` of bisection's initial
    condition."""
    odd = np.tile(_ODD != mirrored, cells.shape[0] // 6)
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


def mirrored_kuhn_grid(
    nx: int, ny: int, nz: int, axes: tuple[int, ...] = (1, 2)
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Kuhn grid of :func:`kuhn_grid` with every cube in the upper half along each of
    ``axes`` mirrored in that axis: the split is symmetric about the mid-planes of ``axes``
    (a 3D "union jack").

    A cube's Kuhn path ``x0 + o_0 … x0 + o_3`` (offsets ``o ∈ {0, 1}³``) becomes ``x0 + o′``
    with ``o′_a = 1 − o_a`` for each axis ``a`` it is mirrored in: the Kuhn path of the
    mirrored diagonal. Faces across a mid-plane are each other's mirror images, so the mesh
    is conforming; each cell keeps its path as its bisection tag order, and a cell mirrored
    an odd number of times has its vertices 1 and 2 swapped (positive orientation).

    Parameters
    ----------
    nx, ny, nz : int
        Cubes per direction; even along each axis of ``axes``.
    axes : tuple of int
        The axes (0, 1, 2 for x, y, z) whose mid-planes are planes of symmetry.

    Returns
    -------
    grid : (n_points, 3) int array
        As :func:`kuhn_grid`.
    cells : (6 nx ny nz, 4) int array
        Positively oriented.
    paths : (6 nx ny nz, 4) int array
        The cells' Kuhn paths (the tag order of bisection, :func:`~.refine3d.tagged`).
    """
    n = np.array(_counts((nx, ny, nz)))
    axes = tuple(int(a) for a in axes)
    if any(a not in (0, 1, 2) for a in axes) or len(set(axes)) != len(axes):
        raise MeshError(f"mirrored_kuhn_grid: axes must be distinct among 0, 1, 2, got {axes}")
    if any(n[a] % 2 for a in axes):
        raise MeshError(
            f"mirrored_kuhn_grid: the counts along the mirrored axes {axes} must be even, "
            f"got {tuple(n.tolist())}"
        )
    grid, _ = kuhn_grid(*n)
    shape = n + 1
    stride = np.array([1, shape[0], shape[0] * shape[1]])
    ck, cj, ci = np.meshgrid(np.arange(n[2]), np.arange(n[1]), np.arange(n[0]), indexing="ij")
    corner = np.column_stack([ci.ravel(), cj.ravel(), ck.ravel()])  # (n_cubes, 3)
    offsets = np.concatenate(
        [np.zeros((6, 1, 3), np.int64), np.cumsum(np.eye(3, dtype=np.int64)[_SIGMA], axis=1)],
        axis=1,
    )  # (6, 4, 3): the Kuhn paths' vertex offsets
    flip = np.zeros(corner.shape, dtype=bool)
    for a in axes:  # a loop over the mirrored axes
        flip[:, a] = corner[:, a] >= n[a] // 2
    o = np.where(flip[:, None, None, :], 1 - offsets[None], offsets[None])  # (c, 6, 4, 3)
    paths = ((corner[:, None, None, :] + o) @ stride).reshape(-1, 4)
    odd = (_ODD[None, :] != (flip.sum(axis=1) % 2 == 1)[:, None]).ravel()
    cells = paths.copy()
    cells[odd] = cells[odd][:, [0, 2, 1, 3]]
    return grid, cells, paths


def mirrored_box(
    nx: int,
    ny: int,
    nz: int,
    *,
    axes: tuple[int, ...] = (1, 2),
    lower: tuple[float, float, float] = (0.0, 0.0, 0.0),
    upper: tuple[float, float, float] = (1.0, 1.0, 1.0),
) -> Mesh:
    """The box of :func:`box` on the mirrored Kuhn grid (:func:`mirrored_kuhn_grid`): its
    cells are symmetric about the mid-planes of ``axes``, and with ``axes = (1, 2)`` and
    ``ny == nz`` also under the swap of y and z; on a face normal to the third axis the
    diagonals of the squares run towards the face's centre, along both of its diagonals.

    The cells carry their Kuhn paths as bisection tags (:func:`~.refine3d.tagged`), so
    refinement bisects the mirrored cells as mirror images and keeps the symmetry.

    Parameters
    ----------
    nx, ny, nz : int
        Cubes per direction, even along each axis of ``axes``.
    axes : tuple of int
        The axes whose mid-planes are planes of symmetry of the mesh.
    lower, upper : (3,) float
        Opposite corners.

    Returns
    -------
    Mesh
        Parts :data:`BOX_PARTS`, as :func:`box`.
    """
    from .refine3d import tagged  # refine3d reads this module's Kuhn paths

    lo, hi = np.asarray(lower, dtype=np.float64), np.asarray(upper, dtype=np.float64)
    if (
        lo.shape != (3,)
        or hi.shape != (3,)
        or not (np.isfinite([lo, hi]).all() and (hi > lo).all())
    ):
        raise MeshError(
            f"mirrored_box needs lower < upper, two points (x, y, z); got {lower}, {upper}"
        )
    grid, cells, paths = mirrored_kuhn_grid(nx, ny, nz, axes)
    n = np.array([nx, ny, nz])
    points = lo + (hi - lo) * (grid / n)
    parts = _face_parts(grid, boundary_facets(cells, TETRAHEDRON.facets), n)
    return tagged(Mesh.from_arrays(points, cells, parts), paths)


def round_corner(p: np.ndarray) -> np.ndarray:
    """Map the unit cube (square) ``[0, 1]^k`` onto the unit ball's (disc's) positive
    orthant: ``p ↦ p ((1 − w) + w |p|_∞ / |p|_2)`` with ``w = |p|_∞``.

    Each ray from the origin maps into itself, with the radial factor ``r ↦ r (1 − r (1 −
    c))``, ``c = 1 / |d|_2 ≥ 1/√k`` for the ray's point ``d`` on ``|d|_∞ = 1``: increasing
    (its derivative ``1 − 2 r (1 − c) ≥ 2/√3 − 1 > 0`` for k ≤ 3), so the map is one to one;
    it is the identity near the origin and radial (``|p|_∞ = 1`` onto the sphere) at the
    far sides, and a coordinate that is 0 stays 0 (the symmetry planes stay put).

    Parameters
    ----------
    p : (n, k) float array
        Points of ``[0, 1]^k``.

    Returns
    -------
    (n, k) float array
        Their images; those with ``|p|_∞ = 1`` on the unit sphere to round-off.
    """
    w = np.abs(p).max(axis=1)
    norm = np.sqrt(np.einsum("ij,ij->i", p, p))
    ratio = np.divide(w, norm, out=np.ones_like(w), where=norm > 0)
    return p * ((1.0 - w) + w * ratio)[:, None]


def _curved(points: np.ndarray, cells: np.ndarray, parts: dict, part: str, surface: object) -> Mesh:
    """The mesh of the arrays with ``part`` carrying ``surface``, its vertices put onto it
    exactly (the map leaves them within round-off of it)."""
    on = np.unique(parts[part])
    points[on] = surface.project(points[on])  # type: ignore[attr-defined]
    return Mesh.from_arrays(points, cells, parts).with_curve(part, surface)  # type: ignore[arg-type]


def eighth_ball(
    n: int, *, radius: float = 1.0, center: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> Mesh:
    """The eighth of the ball of ``radius`` R about ``center`` c below it, ``x ≥ c_x``,
    ``y ≥ c_y``, ``z ≤ c_z``: the Hertz sphere's symmetric model, its pole ``c − (0, 0, R)``
    the point where contact starts.

    A Kuhn grid of ``n³`` cubes of ``[0, 1]³`` mapped by :func:`round_corner` and mirrored
    in z (so the cells are those of :func:`kuhn_grid`, each with its vertices 1 and 2
    swapped: :func:`kuhn_paths` with ``mirrored``). Boundary parts: ``"x0"`` (``x = c_x``)
    and ``"y0"`` (``y = c_y``), the symmetry planes through the pole; ``"z1"`` (``z =
    c_z``, the equatorial plane, where the load goes); ``"sphere"``, which carries
    ``Sphere(c, R)`` (:meth:`Mesh.with_curve`), its vertices on the sphere to round-off.

    Parameters
    ----------
    n : int
        Cubes per direction of the grid, positive (``6 n³`` cells).
    radius : float
        R, positive.
    center : (3,) float
        The centre c.

    Returns
    -------
    Mesh
        Its volume converges to π R³ / 6 like ``h²``.
    """
    sphere = Sphere(center, radius)
    grid, cells = kuhn_grid(n, n, n)
    mirror = np.array([1.0, 1.0, -1.0])
    points = sphere.center + sphere.radius * mirror * round_corner(grid / n)
    cells = cells[:, [0, 2, 1, 3]]  # positive after the mirror
    sides = _face_parts(grid, boundary_facets(cells, TETRAHEDRON.facets), np.array([n, n, n]))
    parts = {"x0": sides["x0"], "y0": sides["y0"], "z1": sides["z0"]}
    parts["sphere"] = np.concatenate([sides["x1"], sides["y1"], sides["z1"]])
    return _curved(points, cells, parts, "sphere", sphere)


def quarter_cylinder(
    n: int,
    nz: int | None = None,
    *,
    radius: float = 1.0,
    length: float = 1.0,
    center: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """The quarter of the cylinder of ``radius`` R and ``length`` L along z, ``x ≥ c_x``,
    ``y ≥ c_y``, ``c_z ≤ z ≤ c_z + L``, about the axis through ``center`` c.

    A Kuhn grid of ``n × n × nz`` cuboids of ``[0, 1]² × [0, L]``, its cross-section mapped
    by :func:`round_corner`. Boundary parts: ``"x0"``, ``"y0"`` (the symmetry planes through
    the axis), ``"z0"``, ``"z1"`` (the ends) and ``"cylinder"``, which carries
    ``Cylinder(c, (0, 0, 1), R)``.

    Parameters
    ----------
    n, nz : int
        Cuboids across the radius and along the axis, positive; by default ``nz`` makes
        them about as long as wide (``round(n L / R)``, at least 1).
    radius, length : float
        R and L, positive.
    center : (3,) float
        The point c of the axis at the lower end.
    """
    if not (np.isfinite(length) and length > 0):
        raise MeshError(f"quarter_cylinder: length must be a positive number, got {length!r}")
    cylinder = Cylinder(center, (0.0, 0.0, 1.0), radius)
    if nz is None:
        nz = max(1, round(n * length / cylinder.radius))
    grid, cells = kuhn_grid(n, n, nz)
    section = round_corner(grid[:, :2] / n) * cylinder.radius
    points = cylinder.point + np.column_stack([section, grid[:, 2] * (length / nz)])
    sides = _face_parts(grid, boundary_facets(cells, TETRAHEDRON.facets), np.array([n, n, nz]))
    parts = {name: sides[name] for name in ("x0", "y0", "z0", "z1")}
    parts["cylinder"] = np.concatenate([sides["x1"], sides["y1"]])
    return _curved(points, cells, parts, "cylinder", cylinder)
