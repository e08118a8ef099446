"""The cells' and edges' geometry (fem/mapping.py): affine Jacobians against hand-computed
values, the isoparametric map on straight-sided cells against the affine one, areas and arc
lengths by quadrature along curves, and derivatives of interpolated fields."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.fem import p2
from signorini.fem.mapping import (
    AffineCells,
    CellMap,
    IsoparametricCells,
    QuadraticFacets,
    StraightFacets,
    facet_groups,
)
from signorini.fem.material import Material, stress
from signorini.fem.postprocess import cell_stress
from signorini.fem.quadrature import line_rule, triangle_rule
from signorini.fem.space import P2Space

from .test_iso import curved_sector

#: one cell with v1 - v0 = (3, 1), v2 - v0 = (1, 4): J = [[3, 1], [1, 4]], det J = 11
VERTICES = np.array([[[1.0, 2.0], [4.0, 3.0], [2.0, 6.0]]])


def straight_nodes(vertices: np.ndarray) -> np.ndarray:
    """The six P2 node points of straight cells: vertices, then the edge midpoints."""
    mid = 0.5 * (vertices + np.roll(vertices, -1, axis=1))
    return np.concatenate([vertices, mid], axis=1)


def random_cells(n: int, seed: int = 0) -> np.ndarray:
    """``n`` well-shaped counter-clockwise cells: the reference triangle perturbed, scaled
    and shifted at random."""
    rng = np.random.default_rng(seed)
    v = p2.REFERENCE_NODES[:3] + 0.2 * rng.random((n, 3, 2))
    return rng.uniform(0.5, 2.0, (n, 1, 1)) * v + rng.standard_normal((n, 1, 2))


def sector_nodes(n: int) -> np.ndarray:
    """The quarter disc r < 1 as ``n`` isoparametric cells ``(n, 6, 2)``: the centre and two
    points on the circle, the arc's midpoint node on it."""
    a = np.linspace(0, np.pi / 2, n + 1)
    h = 0.5 * (a[:-1] + a[1:])
    on = lambda t: np.stack([np.cos(t), np.sin(t)], axis=-1)  # noqa: E731
    v0, v1, v2 = np.zeros((n, 2)), on(a[:-1]), on(a[1:])
    return np.stack([v0, v1, v2, 0.5 * v1, on(h), 0.5 * v2], axis=1)


def test_affine_jacobian_determinant_and_inverse_are_the_hand_computed_ones():
    cells = AffineCells(VERTICES)
    xi, w = triangle_rule(4)
    J, det = cells.jacobians(xi)
    assert J.shape == (1, 1, 2, 2) and det.shape == (1, 1)  # one per cell, for every point
    np.testing.assert_array_equal(J[0, 0], [[3.0, 1.0], [1.0, 4.0]])
    assert det[0, 0] == 11.0
    np.testing.assert_allclose(
        cells.inverse_transpose(xi)[0, 0], np.array([[4.0, -1.0], [-1.0, 3.0]]) / 11, rtol=1e-15
    )
    assert cells.measure(w, xi).sum() == pytest.approx(5.5, rel=1e-14)  # the area
    x = cells.points(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.25, 0.5]]))
    np.testing.assert_allclose(x[0], [[1, 2], [4, 3], [2, 6], [1 + 0.75 + 0.5, 2 + 0.25 + 2]])


def test_isoparametric_map_of_straight_sided_cells_is_the_affine_map():
    vertices = random_cells(20)
    affine, curved = AffineCells(vertices), IsoparametricCells(straight_nodes(vertices))
    xi, _ = triangle_rule(6)
    u = np.random.default_rng(1).standard_normal((20, 12))
    J, det = curved.jacobians(xi)
    Ja, deta = affine.jacobians(xi)
    scale = np.abs(Ja).max()
    assert np.abs(curved.points(xi) - affine.points(xi)).max() < 1e-15
    assert np.abs(J - Ja).max() < 1e-14 * scale
    assert np.abs(det - deta).max() < 1e-14 * np.abs(deta).max()
    jit = affine.inverse_transpose(xi)
    assert np.abs(curved.inverse_transpose(xi) - jit).max() < 1e-12 * np.abs(jit).max()
    G = affine.basis_gradients(xi)
    assert np.abs(curved.basis_gradients(xi) - G).max() < 1e-12 * np.abs(G).max()
    g = affine.field_gradients(u, xi)
    assert np.abs(curved.field_gradients(u, xi) - g).max() < 1e-12 * np.abs(g).max()
    assert np.abs(affine.gradient_field(u)(xi) - g).max() < 1e-13 * np.abs(g).max()
    H = affine.field_hessians(u)
    assert np.abs(curved.field_hessians(u, xi) - H).max() < 1e-10 * np.abs(H).max()


def test_the_gradient_of_an_interpolated_quadratic_is_exact_on_affine_cells():
    A = np.array([[0.3, -1.2, 0.7], [2.0, 0.4, -0.9]])  # u_i = A_i0 x² + A_i1 x y + A_i2 y²

    def grad(x):
        X, Y = x[..., 0], x[..., 1]
        return np.stack(
            [
                np.stack([2 * A[i, 0] * X + A[i, 1] * Y, A[i, 1] * X + 2 * A[i, 2] * Y], -1)
                for i in range(2)
            ],
            axis=-2,
        )

    vertices = random_cells(10, seed=3)
    cells = AffineCells(vertices)
    nodes = straight_nodes(vertices)
    X, Y = nodes[..., 0], nodes[..., 1]
    u = np.stack([A[i, 0] * X**2 + A[i, 1] * X * Y + A[i, 2] * Y**2 for i in range(2)], -1)
    xi, _ = triangle_rule(5)
    got = cells.field_gradients(u.reshape(10, 12), xi)
    assert np.abs(got - grad(cells.points(xi))).max() < 1e-13
    H = cells.field_hessians(u.reshape(10, 12))[:, 0]
    expected = [[[2 * A[i, 0], A[i, 1]], [A[i, 1], 2 * A[i, 2]]] for i in range(2)]
    assert np.abs(H - np.array(expected)).max() < 1e-11


def test_points_and_gradients_of_a_curved_cell_agree():
    """On an isoparametric cell the field x itself (its own node points as coefficients) has
    the identity as gradient and a zero Hessian, and the gradients of the map's points
    match finite differences through the Jacobian."""
    cells = IsoparametricCells(sector_nodes(3))
    xi = np.array([[0.2, 0.3], [0.6, 0.1], [0.1, 0.8]])
    u = cells.nodes.reshape(3, 12)
    assert np.abs(cells.field_gradients(u, xi) - np.eye(2)).max() < 1e-13
    assert np.abs(cells.field_hessians(u, xi)).max() < 1e-11
    J, _ = cells.jacobians(xi)
    e = 1e-6
    for j in range(2):
        step = np.zeros(2)
        step[j] = e
        fd = (cells.points(xi + step) - cells.points(xi - step)) / (2 * e)
        assert np.abs(fd - J[..., j]).max() < 1e-8


def test_area_of_a_disc_sector_and_length_of_an_arc_converge_at_the_expected_rates():
    xi, w = triangle_rule(6)
    t, wt = line_rule(8)
    area, length = [], []
    for n in (2, 4, 8, 16):
        nodes = sector_nodes(n)
        area.append(abs(IsoparametricCells(nodes).measure(w, xi).sum() - np.pi / 4))
        arc = QuadraticFacets(nodes[:, [1, 2, 4]])
        length.append(abs((arc.speeds(t) * wt).sum() - np.pi / 2))
    rate_area = np.log2(np.array(area[:-1]) / area[1:])
    rate_length = np.log2(np.array(length[:-1]) / length[1:])
    print(f"area errors {area} rates {rate_area}; length errors {length} rates {rate_length}")
    # the quadratic interpolant of the circle: O(h^4) in area and length (O(h^3) pointwise,
    # the error's mean over each edge one order smaller)
    assert np.all(rate_area > 3.9) and np.all(rate_length > 3.9)
    # straight chords: O(h^2)
    chords = StraightFacets(sector_nodes(16)[:, [1, 2]])
    assert abs(chords.length.sum() - np.pi / 2) > 100 * length[-1]


def test_edges_straight_and_quadratic():
    ends = np.array([[[0.0, 0.0], [3.0, 4.0]], [[1.0, 1.0], [1.0, -1.0]]])
    straight = StraightFacets(ends)
    np.testing.assert_array_equal(straight.length, [5.0, 2.0])
    np.testing.assert_allclose(straight.normals()[:, 0], [[0.8, -0.6], [-1.0, 0.0]])
    t = np.array([0.0, 0.25, 1.0])
    np.testing.assert_allclose(straight.points(t)[0], [[0, 0], [0.75, 1.0], [3, 4]])
    # a quadratic edge with its midpoint on the chord is the straight edge
    flat = QuadraticFacets(np.concatenate([ends, ends.mean(axis=1, keepdims=True)], axis=1))
    assert np.abs(flat.points(t) - straight.points(t)).max() < 1e-15
    assert np.abs(flat.normals(t) - straight.normals(t)).max() < 1e-15
    assert np.abs(flat.speeds(t) - straight.speeds(t)).max() < 1e-14
    assert np.abs(flat.speed_at(np.tile(t, (2, 1))) - straight.length[:, None]).max() < 1e-14
    groups = list(facet_groups(flat.nodes, np.array([False, True])))
    assert [type(g).__name__ for _, g in groups] == ["StraightFacets", "QuadraticFacets"]
    assert [list(r) for r, _ in groups] == [[0], [1]]


def test_cell_map_puts_each_group_in_mesh_order():
    vertices = random_cells(6, seed=7)
    nodes = straight_nodes(vertices)
    nodes[[1, 4], 3] += 0.01  # bulge the first edge of two cells
    mapping = CellMap(vertices, (np.array([1, 4]), nodes[[1, 4]]))
    assert [len(g) for g in mapping.groups] == [4, 2]
    xi, w = triangle_rule(4)
    x = mapping.points(xi)
    np.testing.assert_array_equal(x[[0, 2, 3, 5]], AffineCells(vertices[[0, 2, 3, 5]]).points(xi))
    np.testing.assert_array_equal(x[[1, 4]], IsoparametricCells(nodes[[1, 4]]).points(xi))
    area = mapping.per_cell(lambda g: g.measure(w, xi).sum(axis=1))
    assert area.shape == (6,)
    straight = 0.5 * np.abs(p2.jacobian(vertices)[1])
    np.testing.assert_allclose(area[[0, 2, 3, 5]], straight[[0, 2, 3, 5]], rtol=1e-14)
    assert np.all(np.abs(area[[1, 4]] - straight[[1, 4]]) > 1e-4)  # the bulge counts
    parts = list(mapping.split(np.array([4, 0, 1, 5])))
    assert [(list(r), list(s)) for r, _, s in parts] == [([1, 3], [0, 3]), ([0, 2], [1, 0])]
    only = CellMap(vertices)
    assert len(only.groups) == 1 and only.per_cell(lambda g: g.points(xi)) is not None
    every = CellMap(vertices, (np.arange(6), nodes))  # no affine cell at all
    assert len(every.groups) == 1 and isinstance(every.groups[0], IsoparametricCells)
    np.testing.assert_array_equal(every.points(xi), IsoparametricCells(nodes).points(xi))


def test_the_stress_of_an_interpolated_linear_field_is_exact_through_the_map():
    """On the annulus sector with its arcs, σ(I_h u) of a linear u at points of every cell:
    exact through the cell map; the straight reading of the isoparametric cells' coefficients
    is not."""
    material = Material.from_young(1.0, 0.3)
    B = np.array([[0.3, -0.7], [0.2, 0.5]])
    space = P2Space(curved_sector())
    u_cell = space.cell_values(space.interpolate(lambda x: x @ B.T + 0.1))
    xi, _ = triangle_rule(4)
    expected = stress(material, B)
    sigma = cell_stress(space.mapping, u_cell, material, xi)
    assert sigma.shape == (space.mesh.n_cells, len(xi), 2, 2)
    assert np.abs(sigma - expected).max() < 1e-13
    straight = cell_stress(space.vertices, u_cell, material, xi)
    assert np.abs(straight - expected).max() > 1e-2
    per_cell = np.broadcast_to(xi, (space.mesh.n_cells,) + xi.shape)
    assert np.abs(cell_stress(space.mapping, u_cell, material, per_cell) - sigma).max() < 1e-15
