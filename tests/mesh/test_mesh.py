"""Tests of :mod:`signorini.mesh.mesh`: construction from arrays and boundary parts, cached
topology, geometry."""

from __future__ import annotations

import numpy as np
import pytest
from mesh_problems import (
    ALL,
    HAND_MESHES,
    SQUARE_C,
    SQUARE_P,
    everything,
    hexfan,
    jittered_delaunay,
    square4,
)

from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh, MeshError, boundary_facets


# ---------------------------------------------------------------------------- boundary parts
def test_part_lists_interior_edge() -> None:
    with pytest.raises(MeshError, match=r"part 'diag': \(2, 0\) is not a boundary edge"):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"diag": [[2, 0]], "rest": everything})


@pytest.mark.parametrize(
    "mapping",
    [
        {"a": [[0, 1]], "b": [[1, 0]]},
        {"a": everything, "b": everything},
        {"a": [[0, 1], [1, 2]], "b": [[3, 2], [2, 1]], "c": everything},
    ],
)
def test_edge_claimed_by_two_parts(mapping) -> None:
    with pytest.raises(
        MeshError,
        match=r"boundary edge \(\d, \d\) is claimed by both parts "
        r"'a' and 'b'",
    ):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, mapping)


def test_predicate_claims_only_unlisted_edges() -> None:
    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, {"rest": everything, "contact": [[1, 0]]})
    assert m.part_names == ("rest", "contact")
    assert m.part_measure("contact") == pytest.approx(1.0, abs=1e-15)
    assert m.part_measure("rest") == pytest.approx(3.0, abs=1e-15)


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ([[0, 1, 2]], r"boundary edges must have shape \(n, 2\), got \(1, 3\)"),
        ([[0, 9]], r"boundary edges refer to points outside 0\.\.3"),
        (lambda x: True, r"selector of boundary part 'a' must return one bool per edge "),
    ],
)
def test_bad_part_specs(spec, match) -> None:
    with pytest.raises(MeshError, match=match):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"a": spec})


def test_unknown_part_name() -> None:
    m = rectangle()
    with pytest.raises(MeshError, match=r"no boundary part 'contact'; its parts are \['bottom'"):
        m.part_facets("contact")


# ---------------------------------------------------------------------------- positive cases
def test_from_arrays_with_predicates() -> None:
    p, c = jittered_delaunay(6, seed=3)
    parts = {
        "bottom": lambda x: x[:, 1] < 1e-12,
        "right": lambda x: x[:, 0] > 1 - 1e-12,
        "top": lambda x: x[:, 1] > 1 - 1e-12,
        "left": lambda x: x[:, 0] < 1e-12,
    }
    m = Mesh.from_arrays(p, c, parts)
    assert m.part_names == ("bottom", "right", "top", "left")
    for name in m.part_names:
        assert m.part_measure(name) == pytest.approx(1.0, rel=1e-14)
        assert m.part_facets(name).size == 5  # 6 points per side
    mid = m.edge_midpoints
    assert np.all(mid[m.part_facets("bottom"), 1] == 0.0)
    assert np.all(mid[m.part_facets("left"), 0] == 0.0)
    assert m.area.sum() == pytest.approx(1.0, rel=1e-14)


def test_from_arrays_with_edge_lists() -> None:
    p, c = square4()
    # lists in either orientation, one of them flat
    m = Mesh.from_arrays(p, c, {"south": [[1, 0]], "east": [1, 2], "rest": [[2, 3], [0, 3]]})
    expect = {"south": {0, 1}, "east": {1, 2}, "rest": {2, 3, 0}}
    for name, verts in expect.items():
        e = m.facets[m.part_facets(name)]
        assert set(e.ravel().tolist()) == verts
    assert m.part_measure("rest") == pytest.approx(2.0, abs=1e-15)
    assert m.facet_part[m.facet2cell[:, 1] >= 0].tolist() == [-1] * 4
    assert sorted(m.facet_part[m.facet2cell[:, 1] < 0].tolist()) == [0, 1, 2, 2]


def test_mesh_is_immutable() -> None:
    m = rectangle(nx=2, ny=2)
    for a in (m.points, m.cells, m.boundary, m.boundary_part, m.facet_part):
        with pytest.raises(ValueError, match="read-only"):
            a[0] = 0


# ---------------------------------------------------------------------------- topology
def brute_force_edges(cells: np.ndarray) -> dict[frozenset, list[tuple[int, int]]]:
    """Map each undirected edge to its (cell, local edge) occurrences."""
    out: dict[frozenset, list[tuple[int, int]]] = {}
    for t, cell in enumerate(cells.tolist()):
        for k in range(3):
            out.setdefault(frozenset((cell[k], cell[(k + 1) % 3])), []).append((t, k))
    return out


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_topology_matches_brute_force(name: str) -> None:
    p, c = HAND_MESHES[name]()
    m = Mesh.from_arrays(p, c, ALL)
    ref = brute_force_edges(m.cells)
    assert m.n_edges == len(ref) == m.edges.shape[0]
    assert m.edges.dtype == np.int64 and m.cell2edge.dtype == np.int64
    assert np.all(m.edges[:, 0] < m.edges[:, 1])
    assert {frozenset(e) for e in m.edges.tolist()} == set(ref)
    for e, pair in enumerate(m.edges.tolist()):
        occ = ref[frozenset(pair)]
        # cell2edge: local edge k of cell t is this edge for every occurrence (t, k)
        assert all(m.cell2edge[t, k] == e for t, k in occ)
        cells = set(m.facet2cell[e].tolist()) - {-1}
        assert cells == {t for t, _ in occ}
        if len(occ) == 1:
            assert m.facet2cell[e, 0] == occ[0][0] and m.facet2cell[e, 1] == -1
        else:
            assert len(occ) == 2 and m.facet2cell[e, 1] >= 0
    # Euler: V - E + F = 1 for a triangulated disc
    assert m.n_points - m.n_edges + m.n_cells == 1


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_local_edge_k_joins_vertices_k_and_k_plus_1(name: str) -> None:
    p, c = HAND_MESHES[name]()
    m = Mesh.from_arrays(p, c, ALL)
    for k in range(3):
        got = np.sort(m.edges[m.cell2edge[:, k]], axis=1)
        want = np.sort(m.cells[:, [k, (k + 1) % 3]], axis=1)
        assert np.array_equal(got, want)


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_boundary_edges_have_one_cell(name: str) -> None:
    p, c = HAND_MESHES[name]()
    m = Mesh.from_arrays(p, c, ALL)
    counts = np.bincount(m.cell2edge.ravel(), minlength=m.n_edges)
    on_boundary = m.facet2cell[:, 1] == -1
    assert np.array_equal(on_boundary, counts == 1)
    assert np.all(m.facet2cell[:, 0] >= 0)
    assert np.array_equal(np.sort(m.boundary_facet), np.flatnonzero(on_boundary))
    assert np.array_equal(m.facet_part >= 0, on_boundary)
    # boundary_facets() gives each boundary facet once, in its cell's counter-clockwise order
    be = boundary_facets(m.cells)
    assert len(be) == on_boundary.sum()
    directed = {(cell[k], cell[(k + 1) % 3]) for cell in m.cells.tolist() for k in range(3)}
    assert all(tuple(e) in directed for e in be.tolist())


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_edge_local_is_the_index_of_the_edge_in_its_cells(name: str) -> None:
    p, c = HAND_MESHES[name]()
    m = Mesh.from_arrays(p, c, ALL)
    e = np.arange(m.n_edges)
    for side in range(2):
        has = m.facet2cell[:, side] >= 0
        cell, k = m.facet2cell[has, side], m.facet_local[has, side]
        assert np.array_equal(m.cell2edge[cell, k], e[has])
        # local edge k joins local vertices k and k + 1
        pair = np.sort(np.column_stack([m.cells[cell, k], m.cells[cell, (k + 1) % 3]]), axis=1)
        assert np.array_equal(pair, m.edges[has])
    assert np.array_equal(m.facet_local[:, 1] < 0, m.facet2cell[:, 1] < 0)


def test_topology_is_computed_once() -> None:
    m = rectangle(nx=3, ny=2)
    for name in ("edges", "cell2edge", "facet2cell", "facet_local", "boundary_facet", "facet_part"):
        assert getattr(m, name) is getattr(m, name), name


def test_from_arrays_puts_longest_edge_first() -> None:
    rng = np.random.default_rng(7)
    p, c = jittered_delaunay(8, seed=1)
    shift = rng.integers(0, 3, size=len(c))
    rolled = c[np.arange(len(c))[:, None], (np.arange(3)[None, :] + shift[:, None]) % 3]
    m = Mesh.from_arrays(p, rolled, ALL)
    q = m.points[m.cells]
    length = np.linalg.norm(q[:, [1, 2, 0]] - q, axis=2)  # edge k: vertex k -> k + 1
    assert np.all(length[:, 0] >= length.max(axis=1))
    # each cell is a cyclic rotation of the input cell (same vertices, same orientation)
    rotations = np.stack([np.roll(rolled, -s, axis=1) for s in range(3)])
    assert np.all((rotations == m.cells[None]).all(axis=2).any(axis=0))
    assert np.all(m.area > 0)


def test_oriented_boundary_is_counter_clockwise() -> None:
    m = rectangle(-1.0, 2.0, 0.5, 1.5, nx=3, ny=2, pattern="crossed")
    outward = {"bottom": (0, -1), "right": (1, 0), "top": (0, 1), "left": (-1, 0)}
    for name, normal in outward.items():
        pairs = m.oriented_boundary(m.part_facets(name))
        t = m.points[pairs[:, 1]] - m.points[pairs[:, 0]]
        n = np.column_stack([t[:, 1], -t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
        assert np.allclose(n, normal, atol=1e-15)
    # the whole oriented boundary encloses the area positively (shoelace formula)
    pairs = m.oriented_boundary(m.boundary_facet)
    a, b = m.points[pairs[:, 0]], m.points[pairs[:, 1]]
    assert 0.5 * np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1]) == pytest.approx(3.0, rel=1e-14)


@pytest.mark.parametrize("name", sorted(HAND_MESHES))
def test_oriented_boundary_keeps_cell_on_the_left(name: str) -> None:
    p, c = HAND_MESHES[name]()
    m = Mesh.from_arrays(p, c, ALL)
    e = m.boundary_facet
    pairs = m.oriented_boundary(e)
    assert np.array_equal(np.sort(pairs, axis=1), m.edges[e])
    third = m.cells[m.facet2cell[e, 0]].sum(axis=1) - pairs.sum(axis=1)
    a, b, x = m.points[pairs[:, 0]], m.points[pairs[:, 1]], m.points[third]
    cross = (b - a)[:, 0] * (x - a)[:, 1] - (b - a)[:, 1] * (x - a)[:, 0]
    assert np.all(cross > 0)


# ---------------------------------------------------------------------------- geometry
def test_geometry_closed_form() -> None:
    p, c = hexfan()
    m = Mesh.from_arrays(p, c, ALL)
    hexagon = 6 * np.sqrt(3) / 4
    u, v = p[7] - p[1], p[2] - p[1]
    extra = 0.5 * abs(u[0] * v[1] - u[1] * v[0])
    assert m.area.sum() == pytest.approx(hexagon + extra, rel=1e-14)
    assert np.allclose(m.area[:6], np.sqrt(3) / 4, rtol=1e-14)
    # all hexagon edges have length 1
    fan = m.cell2edge[:6].ravel()
    assert np.allclose(m.edge_length[fan], 1.0, rtol=1e-14)
    assert np.allclose(m.h[:6], 1.0, rtol=1e-14)
    assert m.h[6] == pytest.approx(
        max(np.linalg.norm(p[7] - p[1]), np.linalg.norm(p[7] - p[2]), 1.0), rel=1e-14
    )
    assert np.allclose(m.edge_midpoints, p[m.edges].mean(axis=1), rtol=0, atol=1e-15)
    # the equilateral fan has min angle 60 degrees; the extra triangle is smaller
    # law of cosines on the extra triangle (1, 7, 2): side s[k] is opposite vertex k
    q = p[[1, 7, 2]]
    s = [np.linalg.norm(q[(k + 1) % 3] - q[(k + 2) % 3]) for k in range(3)]
    ang = [
        np.arccos(
            (s[(k + 1) % 3] ** 2 + s[(k + 2) % 3] ** 2 - s[k] ** 2)
            / (2 * s[(k + 1) % 3] * s[(k + 2) % 3])
        )
        for k in range(3)
    ]
    assert sum(ang) == pytest.approx(np.pi)
    assert m.min_angle() == pytest.approx(min(min(ang), np.pi / 3), rel=1e-12)


def test_min_angle_of_rectangle_cells() -> None:
    m = rectangle(0, 3, 0, 1, nx=2, ny=2, pattern="right")  # cells 1.5 x 0.5
    assert m.min_angle() == pytest.approx(np.arctan(0.5 / 1.5), rel=1e-14)
    assert np.allclose(m.h, np.hypot(1.5, 0.5), rtol=1e-14)


def test_repr_counts() -> None:
    m = rectangle(nx=2, ny=3)
    assert repr(m) == "Mesh(n_points=12, n_cells=12, parts=['bottom', 'right', 'top', 'left'])"


@pytest.mark.parametrize(("nx", "ny"), [(20_000, 1), (1, 20_000)])
def test_long_boundary_validates(nx: int, ny: int) -> None:
    # 40 000 boundary edges: the hanging-node check must not compare all pairs
    m = rectangle(0, nx, 0, ny, nx=nx, ny=ny, pattern="left")
    assert len(m.boundary) == 2 * (nx + ny)
    assert m.part_measure("bottom") == pytest.approx(nx, rel=1e-12)
    assert m.part_measure("left") == pytest.approx(ny, rel=1e-12)
    assert m.area.sum() == pytest.approx(nx * ny, rel=1e-12)


def test_cached_arrays_are_read_only():
    mesh = rectangle(nx=2, ny=2)
    for name in (
        "edges",
        "cell2edge",
        "facet2cell",
        "facet_local",
        "area",
        "edge_length",
        "h",
        "edge_midpoints",
        "boundary_facet",
        "facet_part",
        "points",
        "cells",
    ):
        with pytest.raises(ValueError, match="read-only"):
            getattr(mesh, name)[0] = 0


# ---------------------------------------------------------------------------- selectors f(x)
def test_selectors_are_called_with_points_of_shape_n_2() -> None:
    seen = []

    def right(x):
        seen.append(x.shape)
        return x[:, 0] > 1 - 1e-12

    m = Mesh.from_arrays(SQUARE_P, SQUARE_C, {"right": right, "rest": lambda x: x[:, 0] < 1})
    assert seen == [(4, 2)]
    assert m.facets[m.part_facets("right")].tolist() == [[1, 2]]


def test_old_two_argument_selectors_warn_and_still_work() -> None:
    rest = {"rest": lambda x: x[:, 0] <= 0.5}
    new = Mesh.from_arrays(SQUARE_P, SQUARE_C, {"right": lambda x: x[:, 0] > 0.5, **rest})
    with pytest.warns(
        DeprecationWarning,
        match=r"selector of boundary part 'right' takes \(x, y\); selectors take the points x "
        r"of shape \(n, 2\): write `lambda x: \.\.\.` with x\[:, 0\] and x\[:, 1\]",
    ) as record:
        old = Mesh.from_arrays(SQUARE_P, SQUARE_C, {"right": lambda x, y: x > 0.5, **rest})
    assert len(record) == 1 and record[0].filename == __file__
    np.testing.assert_array_equal(old.boundary_part, new.boundary_part)
    np.testing.assert_array_equal(old.part_facets("right"), new.part_facets("right"))


def test_selector_that_raises_is_named() -> None:
    with pytest.raises(MeshError, match=r"selector of boundary part 'top' raised IndexError: "):
        Mesh.from_arrays(SQUARE_P, SQUARE_C, {"top": lambda x: x[:, 2] > 0})


# ---------------------------------------------------------------------------- argument kinds
@pytest.mark.parametrize(
    ("points", "cells", "parts", "match"),
    [
        (
            "0 0 1 0 1 1",
            SQUARE_C,
            ALL,
            r"points must be an \(n_points, 2\) array of numbers, got a string '0 0 1 0 1 1'",
        ),
        (
            SQUARE_P.astype(str),
            SQUARE_C,
            ALL,
            r"points must be an \(n_points, 2\) array of numbers, got an array of strings",
        ),
        (
            [[0, 0], [1, 0, 0]],
            SQUARE_C,
            ALL,
            r"points must be an \(n_points, 2\) array of numbers; NumPy says",
        ),
        (
            SQUARE_P,
            "0 1 2",
            ALL,
            r"cells must be an \(n, 3\) array of point indices, got a string '0 1 2'",
        ),
        (
            SQUARE_P,
            [["0", "1", "2"]],
            ALL,
            r"cells must be an \(n, 3\) array of point indices, got an array of strings",
        ),
        (
            SQUARE_P,
            SQUARE_C,
            [everything],
            r"parts must be a mapping \{name: \(k, 2\) boundary vertex pairs or selector "
            r"f\(x\)\}, got list",
        ),
        (SQUARE_P, SQUARE_C, ["all"], r"parts must be a mapping .*, got list"),
        (
            SQUARE_P,
            SQUARE_C,
            {"all": "everything"},
            r"boundary part 'all' must be a \(k, 2\) array of boundary vertex pairs or a "
            r"selector f\(x\), got the string 'everything'",
        ),
        (
            SQUARE_P,
            SQUARE_C,
            {"all": [[0, 1], [2]]},
            r"boundary part 'all' must be a \(k, 2\) array .*, got list",
        ),
        (SQUARE_P, SQUARE_C, {1: everything}, r"part names must be strings, got 1"),
    ],
)
def test_arguments_of_the_wrong_kind(points, cells, parts, match) -> None:
    with pytest.raises(MeshError, match=match):
        Mesh.from_arrays(points, cells, parts)


def test_parts_are_checked_before_any_work() -> None:
    # a list of parts is named even when the arrays are huge (nothing else is looked at)
    calls = []

    class Points:
        def __array__(self, *args, **kwargs):
            calls.append(1)
            return SQUARE_P

    with pytest.raises(MeshError, match="parts must be a mapping"):
        Mesh.from_arrays(Points(), SQUARE_C, [everything])
    assert calls == []
