"""Tetrahedral meshes refused (or warned about) with errors naming the cell, face or point."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from signorini.mesh import Mesh, MeshError
from signorini.mesh.builders3d import box
from signorini.mesh.validation3d import SliverWarning, dihedral_angles

ALL = {"all": lambda x: np.ones(len(x), dtype=bool)}
TET = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def _rebuild(mesh: Mesh, **changes) -> Mesh:
    """The constructor on a mesh's arrays, some replaced."""
    args = {
        "points": mesh.points,
        "cells": mesh.cells,
        "boundary": mesh.boundary,
        "boundary_part": mesh.boundary_part,
        "part_names": mesh.part_names,
    }
    args.update(changes)
    return Mesh(**args)


def test_a_valid_mesh_passes_and_has_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = _rebuild(box(2, 1, 1))
    assert mesh.dim == 3


def test_dihedral_angles_of_the_corner_tetrahedron():
    angles = np.rad2deg(dihedral_angles(TET, np.array([[0, 1, 2, 3]])))[0]
    # edges 01, 12, 20, 03, 13, 23: right angles at the three edges from the corner
    np.testing.assert_allclose(angles[[0, 2, 3]], 90.0)
    np.testing.assert_allclose(angles[[1, 4, 5]], np.rad2deg(np.arccos(1 / np.sqrt(3))))


@pytest.mark.parametrize(
    ("points", "cells", "message"),
    [
        (np.vstack([TET[:3], [np.nan, 0, 1]]), [[0, 1, 2, 3]], r"point\(s\) 3 have non-finite"),
        (TET, [[0, 1, 2, 4]], r"cells refer to points outside 0..3"),
        (TET, [[0, 1, 2]], r"cells must have shape \(n, 4\)"),
        (TET, [[0, 1, 2, 3.5]], r"cells must hold integer point indices"),
        (np.vstack([TET[:3], [0.3, 0.3, 0.0]]), [[0, 1, 2, 3]], r"degenerate tetrahedra 0 .*"),
        (TET, [[0, 1, 2, 2]], r"degenerate tetrahedra 0 \(zero volume"),
        (np.vstack([TET, [5, 5, 5]]), [[0, 1, 2, 3]], r"unreferenced point\(s\) 4"),
        (
            np.vstack([TET, TET[3:]]),
            [[0, 1, 2, 3], [1, 2, 4, 0]],
            r"duplicate points 3, 4",
        ),
        (TET, [[0, 1, 2, 3], [1, 0, 2, 3]], r"duplicate cells 0 and 1"),
    ],
)
def test_bad_arrays_are_refused(points, cells, message):
    with pytest.raises(MeshError, match=message):
        Mesh.from_arrays(points, cells, ALL)


def test_a_sliver_is_warned_about():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.02]])
    with pytest.warns(SliverWarning, match=r"1 sliver tetrahedra .* cell 0 with"):
        mesh = Mesh.from_arrays(points, [[0, 1, 2, 3]], ALL)
    assert np.rad2deg(mesh.min_angle()) < 5.0


def test_a_face_of_three_cells_is_refused():
    points = np.vstack([TET, [[0.0, 0.0, -1.0], [0.1, 0.1, 2.0]]])
    cells = [[0, 1, 2, 3], [0, 2, 1, 4], [0, 1, 2, 5]]
    with pytest.raises(MeshError, match=r"non-manifold mesh: 1 face\(s\) shared by more than two"):
        Mesh.from_arrays(points, cells, ALL)


def test_cells_on_one_side_of_their_face_are_refused():
    points = np.vstack([TET, [[0.1, 0.1, 2.0]]])
    with pytest.raises(MeshError, match=r"cells 0 and 1 overlap: both lie on one side .* face"):
        Mesh.from_arrays(points, [[0, 1, 2, 3], [0, 1, 2, 4]], ALL)


def test_a_hanging_node_is_refused():
    coarse, fine = box(1, 1, 1), box(2, 2, 2, lower=(1.0, 0.0, 0.0), upper=(2.0, 1.0, 1.0))
    points = np.vstack([coarse.points, fine.points])
    unique, inverse = np.unique(points.round(12), axis=0, return_inverse=True)
    cells = np.vstack([coarse.cells, fine.cells + coarse.n_points])
    cells = inverse.reshape(-1)[cells]
    with pytest.raises(MeshError, match=r"non-conforming mesh: point \d+ \[1.0, 0.5, .* lies on"):
        Mesh.from_arrays(unique, cells, ALL)


def test_boundary_faces_must_be_faces_and_labelled():
    mesh = box(1, 1, 1)
    bogus = mesh.boundary.copy()
    bogus[0] = [0, 1, 6]
    with pytest.raises(MeshError, match=r"boundary face\(s\) 0 are not faces of the mesh"):
        _rebuild(mesh, boundary=bogus)
    with pytest.raises(MeshError, match=r"1 boundary face\(s\) without a part, first face \("):
        _rebuild(mesh, boundary=mesh.boundary[1:], boundary_part=mesh.boundary_part[1:])
    inner = mesh.facets[mesh.facet2cell[:, 1] >= 0][0]
    with pytest.raises(MeshError, match=r"face .* is labelled as boundary but is shared by two"):
        _rebuild(
            mesh,
            boundary=np.vstack([mesh.boundary, inner]),
            boundary_part=np.append(mesh.boundary_part, 0),
        )
    with pytest.raises(MeshError, match=r"boundary part 'z1' has no faces"):
        _rebuild(mesh, boundary_part=np.where(mesh.boundary_part == 5, 4, mesh.boundary_part))
    with pytest.raises(MeshError, match=r"2 boundary face\(s\) have no part, first face"):
        _rebuild(mesh, boundary_part=np.where(mesh.boundary_part == 5, 9, mesh.boundary_part))
