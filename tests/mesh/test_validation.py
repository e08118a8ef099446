"""The checks of a mesh built from user arrays (:mod:`signorini.mesh.validation`): each
violation raises a :class:`MeshError` naming the offending cells, edges or points."""

from __future__ import annotations

import numpy as np
import pytest
from mesh_problems import ALL, SQUARE_C, SQUARE_P, everything

from signorini.mesh import mesh as mesh_module
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.validation import MeshError, validate_mesh


def test_degenerate_triangle() -> None:
    p = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    with pytest.raises(MeshError, match=r"degenerate triangle\(s\) 1 .*cell 1 = \[0, 1, 2\]"):
        Mesh.from_arrays(p, [[0, 1, 3], [0, 1, 2]], ALL)


def test_repeated_vertex_is_degenerate() -> None:
    with pytest.raises(MeshError, match="degenerate triangle.*repeated vertex"):
        Mesh.from_arrays(SQUARE_P, [[0, 1, 1], [0, 2, 3]], ALL)


def test_clockwise_triangle() -> None:
    with pytest.raises(MeshError, match=r"clockwise triangle\(s\) 1: .*counter-clockwise"):
        Mesh.from_arrays(SQUARE_P, [[0, 1, 2], [0, 3, 2]], ALL)


def test_duplicate_points() -> None:
    # two triangles that touch along the diagonal, but through copies of its end points
    p = np.vstack([SQUARE_P, SQUARE_P[[0, 2]]])
    with pytest.raises(MeshError, match=r"duplicate points 0, 2, 4, 5"):
        Mesh.from_arrays(p, [[0, 1, 2], [4, 5, 3]], ALL)


def test_unreferenced_points() -> None:
    p = np.vstack([SQUARE_P, [[5.0, 5.0], [6.0, 5.0]]])
    with pytest.raises(MeshError, match=r"unreferenced point\(s\) 4, 5"):
        Mesh.from_arrays(p, SQUARE_C, ALL)


def test_hanging_node() -> None:
    # one triangle below the segment (0,0)-(2,0), four above it that use its midpoint 3
    p = np.array([[0, 0], [2, 0], [1, -1], [1, 0], [1, 1], [0, 1], [2, 1]], dtype=float)
    c = [[0, 2, 1], [0, 3, 4], [3, 1, 4], [0, 4, 5], [1, 6, 4]]
    with pytest.raises(MeshError, match=r"point 3 lies inside edge \(0, 1\) \(hanging node\)"):
        Mesh.from_arrays(p, c, ALL)


@pytest.mark.parametrize("turn", [0.5 * np.pi, 0.3, 2.0])
def test_hanging_node_in_any_direction(turn: float) -> None:
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    p = np.array([[0, 0], [2, 0], [1, -1], [1, 0], [1, 1], [0, 1], [2, 1]], dtype=float)
    c = [[0, 2, 1], [0, 3, 4], [3, 1, 4], [0, 4, 5], [1, 6, 4]]
    with pytest.raises(MeshError, match=r"point 3 lies inside edge \(0, 1\) \(hanging node\)"):
        Mesh.from_arrays(p @ rot.T + [5.0, -2.0], c, ALL)


@pytest.mark.parametrize("pattern", ["unionjack", "crossed"])
def test_bisecting_one_cell_alone_leaves_a_hanging_node(pattern: str) -> None:
    # split each interior-edge cell in turn without touching its neighbour
    m = rectangle(0, 1, 0, 2, nx=3, ny=3, pattern=pattern)
    p = m.points @ np.array([[1.0, 0.4], [0.0, 1.0]]).T
    interior = np.flatnonzero(m.edge2cell[m.cell2edge[:, 0], 1] >= 0)
    assert interior.size > 10
    for t in interior[::3]:
        a, b, c = m.cells[t]
        q = np.vstack([p, 0.5 * (p[a] + p[b])])
        n = len(p)
        cells = np.vstack([np.delete(m.cells, t, axis=0), [[c, a, n], [b, c, n]]])
        lo, hi = sorted((a, b))
        with pytest.raises(MeshError, match=rf"point {n} lies inside edge \({lo}, {hi}\)"):
            Mesh.from_arrays(q, cells, ALL)


def test_non_manifold_edge() -> None:
    # three cells on the edge (0, 1): one below, two above
    p = np.array([[0, 0], [1, 0], [0.5, 1], [0.5, -1], [0.2, 2]], dtype=float)
    with pytest.raises(MeshError, match=r"non-manifold mesh: 1 edge\(s\).*first \(0, 1\)"):
        Mesh.from_arrays(p, [[0, 1, 2], [1, 0, 3], [0, 1, 4]], ALL)


def test_overlapping_cells() -> None:
    # both cells lie above (0, 1): the edge is traversed twice in the same direction
    p = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], dtype=float)
    m = Mesh.from_arrays(p, [[0, 1, 2], [1, 3, 2]], ALL)
    with pytest.raises(MeshError, match=r"inconsistently oriented across edge \(0, 1\)"):
        Mesh(p, [[0, 1, 2], [0, 1, 3]], m.boundary, m.boundary_part, m.part_names)


def test_boundary_edges_without_part_from_arrays() -> None:
    with pytest.raises(MeshError, match=r"3 boundary edge\(s\) have no part.*label every"):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"bottom": lambda x, y: y < 1e-12})


def test_boundary_edges_without_part_constructor() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    keep = np.any(np.sort(m.boundary, axis=1) != [2, 3], axis=1)
    assert keep.sum() == 3
    with pytest.raises(MeshError, match=r"1 boundary edge\(s\) without a part, first \(2, 3\)"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary[keep], m.boundary_part[keep], ["all"])


def test_part_index_out_of_range() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"4 boundary edge\(s\) have no part"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary, m.boundary_part + 1, ["all"])


@pytest.mark.parametrize("empty", [lambda x, y: x > 5, [], np.zeros((0, 2), dtype=int)])
def test_part_without_edges(empty) -> None:
    with pytest.raises(MeshError, match=r"boundary part 'ghost' has no edges"):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"all": everything, "ghost": empty})


def test_part_without_edges_constructor() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"boundary part 'x' has no edges"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary, m.boundary_part, ["all", "x"])


def test_constructor_labels_interior_edge() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    b = np.vstack([m.boundary, [[0, 2]]])
    with pytest.raises(MeshError, match=r"edge \(0, 2\) is labelled as boundary but is shared"):
        Mesh(SQUARE_P, SQUARE_C, b, np.append(m.boundary_part, 0), ["all"])


def test_constructor_edge_not_in_mesh() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    b = np.vstack([m.boundary, [[1, 3]]])
    with pytest.raises(MeshError, match=r"boundary edge\(s\) 4 are not edges of the mesh"):
        Mesh(SQUARE_P, SQUARE_C, b, np.append(m.boundary_part, 0), ["all"])


def test_constructor_boundary_edge_twice() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    b = np.vstack([m.boundary, m.boundary[:1, ::-1]])
    with pytest.raises(MeshError, match="a boundary edge is listed twice"):
        Mesh(SQUARE_P, SQUARE_C, b, np.append(m.boundary_part, 0), ["all"])


def test_constructor_boundary_index_out_of_range() -> None:
    # (0, 6) has the same key as the edge (1, 2) when n_points = 4: it must not pass
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    b = m.boundary.copy()
    b[np.flatnonzero(np.sort(b, axis=1)[:, 0] == 1)[0]] = [0, 6]
    with pytest.raises(MeshError, match=r"boundary edges refer to points outside 0\.\.3"):
        Mesh(SQUARE_P, SQUARE_C, b, m.boundary_part, ["all"])


@pytest.mark.parametrize(
    ("points", "cells", "match"),
    [
        (SQUARE_P[:, :1], SQUARE_C, r"points must have shape \(n_points, 2\), got \(4, 1\)"),
        (SQUARE_P.ravel(), SQUARE_C, r"points must have shape \(n_points, 2\), got \(8,\)"),
        (SQUARE_P, SQUARE_C[:, :2], r"cells must have shape \(n, 3\), got \(2, 2\)"),
        (SQUARE_P, SQUARE_C.ravel(), r"cells must have shape \(n, 3\), got \(6,\)"),
        (SQUARE_P, SQUARE_C + 1, r"cells refer to points outside 0\.\.3"),
        (SQUARE_P, SQUARE_C - 1, r"cells refer to points outside 0\.\.3"),
        (SQUARE_P, SQUARE_C + 0.5, "cells must hold integer point indices"),
        (SQUARE_P, SQUARE_C[:0], "the mesh has no cells"),
        (
            np.where([[0, 0], [0, 0], [0, 1], [0, 0]], np.nan, SQUARE_P),
            SQUARE_C,
            r"point\(s\) 2 have non-finite coordinates",
        ),
        (
            np.where([[0, 0], [1, 0], [0, 0], [0, 0]], np.inf, SQUARE_P),
            SQUARE_C,
            r"point\(s\) 1 have non-finite coordinates",
        ),
    ],
)
def test_bad_arrays(points, cells, match) -> None:
    with pytest.raises(MeshError, match=match):
        Mesh.from_arrays(points, cells, ALL)


def test_constructor_bad_boundary_shape() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"boundary edges must have shape \(n, 2\)"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary.ravel()[:7], m.boundary_part, ["all"])
    with pytest.raises(MeshError, match="boundary_part must have one entry per boundary edge"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary, m.boundary_part[:3], ["all"])


def test_mesh_error_is_value_error() -> None:
    assert issubclass(MeshError, ValueError)
    with pytest.raises(ValueError, match="clockwise"):
        Mesh.from_arrays(SQUARE_P, [[0, 2, 1], [0, 2, 3]], ALL)


def test_validate_mesh_is_what_the_constructor_runs() -> None:
    # the same bad arrays: skipped with validate=False, caught by validate_mesh afterwards
    p = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], dtype=float)
    good = Mesh.from_arrays(p, [[0, 1, 2], [1, 3, 2]], ALL)
    validate_mesh(good)
    bad = Mesh(
        p,
        [[0, 1, 2], [0, 1, 3]],
        good.boundary,
        good.boundary_part,
        good.part_names,
        validate=False,
    )
    with pytest.raises(MeshError, match=r"inconsistently oriented across edge \(0, 1\)"):
        validate_mesh(bad)
    assert MeshError is mesh_module.MeshError
