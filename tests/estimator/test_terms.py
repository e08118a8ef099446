"""The estimator's term functions and distributing helpers
(:mod:`signorini.estimator.terms`), each on arrays with a closed form."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from signorini.estimator.terms import (
    FacetSet,
    boundary_cell_shares,
    complementarity,
    facet_traction,
    interior_residual,
    normal_stress,
    penetration,
    spread_cell_integrals,
    spread_facet_integrals,
    spread_node_parts,
    stress_jump,
    tangential_stress,
    third_integrals,
)
from signorini.fem.quadrature import line_rule, triangle_rule

T, W = line_rule(7)


# ---------------------------------------------------------------------------- distribution
def test_spread_facet_integrals_weights_and_halves():
    """An interior facet (cells 0, 1) and a boundary facet (cell 1) with J = 2 and 3."""
    h_p = np.array([0.0, 1.0, 2.0, 4.0, 8.0, 16.0])  # node 0 a Dirichlet node
    edges = FacetSet(
        index=np.array([7, 9]),
        nodes=np.array([[0, 1, 4], [1, 2, 5]]),
        cells=np.array([[0, 1], [1, -1]]),
        measure=np.array([1.0, 1.0]),
    )
    shares = spread_facet_integrals(edges, np.array([2.0, 3.0]), h_p, n_cells=3)
    np.testing.assert_array_equal(shares.node, [0, 2 * 1 + 3 * 1, 3 * 2, 0, 2 * 8, 3 * 16])
    total0, total1 = 2 * (0 + 1 + 8), 3 * (1 + 2 + 16)
    np.testing.assert_array_equal(shares.cell, [total0 / 2, total0 / 2 + total1, 0])
    assert shares.cell.sum() == shares.node.sum()


def test_spread_cell_integrals():
    cell_nodes = np.array([[0, 1, 2, 3, 4, 5], [1, 6, 2, 7, 8, 4]])
    h_p = np.arange(9, dtype=float)
    R = np.array([2.0, 5.0])
    shares = spread_cell_integrals(R, cell_nodes, h_p)
    expected = np.zeros(9)
    for r, nodes in zip(R, cell_nodes, strict=True):
        expected[nodes] += r * h_p[nodes] ** 2
    np.testing.assert_array_equal(shares.node, expected)
    np.testing.assert_array_equal(shares.cell, R * (h_p[cell_nodes] ** 2).sum(axis=1))
    assert shares.cell.sum() == pytest.approx(shares.node.sum(), rel=1e-15)


def test_spread_node_parts_and_boundary_cells():
    edges = FacetSet(
        np.array([0, 1]), np.array([[0, 1, 3], [1, 2, 4]]), np.array([[2, -1], [0, -1]]), np.ones(2)
    )
    parts = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    shares = spread_node_parts(edges, parts, n_nodes=5, n_cells=3)
    np.testing.assert_array_equal(shares.node, [1, 6, 5, 3, 6])
    np.testing.assert_array_equal(shares.cell, [15, 0, 6])
    np.testing.assert_array_equal(boundary_cell_shares(edges, np.array([7.0, 1.0]), 3), [1, 0, 7])


# ---------------------------------------------------------------------------- σ(u_h) n
def test_facet_traction_of_a_constant_stress_uses_outward_normals():
    points = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]])
    cells = np.array([[0, 1, 2]])
    sigma = np.array([[1.0, 0.5], [0.5, -2.0]])
    sigma_vertex = np.broadcast_to(sigma, (1, 3, 2, 2))
    out = facet_traction(sigma_vertex, points, cells, np.zeros(3, int), np.arange(3), T)
    normals = np.array([[0.0, -1.0], [1.0, 2.0] / np.sqrt(5.0), [-1.0, 0.0]])
    np.testing.assert_allclose(out, np.broadcast_to((normals @ sigma)[:, None], out.shape))


def test_facet_traction_interpolates_linearly_along_the_facet():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    cells = np.array([[0, 1, 2]])
    sigma_vertex = np.zeros((1, 3, 2, 2))
    sigma_vertex[0, 1] = np.eye(2)  # σ = λ_1 I: on edge 0 (from vertex 0 to 1) equal to t I
    out = facet_traction(sigma_vertex, points, cells, np.array([0]), np.array([0]), T)
    np.testing.assert_allclose(out[0], T[:, None] * [0.0, -1.0], atol=1e-16)


# ---------------------------------------------------------------------------- the terms
def test_eta1_interior_residual():
    area = np.array([0.5, 2.0])
    div_sigma = np.array([[1.0, 2.0], [0.0, -3.0]])
    np.testing.assert_allclose(interior_residual(area, div_sigma), [2.5, 18.0])
    xi, w = triangle_rule(8)
    f = np.broadcast_to(np.array([-1.0, 1.0]), (2, w.size, 2))  # constant body force
    np.testing.assert_allclose(interior_residual(area, div_sigma, f, w), [4.5, 10.0])


def test_eta2_stress_jump():
    traction = np.broadcast_to([1.0, -2.0], (2, T.size, 2))
    length = np.array([1.0, 0.5])
    np.testing.assert_array_equal(stress_jump(traction, -traction, W, length), 0.0)
    np.testing.assert_allclose(stress_jump(traction, traction, W, length), 20 * length)


def test_eta4_eta5_split_the_traction():
    """Normal (0, −1), traction (a, b): σ_nn = −b, σ_t = (a, 0)."""
    a, b, p = 3.0, -2.0, 0.5
    traction = np.broadcast_to([a, b], (1, T.size, 2))
    normal = np.array([[0.0, -1.0]])
    length = np.array([0.25])
    assert tangential_stress(traction, normal, W, length)[0] == pytest.approx(a * a / 4)
    assert normal_stress(traction, normal, T, W, length)[0] == pytest.approx(b * b / 4)
    # a constant pressure at the three nodes: p_h = p, σ_nn + p_h = p − b
    consistent = normal_stress(traction, normal, T, W, length, np.full((1, 3), p))
    assert consistent[0] == pytest.approx((p - b) ** 2 / 4, rel=1e-14)
    # a pressure t at [start, end, midpoint] = [0, 1, 1/2]: ∫ (t − b)² = 1/3 − b + b²
    linear = normal_stress(traction, normal, T, W, length, np.array([[0.0, 1.0, 0.5]]))
    assert linear[0] == pytest.approx((1 / 3 - b + b * b) / 4, rel=1e-14)


def test_eta6_complementarity_of_a_uniform_clearance():
    """ψ − u_h·n = 1 everywhere: d_p = |e| (2/9, 2/9, 5/18) (see the thirds below)."""
    gap = -np.ones((2, 3))
    density = np.array([[1.0, 0.0, 2.0], [0.0, 0.0, 0.0]])
    out = complementarity(gap, density, np.array([0.5, 1.0]))
    np.testing.assert_allclose(out, [[1 / 9, 0.0, 5 / 18], [0.0, 0.0, 0.0]], rtol=1e-14)


def test_eta7_penetration_on_one_edge():
    """u_h·n − ψ = t on a unit edge, values [0, 1, 1/2]: ‖t‖²_{H^{1/2}} = 1/3 + 1."""
    share = penetration(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]), np.array([[0, 1, 0.5]]))
    assert share[0] == pytest.approx(4 / 3, rel=1e-14)


# ---------------------------------------------------------------------------- thirds
def _quadratic(v: np.ndarray):
    a, b, m = v
    return lambda t: a * (1 - t) * (1 - 2 * t) + b * t * (2 * t - 1) + m * 4 * t * (1 - t)


def quad_thirds(v: np.ndarray, length: float) -> np.ndarray:
    """∫ v⁺ φ_p over the three thirds by adaptive quadrature, splitting at v's roots."""
    f = _quadratic(v)
    a, b, m = v
    roots = np.roots([2 * a + 2 * b - 4 * m, -3 * a - b + 4 * m, a])
    roots = [float(r.real) for r in roots if abs(r.imag) < 1e-14 and 0 < r.real < 1]
    out = np.zeros(3)
    hats = [
        (0, 0, 1 / 3, lambda t: 1 - 2 * t),
        (1, 2 / 3, 1, lambda t: 2 * t - 1),
        (2, 1 / 3, 1 / 2, lambda t: 2 * t),
        (2, 1 / 2, 2 / 3, lambda t: 2 - 2 * t),
    ]
    for col, lo, hi, phi in hats:
        pts = [r for r in roots if lo < r < hi] or None
        val, _ = quad(
            lambda t, phi=phi: max(f(t), 0.0) * phi(t),
            lo,
            hi,
            points=pts,
            epsabs=1e-14,
            epsrel=1e-13,
        )
        out[col] += val
    return out * length


def test_third_integrals_of_one_closed_form():
    """With v = 1: |e|·(∫_0^{1/3}(1−2t), ∫_{2/3}^1(2t−1), ∫_{1/3}^{1/2}2t + ∫_{1/2}^{2/3}(2−2t))
    = |e|·(1/3 − 1/9, 1/3 − 1/9, 5/36 + 5/36) = |e|·(2/9, 2/9, 5/18)."""
    length = np.array([1.0, 0.25, 3.0])
    out = third_integrals(np.ones((3, 3)), length)
    np.testing.assert_allclose(out, length[:, None] * [2 / 9, 2 / 9, 5 / 18], rtol=1e-14)
    np.testing.assert_array_equal(third_integrals(-np.ones((3, 3)), length), 0.0)
    # v(t) = t on [0, 1]: ∫_0^{1/3} t(1−2t) = 5/162, ∫_{2/3}^1 t(2t−1) = 31/162,
    # ∫_{1/3}^{1/2} 2t² + ∫_{1/2}^{2/3} t(2−2t) = 19/324 + 26/324 = 45/324
    out = third_integrals(np.array([[0.0, 1.0, 0.5]]), np.array([1.0]))
    np.testing.assert_allclose(out[0], [5 / 162, 31 / 162, 45 / 324], rtol=1e-14)


def test_third_integrals_random_quadratics_against_quad():
    rng = np.random.default_rng(7)
    # roots placed in every third and across the third boundaries, plus random quadratics
    r1 = rng.uniform(0, 1, 150)
    r2 = rng.uniform(0, 1, 150)
    sign = rng.choice([-1.0, 1.0], 150)
    t = np.array([0.0, 1.0, 0.5])
    by_roots = sign[:, None] * (t[None] - r1[:, None]) * (t[None] - r2[:, None])
    linear = rng.normal(size=(50, 2)) @ np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5]])
    v = np.vstack(
        [
            by_roots,
            rng.normal(size=(100, 3)),
            linear,
            [[0.0, 0.0, 0.0], [1.0, 1.0, -0.5], [0.0, 0.0, 1.0]],
        ]
    )
    length = rng.uniform(0.01, 2.0, len(v))
    out = third_integrals(v, length)
    ref = np.array([quad_thirds(vi, li) for vi, li in zip(v, length, strict=True)])
    crossings = sum(
        np.any(np.diff(np.sign(_quadratic(vi)(np.linspace(lo, hi, 50)))) != 0)
        for vi in v
        for lo, hi in ((0, 1 / 3), (1 / 3, 2 / 3), (2 / 3, 1))
    )
    print(
        f"{len(v)} quadratics, {crossings} sign changes inside a third, max abs deviation "
        f"{np.abs(out - ref).max():.2e}"
    )
    assert crossings > 100
    np.testing.assert_allclose(out, ref, rtol=1e-10, atol=1e-13)
