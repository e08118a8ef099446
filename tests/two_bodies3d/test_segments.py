"""The segmentation of a 3D mortar interface (docs/method.md, *Two bodies in three
dimensions*): Sutherland–Hodgman clipping against hand cases, and the integration cells of
every slave face tiling it where the master covers it, on non-matching flat meshes."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.mortar3d_segments import (
    MAX_VERTICES,
    ON_LINE,
    clip_polygons,
    polygon_areas,
    segments,
)
from signorini.fem.space import space_of
from signorini.mesh.bodies import union
from signorini.mesh.builders3d import box

UNIT = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def clip_one(subject: np.ndarray, clip: np.ndarray) -> tuple[np.ndarray, int]:
    poly = np.zeros((1, MAX_VERTICES, 2))
    poly[0, : len(subject)] = subject
    out, count = clip_polygons(poly, np.array([len(subject)]), clip[None], ON_LINE)
    return out[0, : count[0]], int(count[0])


def same_polygon(a: np.ndarray, b: np.ndarray) -> bool:
    """The same vertices in the same cyclic order."""
    if len(a) != len(b):
        return False
    if len(a) == 0:
        return True
    start = int(np.argmin(np.linalg.norm(a - b[0], axis=1)))
    return np.allclose(np.roll(a, -start, axis=0), b, atol=1e-15)


@pytest.mark.parametrize(
    ("clip", "expected"),
    [
        (UNIT, UNIT),  # the triangle itself
        (4 * UNIT - 1, UNIT),  # a triangle holding it
        (UNIT + [0.5, 0.0], np.array([[0.5, 0.0], [1.0, 0.0], [0.5, 0.5]])),
        (UNIT + [2.0, 0.0], np.zeros((0, 2))),  # apart
        # a vertex on the clipping line: below the line through (5, −1) and (−1, ½)
        (np.array([[-1.0, -1.0], [5.0, -1.0], [-1.0, 0.5]]),
         np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.25]])),
        # the band y ≤ ½ (a wide triangle with its top side on y = ½): a quadrilateral
        (np.array([[0.5, -20.0], [20.0, 0.5], [-20.0, 0.5]]),
         np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [0.0, 0.5]])),
    ],
)  # fmt: skip
def test_clip_hand_cases(clip, expected):
    got, count = clip_one(UNIT, clip)
    assert count == len(expected)
    assert same_polygon(got, expected)


def test_clip_hexagon_of_two_triangles():
    """An equilateral triangle and its point reflection through the centroid meet in the
    regular hexagon of 2/3 of the triangle's area, its vertices at the sides' thirds."""
    t = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    centre = t.mean(axis=0)
    got, count = clip_one(t, 2 * centre - t)
    assert count == 6
    area = polygon_areas(np.pad(got, ((0, MAX_VERTICES - 6), (0, 0)))[None], np.array([6]))
    assert area[0] == pytest.approx(2 / 3 * np.sqrt(3) / 4, rel=1e-14)
    thirds = np.concatenate([t + (np.roll(t, -1, axis=0) - t) * s for s in (1 / 3, 2 / 3)])
    assert np.abs(got[:, None] - thirds[None]).max(axis=2).min(axis=1).max() < 1e-15


def face_triangles(mesh, name: str) -> np.ndarray:
    space = space_of(mesh, "P2")
    return space.node_points[space.facet_nodes(mesh.part_facets(name))[:, :3]]


def areas(tri: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


@pytest.mark.parametrize("counts", [((3, 3, 2), (4, 4, 2)), ((4, 4, 2), (3, 3, 2)),
                                    ((5, 2, 1), (2, 7, 1))])  # fmt: skip
@pytest.mark.parametrize("turn", [False, True])
def test_cells_tile_the_slave_faces(counts, turn):
    """Stacked boxes with non-matching meshes (either side the finer), also the whole pair
    turned in space: every slave face's cells sum to its area (to 1e-13 relative), and
    every cell lies in its slave face."""
    upper = box(*counts[0], lower=(0, 0, 1), upper=(1, 1, 2))
    lower = box(*counts[1])
    mesh = union({"upper": upper, "lower": lower})
    slave, master = face_triangles(mesh, "upper.z0"), face_triangles(mesh, "lower.z1")
    if turn:
        R = rotation([1.0, 2.0, 0.5], 0.7)
        slave, master = slave @ R.T, master @ R.T
    seg = segments(slave, master)
    covered = np.bincount(seg.slave, weights=seg.area, minlength=len(slave))
    assert np.abs(covered / areas(slave) - 1).max() < 1e-13
    # each cell in the plane of its slave face and inside it (barycentric coordinates ≥ 0)
    s = slave[seg.slave]
    n = np.cross(s[:, 1] - s[:, 0], s[:, 2] - s[:, 0])
    off = np.einsum("ckx,cx->ck", seg.points - s[:, :1], n / np.linalg.norm(n, axis=1)[:, None])
    assert np.abs(off).max() < 1e-14
    assert np.isclose(seg.area, areas(seg.points), rtol=1e-12).all()


def test_cells_where_the_master_covers_part_of_a_face():
    """The upper unit square's faces turned about the vertical axis through its centre by
    θ = 0.3 rad, 0.01 above the lower box: faces inside the unit square are covered
    wholly, and all cells together cover the octagon of the two squares, of area
    ``1 − 4 h² / sin 2θ``, ``h = sin(π/4 + θ)/√2 − 1/2`` the height of each corner of the
    turned square beyond the side it crosses."""
    theta = 0.3
    upper = box(4, 4, 1, lower=(0, 0, 1.01), upper=(1, 1, 2))
    mesh = union({"upper": upper, "lower": box(3, 3, 1)})
    c = np.array([0.5, 0.5, 0.0])
    slave = (face_triangles(mesh, "upper.z0") - c) @ rotation([0, 0, 1], theta).T + c
    master = face_triangles(mesh, "lower.z1")
    seg = segments(slave, master)
    covered = np.bincount(seg.slave, weights=seg.area, minlength=len(slave)) / areas(slave)
    xy = slave[..., :2]
    inside = ((xy >= 0) & (xy <= 1)).all(axis=(1, 2))
    assert inside.any() and (~inside).any()
    assert np.abs(covered[inside] - 1).max() < 1e-13
    assert (covered[~inside] < 1 - 1e-3).all()
    h = np.sin(np.pi / 4 + theta) / np.sqrt(2) - 0.5
    assert seg.area.sum() == pytest.approx(1 - 4 * h**2 / np.sin(2 * theta), rel=1e-13)
