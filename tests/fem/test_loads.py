"""Load vectors (:mod:`signorini.fem.loads`) against independent quadrature, and the patch
tests that join them with the stiffness matrix."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from contact_problems import random_quadratic
from fem_problems import SquareMesh

from signorini.fem import p2
from signorini.fem.loads import assemble_body_force, assemble_facet_load
from signorini.fem.material import Material
from signorini.fem.stiffness import assemble_stiffness

RNG = np.random.default_rng(11)
MAT = Material.from_lame(1.3, 0.8)


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
    mesh = SquareMesh(3, RNG, perturb=0.3)
    F = assemble_body_force(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, poly_force, degree=6)
    ref = independent_body_load(mesh, poly_force)
    assert np.abs(F - ref).max() < 1e-14 * np.abs(ref).max() * 10
    # the basis sums to one: component sums are the integrals of f over the square
    # int (1 + x^2 y - 3 y^3) = 1 + 1/6 - 3/4 ; int (x y + 2 x^4) = 1/4 + 2/5
    assert F[0::2].sum() == pytest.approx(1 + 1 / 6 - 3 / 4, rel=1e-13)
    assert F[1::2].sum() == pytest.approx(1 / 4 + 2 / 5, rel=1e-13)
    # a too-low degree is visibly inexact for this degree-4 force
    F1 = assemble_body_force(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, poly_force, degree=1)
    assert np.abs(F1 - ref).max() > 1e-6


def test_body_force_constant_broadcasts():
    mesh = SquareMesh(2)
    F = assemble_body_force(
        mesh.vertices, mesh.cell_dofs, mesh.n_dofs, lambda x: np.array([0.0, -2.0])
    )
    assert F[1::2].sum() == pytest.approx(-2.0, rel=1e-14)
    assert np.all(F[0::2] == 0)
    # P2 vertex basis functions integrate to zero over a triangle: only midpoints load
    assert np.allclose(F[1 : 2 * mesh.n_points : 2], 0.0, atol=1e-15)


def test_facet_load_polynomial_exact_and_normals():
    mesh = SquareMesh(3, RNG, perturb=0.3)
    ev, ed = mesh.bedge_vertices, mesh.bedge_dofs

    def g(x, normal):
        X, Y = x[..., 0], x[..., 1]
        return np.stack([X**3 + Y, X * Y**2], axis=-1) + 0 * normal

    G = assemble_facet_load(ev, ed, mesh.n_dofs, g, degree=5)
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
    Gn = assemble_facet_load(ev, ed, mesh.n_dofs, lambda x, n: np.broadcast_to(n, x.shape))
    assert np.allclose([Gn[0::2].sum(), Gn[1::2].sum()], 0.0, atol=1e-14)
    right = ev.mean(axis=1)[:, 0] > 1 - 1e-12
    Gr = assemble_facet_load(ev[right], ed[right], mesh.n_dofs, lambda x, n: n + 0 * x)
    assert Gr[0::2].sum() == pytest.approx(1.0, rel=1e-14)
    assert abs(Gr[1::2].sum()) < 1e-15


# ---------------------------------------------------------------------------
# patch tests: stiffness and loads together reproduce every quadratic
# ---------------------------------------------------------------------------


def solve_with_dirichlet(A, F, fixed, values):
    n = A.shape[0]
    free = np.setdiff1d(np.arange(n), fixed)
    U = np.zeros(n)
    U[fixed] = values
    rhs = F[free] - A[free][:, fixed] @ values
    U[free] = spla.spsolve(A[free][:, free].tocsc(), rhs)
    return U


def patch(seed):
    """A perturbed mesh, a random quadratic ``u``, the stiffness and the load of ``-div σ(u)``."""
    rng = np.random.default_rng(seed)
    mesh = SquareMesh(4, rng, perturb=0.35)
    u = random_quadratic(rng)
    A = assemble_stiffness(mesh.vertices, mesh.cell_dofs, mesh.n_dofs, MAT)
    F = assemble_body_force(
        mesh.vertices, mesh.cell_dofs, mesh.n_dofs, lambda x: -u.div_stress(MAT) + 0 * x
    )
    return mesh, u, A, F


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_patch_test_dirichlet(seed):
    mesh, u, A, F = patch(seed)
    bnodes = np.unique(mesh.bedge_nodes)
    fixed = (2 * bnodes[:, None] + np.arange(2)).ravel()
    exact = mesh.interpolate(u.value)
    U = solve_with_dirichlet(A, F, fixed, exact[fixed])
    err = np.abs(U - exact).max() / np.abs(exact).max()
    assert err < 1e-12, f"relative nodal error {err:.1e}"


@pytest.mark.parametrize("seed", [3, 4])
def test_patch_test_with_neumann_tractions(seed):
    mesh, u, A, F = patch(seed)
    # Neumann on the right (x = 1) and top (y = 1) sides, Dirichlet on the rest
    ev = mesh.bedge_vertices
    mid = ev.mean(axis=1)
    neu = (mid[:, 0] > 1 - 1e-12) | (mid[:, 1] > 1 - 1e-12)
    seen_normals = []

    def g(x, normal):
        seen_normals.append(normal)
        return np.einsum("kqij,kqj->kqi", u.stress(x, MAT), np.broadcast_to(normal, x.shape))

    F = F + assemble_facet_load(ev[neu], mesh.bedge_dofs[neu], mesh.n_dofs, g)
    normals = seen_normals[0][:, 0]
    expected = np.where(mid[neu, 0:1] > 1 - 1e-12, [[1.0, 0.0]], [[0.0, 1.0]])
    assert np.allclose(normals, expected)
    dnodes = np.unique(mesh.bedge_nodes[~neu])
    fixed = (2 * dnodes[:, None] + np.arange(2)).ravel()
    exact = mesh.interpolate(u.value)
    U = solve_with_dirichlet(A, F, fixed, exact[fixed])
    err = np.abs(U - exact).max() / np.abs(exact).max()
    assert err < 1e-11, f"relative nodal error {err:.1e}"
