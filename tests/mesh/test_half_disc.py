"""The half-disc mesh of the Hertz example (signorini.mesh.builders.half_disc)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.fem import iso
from signorini.fem.quadrature import triangle_rule
from signorini.fem.space import P2Space
from signorini.mesh.builders import half_disc
from signorini.mesh.curves import Circle
from signorini.mesh.mesh import MeshError
from signorini.mesh.refine import refine_uniform


def isoparametric_area(mesh) -> float:
    """Area of the mesh with its curved cells as the quadratic maps of the P2 space."""
    cells, nodes = P2Space(mesh).curved
    xi, w = triangle_rule(4)
    _, _, det = iso.geometry(nodes, xi)
    return float(mesh.area.sum() - mesh.area[cells].sum() + (det @ w).sum())


def test_areas_converge_to_the_half_disc_polygon_like_h2_isoparametric_like_h4():
    radius = 2.0
    exact = np.pi * radius**2 / 2
    mesh = half_disc(radius, 2)
    chord, curved = [], []
    for _ in range(4):
        chord.append(exact - mesh.area.sum())
        curved.append(abs(isoparametric_area(mesh) - exact))
        mesh = refine_uniform(mesh).mesh
    chord_rate = np.log2(np.array(chord[:-1]) / chord[1:])
    curved_rate = np.log2(np.array(curved[:-1]) / curved[1:])
    print("polygon area errors", chord, "rates", chord_rate)
    print("isoparametric area errors", curved, "rates", curved_rate)
    assert np.all(np.array(chord) > 0)
    assert np.all(np.abs(chord_rate - 2) < 0.05), chord_rate
    assert np.all(curved_rate > 3.9), curved_rate
    assert curved[-1] < 1e-4 * chord[-1]


@pytest.mark.parametrize("rings", [1, 2, 3, 4, 6])
def test_parts_lengths_and_cells(rings: int):
    radius = 1.5
    mesh = half_disc(radius, rings)
    assert mesh.n_cells == 3 * rings**2
    assert mesh.part_names == ("top", "arc")
    assert mesh.part_measure("top") == pytest.approx(2 * radius, rel=1e-14)
    n_arc = 3 * rings
    assert mesh.part_facets("arc").size == n_arc
    # the arc's chords: n_arc equal chords of the angle π / n_arc
    chord = 2 * radius * np.sin(np.pi / (2 * n_arc))
    assert mesh.part_measure("arc") == pytest.approx(n_arc * chord, rel=1e-13)
    assert np.all(mesh.area > 0)
    assert mesh.min_angle() > np.radians(29.9), np.degrees(mesh.min_angle())
    curve = mesh.curves[mesh.part_index("arc")]
    assert isinstance(curve, Circle)
    assert curve.radius == radius and np.array_equal(curve.center, [0.0, radius])
    arc = np.unique(mesh.boundary[mesh.boundary_part == mesh.part_index("arc")])
    distance = np.hypot(*(mesh.points[arc] - [0.0, radius]).T) - radius
    assert np.abs(distance).max() < 1e-14 * radius
    assert P2Space(mesh).curved is not None  # no isoparametric cell folds over


@pytest.mark.parametrize("rings", [2, 4])
def test_even_rings_mirror_symmetric_with_the_bottom_point_a_vertex(rings: int):
    mesh = half_disc(1.0, rings)
    assert np.any(np.all(mesh.points == 0.0, axis=1))
    mirrored = mesh.points[mesh.cells] * [-1.0, 1.0]
    key = {tuple(sorted(map(tuple, np.round(c, 12)))) for c in mesh.points[mesh.cells]}
    assert {tuple(sorted(map(tuple, np.round(c, 12)))) for c in mirrored} == key


def test_grading_bounds_the_cells_by_their_distance_to_the_bottom_point():
    h_bottom, grading = 0.01, 0.5
    mesh = half_disc(1.0, 4, h_bottom=h_bottom, grading=grading)
    distance = np.hypot(*mesh.points[mesh.cells].transpose(2, 0, 1)).min(axis=1)
    assert np.all(mesh.h <= np.maximum(h_bottom, grading * distance) * (1 + 1e-12))
    near = distance == 0.0
    assert near.any() and mesh.h[near].max() <= h_bottom
    assert mesh.h.max() > 20 * h_bottom  # graded, not uniform
    assert mesh.min_angle() > np.radians(25), np.degrees(mesh.min_angle())
    arc = np.unique(mesh.boundary[mesh.boundary_part == mesh.part_index("arc")])
    assert np.abs(np.hypot(*(mesh.points[arc] - [0.0, 1.0]).T) - 1.0).max() < 1e-14
    assert P2Space(mesh).curved is not None


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": 0.0}, "radius"),
        ({"radius": np.nan}, "radius"),
        ({"rings": 0}, "rings"),
        ({"rings": 2.5}, "rings"),
        ({"h_bottom": -1.0}, "h_bottom"),
        ({"grading": 0.0}, "grading"),
    ],
)
def test_half_disc_rejects_bad_input(kwargs, match: str):
    with pytest.raises(MeshError, match=match):
        half_disc(**kwargs)
