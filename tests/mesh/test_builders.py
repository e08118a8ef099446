"""Tests of the built-in structured meshes in :mod:`signorini.mesh.builders`."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import MeshError

PATTERNS = ("unionjack", "right", "left", "crossed")
DOMAINS = [(0.0, 1.0, 0.0, 1.0), (-1.0, 2.0, 0.5, 1.25), (10.0, 10.5, -3.0, 4.0)]


@pytest.mark.parametrize("pattern", PATTERNS)
@pytest.mark.parametrize(("nx", "ny"), [(1, 1), (3, 2), (4, 6)])
@pytest.mark.parametrize("box", DOMAINS)
def test_counts_area_and_parts(pattern: str, nx: int, ny: int, box) -> None:
    x0, x1, y0, y1 = box
    m = rectangle(x0, x1, y0, y1, nx=nx, ny=ny, pattern=pattern)
    per_square = 4 if pattern == "crossed" else 2
    assert m.n_cells == per_square * nx * ny
    assert m.n_points == (nx + 1) * (ny + 1) + (nx * ny if pattern == "crossed" else 0)
    assert m.n_points - m.n_edges + m.n_cells == 1  # Euler characteristic of a disc
    assert m.area.sum() == pytest.approx((x1 - x0) * (y1 - y0), rel=1e-13)
    assert np.all(m.area > 0)
    assert m.part_names == ("bottom", "right", "top", "left")
    for name, length, count in [
        ("bottom", x1 - x0, nx),
        ("top", x1 - x0, nx),
        ("left", y1 - y0, ny),
        ("right", y1 - y0, ny),
    ]:
        assert m.part_measure(name) == pytest.approx(length, rel=1e-13)
        assert m.part_facets(name).size == count
    mid = m.edge_midpoints
    assert np.all(mid[m.part_facets("bottom"), 1] == y0)
    assert np.all(mid[m.part_facets("top"), 1] == y1)
    assert np.all(mid[m.part_facets("left"), 0] == x0)
    assert np.all(mid[m.part_facets("right"), 0] == x1)
    # every grid square is covered exactly: the cells whose centroid lies in it fill it
    dx, dy = (x1 - x0) / nx, (y1 - y0) / ny
    centroid = m.points[m.cells].mean(axis=1)
    square = (
        np.floor((centroid[:, 0] - x0) / dx) * ny + np.floor((centroid[:, 1] - y0) / dy)
    ).astype(int)
    covered = np.bincount(square, weights=m.area, minlength=nx * ny)
    assert np.allclose(covered, dx * dy, rtol=1e-12)
    assert np.all(np.bincount(square, minlength=nx * ny) == per_square)


@pytest.mark.parametrize("pattern", ["unionjack", "right", "left"])
def test_diagonal_patterns_are_right_triangles_with_hypotenuse_first(pattern: str) -> None:
    m = rectangle(0, 3, 0, 1, nx=3, ny=4, pattern=pattern)
    p = m.points[m.cells]
    # the newest vertex (local 2) carries the right angle: local edge 0 is the hypotenuse
    u, v = p[:, 0] - p[:, 2], p[:, 1] - p[:, 2]
    assert np.allclose((u * v).sum(axis=1), 0.0, atol=1e-14)
    assert np.allclose(m.h, np.hypot(1.0, 0.25), rtol=1e-14)
    d = p[:, 1] - p[:, 0]
    slope = np.sign(d[:, 0] * d[:, 1])
    if pattern == "right":
        assert np.all(slope > 0)
    elif pattern == "left":
        assert np.all(slope < 0)
    else:
        assert (slope > 0).sum() == (slope < 0).sum() == 12


def test_crossed_cells_meet_at_square_centres() -> None:
    m = rectangle(0, 2, 0, 1, nx=2, ny=1, pattern="crossed")
    # right isosceles triangles: the square's side is the refinement edge, the centre the
    # newest vertex, and each centre is shared by exactly four cells
    apex = m.points[m.cells[:, 2]]
    assert sorted(set(map(tuple, apex.tolist()))) == [(0.5, 0.5), (1.5, 0.5)]
    assert np.bincount(m.cells[:, 2]).max() == 4
    assert np.allclose(m.edge_length[m.cell2edge[:, 0]], 1.0, rtol=1e-15)
    assert m.min_angle() == pytest.approx(np.pi / 4, rel=1e-14)


def cell_keys(
    m,
    x0: float,
    y0: float,
    dx: float,
    dy: float,
    mirror_x: bool = False,
    mirror_y: bool = False,
    nx: int = 0,
    ny: int = 0,
) -> set:
    """Cells as frozensets of vertex coordinates on the half-step integer grid."""
    q = np.rint(2 * (m.points - [x0, y0]) / [dx, dy]).astype(np.int64)
    assert np.allclose(q * [dx, dy] / 2 + [x0, y0], m.points, atol=1e-12)
    if mirror_x:
        q[:, 0] = 2 * nx - q[:, 0]
    if mirror_y:
        q[:, 1] = 2 * ny - q[:, 1]
    return {frozenset(map(tuple, q[c].tolist())) for c in m.cells}


@pytest.mark.parametrize(("nx", "ny"), [(2, 2), (4, 2), (6, 4), (8, 8)])
def test_unionjack_mirror_symmetric(nx: int, ny: int) -> None:
    x0, x1, y0, y1 = -1.0, 2.0, 0.0, 1.5
    m = rectangle(x0, x1, y0, y1, nx=nx, ny=ny, pattern="unionjack")
    dx, dy = (x1 - x0) / nx, (y1 - y0) / ny
    cells = cell_keys(m, x0, y0, dx, dy)
    assert len(cells) == m.n_cells
    assert cell_keys(m, x0, y0, dx, dy, mirror_x=True, nx=nx) == cells
    assert cell_keys(m, x0, y0, dx, dy, mirror_y=True, ny=ny) == cells
    assert cell_keys(m, x0, y0, dx, dy, mirror_x=True, mirror_y=True, nx=nx, ny=ny) == cells


@pytest.mark.parametrize(("nx", "ny"), [(2, 2), (4, 6)])
def test_unionjack_diagonals_point_to_the_centre(nx: int, ny: int) -> None:
    m = rectangle(0, 1, 0, 1, nx=nx, ny=ny, pattern="unionjack")
    p = m.points[m.cells]
    d = p[:, 1] - p[:, 0]  # the diagonal (hypotenuse) of the cell's square
    to_centre = 0.5 - p.mean(axis=1)
    # the diagonal is parallel to the direction from its square to the centre, in sign
    assert np.all(np.sign(d[:, 0] * d[:, 1]) == np.sign(to_centre[:, 0] * to_centre[:, 1]))


def test_one_direction_patterns_are_not_mirror_symmetric() -> None:
    # the comparison above can fail: "right" and "left" are mirror images of each other,
    # each is symmetric under the half turn but not under a mirror
    nx = ny = 4
    right = rectangle(nx=nx, ny=ny, pattern="right")
    left = rectangle(nx=nx, ny=ny, pattern="left")
    h = 1 / nx
    r = cell_keys(right, 0, 0, h, h)
    assert cell_keys(right, 0, 0, h, h, mirror_x=True, nx=nx) != r
    assert cell_keys(right, 0, 0, h, h, mirror_x=True, nx=nx) == cell_keys(left, 0, 0, h, h)
    assert cell_keys(right, 0, 0, h, h, mirror_x=True, mirror_y=True, nx=nx, ny=ny) == r


@pytest.mark.parametrize(("nx", "ny"), [(1, 1), (3, 2), (5, 3)])
def test_crossed_symmetric_for_any_counts(nx: int, ny: int) -> None:
    m = rectangle(0, 2, 0, 1, nx=nx, ny=ny, pattern="crossed")
    dx, dy = 2 / nx, 1 / ny
    cells = cell_keys(m, 0, 0, dx, dy)
    assert cell_keys(m, 0, 0, dx, dy, mirror_x=True, nx=nx) == cells
    assert cell_keys(m, 0, 0, dx, dy, mirror_y=True, ny=ny) == cells


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"x0": 1.0, "x1": 1.0}, r"x0 < x1 and y0 < y1, got \[1.0, 1.0\]"),
        ({"y0": 2.0, "y1": 1.0}, r"x0 < x1 and y0 < y1"),
        ({"x1": np.nan}, r"x0 < x1 and y0 < y1"),
        ({"nx": 0}, "nx and ny must be positive integers, got 0, 4"),
        ({"ny": 2.5}, "nx and ny must be positive integers, got 4, 2.5"),
        ({"pattern": "diamond"}, r"unknown pattern 'diamond'"),
    ],
)
def test_rectangle_rejects_bad_input(kwargs, match: str) -> None:
    with pytest.raises(MeshError, match=match):
        rectangle(**kwargs)


def test_rectangle_accepts_integral_floats() -> None:
    m, ref = rectangle(nx=3.0, ny=2.0), rectangle(nx=3, ny=2)
    assert np.array_equal(m.points, ref.points) and np.array_equal(m.cells, ref.cells)
    assert np.array_equal(m.boundary_part, ref.boundary_part)
    assert m.part_measure("bottom") == pytest.approx(1.0, rel=1e-14)
    assert m.part_facets("left").size == 2
