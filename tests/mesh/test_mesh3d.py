"""Tetrahedral meshes: Mesh with dim = 3, its topology, orientation and geometry."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh import Mesh, MeshError
from signorini.mesh.builders import rectangle
from signorini.mesh.builders3d import BOX_PARTS, box, kuhn_paths
from signorini.mesh.geometry import facet_normals
from signorini.mesh.reference import TETRAHEDRON, TRIANGLE

#: One unit cube in six Kuhn tetrahedra (vertex (i, j, k) has number i + 2 j + 4 k), cells
#: 1, 3 and 5 listed negatively (vertices 0 and 3 swapped).
CUBE_POINTS = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], float)
CUBE_CELLS = box(1, 1, 1).cells.copy()
CUBE_CELLS[1::2] = CUBE_CELLS[1::2][:, [3, 1, 2, 0]]


def _outward(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Areas, unit normals and centroids of the boundary faces, in their cells' order."""
    faces = mesh.oriented_boundary(mesh.boundary_facet)
    corners = mesh.points[faces]
    area, normal = facet_normals(corners)
    return area, normal, corners.mean(axis=1)


@pytest.mark.parametrize("n", [1, 2, 3])
def test_kuhn_cube_topology(n):
    mesh = box(n, n, n)
    assert mesh.dim == 3 and mesh.reference is TETRAHEDRON
    assert mesh.cells.shape == (6 * n**3, 4) and mesh.points.shape == ((n + 1) ** 3, 3)
    assert mesh.boundary.shape == (12 * n * n, 3)
    # V - E + F - C = 1 for a ball
    euler = mesh.n_points - mesh.n_edges + mesh.n_facets - mesh.n_cells
    assert euler == 1
    assert mesh.cell2edge.shape == (mesh.n_cells, 6)
    assert mesh.cell2facet.shape == (mesh.n_cells, 4)
    inner = mesh.facet2cell[:, 1] >= 0
    assert inner.sum() == mesh.n_facets - mesh.boundary.shape[0]
    assert np.all(mesh.facet2cell[:, 0] >= 0)
    # every face of a cell is the face of its local index
    f = mesh.cell2facet
    local = np.sort(mesh.cells[:, TETRAHEDRON.facets], axis=2)
    assert np.array_equal(mesh.facets[f], local)
    rows = np.arange(mesh.n_facets)
    for s in (0, 1):
        ok = mesh.facet2cell[:, s] >= 0
        assert np.array_equal(
            mesh.cell2facet[mesh.facet2cell[ok, s], mesh.facet_local[ok, s]], rows[ok]
        )
    # edges: six per cell, sorted pairs
    assert np.all(mesh.edges[:, 0] < mesh.edges[:, 1])
    assert np.array_equal(
        np.sort(mesh.edges[mesh.cell2edge], axis=2),
        np.sort(mesh.cells[:, TETRAHEDRON.edges], axis=2),
    )
    assert mesh.facets is not mesh.edges


@pytest.mark.parametrize("n", [1, 3])
def test_kuhn_cube_boundary_is_outward(n):
    lower, upper = np.array([-1.0, 0.5, 2.0]), np.array([1.0, 2.0, 2.25])
    mesh = box(n, 2 * n, n, lower=tuple(lower), upper=tuple(upper))
    volume = float(np.prod(upper - lower))
    assert np.all(mesh.volume > 0)
    assert np.isclose(mesh.volume.sum(), volume, rtol=1e-14)
    area, normal, centroid = _outward(mesh)
    np.testing.assert_allclose((area[:, None] * normal).sum(0), 0.0, atol=1e-14)
    # the divergence theorem for x: 3 |Ω| = Σ_F (x_F · n_F) |F|
    flux = float(((centroid * normal).sum(1) * area).sum())
    assert np.isclose(flux, 3 * volume, rtol=1e-13)
    # each boundary face points away from its cell's fourth vertex
    c = mesh.facet2cell[mesh.boundary_facet, 0]
    opposite = mesh.points[mesh.cells[c, mesh.facet_local[mesh.boundary_facet, 0]]]
    assert np.all(((centroid - opposite) * normal).sum(1) > 0)
    # the parts are the six sides with their areas
    assert mesh.part_names == BOX_PARTS
    side = upper - lower
    for axis in range(3):
        face_area = np.prod(np.delete(side, axis))
        for k, name in enumerate(BOX_PARTS[2 * axis : 2 * axis + 2]):
            assert np.isclose(mesh.part_measure(name), face_area, rtol=1e-14)
            faces = mesh.part_facets(name)
            sign = 2 * k - 1
            pick = np.isin(mesh.boundary_facet, faces)
            np.testing.assert_allclose(normal[pick, axis], sign, atol=1e-15)


def test_kuhn_cells_are_congruent_and_paths_are_kuhn():
    mesh = box(2, 2, 2)
    assert np.isclose(np.rad2deg(mesh.min_angle()), 45.0)
    np.testing.assert_allclose(mesh.volume, 1 / 48, rtol=1e-14)
    np.testing.assert_allclose(mesh.h, np.sqrt(3) / 2, rtol=1e-15)
    # a Kuhn path steps along one axis at a time, each axis once
    p = mesh.points[kuhn_paths(mesh.cells)]
    step = np.diff(p, axis=1)
    assert np.all((np.abs(step) > 0).sum(axis=2) == 1)
    assert np.all(np.abs(step).sum(axis=1) > 0)


def test_measures_and_midpoints():
    mesh = box(1, 1, 1, upper=(2.0, 3.0, 4.0))
    d = mesh.points[mesh.edges[:, 1]] - mesh.points[mesh.edges[:, 0]]
    np.testing.assert_allclose(mesh.edge_length, np.linalg.norm(d, axis=1), rtol=1e-15)
    np.testing.assert_allclose(mesh.edge_midpoints, mesh.points[mesh.edges].mean(1))
    assert np.isclose(mesh.facet_measure[mesh.boundary_facet].sum(), 2 * (6 + 8 + 12))
    assert mesh.curved_midpoints is mesh.edge_midpoints
    with pytest.raises(MeshError, match="volumes"):
        mesh.area  # noqa: B018


def test_two_dimensional_facets_are_the_edges():
    mesh = rectangle(nx=2, ny=2)
    assert mesh.dim == 2 and mesh.reference is TRIANGLE
    assert mesh.facets is mesh.edges and mesh.cell2facet is mesh.cell2edge
    assert mesh.facet_measure is mesh.edge_length
    assert mesh.area is mesh.measure
    with pytest.raises(MeshError, match="areas"):
        mesh.volume  # noqa: B018


def test_from_arrays_reorients_and_keeps_vertex_order():
    mesh = Mesh.from_arrays(CUBE_POINTS, CUBE_CELLS, {"all": lambda x: np.ones(len(x), bool)})
    assert np.array_equal(mesh.reoriented, [1, 3, 5])
    assert np.all(mesh.volume > 0) and np.isclose(mesh.volume.sum(), 1.0)
    assert np.array_equal(mesh.cells[[0, 2, 4]], CUBE_CELLS[[0, 2, 4]])
    assert np.array_equal(mesh.cells[1], CUBE_CELLS[1][[0, 2, 1, 3]])
    assert np.array_equal(CUBE_POINTS, box(1, 1, 1).points)
    assert mesh.boundary.shape == (12, 3)


def test_from_arrays_parts_by_faces_and_selectors():
    faces = box(1, 1, 1).boundary
    bottom = faces[(CUBE_POINTS[faces][:, :, 2] == 0).all(1)]
    mesh = Mesh.from_arrays(
        CUBE_POINTS,
        CUBE_CELLS,
        {"bottom": bottom[:, ::-1], "rest": lambda x: x[:, 2] > -1.0},
        regions={"low": lambda x: x[:, 2] < 0.5, "high": lambda x: x[:, 2] >= 0.5},
    )
    assert np.isclose(mesh.part_measure("bottom"), 1.0)
    assert np.isclose(mesh.part_measure("rest"), 5.0)
    assert set(mesh.region_names) == {"low", "high"}
    with pytest.raises(MeshError, match=r"is not a boundary face"):
        Mesh.from_arrays(CUBE_POINTS, CUBE_CELLS, {"x": np.array([[0, 1, 7]])})


def test_constructor_refuses_negative_cells_and_mismatched_shapes():
    good = box(1, 1, 1)
    with pytest.raises(MeshError, match=r"negatively oriented tetrahedra 1, 3, 5"):
        Mesh(CUBE_POINTS, CUBE_CELLS, good.boundary, good.boundary_part, good.part_names)
    with pytest.raises(MeshError, match=r"cells must have shape \(n, 4\)"):
        Mesh.from_arrays(CUBE_POINTS, CUBE_CELLS[:, :3], {"a": lambda x: x[:, 0] > -1})
    with pytest.raises(MeshError, match=r"cells must have shape \(n, 3\)"):
        Mesh.from_arrays(CUBE_POINTS[:, :2], CUBE_CELLS, {"a": lambda x: x[:, 0] > -1})


@pytest.mark.parametrize("n", [1, 3])
def test_box_matches_the_independent_cube_of_studies_faces3d(n):
    """The Kuhn cube of the independent study code: the same points, cells (as vertex
    sets), edges and boundary faces."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "studies"))
    from faces3d.mesh import cube_mesh

    cube, mesh = cube_mesh(n), box(n, n, n)
    np.testing.assert_allclose(mesh.points, cube.points[: cube.n_vertices], atol=1e-15)

    def rows(a):
        return {tuple(r) for r in np.sort(a, axis=1).tolist()}

    assert rows(mesh.cells) == rows(cube.tets[:, :4])
    assert np.array_equal(mesh.edges, cube.edges)
    for axis in range(3):
        for side, value in ((0, 0.0), (1, 1.0)):
            faces = cube.boundary_faces(axis, value)[:, :3]
            name = BOX_PARTS[2 * axis + side]
            assert rows(mesh.facets[mesh.part_facets(name)]) == rows(faces)
            # the study orients its faces outward too: the same normals
            ours = mesh.oriented_boundary(mesh.part_facets(name))
            n_ours = facet_normals(mesh.points[ours])[1]
            n_theirs = facet_normals(cube.points[faces])[1]
            np.testing.assert_allclose(n_ours.sum(0), n_theirs.sum(0), atol=1e-12)
