"""The checks of a mesh built from user arrays (:mod:`signorini.mesh.validation`): each
violation raises a :class:`MeshError` naming the offending cells, edges or points."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from mesh_problems import ALL, HAND_MESHES, SQUARE_C, SQUARE_P, everything, jittered_delaunay

from signorini.mesh import mesh as mesh_module
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.validation import MeshError, validate_mesh


def test_degenerate_triangle() -> None:
    p = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    with pytest.raises(MeshError, match=r"degenerate triangle\(s\) 1 .*cell 1 = \[0, 1, 2\]"):
        Mesh.from_arrays(p, [[0, 1, 3], [0, 1, 2]], ALL)


@pytest.mark.parametrize("height", [1e-12, 0.0])
def test_a_sliver_is_refused_naming_the_cell_its_vertices_and_aspect_ratio(height) -> None:
    # aspect ratio = longest edge / smallest height = 1 / height, refused beyond 5e11
    p = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, height], [0.0, 1.0]])
    with pytest.raises(MeshError) as info:
        Mesh.from_arrays(p, [[0, 1, 3], [0, 1, 2]], ALL)
    msg = str(info.value)
    assert "cell 1 = [0, 1, 2] with vertices (0, 0), (1, 0), (0.5, " in msg, msg
    aspect = "1e+12" if height else "inf"
    assert f"aspect ratio (longest edge / smallest height) {aspect}, beyond 5e+11" in msg, msg


def test_a_thin_cell_below_the_bound_is_accepted() -> None:
    # aspect 1e9 (the solve's accuracy on it is checked by its residuals, not here)
    p = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, -1e-9], [0.0, 1.0]])
    mesh = Mesh.from_arrays(p, [[0, 1, 3], [0, 2, 1]], ALL)
    assert mesh.area[1] == pytest.approx(0.5e-9, rel=1e-6)


def test_repeated_vertex_is_degenerate() -> None:
    with pytest.raises(MeshError, match="degenerate triangle.*repeated vertex"):
        Mesh.from_arrays(SQUARE_P, [[0, 1, 1], [0, 2, 3]], ALL)


def test_clockwise_triangle_in_the_constructor() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    cells = m.cells.copy()
    cells[1] = cells[1, [0, 2, 1]]
    with pytest.raises(MeshError, match=r"clockwise triangle\(s\) 1: .*counter-clockwise"):
        Mesh(SQUARE_P, cells, m.boundary, m.boundary_part, m.part_names)


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_from_arrays_reorients_clockwise_cells(name: str, caplog) -> None:
    # other tools mix orientations: every other cell given clockwise gives the same mesh
    p, c = HAND_MESHES[name]()
    c = np.array(c)
    flip = np.arange(len(c))[1::2]
    mixed = c.copy()
    mixed[flip] = mixed[flip][:, [0, 2, 1]]
    reference = Mesh.from_arrays(p, c, ALL)
    with caplog.at_level(logging.INFO, logger="signorini.mesh.mesh"):
        m = Mesh.from_arrays(p, mixed, ALL)
    assert f"{flip.size} of {len(c)} cells were clockwise and were reoriented" in caplog.text
    np.testing.assert_array_equal(m.reoriented, flip)
    assert reference.reoriented.size == 0
    assert np.all(m.area > 0)
    np.testing.assert_array_equal(np.sort(m.cells, axis=1), np.sort(reference.cells, axis=1))
    np.testing.assert_array_equal(m.area, reference.area)
    assert not m.reoriented.flags.writeable


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
    interior = np.flatnonzero(m.facet2cell[m.cell2edge[:, 0], 1] >= 0)
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
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"bottom": lambda x: x[:, 1] < 1e-12})


def test_boundary_edges_without_part_constructor() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    keep = np.any(np.sort(m.boundary, axis=1) != [2, 3], axis=1)
    assert keep.sum() == 3
    with pytest.raises(
        MeshError,
        match=r"1 boundary edge\(s\) without a part, first the edge from \(1, 1\) to \(0, 1\) "
        r"\(vertices 2 and 3\)",
    ):
        Mesh(SQUARE_P, SQUARE_C, m.boundary[keep], m.boundary_part[keep], ["all"])


def test_part_index_out_of_range() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"4 boundary edge\(s\) have no part"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary, m.boundary_part + 1, ["all"])


@pytest.mark.parametrize("empty", [lambda x: x[:, 0] > 5, [], np.zeros((0, 2), dtype=int)])
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


def test_constructor_names_string_arguments() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"points must be an \(n_points, 2\) array of numbers"):
        Mesh(SQUARE_P.astype(str), SQUARE_C, m.boundary, m.boundary_part, m.part_names)
    with pytest.raises(MeshError, match=r"cells must be an \(n, 3\) array of point indices"):
        Mesh(SQUARE_P, "0 1 2", m.boundary, m.boundary_part, m.part_names)


def test_constructor_bad_boundary_shape() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, ALL)
    with pytest.raises(MeshError, match=r"boundary edges must have shape \(n, 2\)"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary.ravel()[:7], m.boundary_part, ["all"])
    with pytest.raises(MeshError, match="boundary_part must have one entry per boundary edge"):
        Mesh(SQUARE_P, SQUARE_C, m.boundary, m.boundary_part[:3], ["all"])


def test_mesh_error_is_value_error() -> None:
    assert issubclass(MeshError, ValueError)
    with pytest.raises(ValueError, match="degenerate"):
        Mesh.from_arrays(SQUARE_P, [[0, 2, 2], [0, 2, 3]], ALL)


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


# ---------------------------------------------------------------------------- overlapping cells
UNIT = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
TWO = np.array([[0, 1, 2], [0, 2, 3]])


def two_squares(scale: float, shift: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The unit square and a copy scaled and shifted, meshed separately (no shared point)."""
    return np.vstack([UNIT, scale * UNIT + shift]), np.vstack([TWO, TWO + 4])


@pytest.mark.parametrize(
    ("scale", "shift", "match"),
    [
        # overlapping by half in each direction: boundary edges cross
        (1.0, (0.5, 0.5), r"cells overlap: boundary edges \(2, 3\) and \(7, 4\) cross"),
        (1.0, (0.5, -0.25), r"cells overlap: boundary edges \(0, 1\) and \(7, 4\) cross"),
        # a small square inside the big one: no edge crosses, the inside is covered twice
        (0.25, (0.3, 0.2), r"cells overlap: the centroid .* of cell \d is covered by 2 cells"),
    ],
)
def test_overlapping_squares(scale, shift, match) -> None:
    p, c = two_squares(scale, shift)
    with pytest.raises(MeshError, match=match):
        Mesh.from_arrays(p, c, ALL)


def test_crossing_strips() -> None:
    # a plus sign: two thin rectangles, no vertex of one inside the other
    a = np.array([[-1, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    with pytest.raises(MeshError, match=r"cells overlap: boundary edges \(\d, \d\) and"):
        Mesh.from_arrays(np.vstack([a, a[:, ::-1] * [1, -1]]), np.vstack([TWO, TWO + 4]), ALL)


def test_overlap_at_a_pinch_vertex() -> None:
    # a small quadrilateral inside the unit square that touches it only at the corner (0, 0)
    q = 0.1 * np.array([[1.0, 0.5], [1.2, 1.5], [0.3, 1.0]])
    cells = [[0, 1, 2], [0, 2, 3], [0, 4, 5], [0, 5, 6]]
    with pytest.raises(MeshError, match=r"cells overlap: the centroid .* covered by 2 cells"):
        Mesh.from_arrays(np.vstack([UNIT, q]), cells, ALL)


def test_touching_squares_and_holes_are_not_overlaps() -> None:
    # two squares meeting at a corner; the square next to the first one; a square with a hole
    touching = Mesh.from_arrays(np.vstack([UNIT, UNIT[1:] + 1]), [*TWO, [2, 4, 5], [2, 5, 6]], ALL)
    assert touching.area.sum() == pytest.approx(2.0, rel=1e-15)
    side = Mesh.from_arrays(
        np.vstack([UNIT, UNIT[[1, 2]] + [1, 0]]), [*TWO, [1, 4, 5], [1, 5, 2]], ALL
    )
    assert side.area.sum() == pytest.approx(2.0, rel=1e-15)
    m = rectangle(nx=3, ny=3)
    centre = m.points[m.cells].mean(axis=1)
    keep = np.abs(centre - 0.5).max(axis=1) > 1 / 6
    holed = Mesh.from_arrays(m.points, m.cells[keep], ALL)
    assert holed.area.sum() == pytest.approx(8 / 9, rel=1e-14)


def test_mesh_winding_twice_around_a_hole() -> None:
    # an annulus of 8 quadrilaterals around a square hole, closed after two turns: each
    # interior edge has a cell on either side, but every point is covered twice
    t = np.arange(16) * 2 * np.pi / 8
    inner = np.column_stack([np.cos(t), np.sin(t)]) * (1 + 0.01 * np.arange(16))[:, None]
    outer = 2 * inner
    p = np.vstack([inner, outer])
    k = np.arange(16)
    nxt = (k + 1) % 16
    c = np.vstack([np.column_stack([k, nxt, 16 + nxt]), np.column_stack([k, 16 + nxt, 16 + k])])
    with pytest.raises(MeshError, match="cells overlap"):
        Mesh.from_arrays(p, c, ALL)


# ---------------------------------------------------------------------------- relative tolerances
@pytest.mark.parametrize(
    ("scale", "shift"),
    [(1e-12, 0.0), (1e-150, 0.0), (1e12, 0.0), (1e150, 0.0), (1.0, 1e9), (1.0, -1e12), (1e6, 1e15)],
)
def test_tolerances_are_relative_to_the_mesh(scale: float, shift: float) -> None:
    # Example 6.2's mesh scaled by 1e-12 and the unit square at x = 1e9 were "duplicate points"
    base = rectangle(nx=4, ny=4)
    p = base.points * scale + [shift, 0.5 * shift]
    m = Mesh.from_arrays(p, base.cells, ALL)
    assert m.n_points == base.n_points
    np.testing.assert_allclose(m.area.sum(), scale**2, rtol=1e-6)
    # still caught at that scale: a duplicate point, a hanging node, an overlap
    q = np.vstack([p, p[[5]] + scale * 1e-13])
    with pytest.raises(MeshError, match=r"duplicate points 5, 25"):
        Mesh.from_arrays(q, np.vstack([base.cells, [[25, 1, 0]]]), ALL)
    u, c = two_squares(0.25, (0.3, 0.2))
    with pytest.raises(MeshError, match="cells overlap"):
        Mesh.from_arrays(u * scale + [shift, 0.5 * shift], c, ALL)


def test_duplicate_points_after_a_large_shift() -> None:
    # at x = 1e9 two points one rounding unit apart are the same point
    p, c = jittered_delaunay(5)
    p = p + [1e9, 0.0]
    q = np.vstack([p, p[[3]] + [np.spacing(1e9), 0.0]])
    extra = np.vstack([c, [[len(p), 4, 9]]])
    with pytest.raises(MeshError, match=rf"duplicate points 3, {len(p)}"):
        Mesh.from_arrays(q, extra, ALL)
