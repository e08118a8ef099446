"""The P2 stiffness matrix (:mod:`signorini.fem.stiffness`): element matrices against an
independent quadrature, rigid motions, invariances, the node-block CSR assembly, and input
checks."""

import os
import time

import numpy as np
import pytest
from contact_problems import random_quadratic
from fem_problems import SquareMesh, gauss_square, random_triangles, rigid_modes

from signorini.fem import p2
from signorini.fem.material import Material
from signorini.fem.quadrature import triangle_rule
from signorini.fem.stiffness import assemble_stiffness, element_stiffness

RNG = np.random.default_rng(7)
MAT = Material.from_lame(1.3, 0.8)


# ---------------------------------------------------------------------------
# element stiffness
# ---------------------------------------------------------------------------


def test_element_stiffness_rigid_body_modes():
    verts = random_triangles(40, RNG, min_angle_deg=20.0, span=1.0)
    K = element_stiffness(verts, MAT)
    assert K.shape == (40, 12, 12)
    for c in range(40):
        k = K[c]
        scale = np.abs(k).max()
        assert np.abs(k - k.T).max() < 1e-14 * scale
        ev, vec = np.linalg.eigh(k)
        # exactly three zero eigenvalues, the rest clearly positive
        assert np.all(np.abs(ev[:3]) < 1e-12 * scale), ev[:4]
        assert ev[3] > 1e-3 * scale, ev[:4]
        # the kernel is spanned by the rigid motions
        R = rigid_modes(verts[c])
        assert np.abs(k @ R.T).max() < 1e-12 * scale
        kernel = vec[:, :3]
        Q, _ = np.linalg.qr(R.T)
        svals = np.linalg.svd(kernel.T @ Q, compute_uv=False)
        assert np.allclose(svals, 1.0, atol=1e-10)


def test_element_stiffness_rotation_and_scale_invariance():
    verts = random_triangles(10, RNG, min_angle_deg=20.0, span=1.0)
    K = element_stiffness(verts, MAT)
    theta = 0.7
    Q = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    shift = np.array([3.0, -2.0])
    Kr = element_stiffness(verts @ Q.T + shift, MAT)
    R = np.kron(np.eye(6), Q)  # rotates the two components of every node
    assert np.allclose(Kr, R @ K @ R.T, atol=1e-12 * np.abs(K).max())
    # in 2D the stiffness does not change under scaling x -> s x
    assert np.allclose(element_stiffness(2.5 * verts, MAT), K, atol=1e-12 * np.abs(K).max())
    # cyclic relabelling of the vertices permutes the local nodes accordingly
    Kc = element_stiffness(verts[:, [1, 2, 0]], MAT)
    node_perm = np.array([1, 2, 0, 4, 5, 3])
    dof_perm = (2 * node_perm[:, None] + np.arange(2)).ravel()
    assert np.allclose(Kc, K[:, dof_perm][:, :, dof_perm], atol=1e-12 * np.abs(K).max())


def test_element_stiffness_against_direct_quadrature():
    # independent route: 2 mu eps:eps + lam div div at the 7 points of a degree-5 rule
    verts = random_triangles(6, RNG, min_angle_deg=20.0, span=1.0)
    mat = Material.from_young(3.0, 0.25)
    xi, w = triangle_rule(5)
    G = p2.physical_gradients(verts, xi)  # (m, q, 6, 2)
    _, det = p2.jacobian(verts)
    m = len(verts)
    Bm = np.zeros((m, len(w), 3, 12))  # Voigt strain-displacement matrices
    Bm[:, :, 0, 0::2] = G[..., 0]
    Bm[:, :, 1, 1::2] = G[..., 1]
    Bm[:, :, 2, 0::2] = G[..., 1]
    Bm[:, :, 2, 1::2] = G[..., 0]
    D = np.array(
        [
            [mat.lam + 2 * mat.mu, mat.lam, 0],
            [mat.lam, mat.lam + 2 * mat.mu, 0],
            [0, 0, mat.mu],
        ]
    )
    Kd = np.einsum("q,m,mqki,kl,mqlj->mij", w, det, Bm, D, Bm)
    K = element_stiffness(verts, mat)
    assert np.allclose(K, Kd, atol=1e-13 * np.abs(K).max())


def test_energy_of_quadratic_field_matches_independent_integral():
    mesh = SquareMesh(4, RNG, perturb=0.3)
    A = assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    u = random_quadratic(RNG)
    U = mesh.interpolate(u.value)
    # int_{[0,1]^2} sigma(u) : eps(u), eps linear => integrand quadratic, 3x3 Gauss exact
    x, w = gauss_square(3)
    g = u.gradient(x)
    exact = np.sum(w * np.einsum("qij,qij->q", u.stress(x, MAT), g))
    assert U @ (A @ U) == pytest.approx(exact, rel=1e-12)


# ---------------------------------------------------------------------------
# assembly
# ---------------------------------------------------------------------------


def coupled_node_pairs(cell_nodes):
    pairs = set()
    for row in cell_nodes:
        for a in row:
            for b in row:
                pairs.add((int(a), int(b)))
    return pairs


def test_assembly_matches_dense_sum_and_has_node_block_pattern():
    mesh = SquareMesh(3, RNG, perturb=0.3)
    A = assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    assert A.format == "csr" and A.shape == (mesh.n_dofs, mesh.n_dofs)
    assert A.has_sorted_indices
    assert all(np.all(np.diff(A.indices[A.indptr[r] : A.indptr[r + 1]]) > 0) for r in range(6))
    # independent assembly: element matrices summed densely
    K = element_stiffness(mesh.vertices, MAT)
    dense = np.zeros((mesh.n_dofs, mesh.n_dofs))
    for c in range(len(K)):
        dense[np.ix_(mesh.cell_dofs[c], mesh.cell_dofs[c])] += K[c]
    assert np.abs(A.toarray() - dense).max() < 1e-13 * np.abs(dense).max()
    assert abs(A - A.T).max() < 1e-13 * np.abs(dense).max()
    # node-block pattern: one full 2x2 block per pair of nodes sharing a cell
    pairs = coupled_node_pairs(mesh.cell_nodes)
    assert A.nnz == 4 * len(pairs)
    indptr, indices = A.indptr, A.indices
    for z in range(mesh.n_nodes):
        r0 = indices[indptr[2 * z] : indptr[2 * z + 1]]
        r1 = indices[indptr[2 * z + 1] : indptr[2 * z + 2]]
        assert np.array_equal(r0, r1)
        assert np.array_equal(r0[0::2] % 2, np.zeros(len(r0) // 2))
        assert np.array_equal(r0[1::2], r0[0::2] + 1)
        assert set((r0[0::2] // 2).tolist()) == {b for (a, b) in pairs if a == z}


def test_unvalidated_assembly_is_the_same_matrix():
    mesh = SquareMesh(4, RNG, perturb=0.2)
    args = (mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    A, B = assemble_stiffness(*args), assemble_stiffness(*args, validate=False)
    assert np.array_equal(A.indptr, B.indptr) and np.array_equal(A.indices, B.indices)
    assert np.array_equal(A.data, B.data)


def test_assembled_matrix_holds_no_more_memory_than_its_entries():
    """K keeps only its own entries alive: not the COO-sized buffer SciPy sums duplicates in
    (it would hold ~1.5 x the data of K through the whole PDAS solve)."""
    mesh = SquareMesh(6, RNG, perturb=0.2)
    A = assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    for array in (A.data, A.indices, A.indptr):
        owner = array if array.base is None else array.base
        assert owner.nbytes == array.nbytes, (owner.nbytes, array.nbytes)


def test_assembly_keeps_explicit_zero_blocks():
    # on an axis-aligned right triangle some couplings vanish exactly; the blocks stay
    verts = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])
    dofs = np.arange(12)[None, :]
    K = element_stiffness(verts, Material(lam=0.0, mu=1.0))
    assert np.count_nonzero(K == 0.0) > 0
    A = assemble_stiffness(verts, dofs, 12, Material(lam=0.0, mu=1.0))
    assert A.nnz == 144
    assert np.array_equal(A.toarray(), K[0])


def test_assembly_input_errors():
    mesh = SquareMesh(2)
    V, D, n = mesh.vertices, mesh.cell_dofs, mesh.n_dofs
    with pytest.raises(ValueError, match="even"):
        assemble_stiffness(V, D, n + 1, MAT)
    with pytest.raises(ValueError, match="non-negative integer"):
        assemble_stiffness(V, D, 2.5, MAT)
    with pytest.raises(ValueError, match="out of range"):
        assemble_stiffness(V, D, n - 2, MAT)
    swapped = D.copy()
    swapped[:, [0, 1]] = swapped[:, [1, 0]]
    with pytest.raises(ValueError, match="interleaved"):
        assemble_stiffness(V, swapped, n, MAT)
    with pytest.raises(ValueError, match=r"cell_dofs must have shape"):
        assemble_stiffness(V, D[:, :6], n, MAT)
    with pytest.raises(ValueError, match="rows"):
        assemble_stiffness(V, D[:-1], n, MAT)
    with pytest.raises(ValueError, match=r"vertices must have shape"):
        assemble_stiffness(V[:, :2], D, n, MAT)
    flipped = V.copy()
    flipped[3] = flipped[3][[0, 2, 1]]
    with pytest.raises(ValueError, match=r"1 cell\(s\).*first: cell 3"):
        assemble_stiffness(flipped, D, n, MAT)
    nan = V.copy()
    nan[5, 1, 0] = np.nan
    with pytest.raises(ValueError, match=r"not finite \(first: cell 5\)"):
        assemble_stiffness(nan, D, n, MAT)
    with pytest.raises(ValueError, match="Material"):
        assemble_stiffness(V, D, n, (1.0, 1.0))
    with pytest.raises(ValueError, match="integer"):
        assemble_stiffness(V, D.astype(float), n, MAT)


# ---------------------------------------------------------------------------
# scale: timing print, with correctness checks that can fail
# ---------------------------------------------------------------------------


@pytest.mark.slow
def test_assembly_at_1_6_million_unknowns(capsys):
    """With ``SIGNORINI_BENCHMARK_SIZE=full`` 401 408 triangles, 1 609 218 unknowns; by
    default 32 768 triangles, 132 098 unknowns (the same checks)."""
    full = os.environ.get("SIGNORINI_BENCHMARK_SIZE") == "full"
    mesh = SquareMesh(448 if full else 128)
    mat = Material.from_young(500.0, 0.3)
    t0 = time.perf_counter()
    K = element_stiffness(mesh.vertices, mat)
    t_elem = time.perf_counter() - t0
    del K
    t0 = time.perf_counter()
    A = assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, mat)
    t_asm = time.perf_counter() - t0
    with capsys.disabled():
        print(
            f"\n{len(mesh.cells)} triangles, {mesh.n_dofs} unknowns, nnz = {A.nnz}: "
            f"element_stiffness {t_elem:.2f} s, assemble_stiffness (elements + CSR) {t_asm:.2f} s"
        )
    # rigid motions are in the kernel of the assembled matrix
    xy = mesh.node_xy
    for mode in (
        np.column_stack([np.ones(len(xy)), np.zeros(len(xy))]),
        np.column_stack([-xy[:, 1], xy[:, 0]]),
    ):
        assert np.abs(A @ mode.ravel()).max() < 1e-9 * abs(A).max()
    assert A.has_sorted_indices
    rows = np.diff(A.indptr)
    assert np.array_equal(rows[0::2], rows[1::2])
