"""3D elasticity on P2 tetrahedra: the law, element and global stiffness, loads, the patch
test, the manufactured rate, the independent study's assembly and rotation invariance."""

import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from fem3d_problems import (
    MATERIAL,
    Smooth,
    distorted_box,
    divergence_of_stress,
    quadratic_field,
    solve_dirichlet,
)

from signorini.fem.dofs import node_dofs
from signorini.fem.elasticity3d import (
    assemble_body_force_3d,
    assemble_face_load_3d,
    cell_stress_3d,
    energy_error2_3d,
    h1_seminorm_error2_3d,
    l2_error2_3d,
    von_mises_3d,
)
from signorini.fem.mapping3d import AffineTetrahedra, IsoparametricTetrahedra
from signorini.fem.material import CellMaterials, Material, lame_parameters, stress, von_mises
from signorini.fem.p2_tet import REFERENCE_NODES
from signorini.fem.quadrature import tetrahedron_rule
from signorini.fem.space import space_of
from signorini.fem.stiffness3d import assemble_stiffness_3d, element_stiffness_3d
from signorini.mesh.builders3d import box
from signorini.mesh.jacobians import affine_jacobian
from signorini.mesh.mesh import Mesh
from signorini.mesh.reference import TETRAHEDRON

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "studies"))

RNG = np.random.default_rng(37)


def random_tetrahedra(m):
    v = RNG.normal(size=(m, 4, 3))
    flip = affine_jacobian(v)[1] < 0
    v[flip] = v[flip][:, [0, 2, 1, 3]]
    return v


def rigid_motions(x):
    """``(6, n, 3)`` the three translations and three rotations at points ``x (n, 3)``."""
    out = [np.broadcast_to(e, x.shape) for e in np.eye(3)]
    out += [np.cross(e, x) for e in np.eye(3)]
    return np.array(out)


# ---------------------------------------------------------------------------- the law


def test_3d_law_from_the_same_parameters_and_plane_stress_refused():
    mat = Material.from_young(210.0, 0.3)
    assert lame_parameters(mat, 3) == (mat.lam, mat.mu)
    assert lame_parameters(mat, 2) == (mat.lam_eff, mat.mu)
    g = RNG.normal(size=(4, 3, 3))
    eps = 0.5 * (g + np.swapaxes(g, -1, -2))
    expected = (
        mat.lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(3) + 2 * mat.mu * eps
    )
    assert np.allclose(stress(mat, g), expected, atol=1e-12)
    # uniaxial stress σ = s e1 ⊗ e1: ε_11 = s / E, ε_22 = ε_33 = -ν s / E (the same E, ν)
    s = 3.0
    eps = np.diag([s / 210.0, -0.3 * s / 210.0, -0.3 * s / 210.0])
    assert np.allclose(stress(mat, eps), np.diag([s, 0, 0]), atol=1e-12)
    assert np.isclose(von_mises(np.diag([s, 0, 0])), s)
    assert np.isclose(von_mises(np.eye(3) * 5.0), 0.0, atol=1e-13)
    with pytest.raises(ValueError, match='plane="stress" is a 2D reduction'):
        lame_parameters(Material.from_young(1.0, 0.3, plane="stress"), 3)
    with pytest.raises(ValueError, match="2D reduction"):
        stress(Material(lam=1.0, mu=1.0, plane="stress"), g)
    with pytest.raises(ValueError, match="dim must be 2 or 3"):
        lame_parameters(mat, 4)


# ---------------------------------------------------------------------------- element stiffness


def test_element_stiffness_symmetric_psd_with_six_rigid_modes():
    v = random_tetrahedra(5)
    K = element_stiffness_3d(AffineTetrahedra(v), MATERIAL)
    assert K.shape == (5, 30, 30)
    assert np.allclose(K, np.swapaxes(K, 1, 2), atol=1e-13 * np.abs(K).max())
    for c in range(5):
        ev = np.linalg.eigvalsh(K[c])
        tol = 1e-10 * ev.max()
        assert (ev > -tol).all() and (np.abs(ev) < tol).sum() == 6
        x = AffineTetrahedra(v[c : c + 1]).points(REFERENCE_NODES)[0]
        modes = rigid_motions(x).reshape(6, 30)
        assert np.abs(modes @ K[c]).max() < 1e-11 * np.abs(K[c]).max()


def test_isoparametric_element_with_straight_nodes_equals_affine():
    v = random_tetrahedra(3)
    nodes = AffineTetrahedra(v).points(REFERENCE_NODES)
    Ka = element_stiffness_3d(AffineTetrahedra(v), MATERIAL)
    Ki = element_stiffness_3d(IsoparametricTetrahedra(nodes), MATERIAL)
    assert np.allclose(Ki, Ka, atol=1e-11 * np.abs(Ka).max())


def test_cell_materials_per_cell():
    v = random_tetrahedra(4)
    soft, hard = Material(lam=1.0, mu=0.5), Material(lam=3.0, mu=2.0)
    mats = CellMaterials([soft, hard], np.array([0, 1, 1, 0]))
    K = element_stiffness_3d(AffineTetrahedra(v), mats)
    for c, mat in enumerate([soft, hard, hard, soft]):
        assert np.allclose(K[c], element_stiffness_3d(AffineTetrahedra(v[c : c + 1]), mat)[0])


def test_a_cell_matrix_is_the_same_bits_whatever_cells_beside_it():
    v = random_tetrahedra(300)
    K = element_stiffness_3d(AffineTetrahedra(v), MATERIAL)
    assert np.array_equal(element_stiffness_3d(AffineTetrahedra(v[7:8]), MATERIAL)[0], K[7])


# ---------------------------------------------------------------------------- global assembly


def study_matrix(n, lam, mu):
    """The independent study's stiffness on its n³ Kuhn cube and our DOF order of it."""
    from faces3d import elasticity
    from faces3d.mesh import cube_mesh

    cube = cube_mesh(n)
    v = cube.tets[:, :4].copy()
    flip = affine_jacobian(cube.points[v])[1] < 0
    v[flip] = v[flip][:, [0, 2, 1, 3]]
    e = TETRAHEDRON.edges
    nodes = np.hstack([v, cube.edge_nodes(v[:, e[:, 0]], v[:, e[:, 1]])])
    return cube, nodes, elasticity.stiffness(cube, lam, mu)


def test_stiffness_equals_the_independent_study_assembly():
    cube, nodes, K_study = study_matrix(3, MATERIAL.lam, MATERIAL.mu)
    cell_dofs = node_dofs(nodes, 3).reshape(-1, 30)
    n_dofs = 3 * cube.n_nodes
    K = assemble_stiffness_3d(cube.points[nodes[:, :4]], cell_dofs, n_dofs, MATERIAL)
    assert isinstance(K, sp.csr_matrix) and K.has_sorted_indices
    assert abs(K - K_study).max() < 1e-14 * abs(K_study).max()
    # and the same through the package's own mesh and space, after matching the node order
    V = space_of(box(3, 3, 3))
    K_space = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    match = np.lexsort(np.round(V.node_points, 12).T)
    theirs = np.lexsort(np.round(cube.points, 12).T)
    order = np.empty(V.n_nodes, dtype=np.int64)
    order[match] = theirs  # our node -> the study's node
    P = node_dofs(order, 3).ravel()
    assert abs(K_space - K_study[P][:, P]).max() < 1e-14 * abs(K_study).max()


def test_global_matrix_symmetric_block_pattern_and_rigid_kernel():
    V = space_of(distorted_box(2))
    K = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    assert abs(K - K.T).max() < 1e-14 * abs(K).max()
    assert isinstance(K, sp.csr_matrix) and K.has_sorted_indices
    resorted = K.copy()
    resorted.has_sorted_indices = False
    resorted.sort_indices()
    assert np.array_equal(resorted.indices, K.indices) and np.array_equal(resorted.data, K.data)
    indptr = K.indptr
    lengths = np.diff(indptr).reshape(-1, 3)
    assert (lengths == lengths[:, :1]).all() and (lengths % 3 == 0).all()
    modes = rigid_motions(V.node_points).reshape(6, -1)
    assert np.abs(K @ modes.T).max() < 1e-12 * abs(K).max()


# ---------------------------------------------------------------------------- loads


def test_loads_of_constant_data_sum_to_volume_and_area():
    V = space_of(distorted_box(2, seed=3))
    F = assemble_body_force_3d(V, lambda x: np.broadcast_to([1.0, 2.0, -3.0], x.shape))
    assert np.allclose(F.reshape(-1, 3).sum(axis=0), [1.0, 2.0, -3.0], atol=1e-13)
    f = V.mesh.part_facets("y1")
    G = assemble_face_load_3d(V, f, lambda x: np.broadcast_to([0.5, 0.0, 1.0], x.shape))
    assert np.allclose(G.reshape(-1, 3).sum(axis=0), [0.5, 0.0, 1.0], atol=1e-13)
    # a pressure -p n through the outward normals
    G = assemble_face_load_3d(V, f, lambda x, n: -2.0 * n)
    assert np.allclose(G.reshape(-1, 3).sum(axis=0), [0.0, -2.0, 0.0], atol=1e-13)
    # ∫ g · v for a linear v: the face load against the interpolant is exact
    v = V.interpolate(lambda x: x @ np.array([[1.0, 2, 0], [0, 1, 1], [3, 0, 1]]).T)
    g = lambda x: np.broadcast_to([1.0, 1.0, 1.0], x.shape)  # noqa: E731
    # on y = 1: ∫ (x + 2 + 1 + z + 3x + z) = ∫ (4x + 2z + 3) over the unit square
    assert np.isclose(assemble_face_load_3d(V, f, g) @ v.ravel(), 2 + 1 + 3, atol=1e-13)


# ---------------------------------------------------------------------------- solutions


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_patch_test_every_quadratic_reproduced_on_a_distorted_mesh(seed):
    u, grad, H = quadratic_field(seed)
    V = space_of(distorted_box(3, seed=seed))
    f = lambda x: np.broadcast_to(-divergence_of_stress(H, MATERIAL), x.shape)  # noqa: E731
    uh = solve_dirichlet(V, f, u)
    scale = np.abs(u(V.node_points)).max()
    assert np.abs(uh - u(V.node_points)).max() < 1e-12 * scale
    assert energy_error2_3d(V, uh, grad, MATERIAL) < 1e-22 * scale**2
    xi = tetrahedron_rule(2)[0]
    sigma = cell_stress_3d(V, MATERIAL, uh, xi)
    x = V.mapping.points(xi)
    assert np.allclose(sigma, stress(MATERIAL, grad(x)), atol=1e-10 * scale)
    assert np.allclose(von_mises_3d(V, MATERIAL, uh, xi), von_mises(stress(MATERIAL, grad(x))))


def test_patch_test_with_a_traction_face():
    # Dirichlet on five faces, the traction σ(u) n on z1: still exact
    u, grad, H = quadratic_field(4)
    mesh = distorted_box(2, seed=4)
    V = space_of(mesh)
    K = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    f = lambda x: np.broadcast_to(-divergence_of_stress(H, MATERIAL), x.shape)  # noqa: E731
    traction = lambda x, n: np.einsum("...ij,...j->...i", stress(MATERIAL, grad(x)), n)  # noqa: E731
    F = assemble_body_force_3d(V, f) + assemble_face_load_3d(V, mesh.part_facets("z1"), traction)
    fixed = node_dofs(V.part_nodes([p for p in mesh.part_names if p != "z1"]), 3).ravel()
    exact = u(V.node_points).ravel()
    free = np.setdiff1d(np.arange(V.n_dofs), fixed)
    uh = exact.copy()
    rhs = F[free] - K[free][:, fixed] @ exact[fixed]
    uh[free] = sp.linalg.spsolve(K[free][:, free].tocsc(), rhs)
    assert np.abs(uh - exact).max() < 1e-11 * np.abs(exact).max()


def test_manufactured_smooth_solution_rates():
    sizes, energy, l2, h1 = [], [], [], []
    for n in (2, 3, 4, 6):
        V = space_of(box(n, n, n))
        uh = solve_dirichlet(V, Smooth.force(), Smooth.u)
        sizes.append(V.n_dofs)
        energy.append(np.sqrt(energy_error2_3d(V, uh, Smooth.grad, MATERIAL)))
        l2.append(np.sqrt(l2_error2_3d(V, uh, Smooth.u)))
        h1.append(np.sqrt(h1_seminorm_error2_3d(V, uh, Smooth.grad)))
    slope = lambda e: np.log(e[-1] / e[-2]) / np.log(sizes[-1] / sizes[-2])  # noqa: E731
    assert -0.75 < slope(energy) < -0.62, f"energy slope {slope(energy):.3f}, expected -2/3"
    assert -0.75 < slope(h1) < -0.62, f"H1 slope {slope(h1):.3f}, expected -2/3"
    assert -1.25 < slope(l2) < -0.95, f"L2 slope {slope(l2):.3f}, expected -1"


def test_rotation_invariance():
    R = np.linalg.qr(RNG.normal(size=(3, 3)))[0]
    if np.linalg.det(R) < 0:
        R[:, 0] *= -1
    u, grad, H = quadratic_field(5)
    mesh = distorted_box(2, seed=5)
    turned = Mesh(mesh.points @ R.T, mesh.cells, mesh.boundary, mesh.boundary_part, mesh.part_names)
    V, W = space_of(mesh), space_of(turned)
    f0 = -divergence_of_stress(H, MATERIAL) + 1.0  # a body force off the patch
    uh = solve_dirichlet(V, lambda x: np.broadcast_to(f0, x.shape), lambda x: 0.1 * u(x))
    vh = solve_dirichlet(
        W, lambda x: np.broadcast_to(R @ f0, x.shape), lambda y: 0.1 * u(y @ R) @ R.T
    )
    assert np.abs(vh - uh @ R.T).max() < 1e-12 * np.abs(uh).max()
    K = assemble_stiffness_3d(V.mapping, V.cell_dofs, V.n_dofs, MATERIAL)
    KR = assemble_stiffness_3d(W.mapping, W.cell_dofs, W.n_dofs, MATERIAL)
    Q = sp.block_diag([R] * V.n_nodes, format="csr")
    assert abs(Q @ K @ Q.T - KR).max() < 1e-13 * abs(K).max()
