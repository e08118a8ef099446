"""The P2 tetrahedron: basis, face basis, quadrature, element record, mapping and space."""

from math import factorial

import numpy as np
import pytest
from fem3d_problems import distorted_box

from signorini.fem import p2, p2_tet
from signorini.fem.element import P2, P2_TET, element_of
from signorini.fem.facet_element import P2_TRIANGLE
from signorini.fem.mapping3d import AffineTetrahedra, IsoparametricTetrahedra, QuadraticFaces
from signorini.fem.quadrature import tetrahedron_rule, triangle_rule
from signorini.fem.space import space_of
from signorini.fem.space3d import P2TetSpace
from signorini.mesh.builders3d import box, eighth_ball
from signorini.mesh.jacobians import affine_jacobian
from signorini.mesh.reference import TETRAHEDRON, TRIANGLE
from signorini.mesh.refine import Refinement
from signorini.mesh.refine3d import bisect_mesh

RNG = np.random.default_rng(20261202)


def random_points(n):
    """``n`` random points of the reference tetrahedron."""
    return RNG.dirichlet(np.ones(4), size=n)[:, 1:]


def random_tetrahedron():
    """The vertices ``(1, 4, 3)`` of a random positively oriented tetrahedron."""
    v = RNG.normal(size=(4, 3))
    if affine_jacobian(v[None])[1][0] < 0:
        v = v[[0, 2, 1, 3]]
    return v[None]


def test_partition_of_unity_and_zero_gradient_sums():
    xi = random_points(40)
    assert np.allclose(p2_tet.basis(xi).sum(axis=1), 1.0, atol=1e-14)
    assert np.allclose(p2_tet.grad_basis(xi).sum(axis=1), 0.0, atol=1e-13)
    assert np.allclose(p2_tet.hessian_basis().sum(axis=0), 0.0, atol=1e-13)


def test_nodal_and_vtk_tetra10_order():
    assert np.array_equal(p2_tet.basis(p2_tet.REFERENCE_NODES), np.eye(10))
    # the 4 vertices, then the midpoints of 01, 12, 20, 03, 13, 23 (VTK's quadratic tetra)
    v = TETRAHEDRON.vertices
    mids = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
    expected = np.vstack([v, [0.5 * (v[a] + v[b]) for a, b in mids]])
    assert np.array_equal(p2_tet.REFERENCE_NODES, expected)


def test_gradients_and_hessians_match_finite_differences():
    xi, h = random_points(5), 1e-6
    g = p2_tet.grad_basis(xi)
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        fd = (p2_tet.basis(xi + e) - p2_tet.basis(xi - e)) / (2 * h)
        assert np.allclose(g[:, :, j], fd, atol=1e-8)
        fd2 = (p2_tet.grad_basis(xi + e) - p2_tet.grad_basis(xi - e)) / (2 * h)
        assert np.allclose(p2_tet.hessian_basis()[None, :, :, j], fd2, atol=1e-7)


def test_face_trace_is_the_p2_triangle_and_integrates_to_a_third_at_midpoints():
    s, w = triangle_rule(4)
    v = random_tetrahedron()[0]
    for k in range(4):
        nodes = np.concatenate([TETRAHEDRON.facets[k], 4 + p2_tet.FACE_EDGES[k]])
        phi = p2_tet.basis(p2_tet.face_reference_points(k, s))  # (q, 10)
        # the cell's basis on the face: the face's six functions are the P2 triangle's, the
        # other four vanish
        assert np.allclose(phi[:, nodes], p2_tet.face_basis(s), atol=1e-14)
        others = np.setdiff1d(np.arange(10), nodes)
        assert np.allclose(phi[:, others], 0.0, atol=1e-14)
        corners = v[TETRAHEDRON.facets[k]]
        area = 0.5 * np.linalg.norm(np.cross(corners[1] - corners[0], corners[2] - corners[0]))
        integral = 2 * area * (w @ p2_tet.face_basis(s))
        assert np.allclose(integral, np.array([0, 0, 0, 1, 1, 1]) / 3 * area, atol=1e-14)
    assert P2_TRIANGLE.basis_share == (0.0, 0.0, 0.0, 1 / 3, 1 / 3, 1 / 3)
    assert P2_TRIANGLE.basis is p2.basis and P2_TRIANGLE.n_nodes == 6


def test_face_sides_are_the_local_edges_of_the_face():
    for k in range(4):
        a, b, c = TETRAHEDRON.facets[k]
        for side, (x, y) in zip(p2_tet.FACE_EDGES[k], [(a, b), (b, c), (c, a)], strict=True):
            assert set(TETRAHEDRON.edges[side]) == {x, y}


@pytest.mark.parametrize("name", ["hat_pieces", "node_parts"])
def test_estimator_pieces_of_a_face_refuse_naming_the_contact_issue(name):
    with pytest.raises(NotImplementedError, match="issue 38"):
        getattr(P2_TRIANGLE, name)


@pytest.mark.parametrize("alpha", [0.0, 0.2, 0.35])
def test_contact_weights_of_a_face(alpha):
    s, w = triangle_rule(4)
    phi = p2.basis(s)  # (q, 6); the reference triangle has area 1/2
    T = np.eye(6)
    for e, (a, b) in zip(range(3, 6), [(0, 1), (1, 2), (2, 0)], strict=True):
        T[e, e], T[a, e], T[b, e] = 1 - 2 * alpha, alpha, alpha
    share = 2 * (w @ (phi @ T.T))
    np.testing.assert_allclose(P2_TRIANGLE.transformed_share(alpha), share, atol=1e-15)
    assert P2_TRIANGLE.hat_share == (1 / 12, 1 / 12, 1 / 12, 1 / 4, 1 / 4, 1 / 4)
    if alpha > 0:
        p = P2_TRIANGLE.pressure(0.3 * np.array(share), np.array(share))
        np.testing.assert_allclose(p, 0.3, rtol=1e-15)
    else:
        with pytest.raises(ValueError, match="integrate to zero"):
            P2_TRIANGLE.pressure(np.ones(6), np.array(share))


@pytest.mark.parametrize("degree", range(9))
def test_tetrahedron_rule_is_exact_on_monomials(degree):
    xi, w = tetrahedron_rule(degree)
    assert (w > 0).all() and np.isclose(w.sum(), 1 / 6, rtol=1e-14, atol=0)
    assert (xi > 0).all() and (xi.sum(axis=1) < 1).all()
    for a in range(degree + 1):
        for b in range(degree + 1 - a):
            for c in range(degree + 1 - a - b):
                exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3)
                got = w @ (xi[:, 0] ** a * xi[:, 1] ** b * xi[:, 2] ** c)
                assert abs(got - exact) < 1e-15, (degree, a, b, c)


def test_tetrahedron_rule_sizes_and_bad_degree():
    assert [len(tetrahedron_rule(d)[1]) for d in range(1, 7)] == [1, 4, 8, 14, 14, 64]
    with pytest.raises(ValueError, match="quadrature degree"):
        tetrahedron_rule(-1)


def test_element_records_by_cell():
    assert element_of("p2", reference=TETRAHEDRON) is P2_TET
    assert element_of("P2") is P2 and element_of(P2_TET, reference=TETRAHEDRON) is P2_TET
    assert P2_TET.n_local == 10 and P2_TET.vtk_cell == "tetra10" and P2_TET.facet is P2_TRIANGLE
    with pytest.raises(ValueError, match=r"one of \('P2',\) on the tetrahedron"):
        element_of("P1", reference=TETRAHEDRON)
    with pytest.raises(ValueError, match="lives on the triangle"):
        element_of(P2, reference=TETRAHEDRON)
    assert element_of(P2, reference=TRIANGLE) is P2


def test_affine_map_reads_the_d3_jacobians():
    v = random_tetrahedron()
    cells = AffineTetrahedra(v)
    J, det = cells.jacobians()
    assert np.allclose(J[0, 0], (v[0, 1:] - v[0, 0]).T) and det[0, 0] > 0
    assert np.allclose(cells.inverse_transpose()[0, 0], np.linalg.inv(J[0, 0]).T)
    xi = random_points(6)
    assert np.allclose(cells.points(xi)[0], v[0, 0] + xi @ J[0, 0].T)


def test_isoparametric_map_with_straight_nodes_is_the_affine_map():
    v = random_tetrahedron()
    nodes = AffineTetrahedra(v).points(p2_tet.REFERENCE_NODES)
    iso, aff = IsoparametricTetrahedra(nodes), AffineTetrahedra(v)
    xi = random_points(7)
    assert np.allclose(iso.basis_gradients(xi), aff.basis_gradients(xi), atol=1e-12)
    assert np.allclose(iso.measure(np.ones(7), xi), aff.measure(np.ones(7)), atol=1e-14)


def test_hand_moved_edge_node_reproduces_every_quadratic_of_the_map():
    # move one edge node off the chord: the map is quadratic, and the P2 fields through it
    # still reproduce the linear fields (isoparametric: x itself is a P2 field)
    v = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]])
    nodes = AffineTetrahedra(v).points(p2_tet.REFERENCE_NODES)
    nodes[0, 5] += [0.05, 0.04, 0.0]  # the node of edge 12, pushed outward
    iso = IsoparametricTetrahedra(nodes)
    B, c = RNG.normal(size=(3, 3)), RNG.normal(size=3)
    u = nodes[0] @ B.T + c
    xi = random_points(9)
    assert np.allclose(iso.field_gradients(u[None].reshape(1, 30), xi), B, atol=1e-12)
    # the volume: the flat tet plus the bulge, ∫ det J by a rule exact for its degree 3
    xq, w = tetrahedron_rule(3)
    volume = iso.measure(w, xq).sum()
    assert volume > 1 / 6 and np.isclose(
        volume, tetrahedron_rule(8)[1] @ iso.jacobians(tetrahedron_rule(8)[0])[1][0], rtol=1e-14
    )


def test_space_on_a_tetrahedral_mesh():
    mesh = distorted_box(2)
    V = space_of(mesh, "P2")
    assert isinstance(V, P2TetSpace) and V.element is P2_TET and V.n_components == 3
    assert V.n_nodes == mesh.n_points + mesh.n_edges == 125 and V.n_dofs == 375
    assert V.cell_dofs.shape == (48, 30)
    assert np.array_equal(V.cell_dofs[:, 1::3], V.cell_dofs[:, 0::3] + 1)
    assert np.array_equal(V.cell_dofs[:, 0::3] // 3, V.cell_nodes)
    # local edge nodes at the midpoints of TETRAHEDRON.edges
    x = V.node_points[V.cell_nodes]
    e = TETRAHEDRON.edges
    assert np.allclose(x[:, 4:], 0.5 * (x[:, e[:, 0]] + x[:, e[:, 1]]), atol=1e-15)
    # interpolation of f(x (..., 3)) -> (..., 3)
    u = V.interpolate(lambda p: p[..., ::-1] ** 2)
    assert u.shape == (V.n_nodes, 3)
    with pytest.raises(ValueError):
        space_of(mesh, "P1")


def test_boundary_faces_six_nodes_outward_and_part_nodes():
    n = 3
    V = space_of(box(n, n, n))
    for name, axis, side in [("x0", 0, -1), ("z1", 2, 1)]:
        f = V.mesh.part_facets(name)
        nodes = V.facet_nodes(f)
        assert nodes.shape == (len(f), 6)
        x = V.node_points[nodes]
        assert np.allclose(x[:, 3:], 0.5 * (x[:, [0, 1, 2]] + x[:, [1, 2, 0]]), atol=1e-15)
        (rows, faces), *rest = V.boundary_facets(f)
        assert not rest
        assert np.allclose(faces.normals()[:, 0, axis], side)
        assert np.isclose(faces.area.sum(), 1.0)
        assert len(V.part_nodes([name])) == (2 * n + 1) ** 2
    assert len(V.part_nodes(V.mesh.part_names)) == (2 * n + 1) ** 3 - (2 * n - 1) ** 3


def test_curved_part_gives_isoparametric_cells_closer_to_the_ball():
    mesh = eighth_ball(2)
    V = space_of(mesh)
    cells, nodes = V.curved
    assert nodes.shape == (len(cells), 10, 3) and 0 < len(cells) < mesh.n_cells
    assert len(V.mapping.groups) == 2
    xi, w = tetrahedron_rule(4)
    iso_volume = sum(g.measure(w, xi).sum() for g in V.mapping.groups)
    flat_volume = affine_jacobian(V.vertices)[1].sum() / 6
    exact = np.pi / 6
    assert abs(iso_volume - exact) < 0.2 * abs(flat_volume - exact)
    faces = [f for _, f in V.boundary_facets(V.curved_facets)]
    assert all(isinstance(f, QuadraticFaces) for f in faces)


def test_interior_face_nodes():
    V = space_of(box(2, 2, 2))
    interior = np.flatnonzero(V.mesh.facet2cell[:, 1] >= 0)[:5]
    nodes = V.mesh_facet_nodes(interior)
    x = V.node_points[nodes]
    assert nodes.shape == (5, 6)
    assert np.allclose(x[:, 3:], 0.5 * (x[:, [0, 1, 2]] + x[:, [1, 2, 0]]), atol=1e-15)
    assert np.array_equal(np.sort(nodes[:, :3], axis=1), V.mesh.facets[interior])


@pytest.mark.parametrize("bisections", [1, 3])
def test_prolongation_onto_a_bisected_mesh_is_exact_for_quadratics(bisections):
    mesh = distorted_box(2, seed=7)
    marked = np.zeros(mesh.n_cells, dtype=bool)
    marked[::5] = True
    fine, parent, edge_point, parent_edge = bisect_mesh(mesh, marked, bisections)
    coarse_space, fine_space = space_of(mesh), space_of(fine)
    A = RNG.normal(size=(3, 3, 3))

    def field(x):
        return np.einsum("ijk,...j,...k->...i", A, x, x) + x

    u = coarse_space.interpolate(field)
    v = coarse_space.prolongate(u, Refinement(fine, parent, edge_point, parent_edge))
    assert v.shape == (fine_space.n_nodes, 3)
    assert np.abs(v - fine_space.interpolate(field)).max() < 1e-13
