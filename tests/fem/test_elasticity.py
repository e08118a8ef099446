"""Plane-strain P2 elasticity: element matrices, assembly, loads, patch test, errors."""

import time

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from signorini.fem import elasticity as el
from signorini.fem import p2

RNG = np.random.default_rng(7)
MAT = el.Material.from_lame(1.3, 0.8)


# ---------------------------------------------------------------------------
# small meshes built from arrays (independent of the package's Mesh class)
# ---------------------------------------------------------------------------


class SquareMesh:
    """Structured n x n triangulation of [0, 1]^2, optionally with perturbed interior points.

    P2 nodes: vertices, then edge midpoints (edges numbered by np.unique).
    """

    def __init__(self, n, perturb=0.0, rng=RNG):
        x = np.linspace(0.0, 1.0, n + 1)
        X, Y = np.meshgrid(x, x, indexing="xy")
        pts = np.column_stack([X.ravel(), Y.ravel()])
        inner = (pts > 0).all(axis=1) & (pts < 1).all(axis=1)
        pts[inner] += perturb / n * rng.uniform(-1, 1, size=(inner.sum(), 2))
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
        c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
        cells = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        local = np.stack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]], axis=1)
        edges, inv, count = np.unique(
            np.sort(local.reshape(-1, 2), axis=1), axis=0, return_inverse=True, return_counts=True
        )
        inv = inv.reshape(-1, 3)
        self.points, self.cells = pts, cells.astype(np.int64)
        self.n_points = len(pts)
        self.n_nodes = len(pts) + len(edges)
        self.n_dofs = 2 * self.n_nodes
        self.cell_nodes = np.concatenate([cells, self.n_points + inv], axis=1)
        self.cell_dofs = np.empty((len(cells), 12), dtype=np.int64)
        self.cell_dofs[:, 0::2] = 2 * self.cell_nodes
        self.cell_dofs[:, 1::2] = 2 * self.cell_nodes + 1
        self.vertices = pts[cells]
        mid = 0.5 * (pts[edges[:, 0]] + pts[edges[:, 1]])
        self.node_xy = np.concatenate([pts, mid])
        # boundary edges, with the (counter-clockwise) orientation of their cell
        bnd = count[inv] == 1  # (m, 3)
        cell_id, k = np.nonzero(bnd)
        start = cells[cell_id, k]
        end = cells[cell_id, (k + 1) % 3]
        self.bedge_vertices = np.stack([pts[start], pts[end]], axis=1)
        bnodes = np.column_stack([start, end, self.n_points + inv[cell_id, k]])
        self.bedge_dofs = np.empty((len(bnodes), 6), dtype=np.int64)
        self.bedge_dofs[:, 0::2] = 2 * bnodes
        self.bedge_dofs[:, 1::2] = 2 * bnodes + 1
        self.bedge_nodes = bnodes

    def interpolate(self, field):
        return field(self.node_xy).ravel()


class Quadratic:
    """Random quadratic displacement with exact gradient, stress and div sigma."""

    def __init__(self, rng=RNG, scale=1.0):
        self.c = scale * rng.standard_normal(2)
        self.b = scale * rng.standard_normal((2, 2))
        a = scale * rng.standard_normal((2, 2, 2))
        self.A = 0.5 * (a + a.transpose(0, 2, 1))

    def __call__(self, x):
        x = np.asarray(x)
        return (
            self.c
            + np.einsum("ij,...j->...i", self.b, x)
            + np.einsum("...j,ijk,...k->...i", x, self.A, x)
        )

    def grad(self, x):
        return self.b + 2 * np.einsum("ijk,...k->...ij", self.A, np.asarray(x))

    def stress(self, x, mat=MAT):
        g = self.grad(x)
        eps = 0.5 * (g + np.swapaxes(g, -1, -2))
        tr = eps[..., 0, 0] + eps[..., 1, 1]
        return mat.lam * tr[..., None, None] * np.eye(2) + 2 * mat.mu * eps

    def div_stress(self, mat=MAT):
        # d_j sigma_ij = mu lap u_i + (lam + mu) d_i div u, with d_jk u_i = 2 A_ijk
        H = 2 * self.A
        lap = H[:, 0, 0] + H[:, 1, 1]
        grad_div = H[0, 0, :] + H[1, 1, :]
        return mat.mu * lap + (mat.lam + mat.mu) * grad_div


def random_triangles(m, rng=RNG, min_angle_deg=20.0):
    out = []
    while len(out) < m:
        v = rng.uniform(-1, 1, size=(3, 2))
        e = np.roll(v, -1, axis=0) - v
        if e[0, 0] * e[1, 1] - e[0, 1] * e[1, 0] < 0:
            v = v[[0, 2, 1]]
            e = np.roll(v, -1, axis=0) - v
        lens = np.linalg.norm(e, axis=1)
        cosines = [(-e[k - 1]) @ e[k] / (lens[k - 1] * lens[k]) for k in range(3)]
        if np.degrees(np.arccos(np.max(cosines))) > min_angle_deg:
            out.append(v)
    return np.array(out)


def gauss_square(n):
    """Tensor Gauss-Legendre rule on [0, 1]^2: points (n*n, 2), weights (n*n,)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x, w = 0.5 * (x + 1), 0.5 * w
    X, Y = np.meshgrid(x, x, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()]), np.outer(w, w).ravel()


def rigid_modes(vertices):
    """(3, 12) interleaved nodal values of x- and y-translation and rotation (-y, x)."""
    nodes = p2.physical_points(vertices[None], p2.REFERENCE_NODES)[0]  # (6, 2)
    modes = np.zeros((3, 6, 2))
    modes[0, :, 0] = 1
    modes[1, :, 1] = 1
    modes[2, :, 0] = -nodes[:, 1]
    modes[2, :, 1] = nodes[:, 0]
    return modes.reshape(3, 12)


# ---------------------------------------------------------------------------
# material and stress
# ---------------------------------------------------------------------------


def test_material_from_young_plane_strain():
    m = el.Material.from_young(500.0, 0.3)
    assert m.mu == pytest.approx(500 / 2.6, rel=1e-15)
    assert m.lam == pytest.approx(500 * 0.3 / (1.3 * 0.4), rel=1e-15)
    assert m.young == pytest.approx(500.0, rel=1e-14)
    assert m.poisson == pytest.approx(0.3, rel=1e-14)
    assert el.Material.from_lame(1, 1) == el.Material(1.0, 1.0)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((0.0, 0.3), "E must be positive"),
        ((-1.0, 0.3), "E must be positive"),
        ((1.0, 0.5), "incompressible limit not supported"),
        ((1.0, 0.7), "incompressible limit not supported"),
        ((1.0, -1.0), "nu must be > -1"),
        ((np.inf, 0.3), "finite"),
        ((1.0, np.nan), "finite"),
    ],
)
def test_material_from_young_rejects(args, match):
    with pytest.raises(ValueError, match=match):
        el.Material.from_young(*args)


@pytest.mark.parametrize(
    ("lam", "mu", "match"),
    [
        (1.0, 0.0, "mu must be positive"),
        (1.0, -2.0, "mu must be positive"),
        (-1.0, 1.0, "lam \\+ mu must be positive"),
        (-3.0, 1.0, "lam \\+ mu must be positive"),
        (np.nan, 1.0, "finite"),
        (1.0, np.inf, "finite"),
        ("a", 1.0, "real number"),
    ],
)
def test_material_from_lame_rejects(lam, mu, match):
    with pytest.raises(ValueError, match=match):
        el.Material.from_lame(lam, mu)


def test_material_allows_negative_lam_with_positive_bulk():
    # auxetic: nu < 0 gives lam < 0 but lam + mu > 0
    m = el.Material.from_young(1.0, -0.5)
    assert m.lam < 0 < m.lam + m.mu


def test_stress_closed_form():
    g = np.array([[1.0, 2.0], [4.0, -3.0]])
    sig = el.stress(el.Material(2.0, 0.5), g)
    # eps = [[1, 3], [3, -3]], tr = -2: sigma = 2 * (-2) I + 1.0 * eps
    assert np.allclose(sig, [[-3.0, 3.0], [3.0, -7.0]])
    batch = el.stress(el.Material(2.0, 0.5), np.broadcast_to(g, (4, 5, 2, 2)))
    assert batch.shape == (4, 5, 2, 2) and np.allclose(batch, sig)
    with pytest.raises(ValueError, match="grad_u"):
        el.stress(MAT, np.zeros((3, 2)))


# ---------------------------------------------------------------------------
# element stiffness
# ---------------------------------------------------------------------------


def test_element_stiffness_rigid_body_modes():
    verts = random_triangles(40)
    K = el.element_stiffness(verts, MAT)
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
    verts = random_triangles(10)
    K = el.element_stiffness(verts, MAT)
    theta = 0.7
    Q = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    shift = np.array([3.0, -2.0])
    rotated = verts @ Q.T + shift
    Kr = el.element_stiffness(rotated, MAT)
    R = np.kron(np.eye(6), Q)  # rotates the two components of every node
    assert np.allclose(Kr, R @ K @ R.T, atol=1e-12 * np.abs(K).max())
    # in 2D the stiffness does not change under scaling x -> s x
    assert np.allclose(el.element_stiffness(2.5 * verts, MAT), K, atol=1e-12 * np.abs(K).max())
    # cyclic relabelling of the vertices permutes the local nodes accordingly
    Kc = el.element_stiffness(verts[:, [1, 2, 0]], MAT)
    node_perm = np.array([1, 2, 0, 4, 5, 3])
    dof_perm = (2 * node_perm[:, None] + np.arange(2)).ravel()
    assert np.allclose(Kc, K[:, dof_perm][:, :, dof_perm], atol=1e-12 * np.abs(K).max())


def test_element_stiffness_against_direct_quadrature():
    # independent route: 2 mu eps:eps + lam div div at the 7 points of a degree-5 rule
    verts = random_triangles(6)
    mat = el.Material.from_young(3.0, 0.25)
    from signorini.fem.quadrature import triangle_rule

    xi, w = triangle_rule(5)
    G = p2.physical_gradients(verts, xi)  # (m, q, 6, 2)
    J, det = p2.jacobian(verts)
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
    K = el.element_stiffness(verts, mat)
    assert np.allclose(K, Kd, atol=1e-13 * np.abs(K).max())


def test_energy_of_quadratic_field_matches_independent_integral():
    mesh = SquareMesh(4, perturb=0.3)
    A = el.assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    u = Quadratic()
    U = mesh.interpolate(u)
    # int_{[0,1]^2} sigma(u) : eps(u), eps linear => integrand quadratic, 3x3 Gauss exact
    x, w = gauss_square(3)
    g = u.grad(x)
    eps = 0.5 * (g + np.swapaxes(g, -1, -2))
    exact = np.sum(w * np.einsum("qij,qij->q", u.stress(x), eps))
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


def test_assembly_matches_coo_reference_and_has_node_block_pattern():
    mesh = SquareMesh(3, perturb=0.3)
    A = el.assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    assert isinstance(A, sp.csr_matrix) and A.shape == (mesh.n_dofs, mesh.n_dofs)
    assert A.has_sorted_indices
    assert np.all(np.diff(A.indices[A.indptr[0] : A.indptr[1]]) > 0)
    # independent assembly: element matrices summed densely
    K = el.element_stiffness(mesh.vertices, MAT)
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


def test_assembly_keeps_explicit_zero_blocks():
    # on an axis-aligned right triangle some couplings vanish exactly; the blocks stay
    verts = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])
    dofs = np.arange(12)[None, :]
    K = el.element_stiffness(verts, el.Material(0.0, 1.0))
    assert np.count_nonzero(K == 0.0) > 0
    A = el.assemble_stiffness(verts, dofs, 12, el.Material(0.0, 1.0))
    assert A.nnz == 144
    assert np.array_equal(A.toarray(), K[0])


def test_assembly_input_errors():
    mesh = SquareMesh(2)
    V, D, n = mesh.vertices, mesh.cell_dofs, mesh.n_dofs
    with pytest.raises(ValueError, match="even"):
        el.assemble_stiffness(V, D, n + 1, MAT)
    with pytest.raises(ValueError, match="out of range"):
        el.assemble_stiffness(V, D, n - 2, MAT)
    swapped = D.copy()
    swapped[:, [0, 1]] = swapped[:, [1, 0]]
    with pytest.raises(ValueError, match="interleaved"):
        el.assemble_stiffness(V, swapped, n, MAT)
    with pytest.raises(ValueError, match=r"cell_dofs must have shape"):
        el.assemble_stiffness(V, D[:, :6], n, MAT)
    with pytest.raises(ValueError, match="rows"):
        el.assemble_stiffness(V, D[:-1], n, MAT)
    flipped = V.copy()
    flipped[3] = flipped[3][[0, 2, 1]]
    with pytest.raises(ValueError, match=r"1 cell\(s\).*first: cell 3"):
        el.assemble_stiffness(flipped, D, n, MAT)
    with pytest.raises(ValueError, match="Material"):
        el.assemble_stiffness(V, D, n, (1.0, 1.0))
    with pytest.raises(ValueError, match="integer"):
        el.assemble_stiffness(V, D.astype(float), n, MAT)


# ---------------------------------------------------------------------------
# patch tests
# ---------------------------------------------------------------------------


def solve_with_dirichlet(A, F, fixed, values):
    n = A.shape[0]
    free = np.setdiff1d(np.arange(n), fixed)
    U = np.zeros(n)
    U[fixed] = values
    rhs = F[free] - A[free][:, fixed] @ values
    U[free] = spla.spsolve(A[free][:, free].tocsc(), rhs)
    return U


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_patch_test_dirichlet(seed):
    rng = np.random.default_rng(seed)
    mesh = SquareMesh(4, perturb=0.35, rng=rng)
    u = Quadratic(rng)
    A = el.assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    F = el.assemble_body_force(
        mesh.vertices, mesh.cell_dofs, mesh.n_dofs, lambda x: -u.div_stress() + 0 * x
    )
    bnodes = np.unique(mesh.bedge_nodes)
    fixed = (2 * bnodes[:, None] + np.arange(2)).ravel()
    exact = mesh.interpolate(u)
    U = solve_with_dirichlet(A, F, fixed, exact[fixed])
    assert np.abs(U - exact).max() < 1e-12 * np.abs(exact).max()


@pytest.mark.parametrize("seed", [3, 4])
def test_patch_test_with_neumann_tractions(seed):
    rng = np.random.default_rng(seed)
    mesh = SquareMesh(4, perturb=0.35, rng=rng)
    u = Quadratic(rng)
    A = el.assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    F = el.assemble_body_force(
        mesh.vertices, mesh.cell_dofs, mesh.n_dofs, lambda x: -u.div_stress() + 0 * x
    )
    # Neumann on the right (x = 1) and top (y = 1) sides, Dirichlet on the rest
    ev = mesh.bedge_vertices
    mid = ev.mean(axis=1)
    neu = (mid[:, 0] > 1 - 1e-12) | (mid[:, 1] > 1 - 1e-12)
    seen_normals = []

    def g(x, normal):
        seen_normals.append(normal)
        return np.einsum("kqij,kqj->kqi", u.stress(x), np.broadcast_to(normal, x.shape))

    F = F + el.assemble_edge_load(ev[neu], mesh.bedge_dofs[neu], mesh.n_dofs, g)
    normals = seen_normals[0][:, 0]
    expected = np.where(mid[neu, 0:1] > 1 - 1e-12, [[1.0, 0.0]], [[0.0, 1.0]])
    assert np.allclose(normals, expected)
    dnodes = np.unique(mesh.bedge_nodes[~neu])
    fixed = (2 * dnodes[:, None] + np.arange(2)).ravel()
    exact = mesh.interpolate(u)
    U = solve_with_dirichlet(A, F, fixed, exact[fixed])
    assert np.abs(U - exact).max() < 1e-11 * np.abs(exact).max()


# ---------------------------------------------------------------------------
# loads
# ---------------------------------------------------------------------------


def poly_force(x):
    X, Y = x[..., 0], x[..., 1]
    return np.stack([1 + X**2 * Y - 3 * Y**3, X * Y + 2 * X**4], axis=-1)


def independent_body_load(mesh, f, n=8):
    """Load vector by a collapsed Gauss-Legendre rule (Legendre in both directions)."""
    s, ws = np.polynomial.legendre.leggauss(n)
    s, ws = 0.5 * (s + 1), 0.5 * ws
    S, T = np.meshgrid(s, s, indexing="ij")
    xi = np.column_stack([S.ravel(), (T * (1 - S)).ravel()])
    w = (np.outer(ws, ws) * (1 - S)).ravel()  # exact for total degree <= 2n - 2
    J, det = p2.jacobian(mesh.vertices)
    x = mesh.vertices[:, 0, None, :] + np.einsum("mij,qj->mqi", J, xi)
    local = np.einsum("q,qa,mqc,m->mac", w, p2.basis(xi), f(x), det)
    F = np.zeros(mesh.n_dofs)
    np.add.at(F, mesh.cell_dofs.ravel(), local.ravel())
    return F


def test_body_force_polynomial_exact():
    mesh = SquareMesh(3, perturb=0.3)
    F = el.assemble_body_force(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, poly_force, degree=6)
    ref = independent_body_load(mesh, poly_force)
    assert np.abs(F - ref).max() < 1e-14 * np.abs(ref).max() * 10
    # the basis sums to one: component sums are the integrals of f over the square
    # int (1 + x^2 y - 3 y^3) = 1 + 1/6 - 3/4 ; int (x y + 2 x^4) = 1/4 + 2/5
    assert F[0::2].sum() == pytest.approx(1 + 1 / 6 - 3 / 4, rel=1e-13)
    assert F[1::2].sum() == pytest.approx(1 / 4 + 2 / 5, rel=1e-13)
    # a too-low degree is visibly inexact for this degree-4 force
    F1 = el.assemble_body_force(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, poly_force, degree=1)
    assert np.abs(F1 - ref).max() > 1e-6


def test_body_force_constant_broadcasts():
    mesh = SquareMesh(2)
    F = el.assemble_body_force(
        mesh.vertices, mesh.cell_dofs, mesh.n_dofs, lambda x: np.array([0.0, -2.0])
    )
    assert F[1::2].sum() == pytest.approx(-2.0, rel=1e-14)
    assert np.all(F[0::2] == 0)
    # P2 vertex basis functions integrate to zero over a triangle: only midpoints load
    assert np.allclose(F[1 : 2 * mesh.n_points : 2], 0.0, atol=1e-15)


def test_edge_load_polynomial_exact_and_normals():
    mesh = SquareMesh(3, perturb=0.3)
    ev, ed = mesh.bedge_vertices, mesh.bedge_dofs

    def g(x, normal):
        X, Y = x[..., 0], x[..., 1]
        return np.stack([X**3 + Y, X * Y**2], axis=-1) + 0 * normal

    G = el.assemble_edge_load(ev, ed, mesh.n_dofs, g, degree=5)
    # independent: 6-point Gauss-Legendre per edge, basis (start, end, mid)
    t, w = np.polynomial.legendre.leggauss(6)
    t, w = 0.5 * (t + 1), 0.5 * w
    psi = np.column_stack([(1 - t) * (1 - 2 * t), t * (2 * t - 1), 4 * t * (1 - t)])
    x = ev[:, 0, None, :] + t[None, :, None] * (ev[:, 1] - ev[:, 0])[:, None, :]
    L = np.linalg.norm(ev[:, 1] - ev[:, 0], axis=1)
    local = np.einsum("q,qa,kqc,k->kac", w, psi, g(x, 0.0), L)
    ref = np.zeros(mesh.n_dofs)
    np.add.at(ref, ed.ravel(), local.ravel())
    assert np.abs(G - ref).max() < 1e-14 * np.abs(ref).max() * 10
    # sum of x-components: int over the boundary of x^3 + y
    #   bottom (y=0): 1/4, right (x=1): 1 + 1/2, top (y=1): 1/4 + 1, left (x=0): 1/2
    assert G[0::2].sum() == pytest.approx(0.25 + 1.5 + 1.25 + 0.5, rel=1e-13)
    # the outward unit normals integrate to zero around the closed boundary, and
    # on each side to the side length times its normal
    Gn = el.assemble_edge_load(ev, ed, mesh.n_dofs, lambda x, n: np.broadcast_to(n, x.shape))
    assert np.allclose([Gn[0::2].sum(), Gn[1::2].sum()], 0.0, atol=1e-14)
    right = ev.mean(axis=1)[:, 0] > 1 - 1e-12
    Gr = el.assemble_edge_load(ev[right], ed[right], mesh.n_dofs, lambda x, n: n + 0 * x)
    assert Gr[0::2].sum() == pytest.approx(1.0, rel=1e-14)
    assert abs(Gr[1::2].sum()) < 1e-15


def test_load_function_errors():
    mesh = SquareMesh(2)
    V, D, n = mesh.vertices, mesh.cell_dofs, mesh.n_dofs
    with pytest.raises(ValueError, match="body force f returned an array of shape"):
        el.assemble_body_force(V, D, n, lambda x: x[..., 0])
    with pytest.raises(ValueError, match="body force f returned non-finite"):
        el.assemble_body_force(V, D, n, lambda x: np.full(x.shape, -np.inf))
    ev, ed = mesh.bedge_vertices, mesh.bedge_dofs
    with pytest.raises(ValueError, match="edge load g returned an array of shape"):
        el.assemble_edge_load(ev, ed, n, lambda x, nn: np.zeros(3))
    with pytest.raises(ValueError, match="edge load g returned non-finite"):
        el.assemble_edge_load(ev, ed, n, lambda x, nn: np.full(x.shape, np.nan))
    with pytest.raises(ValueError, match="edge_dofs"):
        el.assemble_edge_load(ev, ed[:, :4], n, lambda x, nn: x)
    with pytest.raises(ValueError, match="zero length"):
        el.assemble_edge_load(np.zeros((1, 2, 2)), ed[:1], n, lambda x, nn: x)


# ---------------------------------------------------------------------------
# stresses of u_h
# ---------------------------------------------------------------------------


def test_div_stress_traction_and_jumps_for_quadratic_field():
    mesh = SquareMesh(3, perturb=0.3)
    u = Quadratic()
    u_cell = mesh.interpolate(u)[mesh.cell_dofs]
    m = len(mesh.cells)
    assert np.allclose(el.div_stress(mesh.vertices, u_cell, MAT), u.div_stress(), atol=1e-10)
    xi = np.array([[0.2, 0.3], [0.6, 0.1]])
    x = p2.physical_points(mesh.vertices, xi)
    nrm = RNG.standard_normal((m, 2))
    tr = el.traction(mesh.vertices, u_cell, MAT, xi, nrm)
    assert np.allclose(tr, np.einsum("mqij,mj->mqi", u.stress(x), nrm), atol=1e-11)
    # along every local edge: outward normal and sigma n at the right points
    t = np.array([0.0, 0.3, 1.0])
    for k in range(3):
        le = np.full(m, k)
        trac, normal = el.edge_traction(mesh.vertices, u_cell, MAT, le, t)
        start, end = mesh.vertices[:, k], mesh.vertices[:, (k + 1) % 3]
        centroid = mesh.vertices.mean(axis=1)
        assert np.all(np.einsum("mi,mi->m", normal, 0.5 * (start + end) - centroid) > 0)
        assert np.allclose(np.linalg.norm(normal, axis=1), 1.0)
        assert np.allclose(np.einsum("mi,mi->m", normal, end - start), 0.0, atol=1e-14)
        xs = start[:, None, :] + t[None, :, None] * (end - start)[:, None, :]
        assert np.allclose(trac, np.einsum("mqij,mj->mqi", u.stress(xs), normal), atol=1e-10)


def test_stress_jump_vanishes_for_quadratic_and_not_for_cubic():
    mesh = SquareMesh(2)
    # cell 0 = (a, b, c) and cell 4 = (a, c, d) of the first square share the diagonal a-c:
    # it is local edge 2 (c -> a) of cell 0 and local edge 0 (a -> c) of cell 4
    lower, upper = 0, 4
    assert mesh.cells[lower, 2] == mesh.cells[upper, 1]
    assert mesh.cells[lower, 0] == mesh.cells[upper, 0]
    t = np.array([0.1, 0.5, 0.8])

    def jump(field):
        u_cell = mesh.interpolate(field)[mesh.cell_dofs]
        ta, na = el.edge_traction(mesh.vertices[[lower]], u_cell[[lower]], MAT, np.array([2]), t)
        tb, nb = el.edge_traction(
            mesh.vertices[[upper]], u_cell[[upper]], MAT, np.array([0]), 1 - t
        )
        assert np.allclose(na, -nb)
        return np.abs(ta + tb).max()

    assert jump(Quadratic()) < 1e-12
    assert jump(lambda x: np.stack([x[..., 0] ** 3 * x[..., 1], x[..., 1] ** 3], -1)) > 1e-3


# ---------------------------------------------------------------------------
# errors against exact solutions
# ---------------------------------------------------------------------------


def smooth(x):
    X, Y = x[..., 0], x[..., 1]
    return np.stack([np.sin(2 * X) * np.exp(Y), X * Y**2 * np.cos(Y)], axis=-1)


def smooth_grad(x):
    X, Y = x[..., 0], x[..., 1]
    g = np.empty(x.shape[:-1] + (2, 2))
    g[..., 0, 0] = 2 * np.cos(2 * X) * np.exp(Y)
    g[..., 0, 1] = np.sin(2 * X) * np.exp(Y)
    g[..., 1, 0] = Y**2 * np.cos(Y)
    g[..., 1, 1] = X * (2 * Y * np.cos(Y) - Y**2 * np.sin(Y))
    return g


def test_errors_vanish_for_quadratic_and_match_closed_forms():
    mesh = SquareMesh(3, perturb=0.3)
    u = Quadratic()
    u_cell = mesh.interpolate(u)[mesh.cell_dofs]
    V = mesh.vertices
    assert el.energy_error2(V, u_cell, u.grad, MAT).sum() < 1e-24
    assert el.h1_seminorm_error2(V, u_cell, u.grad).sum() < 1e-24
    assert el.l2_error2(V, u_cell, u).sum() < 1e-24
    # with u_h = 0 the errors are the norms of u: Gauss on the square is independent
    zero = np.zeros_like(u_cell)
    x, w = gauss_square(4)
    g = u.grad(x)
    eps = 0.5 * (g + np.swapaxes(g, -1, -2))
    energy = np.sum(w * np.einsum("qij,qij->q", u.stress(x), eps))
    e2 = el.energy_error2(V, zero, u.grad, MAT)
    assert e2.shape == (len(V),) and np.all(e2 >= 0)
    assert e2.sum() == pytest.approx(energy, rel=1e-12)
    assert el.h1_seminorm_error2(V, zero, u.grad).sum() == pytest.approx(
        np.sum(w * np.einsum("qij,qij->q", g, g)), rel=1e-12
    )
    assert el.l2_error2(V, zero, u).sum() == pytest.approx(
        np.sum(w * np.einsum("qi,qi->q", u(x), u(x))), rel=1e-12
    )
    xs, ws = gauss_square(12)
    assert el.l2_error2(V, zero, smooth, degree=12).sum() == pytest.approx(
        np.sum(ws * np.einsum("qi,qi->q", smooth(xs), smooth(xs))), rel=1e-12
    )


def test_interpolation_error_rates():
    h1, l2, en = [], [], []
    ns = [4, 8, 16]
    for n in ns:
        mesh = SquareMesh(n)
        u_cell = mesh.interpolate(smooth)[mesh.cell_dofs]
        V = mesh.vertices
        h1.append(np.sqrt(el.h1_seminorm_error2(V, u_cell, smooth_grad).sum()))
        en.append(np.sqrt(el.energy_error2(V, u_cell, smooth_grad, MAT).sum()))
        l2.append(np.sqrt(el.l2_error2(V, u_cell, smooth).sum()))
    for name, errs, expected in (("H1", h1, 2.0), ("energy", en, 2.0), ("L2", l2, 3.0)):
        rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
        assert np.all(np.abs(rates - expected) < 0.15), f"{name} rates {rates}"


def test_error_function_checks():
    mesh = SquareMesh(2)
    u_cell = np.zeros((len(mesh.cells), 12))
    with pytest.raises(ValueError, match="grad_exact returned an array of shape"):
        el.energy_error2(mesh.vertices, u_cell, lambda x: x, MAT)
    with pytest.raises(ValueError, match="u_exact returned non-finite"):
        el.l2_error2(mesh.vertices, u_cell, lambda x: np.full(x.shape, np.nan))


# ---------------------------------------------------------------------------
# scale: timing print, with correctness checks that can fail
# ---------------------------------------------------------------------------


@pytest.mark.slow
def test_assembly_at_1_6_million_unknowns(capsys):
    mesh = SquareMesh(448)  # 401 408 triangles, 1 609 218 unknowns
    mat = el.Material.from_young(500.0, 0.3)
    t0 = time.perf_counter()
    K = el.element_stiffness(mesh.vertices, mat)
    t_elem = time.perf_counter() - t0
    del K
    t0 = time.perf_counter()
    A = el.assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, mat)
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
