"""The 12-cell initial tagging with the matching condition (mesh/matching3d.py): the
subdivision conforms, keeps volumes, parts, surfaces and regions, passes ``matches``, and
bounds the closure rounds and the similarity classes under local refinement."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Delaunay

from signorini.mesh.bisect3d import bisect_tagged
from signorini.mesh.builders import rectangle
from signorini.mesh.builders3d import eighth_ball
from signorini.mesh.matching3d import SUBCELLS, prepare_for_bisection
from signorini.mesh.mesh import Mesh, MeshError
from signorini.mesh.quality3d import min_dihedral_angle, similarity_classes
from signorini.mesh.refine import refine_nvb
from signorini.mesh.refine3d import matches, tags_of
from signorini.mesh.tags3d import mesh_cells

from .test_bisect3d import assert_conforming, six_volumes


def delaunay_cube(n_points: int = 40, seed: int = 1) -> Mesh:
    """A Delaunay mesh of the cube's corners and random points (slivers included), the
    bottom face a part of its own, two regions split at x = 1/2."""
    rng = np.random.default_rng(seed)
    corners = np.stack(np.meshgrid(*[[0.0, 1.0]] * 3), axis=-1).reshape(-1, 3)
    points = np.vstack([corners, rng.random((n_points, 3))])
    cells = Delaunay(points).simplices
    with pytest.warns(Warning):  # slivers
        return Mesh.from_arrays(
            points,
            cells,
            {"bottom": lambda x: x[:, 2] < 1e-12, "rest": lambda x: x[:, 2] >= 1e-12},
            regions={"left": lambda x: x[:, 0] < 0.5, "right": lambda x: x[:, 0] >= 0.5},
        )


def test_the_subdivision_conforms_and_keeps_volumes_parts_and_regions():
    mesh = delaunay_cube()
    sub = prepare_for_bisection(mesh)
    assert sub.n_cells == SUBCELLS * mesh.n_cells
    assert sub.n_points == mesh.n_points + mesh.n_facets + mesh.n_cells
    np.testing.assert_array_equal(sub.points[: mesh.n_points], mesh.points)
    assert_conforming(sub)
    parent = np.arange(sub.n_cells) // SUBCELLS
    total = np.bincount(parent, six_volumes(sub.points, sub.cells), minlength=mesh.n_cells)
    np.testing.assert_allclose(total, six_volumes(mesh.points, mesh.cells), rtol=1e-12)
    np.testing.assert_array_equal(sub.cell_region, mesh.cell_region[parent])
    assert sub.region_names == mesh.region_names
    assert sub.part_names == mesh.part_names
    np.testing.assert_array_equal(
        np.bincount(sub.boundary_part), 3 * np.bincount(mesh.boundary_part)
    )
    for part in mesh.part_names:
        assert sub.part_measure(part) == pytest.approx(mesh.part_measure(part), rel=1e-13)
    bottom = sub.boundary[sub.boundary_part == sub.part_index("bottom")]
    assert np.all(sub.points[bottom][..., 2] == 0.0)


def test_the_subdivision_satisfies_the_matching_check_and_an_arbitrary_mesh_does_not():
    mesh = delaunay_cube()
    assert not matches(mesh.points, tags_of(mesh))  # the global vertex order
    sub = prepare_for_bisection(mesh)
    tags = tags_of(sub)
    assert np.all(tags.gamma == 2)
    assert matches(sub.points, tags)
    points = sub.points
    for _ in range(6):  # six uniform bisections, one round each: no closure needed
        result = bisect_tagged(points, tags, np.ones(tags.order.shape[0], bool))
        assert result.rounds == 1
        points, tags = result.points, result.tags


def test_refinement_towards_a_corner_saturates_the_classes():
    sub = prepare_for_bisection(delaunay_cube())
    initial = similarity_classes(sub.points, sub.cells)
    corner = np.flatnonzero(np.all(sub.points == 0.0, axis=1))[0]
    mesh, classes = sub, []
    for _ in range(10):
        ref = refine_nvb(mesh, (mesh.cells == corner).any(axis=1))
        mesh = ref.mesh
        classes.append(similarity_classes(mesh.points, mesh.cells))
    assert_conforming(mesh)
    # every cell descends from one of the 12 n initial sub-cells by the rule: the count
    # saturates, a few classes per initial sub-cell at most
    assert max(classes) <= 2 * initial
    assert classes[-5:] == [classes[-1]] * 5
    assert min_dihedral_angle(mesh.points, mesh.cells) > 0.25 * min_dihedral_angle(
        sub.points, sub.cells
    )


def test_random_marking_closes_in_few_rounds():
    sub = prepare_for_bisection(delaunay_cube(seed=4))
    rng = np.random.default_rng(5)
    points, tags = sub.points, tags_of(sub)
    for _ in range(8):
        result = bisect_tagged(points, tags, rng.random(tags.order.shape[0]) < 0.05)
        assert result.rounds <= 10
        points, tags = result.points, result.tags
    assert np.all(six_volumes(points, mesh_cells(tags)) > 0)


def test_a_regular_tetrahedron_keeps_six_classes_under_uniform_bisection():
    points = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    mesh = Mesh.from_arrays(points, [[0, 1, 2, 3]], {"all": lambda x: np.ones(len(x), bool)})
    sub = prepare_for_bisection(mesh)
    assert similarity_classes(sub.points, sub.cells) == 1
    assert min_dihedral_angle(sub.points, sub.cells) == pytest.approx(35.26438968, abs=1e-6)
    points, tags = sub.points, tags_of(sub)
    for level in range(6):
        result = bisect_tagged(points, tags, np.ones(tags.order.shape[0], bool))
        points, tags = result.points, result.tags
        cells = mesh_cells(tags)
        assert similarity_classes(points, cells) <= 6
        if level:
            assert min_dihedral_angle(points, cells) == pytest.approx(22.2076, abs=1e-3)


def test_surfaces_are_carried_and_face_barycentres_projected():
    mesh = eighth_ball(2, radius=2.0)
    sub = prepare_for_bisection(mesh)
    assert sub.curves == mesh.curves
    sphere = sub.part_index("sphere")
    v = np.unique(sub.boundary[sub.boundary_part == sphere])
    np.testing.assert_allclose(np.linalg.norm(sub.points[v], axis=1), 2.0, rtol=1e-14)
    assert np.all(six_volumes(sub.points, sub.cells) > 0)
    assert matches(sub.points, tags_of(sub))
    on = np.zeros(sub.n_cells, dtype=bool)
    on[sub.facet2cell[sub.part_facets("sphere"), 0]] = True
    refined = refine_nvb(sub, on).mesh
    v = np.unique(refined.boundary[refined.boundary_part == sphere])
    np.testing.assert_allclose(np.linalg.norm(refined.points[v], axis=1), 2.0, rtol=1e-14)


def test_a_triangle_mesh_is_refused():
    with pytest.raises(MeshError, match="tetrahedral"):
        prepare_for_bisection(rectangle(nx=2, ny=2))
