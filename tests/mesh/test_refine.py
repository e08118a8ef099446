"""Tests of newest vertex bisection in :mod:`signorini.mesh.refine`."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mesh_problems import affine_copy

from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import Refinement, closure, refine_nvb, refine_uniform
from signorini.mesh.validation import validate_mesh

PATTERNS = ("unionjack", "right", "left", "crossed")


# ---------------------------------------------------------------------------- helpers
def angles(tri: np.ndarray) -> np.ndarray:
    """``(n, 3)`` interior angles at the three vertices of triangles ``tri (n, 3, 2)``."""
    out = []
    for k in range(3):
        u = tri[:, (k + 1) % 3] - tri[:, k]
        v = tri[:, (k + 2) % 3] - tri[:, k]
        cos = (u * v).sum(1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        out.append(np.arccos(np.clip(cos, -1.0, 1.0)))
    return np.stack(out, axis=1)


def shape_keys(tri: np.ndarray) -> np.ndarray:
    """Similarity class of labelled triangles ``[a, b, c]`` (refinement edge a-b, newest
    vertex c), up to a reflection: ``(min(A, B), max(A, B), C)`` of their angles."""
    a = angles(tri)
    return np.column_stack([np.minimum(a[:, 0], a[:, 1]), np.maximum(a[:, 0], a[:, 1]), a[:, 2]])


def reachable_shapes(tri: np.ndarray) -> np.ndarray:
    """All similarity classes in the bisection trees of the labelled triangles ``tri``.

    Walks the trees breadth first, one representative per class, bisecting ``[a, b, c]``
    into ``[c, a, m]`` and ``[b, c, m]`` with ``m`` the midpoint of ``a-b``, until no new
    class appears. Independent of :mod:`signorini.mesh.refine`.
    """
    classes = np.zeros((0, 3))
    frontier = tri
    while len(frontier):
        keys = shape_keys(frontier)
        _, first = np.unique(np.round(keys, 8), axis=0, return_index=True)
        known = [np.abs(classes - keys[i]).max(axis=1).min(initial=1.0) < 1e-8 for i in first]
        new = first[~np.array(known, dtype=bool)]
        classes = np.vstack([classes, keys[new]])
        a, b, c = (frontier[new, k] for k in range(3))
        m = 0.5 * (a + b)
        frontier = np.concatenate([np.stack([c, a, m], 1), np.stack([b, c, m], 1)])
    return classes


def brute_force_closure(mesh: Mesh, marked: np.ndarray) -> np.ndarray:
    """Smallest closed superset of ``marked``: plain fixed point iteration over the cells."""
    marked = marked.copy()
    changed = True
    while changed:
        changed = False
        for t in range(mesh.n_cells):
            e = mesh.cell2edge[t]
            if marked[e].any() and not marked[e[0]]:
                marked[e[0]] = True
                changed = True
    return marked


def barycentric(tri: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``(n, 3)`` barycentric coordinates of points ``x (n, 2)`` in triangles ``(n, 3, 2)``."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    m = np.stack([b - a, c - a], axis=2)  # (n, 2, 2)
    xi = np.linalg.solve(m, (x - a)[..., None])[..., 0]
    return np.column_stack([1 - xi.sum(1), xi])


def check_refinement(old: Mesh, ref: Refinement, marked: np.ndarray | None) -> None:
    """Every property a newest vertex bisection step must have."""
    new, parent, edge_point = ref.mesh, ref.parent, ref.edge_point
    validate_mesh(new)  # conforming, counter-clockwise, every boundary edge labelled
    assert np.all(new.area > 0)
    assert new.part_names == old.part_names
    assert parent.shape == (new.n_cells,) and edge_point.shape == (old.n_edges,)
    # nested: old points keep index and coordinates
    assert np.array_equal(new.points[: old.n_points], old.points)
    # every new point is the midpoint of one bisected old edge
    bisected = edge_point >= 0
    assert np.array_equal(np.sort(edge_point[bisected]), np.arange(old.n_points, new.n_points))
    assert np.allclose(
        new.points[edge_point[bisected]], old.edge_midpoints[bisected], rtol=0, atol=1e-14
    )
    # the bisected edges form a closed set: a cell with a bisected edge has its refinement
    # edge bisected
    cut = bisected[old.cell2edge]
    assert np.all(cut[:, 0] | ~cut.any(axis=1))
    # areas: total, and per parent
    assert new.area.sum() == pytest.approx(old.area.sum(), rel=1e-13)
    assert np.allclose(
        np.bincount(parent, weights=new.area, minlength=old.n_cells), old.area, rtol=1e-12, atol=0
    )
    for name in old.part_names:
        assert new.part_measure(name) == pytest.approx(old.part_measure(name), rel=1e-13)
    # parts survive: each new boundary edge lies on an old boundary edge of the same part
    origin = np.full(new.n_points, -1, dtype=np.int64)  # old edge bisected at a new point
    origin[edge_point[bisected]] = np.flatnonzero(bisected)
    a, b = new.boundary[:, 0], new.boundary[:, 1]
    new_end = np.where(a >= old.n_points, a, b)
    from_split = new_end >= old.n_points
    old_edge = np.empty(len(a), dtype=np.int64)
    old_edge[from_split] = origin[new_end[from_split]]
    keys = old.edges[:, 0] * old.n_points + old.edges[:, 1]  # sorted: edges come from np.unique
    whole = np.sort(new.boundary[~from_split], axis=1)
    old_edge[~from_split] = np.searchsorted(keys, whole[:, 0] * old.n_points + whole[:, 1])
    assert np.array_equal(old.edges[old_edge[~from_split]], whole)
    assert np.array_equal(new.boundary_part, old.facet_part[old_edge])
    # a cell with k bisected edges has k + 1 children; unrefined cells are kept as they are
    children = np.bincount(parent, minlength=old.n_cells)
    assert np.array_equal(children, 1 + cut.sum(axis=1))
    kept = children[parent] == 1
    assert np.array_equal(new.cells[kept], old.cells[parent[kept]])
    # children of refined cells have a new point as newest vertex
    assert np.all(new.cells[~kept, 2] >= old.n_points)
    if marked is not None:
        assert np.all(children[marked] >= 2)
    # each child lies in its parent: centroid strictly inside, diameter not larger
    centroid = new.points[new.cells].mean(axis=1)
    bary = barycentric(old.points[old.cells[parent]], centroid)
    assert bary.min() > 1e-3
    assert np.all(new.h <= old.h[parent] * (1 + 1e-12))


def check_shapes(mesh: Mesh, classes: np.ndarray) -> None:
    """All cells of ``mesh`` are similar to one of ``classes`` (up to a reflection)."""
    keys = np.unique(np.round(shape_keys(mesh.points[mesh.cells]), 9), axis=0)
    dist = np.abs(keys[:, None, :] - classes[None, :, :]).max(axis=2).min(axis=1)
    assert dist.max() < 1e-7, f"{(dist >= 1e-7).sum()} shapes outside the NVB family"


# ---------------------------------------------------------------------------- closed form
def one_triangle() -> Mesh:
    p = np.array([[0.0, 0.0], [2.0, 0.0], [0.5, 1.0]])
    return Mesh.from_arrays(p, [[0, 1, 2]], {"all": lambda x: np.ones(len(x), dtype=bool)})


def test_bisect_one_triangle() -> None:
    m = one_triangle()
    assert m.cells.tolist() == [[0, 1, 2]]  # (0,0)-(2,0) is the longest edge
    r = refine_nvb(m, np.array([True]))
    assert r.mesh.points[3].tolist() == [1.0, 0.0]
    assert r.mesh.cells.tolist() == [[2, 0, 3], [1, 2, 3]]
    assert r.parent.tolist() == [0, 0]
    assert r.edge_point[m.cell2edge[0]].tolist() == [3, -1, -1]
    assert r.mesh.area.tolist() == [0.5, 0.5]
    check_refinement(m, r, np.array([True]))


def test_uniform_one_triangle() -> None:
    m = one_triangle()
    r = refine_uniform(m)
    new = r.mesh
    assert new.n_cells == 4 and new.n_points == 6
    mids = {tuple(x) for x in new.points[3:].tolist()}
    assert mids == {(1.0, 0.0), (1.25, 0.5), (0.25, 0.5)}
    assert np.allclose(new.area, 0.25, rtol=1e-15)
    # the two corner children at a and b are similar to the parent with ratio 1/2
    corner = {tuple(sorted(map(tuple, new.points[c].tolist()))) for c in new.cells}
    assert ((0.0, 0.0), (0.25, 0.5), (1.0, 0.0)) in corner
    assert ((1.0, 0.0), (1.25, 0.5), (2.0, 0.0)) in corner
    check_refinement(m, r, np.array([True]))


def test_marking_one_cell_of_a_square_bisects_the_shared_diagonal() -> None:
    m = rectangle(nx=1, ny=1, pattern="right")
    r = refine_nvb(m, np.array([0]))
    assert r.mesh.n_cells == 4 and r.mesh.n_points == 5
    assert r.mesh.points[4].tolist() == [0.5, 0.5]
    assert np.allclose(r.mesh.area, 0.25, rtol=1e-15)
    assert np.allclose(r.mesh.h, 1.0, rtol=1e-15)  # children: unit legs, hypotenuse a side
    check_refinement(m, r, np.array([True, False]))


def test_no_marked_cell_changes_nothing() -> None:
    m = rectangle(nx=3, ny=2)
    for marked in (np.zeros(m.n_cells, dtype=bool), np.array([], dtype=np.int64)):
        r = refine_nvb(m, marked)
        assert np.array_equal(r.mesh.cells, m.cells)
        assert np.array_equal(r.mesh.points, m.points)
        assert np.array_equal(r.parent, np.arange(m.n_cells))
        assert np.all(r.edge_point == -1)


def test_index_marking_equals_mask_marking() -> None:
    m = rectangle(nx=4, ny=3, pattern="crossed")
    idx = np.array([0, 5, 5, 17, 40])
    mask = np.zeros(m.n_cells, dtype=bool)
    mask[idx] = True
    a, b = refine_nvb(m, idx), refine_nvb(m, mask)
    assert np.array_equal(a.mesh.cells, b.mesh.cells)
    assert np.array_equal(a.edge_point, b.edge_point)


@pytest.mark.parametrize(
    ("marked", "match"),
    [
        (np.ones(5, dtype=bool), r"boolean marking needs shape \(24,\), got \(5,\)"),
        (np.array([0, 24]), r"marked cell indices must lie in 0\.\.23"),
        (np.array([-1]), r"marked cell indices must lie in 0\.\.23"),
        (np.array([0.5]), "boolean mask or an array of cell indices"),
    ],
)
def test_refine_rejects_bad_marking(marked, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        refine_nvb(rectangle(nx=4, ny=3), marked)


# ---------------------------------------------------------------------------- uniform
@pytest.mark.parametrize("pattern", PATTERNS)
@pytest.mark.parametrize(("x1", "y1", "nx", "ny"), [(1, 1, 2, 2), (3, 1, 3, 2), (1, 4, 2, 5)])
def test_uniform_quadruples_cells_and_halves_h(pattern, x1, y1, nx, ny) -> None:
    m = rectangle(0, x1, 0, y1, nx=nx, ny=ny, pattern=pattern)
    h0 = m.h.max()
    for level in range(1, 3):
        r = refine_uniform(m)
        check_refinement(m, r, np.ones(m.n_cells, dtype=bool))
        assert r.mesh.n_cells == 4 * m.n_cells
        assert r.mesh.n_points == m.n_points + m.n_edges
        assert np.all(r.edge_point >= 0)
        assert np.allclose(r.mesh.area, m.area[r.parent] / 4, rtol=1e-12)
        if pattern != "crossed":  # right triangles: every child has half its parent's h
            assert np.allclose(r.mesh.h, m.h[r.parent] / 2, rtol=1e-12)
        m = r.mesh
        assert m.h.max() == pytest.approx(h0 / 2**level, rel=1e-12)


def test_uniform_on_a_sheared_mesh_keeps_area_ratio() -> None:
    m = affine_copy(
        rectangle(nx=3, ny=2, pattern="unionjack"),
        np.array([[1.0, 0.7], [0.2, 1.5]]),
        np.array([3.0, -1.0]),
    )
    r = refine_uniform(m)
    check_refinement(m, r, None)
    assert np.allclose(r.mesh.area, m.area[r.parent] / 4, rtol=1e-12)
    assert np.all(np.bincount(r.parent) == 4)


# ---------------------------------------------------------------------------- closure
@settings(max_examples=20, deadline=None)
@given(
    pattern=st.sampled_from(PATTERNS),
    fraction=st.floats(0.02, 0.5),
    seed=st.integers(0, 2**32 - 1),
)
def test_closure_is_the_smallest_closed_superset(pattern: str, fraction: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    m = rectangle(nx=3, ny=3, pattern=pattern)
    m = refine_nvb(m, rng.random(m.n_cells) < 0.3).mesh  # not all refinement edges alike
    marked = rng.random(m.n_edges) < fraction
    copy = marked.copy()
    closed = closure(m, marked)
    assert np.array_equal(marked, copy)  # input untouched
    assert np.array_equal(closed, brute_force_closure(m, marked))
    assert np.all(closed[marked])
    assert np.array_equal(closure(m, closed), closed)
    cut = closed[m.cell2edge]
    assert np.all(cut[:, 0] | ~cut.any(axis=1))


def test_closure_of_nothing_and_of_everything() -> None:
    m = rectangle(nx=2, ny=3, pattern="left")
    assert not closure(m, np.zeros(m.n_edges, dtype=bool)).any()
    assert closure(m, np.ones(m.n_edges, dtype=bool)).all()


def test_closure_propagates_along_a_chain() -> None:
    # in the "right" pattern every refinement edge is a diagonal; marking a leg of a cell
    # forces its diagonal, which is a whole cell's refinement edge on both sides
    m = rectangle(nx=4, ny=1, pattern="right")
    bottom = m.part_facets("bottom")
    marked = np.zeros(m.n_edges, dtype=bool)
    marked[bottom[0]] = True
    closed = closure(m, marked)
    assert closed.sum() == 2  # the leg and the diagonal of its square
    assert np.array_equal(closed, brute_force_closure(m, marked))


def test_closure_rejects_bad_shape() -> None:
    m = rectangle(nx=2, ny=2)
    with pytest.raises(ValueError, match=rf"marked_edges needs shape \({m.n_edges},\)"):
        closure(m, np.ones(3, dtype=bool))


@settings(max_examples=15, deadline=None)
@given(fraction=st.floats(0.0, 0.5), seed=st.integers(0, 2**32 - 1))
def test_refine_nvb_bisects_exactly_the_closure(fraction: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    m = refine_nvb(rectangle(nx=4, ny=4), rng.random(32) < 0.4).mesh
    marked = rng.random(m.n_cells) < fraction
    r = refine_nvb(m, marked)
    seed = np.zeros(m.n_edges, dtype=bool)
    seed[m.cell2edge[marked, 0]] = True
    assert np.array_equal(r.edge_point >= 0, brute_force_closure(m, seed))


# ---------------------------------------------------------------------------- properties
@st.composite
def starting_meshes(draw) -> Mesh:
    nx = draw(st.integers(1, 4))
    ny = draw(st.integers(1, 4))
    pattern = draw(st.sampled_from(PATTERNS))
    turn = draw(st.floats(0.0, 2 * np.pi))
    sx, sy = draw(st.floats(0.3, 3.0)), draw(st.floats(0.3, 3.0))
    shear = draw(st.floats(-0.8, 0.8))
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    matrix = rot @ np.array([[sx, shear * sx], [0.0, sy]])
    shift = np.array([draw(st.floats(-5.0, 5.0)), draw(st.floats(-5.0, 5.0))])
    return affine_copy(rectangle(nx=nx, ny=ny, pattern=pattern), matrix, shift)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    mesh=starting_meshes(),
    steps=st.integers(1, 4),
    fraction=st.floats(0.0, 0.6),
    seed=st.integers(0, 2**32 - 1),
)
def test_nvb_properties(mesh: Mesh, steps: int, fraction: float, seed: int) -> None:
    """Random markings of random affine images of the built-in meshes: every step keeps the
    mesh conforming and counter-clockwise, nested (old points kept, new points at midpoints of
    bisected edges, children inside their parent), the total area, each cell's area and each
    boundary part's length, with every new boundary edge in its old edge's part; shapes stay
    in the finite NVB family, so the minimum angle stays above the initial mesh's bound."""
    rng = np.random.default_rng(seed)
    classes = reachable_shapes(mesh.points[mesh.cells])
    bound = classes.min()
    area = mesh.area.sum()
    lengths = {name: mesh.part_measure(name) for name in mesh.part_names}
    for _ in range(steps):
        marked = rng.random(mesh.n_cells) < fraction
        if not marked.any():
            marked[rng.integers(mesh.n_cells)] = True
        r = refine_nvb(mesh, marked)
        check_refinement(mesh, r, marked)
        mesh = r.mesh
        check_shapes(mesh, classes)
        assert mesh.min_angle() >= bound - 1e-9
    assert mesh.area.sum() == pytest.approx(area, rel=1e-12)
    for name, length in lengths.items():
        assert mesh.part_measure(name) == pytest.approx(length, rel=1e-12)


@pytest.mark.parametrize(
    ("pattern", "matrix"),
    [
        ("unionjack", [[1.0, 0.0], [0.0, 1.0]]),
        ("right", [[2.0, 0.9], [0.0, 0.7]]),
        ("crossed", [[1.0, -0.5], [0.3, 1.2]]),
        ("left", [[0.4, 0.0], [0.0, 2.5]]),
    ],
)
def test_shapes_stay_in_a_finite_family(pattern: str, matrix) -> None:
    m0 = affine_copy(rectangle(nx=2, ny=2, pattern=pattern), np.array(matrix), np.zeros(2))
    labelled = np.unique(np.round(shape_keys(m0.points[m0.cells]), 9), axis=0)
    classes = reachable_shapes(m0.points[m0.cells])
    # NVB: at most four similarity classes descend from one labelled triangle
    assert len(classes) <= 4 * len(labelled)
    bound = classes.min()
    # uniform refinements stay within the family, and can do no better than its bound
    u = m0
    for _ in range(3):
        u = refine_uniform(u).mesh
        check_shapes(u, classes)
        assert u.min_angle() >= bound - 1e-9
    # refine towards a corner for many levels: the cells shrink a thousandfold and more,
    # their shapes do not degenerate
    corner = m0.points[np.argmin(m0.points.sum(axis=1))]
    m = m0
    for _ in range(24):
        near = np.linalg.norm(m.points[m.cells] - corner, axis=2).min(axis=1) < 1e-12
        m = refine_nvb(m, near).mesh
        check_shapes(m, classes)
    assert m.h.min() < 1e-3 * m0.h.min()
    assert m.min_angle() >= bound - 1e-9
    seen = np.unique(np.round(shape_keys(m.points[m.cells]), 7), axis=0)
    assert len(seen) <= len(classes)
    validate_mesh(m)


# ---------------------------------------------------------------------------- scale
def test_refine_a_hundred_thousand_cells() -> None:
    m = rectangle(nx=224, ny=224, pattern="unionjack")
    assert m.n_cells == 100_352
    rng = np.random.default_rng(5)
    marked = rng.random(m.n_cells) < 0.1
    start = time.perf_counter()
    r = refine_nvb(m, marked)
    elapsed = time.perf_counter() - start
    print(
        f"refine_nvb on {m.n_cells} cells ({marked.sum()} marked): {elapsed:.3f} s, "
        f"{r.mesh.n_cells} cells after"
    )
    # one call refines every marked cell and leaves a valid mesh: no second pass needed
    children = np.bincount(r.parent, minlength=m.n_cells)
    assert np.all(children[marked] >= 2)
    validate_mesh(r.mesh)
    assert r.mesh.area.sum() == pytest.approx(1.0, rel=1e-12)
    assert np.array_equal(r.mesh.points[: m.n_points], m.points)
