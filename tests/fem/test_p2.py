"""The P2 reference element and affine geometry."""

import numpy as np
from contact_problems import random_quadratic
from fem_problems import cell_values, random_reference_points, random_triangles

from signorini.fem import p2

RNG = np.random.default_rng(20240611)


def test_partition_of_unity_and_zero_gradient_sum():
    xi = random_reference_points(50, RNG)
    assert np.allclose(p2.basis(xi).sum(axis=1), 1.0, atol=1e-14)
    assert np.allclose(p2.grad_basis(xi).sum(axis=1), 0.0, atol=1e-13)
    assert np.allclose(p2.hessian_basis().sum(axis=0), 0.0, atol=1e-13)


def test_nodal_kronecker_property():
    assert np.allclose(p2.basis(p2.REFERENCE_NODES), np.eye(6), atol=1e-15)


def test_basis_from_barycentric_coordinates():
    # the one formula of the basis: at barycentric points, and batched over any leading axes
    bary = p2.barycentric(p2.REFERENCE_NODES)
    assert np.array_equal(bary[:3], np.eye(3))
    assert np.array_equal(p2.basis_barycentric(bary), np.eye(6))
    b = RNG.dirichlet(np.ones(3), size=(7, 5))
    phi = p2.basis_barycentric(b)
    assert phi.shape == (7, 5, 6)
    assert np.allclose(phi.sum(-1), 1.0, atol=1e-14)
    xi = b[..., 1:].reshape(-1, 2)
    assert np.allclose(p2.basis(xi), phi.reshape(-1, 6), atol=1e-15)
    # phi_0 = l0 (2 l0 - 1) at the two quarter points of edge 0: 3/8 near vertex 0, -1/8 far
    assert p2.basis_barycentric(np.array([0.75, 0.25, 0.0]))[0] == 0.375
    assert p2.basis_barycentric(np.array([0.25, 0.75, 0.0]))[0] == -0.125


def test_node_order_matches_vtk_triangle6():
    # vertices, then midpoints of (v0, v1), (v1, v2), (v2, v0)
    v = p2.REFERENCE_NODES[:3]
    assert np.allclose(p2.REFERENCE_NODES[3], (v[0] + v[1]) / 2)
    assert np.allclose(p2.REFERENCE_NODES[4], (v[1] + v[2]) / 2)
    assert np.allclose(p2.REFERENCE_NODES[5], (v[2] + v[0]) / 2)


def test_reference_gradients_by_central_differences():
    # central differences are exact for quadratics up to rounding
    xi = random_reference_points(20, RNG)
    h = 1e-3
    fd = np.empty((20, 6, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        fd[:, :, j] = (p2.basis(xi + e) - p2.basis(xi - e)) / (2 * h)
    assert np.allclose(p2.grad_basis(xi), fd, atol=1e-10)
    hd = np.empty((6, 2, 2))
    x0 = np.array([[0.3, 0.2]])
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        hd[:, :, k] = ((p2.grad_basis(x0 + e) - p2.grad_basis(x0 - e)) / (2 * h))[0]
    assert np.allclose(p2.hessian_basis(), hd, atol=1e-9)


def test_physical_gradients_by_finite_differences():
    verts = random_triangles(5, RNG)
    J, det = p2.jacobian(verts)
    xi = random_reference_points(4, RNG)
    G = p2.physical_gradients(verts, xi)  # (m, q, 6, 2)
    h = 1e-4
    for j in range(2):
        dx = np.zeros(2)
        dx[j] = h
        # reference displacement corresponding to the physical step dx, per cell
        dxi = np.linalg.solve(J, np.broadcast_to(dx, (5, 2))[..., None])[..., 0]
        plus = np.stack([p2.basis(xi + dxi[c]) for c in range(5)])
        minus = np.stack([p2.basis(xi - dxi[c]) for c in range(5)])
        assert np.allclose(G[..., j], (plus - minus) / (2 * h), atol=1e-8)


def test_jacobian_and_area():
    verts = random_triangles(10, RNG)
    J, det = p2.jacobian(verts)
    e1, e2 = verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0]
    assert np.allclose(det, e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert np.allclose(J @ np.array([1.0, 0.0]), e1)
    jit = p2.inverse_transpose(J, det)
    assert np.allclose(np.swapaxes(jit, 1, 2) @ J, np.eye(2), atol=1e-13)
    # physical points of the reference vertices are the vertices
    assert np.allclose(p2.physical_points(verts, p2.REFERENCE_NODES[:3]), verts)


def test_quadratic_fields_are_reproduced_exactly():
    verts = random_triangles(8, RNG)
    u = random_quadratic(RNG)
    u_cell = cell_values(u.value, verts)
    xi = random_reference_points(12, RNG)
    x = p2.physical_points(verts, xi)
    assert np.allclose(p2.field_values(u_cell, xi), u.value(x), atol=1e-12)
    assert np.allclose(p2.field_gradients(verts, u_cell, xi), u.gradient(x), atol=1e-11)
    H = p2.field_hessian(verts, u_cell)
    assert H.shape == (8, 2, 2, 2)
    assert np.allclose(H, u.hessian(), atol=1e-10)


def test_per_cell_reference_points():
    verts = random_triangles(6, RNG)
    u = random_quadratic(RNG)
    u_cell = cell_values(u.value, verts)
    xi = np.stack([random_reference_points(3, RNG) for _ in range(6)])  # (6, 3, 2)
    x = np.einsum("mqk,mkd->mqd", np.dstack([1 - xi.sum(-1), xi[..., 0], xi[..., 1]]), verts)
    assert np.allclose(p2.field_values(u_cell, xi), u.value(x), atol=1e-12)
    assert np.allclose(p2.field_gradients(verts, u_cell, xi), u.gradient(x), atol=1e-11)


def test_non_quadratic_field_is_not_reproduced():
    # guards the test above: a cubic is only interpolated, not reproduced
    verts = random_triangles(3, RNG)
    u_cell = cell_values(lambda x: np.stack([x[..., 0] ** 3, x[..., 1] ** 3], -1), verts)
    xi = random_reference_points(5, RNG)
    x = p2.physical_points(verts, xi)
    assert np.abs(p2.field_values(u_cell, xi)[..., 0] - x[..., 0] ** 3).max() > 1e-4


def test_edge_basis_and_edge_points():
    t = np.linspace(0, 1, 7)
    eb = p2.edge_basis(t)
    assert np.allclose(eb.sum(axis=1), 1.0)
    assert np.allclose(p2.edge_basis(np.array([0.0, 1.0, 0.5])), np.eye(3))
    for k in range(3):
        pts = p2.edge_reference_points(k, t)
        assert np.allclose(pts[0], p2.REFERENCE_NODES[k])
        assert np.allclose(pts[-1], p2.REFERENCE_NODES[(k + 1) % 3])
        phi = p2.basis(pts)
        on_edge = [k, (k + 1) % 3, 3 + k]
        # trace of the P2 basis on local edge k is the edge basis (start, end, mid) ...
        assert np.allclose(phi[:, on_edge], eb, atol=1e-14)
        # ... and the other three basis functions vanish there
        others = [a for a in range(6) if a not in on_edge]
        assert np.allclose(phi[:, others], 0.0, atol=1e-14)
    batch = p2.edge_reference_points(np.array([2, 0]), t)
    assert batch.shape == (2, 7, 2)
    assert np.allclose(batch[1], p2.edge_reference_points(0, t))
