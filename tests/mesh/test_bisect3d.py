"""Tagged-simplex bisection of tetrahedra (mesh/bisect3d.py, mesh/tags3d.py,
mesh/refine3d.py): conformity, volumes, tags, nestedness, shape classes, determinism."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh.bisect3d import bisect_tagged, boundary_of
from signorini.mesh.builders3d import BOX_PARTS, box, eighth_ball, kuhn_paths
from signorini.mesh.quality3d import min_dihedral_angle, similarity_classes
from signorini.mesh.reference import TETRAHEDRON
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.mesh.refine3d import matches, tagged, tags_of
from signorini.mesh.tags3d import kuhn_tags, mesh_cells, sorted_tags, with_face_parts


def six_volumes(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Six times the signed volumes, as a plain triple product (exact on dyadic points)."""
    p = points[cells]
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    return (
        a[:, 0] * (b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1])
        - a[:, 1] * (b[:, 0] * c[:, 2] - b[:, 2] * c[:, 0])
        + a[:, 2] * (b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0])
    )


def assert_conforming(mesh) -> None:
    """Every face in one or two cells, the faces in one exactly the boundary faces, and no
    hanging vertex: no edge's midpoint is a point of the mesh."""
    faces = np.sort(mesh.cells[:, TETRAHEDRON.facets].reshape(-1, 3), axis=1)
    u, count = np.unique(faces, axis=0, return_counts=True)
    assert count.max() <= 2
    bnd = np.unique(np.sort(mesh.boundary, axis=1), axis=0)
    np.testing.assert_array_equal(u[count == 1], bnd)
    edges = np.unique(np.sort(mesh.cells[:, TETRAHEDRON.edges].reshape(-1, 2), axis=1), axis=0)
    mid = 0.5 * (mesh.points[edges[:, 0]] + mesh.points[edges[:, 1]])
    both = np.concatenate([mesh.points, mid])
    assert np.unique(both, axis=0).shape[0] == both.shape[0], "a hanging vertex"
    assert np.all(six_volumes(mesh.points, mesh.cells) > 0)


def test_kuhn_tags_are_the_builders_kuhn_paths():
    mesh = box(2, 3, 1, upper=(2.0, 1.5, 0.5))
    np.testing.assert_array_equal(kuhn_tags(mesh.points, mesh.cells), kuhn_paths(mesh.cells))


def test_uniform_refinement_is_three_bisections_and_keeps_one_class():
    mesh = box(2, 2, 2)
    for _ in range(2):
        n, vol = mesh.n_cells, six_volumes(mesh.points, mesh.cells)
        ref = refine_uniform(mesh)
        child = ref.mesh
        assert child.n_cells == 8 * n
        # children's volumes sum to their parent's, bit for bit on a dyadic box
        total = np.bincount(ref.parent, six_volumes(child.points, child.cells), minlength=n)
        np.testing.assert_array_equal(total, vol)
        assert (ref.edge_point >= 0).all()
        mid = 0.5 * (mesh.points[mesh.edges[:, 0]] + mesh.points[mesh.edges[:, 1]])
        np.testing.assert_array_equal(child.points[ref.edge_point], mid)
        assert_conforming(child)
        assert similarity_classes(child.points, child.cells) == 1
        assert min_dihedral_angle(child.points, child.cells) == pytest.approx(45.0)
        mesh = child


def test_matching_condition_of_a_kuhn_box_needs_no_closure():
    mesh = box(3, 2, 2)
    tags = tags_of(mesh)
    points = mesh.points
    for _ in range(6):  # every cell bisected: one round each, no closure
        result = bisect_tagged(points, tags, np.ones(tags.order.shape[0], bool))
        assert result.rounds == 1
        points, tags = result.points, result.tags


def test_random_local_refinement_conforms_with_tags_volumes_and_parents():
    rng = np.random.default_rng(7)
    mesh = box(2, 2, 2)
    for _ in range(12):
        marked = rng.random(mesh.n_cells) < 0.08
        ref = refine_nvb(mesh, marked)
        child = ref.mesh
        assert_conforming(child)
        # volumes: children sum to the parent (bit for bit: dyadic points)
        total = np.bincount(
            ref.parent, six_volumes(child.points, child.cells), minlength=mesh.n_cells
        )
        np.testing.assert_array_equal(total, six_volumes(mesh.points, mesh.cells))
        # every marked cell was bisected; old points keep their indices
        assert np.all(np.bincount(ref.parent, minlength=mesh.n_cells)[marked] >= 2)
        np.testing.assert_array_equal(child.points[: mesh.n_points], mesh.points)
        # nestedness: each child's centroid inside its parent
        p = mesh.points[mesh.cells[ref.parent]]
        x = child.points[child.cells].mean(1)
        lam = np.linalg.solve((p[:, 1:] - p[:, :1]).transpose(0, 2, 1), (x - p[:, 0])[..., None])[
            ..., 0
        ]
        assert lam.min() > 0 and (lam.sum(1) < 1).all()
        # tags: each boundary face carries the part of the side it lies on
        g = child.points[child.boundary]
        for index, name in enumerate(BOX_PARTS):  # a loop over the six parts
            axis, side = divmod(index, 2)
            on = np.all(g[:, :, axis] == float(side), axis=1)
            np.testing.assert_array_equal(child.boundary_part == index, on, err_msg=name)
            assert child.part_measure(name) == pytest.approx(1.0, rel=1e-13)
        np.testing.assert_array_equal(child.cell_region, mesh.cell_region[ref.parent])
        assert similarity_classes(child.points, child.cells) <= 3
        assert min_dihedral_angle(child.points, child.cells) >= 45.0 - 1e-9
        mesh = child


@pytest.mark.parametrize("where", ["vertex", "edge", "face"])
def test_refinement_towards_a_vertex_edge_face_keeps_three_classes(where):
    mesh = box(1, 1, 1)
    classes = set()
    for _ in range(15):
        p = mesh.points[mesh.cells]
        zero = np.abs(p) < 1e-12
        on = {"vertex": zero.all(-1).any(1), "edge": (zero[..., 1] & zero[..., 2]).sum(1) >= 2}
        on["face"] = (zero[..., 2].sum(1) >= 3) & (p[..., 0].min(1) < 0.25)
        mesh = refine_nvb(mesh, on[where]).mesh
        classes.add(similarity_classes(mesh.points, mesh.cells))
        assert min_dihedral_angle(mesh.points, mesh.cells) >= 45.0 - 1e-9
    assert max(classes) == 3
    assert_conforming(mesh)


def test_refinement_is_deterministic():
    rng = np.random.default_rng(3)
    mesh = box(2, 2, 1)
    marks = [rng.random(10**6) < 0.1 for _ in range(5)]
    results = []
    for _ in range(2):
        m = box(2, 2, 1)
        for mark in marks:
            m = refine_nvb(m, mark[: m.n_cells]).mesh
        results.append(m)
    a, b = results
    for name in ("points", "cells", "boundary", "boundary_part", "cell_region"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert mesh.n_cells < a.n_cells


def test_boundary_faces_are_outward():
    mesh = refine_nvb(box(2, 1, 1), np.arange(3)).mesh
    f = mesh.points[mesh.boundary]
    area_normal = np.cross(f[:, 1] - f[:, 0], f[:, 2] - f[:, 0]) / 2
    # the divergence theorem: sum_F (x_F . n_F) |F| = 3 |box|, and sum_F n_F |F| = 0
    assert (f.mean(1) * area_normal).sum() == pytest.approx(3.0, rel=1e-14)
    np.testing.assert_allclose(area_normal.sum(0), 0.0, atol=1e-14)


def test_mapped_kuhn_grids_are_tagged_by_their_paths():
    mesh = eighth_ball(2)
    tags = tags_of(mesh)
    np.testing.assert_array_equal(tags.order, kuhn_paths(mesh.cells, mirrored=True))
    assert matches(mesh.points, tags)
    # the global vertex order of a grid numbering is the Kuhn paths' order; of a random
    # numbering it breaks the matching condition
    np.testing.assert_array_equal(sorted_tags(mesh.cells), tags.order)
    box_mesh = box(2, 2, 2)
    perm = np.random.default_rng(0).permutation(box_mesh.n_points)
    inverse = np.argsort(perm)
    shuffled = with_face_parts(
        box_mesh.points[perm],
        sorted_tags(inverse[box_mesh.cells]),
        np.zeros(box_mesh.n_cells, np.int8),
        inverse[box_mesh.boundary],
        box_mesh.boundary_part,
    )
    assert not matches(box_mesh.points[perm], shuffled)


def test_sphere_vertices_stay_on_the_sphere():
    mesh = eighth_ball(2, radius=2.0)
    sphere = mesh.part_index("sphere")
    for _ in range(6):
        on = np.zeros(mesh.n_cells, dtype=bool)
        cell = mesh.facet2cell[mesh.part_facets("sphere"), 0]
        on[cell] = True
        mesh = refine_nvb(mesh, on).mesh
        v = np.unique(mesh.boundary[mesh.boundary_part == sphere])
        np.testing.assert_allclose(np.linalg.norm(mesh.points[v], axis=1), 2.0, rtol=1e-14)
        assert np.all(six_volumes(mesh.points, mesh.cells) > 0)
    assert mesh.part_measure("sphere") == pytest.approx(2 * np.pi, rel=0.02)


def test_an_arbitrary_numbering_terminates_and_conforms():
    rng = np.random.default_rng(0)
    mesh = box(2, 2, 2)
    perm = rng.permutation(mesh.n_points)
    inverse = np.argsort(perm)
    points = mesh.points[perm]
    cells = inverse[mesh.cells]
    order = sorted_tags(cells)
    tags = with_face_parts(
        points, order, np.zeros(len(cells), np.int8), inverse[mesh.boundary], mesh.boundary_part
    )
    for _ in range(6):
        result = bisect_tagged(points, tags, rng.random(tags.order.shape[0]) < 0.2)
        points, tags = result.points, result.tags
    cells = mesh_cells(tags)
    assert np.all(six_volumes(points, cells) > 0)
    bnd, _ = boundary_of(cells, tags)
    faces = np.sort(cells[:, TETRAHEDRON.facets].reshape(-1, 3), axis=1)
    u, count = np.unique(faces, axis=0, return_counts=True)
    np.testing.assert_array_equal(u[count == 1], np.unique(np.sort(bnd, axis=1), axis=0))


def test_handed_topology_equals_the_global_one():
    from functools import cached_property

    from signorini.mesh.mesh import Mesh
    from signorini.mesh.refine3d import EDGE_CACHE, FACET_CACHE
    from signorini.mesh.topology import entity_topology

    assert isinstance(Mesh.__dict__[EDGE_CACHE], cached_property)
    assert isinstance(Mesh.__dict__[FACET_CACHE], cached_property)
    rng = np.random.default_rng(11)
    mesh = box(2, 2, 2)
    for step in range(8):
        ref = (
            refine_uniform(mesh) if step == 2 else refine_nvb(mesh, rng.random(mesh.n_cells) < 0.1)
        )
        child = ref.mesh
        assert EDGE_CACHE in child.__dict__ and FACET_CACHE in child.__dict__
        edges = entity_topology(child.cells, child.n_points, TETRAHEDRON.edges, facets=False)
        faces = entity_topology(child.cells, child.n_points, TETRAHEDRON.facets)
        for handed, computed in zip(child.__dict__[EDGE_CACHE][:2], edges[:2], strict=True):
            np.testing.assert_array_equal(handed, computed)
        for handed, computed in zip(child.__dict__[FACET_CACHE], faces, strict=True):
            np.testing.assert_array_equal(handed, computed)
        mesh = child


def test_tagged_attaches_a_builders_order_and_refuses_foreign_vertices():
    from signorini.mesh.mesh import MeshError

    mesh = tagged(box(1, 1, 2), kuhn_paths(box(1, 1, 2).cells))
    np.testing.assert_array_equal(tags_of(mesh).order, kuhn_tags(mesh.points, mesh.cells))
    wrong = kuhn_paths(mesh.cells)[::-1]
    with pytest.raises(MeshError, match="own vertices"):
        tagged(box(1, 1, 2), wrong)
