"""The estimator on P2 tetrahedra (estimator/residual3d.py): every term vanishes on the 3D patch
tests, the element indicators sum to η_h², the Hessians through the quadratic map are exact,
and on a smooth problem of 3D elasticity η_h converges like the error (N^{-2/3}) with a bounded
efficiency index."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.contact.solution3d import errors_3d
from signorini.estimator.names import TERMS
from signorini.estimator.residual import NODE_TERMS, estimate
from signorini.examples.elasticity3d import elasticity_3d
from signorini.fem.material import Material
from signorini.fem.p2_tet import REFERENCE_NODES
from signorini.fem.quadrature import tetrahedron_rule
from signorini.fem.space3d import P2TetSpace
from signorini.mesh.builders3d import box, eighth_ball
from signorini.problem import ContactProblem, Dirichlet, Neumann
from signorini.problem.conditions import ExactSolution, Roller

from .cube import cube_problem, full_contact_fields, patch_fields

MATERIAL = Material(lam=1.7, mu=0.9)
A, B, K, G = 0.03, -0.02, 0.015, 0.01


def _quadratic(x: np.ndarray) -> np.ndarray:
    """``u = (A x², B y² + K x², G z²)``: u_x = 0 and σ_xy = σ_xz = 0 on x = 0, u_z = 0 and
    σ_xz = σ_yz = 0 on z = 0."""
    X, Y, Z = x[..., 0], x[..., 1], x[..., 2]
    return np.stack([A * X**2, B * Y**2 + K * X**2, G * Z**2], axis=-1)


def _quadratic_gradient(x: np.ndarray) -> np.ndarray:
    X, Y, Z = x[..., 0], x[..., 1], x[..., 2]
    g = np.zeros(x.shape[:-1] + (3, 3))
    g[..., 0, 0], g[..., 1, 1], g[..., 1, 0], g[..., 2, 2] = (
        2 * A * X,
        2 * B * Y,
        2 * K * X,
        2 * G * Z,
    )
    return g


def _stress(x: np.ndarray) -> np.ndarray:
    g = _quadratic_gradient(x)
    eps = 0.5 * (g + np.swapaxes(g, -1, -2))
    return 2 * MATERIAL.mu * eps + MATERIAL.lam * np.trace(eps, axis1=-2, axis2=-1)[
        ..., None, None
    ] * np.eye(3)


def _body_force(x: np.ndarray) -> np.ndarray:
    """``f = −div σ(u)``, constant: ``−(μ Δu + (λ + μ) ∇ div u)``."""
    mu, lam = MATERIAL.mu, MATERIAL.lam
    laplace = np.array([2 * A, 2 * B + 2 * K, 2 * G])
    grad_div = np.array([2 * A, 2 * B, 2 * G])
    return np.broadcast_to(-(mu * laplace + (lam + mu) * grad_div), x.shape).copy()


def quadratic_problem(n: int = 2) -> ContactProblem:
    """The quadratic field on box(n) with every kind of face η3 reads: a roller on x0, the
    normal component held on z0 (``Dirichlet((None, None, 0))``, the tangential tractions
    free), u on y0, its tractions on x1, y1, z1; the constant body force."""

    def traction(p, normal):
        return np.einsum("...ij,...j->...i", _stress(p), normal)

    return ContactProblem(
        mesh=box(n, n, n),
        material=MATERIAL,
        conditions={
            "x0": Roller(),
            "z0": Dirichlet((None, None, 0.0)),
            "y0": Dirichlet(_quadratic),
            **{name: Neumann(traction) for name in ("x1", "y1", "z1")},
        },
        body_force=_body_force,
        exact=ExactSolution(_quadratic, _quadratic_gradient),
        name="quadratic-3d",
    )


def test_a_quadratic_field_with_rollers_and_held_components_has_every_term_zero():
    result = solve(quadratic_problem(2))
    scale = np.abs(_quadratic(result.space.node_points)).max()
    assert np.abs(result.u - _quadratic(result.space.node_points)).max() <= 1e-12 * scale
    est = estimate(result)
    sigma = np.abs(_stress(result.space.node_points)).max()
    assert est.eta_terms.max() <= 1e-12 * sigma, est.eta_terms
    # the same field, perturbed at one interior node: η1, η2 see it, and the free tractions
    # of the roller and the held part (η3) see a perturbed boundary node
    u = result.u.copy()
    inner = np.flatnonzero(np.all(np.abs(result.space.node_points - 0.5) < 0.3, axis=1))
    u[inner[0]] += 1e-3
    x0 = result.space.part_nodes(["x0"])
    u[x0[len(x0) // 2], 1] += 1e-3
    perturbed = estimate(type(result)(**{**result.__dict__, "u": u}))
    assert perturbed.eta_terms[0] > 1e-4 and perturbed.eta_terms[1] > 1e-4
    assert perturbed.eta_terms[2] > 1e-5


@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b-transformed", "a-nodal"])
def test_the_constant_pressure_contact_patch_test_has_every_term_zero(alpha):
    """u affine, σ constant, p = 0.1 on Γ_C: u_h = u, the discrete pressure exact, every
    node in full contact, so η1 … η7 vanish (round-off of σ ~ 0.1)."""
    fields = patch_fields()
    result = solve(cube_problem(fields, 2, alpha))
    u = fields["u"](result.space.node_points)
    assert np.abs(result.u - u).max() <= 1e-13 * np.abs(u).max()
    est = estimate(result)
    assert est.eta_terms.max() <= 1e-13, est.eta_terms
    assert (result.classes == 2).all()  # FULL_CONTACT at every row
    paper = estimate(result, "paper")  # σ_nn itself, without the pressure: 0.1 |Γ_C|^{1/2} h^{1/2}
    assert paper.eta_terms[4] > 0.05


def test_the_indicators_sum_to_the_estimator_and_the_node_rows_to_the_terms():
    result = solve(cube_problem(full_contact_fields(), 2, 0.0))
    est = estimate(result)
    np.testing.assert_allclose(est.eta2.sum(), est.eta**2, rtol=1e-13)
    rows = [TERMS.index(name) for name in NODE_TERMS]
    np.testing.assert_allclose(
        est.eta2_node.sum(axis=1), est.eta2_cell[rows].sum(axis=1), rtol=1e-12, atol=1e-30
    )
    assert est.eta2_cell.shape == (8, result.mesh.n_cells)
    assert est.eta2_node.shape == (7, result.space.n_nodes)
    assert (est.eta2_node[:, result.dirichlet_nodes] == 0).all()
    assert est.eta_terms[5] > 0 and est.eta_terms[6] > 0  # (a): lift-off and penetration


def test_hessians_through_the_quadratic_map_are_exact():
    """On the isoparametric cells of the eighth ball the P2 interpolant of a quadratic field
    of x is not a polynomial of ξ; its Hessian through the map matches central differences of
    the field along the map's inverse (a Newton solve), and a linear field has none."""
    space = P2TetSpace(eighth_ball(1))
    cells, nodes = space.curved
    group = space.mapping.groups[-1]  # the isoparametric cells
    assert len(group) == len(cells)
    rng = np.random.default_rng(0)
    c = rng.normal(size=(3, 10))  # u_i = c_i · (1, x, y, z, x², y², z², xy, yz, zx)

    def field(x):
        X, Y, Z = x[..., 0], x[..., 1], x[..., 2]
        m = np.stack([np.ones_like(X), X, Y, Z, X * X, Y * Y, Z * Z, X * Y, Y * Z, Z * X], -1)
        return m @ c.T

    u_cell = field(nodes).reshape(len(cells), 30)
    xi = tetrahedron_rule(2)[0][:2]
    hess = group.field_hessians(u_cell, xi)
    x = group.points(xi)

    def at(point, k):  # u_h at the physical point, by Newton on the map of cell k
        q = xi[0].copy()
        for _ in range(30):
            J = group.rows(np.array([k])).jacobians(q[None])[0][0, 0]
            q = q - np.linalg.solve(J, group.rows(np.array([k])).points(q[None])[0, 0] - point)
        return group.rows(np.array([k])).field_values(u_cell[k : k + 1], q[None])[0, 0]

    h, k, p = 1e-4, 0, x[0, 0]
    fd = np.empty((3, 3, 3))
    for j in range(3):
        for m in range(3):
            ej, em = np.eye(3)[j] * h, np.eye(3)[m] * h
            fd[:, j, m] = (
                at(p + ej + em, k) - at(p + ej - em, k) - at(p - ej + em, k) + at(p - ej - em, k)
            ) / (4 * h * h)
    np.testing.assert_allclose(hess[k, 0], fd, atol=1e-5 * np.abs(fd).max())
    linear = nodes @ rng.normal(size=(3, 3))  # a field linear in x
    flat = group.field_hessians(linear.reshape(len(cells), 30), REFERENCE_NODES[:4])
    assert np.abs(flat).max() <= 1e-11


def _elasticity_rows(sizes):
    rows = []
    for n in sizes:
        result = solve(elasticity_3d(n))
        error = errors_3d(result, degree=6)["error_energy"]  # 64 points: a smooth u
        rows.append((result.ndof, estimate(result).eta, error))
    N, eta, err = map(np.array, zip(*rows, strict=True))
    print("elasticity-3d: N", N, "eta", eta, "error", err, "eta/error", eta / err)
    return N, eta, err


def _slope(N, values):
    return np.polyfit(np.log(N), np.log(values), 1)[0]


def test_elasticity_3d_the_estimator_follows_the_error():
    """The smooth manufactured solution of elasticity-3d on the Kuhn cubes n = 3, 4, 5 (still
    before the asymptotic N^{-2/3}: the error's slope is −0.52 there): η_h decays as the error
    does (slopes within 0.05) and η_h/error stays within ±10 % of its mean (measured 41.4,
    43.4, 44.9)."""
    N, eta, err = _elasticity_rows((3, 4, 5))
    assert abs(_slope(N, eta) - _slope(N, err)) <= 0.05, (_slope(N, eta), _slope(N, err))
    ratio = eta / err
    assert np.abs(ratio / ratio.mean() - 1).max() <= 0.10, ratio


@pytest.mark.slow
def test_elasticity_3d_the_estimator_reaches_the_rate_two_thirds():
    """n = 8, 10, 12 (10⁴ to 3.6·10⁴ free unknowns): both slopes ≤ −0.6, η_h/error within
    ±5 % of its mean."""
    N, eta, err = _elasticity_rows((8, 10, 12))
    assert _slope(N, eta) <= -0.6 and _slope(N, err) <= -0.6, (_slope(N, eta), _slope(N, err))
    ratio = eta / err
    assert np.abs(ratio / ratio.mean() - 1).max() <= 0.05, ratio
