"""The contact terms on faces (estimator/contact_faces3d.py): η6's integrals on the refined-face
hats against brute-force quadrature, η6 and η7 vanishing where the discrete solution does not
penetrate or the gap is closed, the node classes of Section 4 on faces, and the pressure η5
balances σ_nn with."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from signorini.contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from signorini.contact.solution import solve
from signorini.estimator.contact_faces3d import _hat_integrals, eta5_pressure
from signorini.estimator.residual import estimate
from signorini.estimator.residual3d import estimate_3d
from signorini.estimator.surface.penetration import surface_penetration
from signorini.fem.facet_element import P2_TRIANGLE
from signorini.fem.p2 import basis, grad_basis

from .cube import cube_problem, full_contact_fields, transition_fields

RNG = np.random.default_rng(7)


def _face(curved: bool) -> np.ndarray:
    """``(1, 6, 3)`` the node points of a face in space: flat, or its side nodes moved."""
    corners = np.array([[0.1, 0.0, 0.2], [0.9, 0.1, 0.3], [0.2, 0.8, 0.1]])
    mids = 0.5 * (corners + np.roll(corners, -1, axis=0))
    if curved:
        mids = mids + np.array([[0.0, -0.03, 0.05], [0.04, 0.02, 0.06], [-0.02, 0.0, 0.04]])
    return np.concatenate([corners, mids])[None]


def _brute_force(v: np.ndarray, points: np.ndarray, level: int = 8) -> np.ndarray:
    """``∫ v⁺ φ_a`` over one face by the midpoint rule on 4^level congruent triangles."""
    n = 2**level
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up = (i + j) < n
    down = (i + j) < n - 1
    centres = np.concatenate(
        [
            np.column_stack([(i[up] + 1 / 3) / n, (j[up] + 1 / 3) / n]),
            np.column_stack([(i[down] + 2 / 3) / n, (j[down] + 2 / 3) / n]),
        ]
    )
    area = 0.5 / n**2
    t = np.einsum("mar,ai->mri", grad_basis(centres), points[0])
    jac = np.linalg.norm(np.cross(t[:, 0], t[:, 1]), axis=1)
    value = np.maximum(basis(centres) @ v[0], 0.0)
    # the refined face's hats at the centres: the P1 interpolant on the sub-triangle
    lam = np.column_stack([1 - centres.sum(axis=1), centres])
    hats = np.zeros((len(centres), 6))
    corner = (2 * lam >= 1).any(axis=1)
    k = np.argmax(lam, axis=1)
    hats[corner, k[corner]] = 2 * lam[corner, k[corner]] - 1
    lam_k = lam[np.arange(len(lam)), k]
    for a in range(3):  # midpoint of side (a, b): 2 λ_b on corner a, 1 − 2 λ_c in the middle
        b = (a + 1) % 3
        phi = np.where(corner, 2 * (lam[:, a] + lam[:, b] - lam_k), 1 - 2 * lam[:, 3 - a - b])
        on = ~corner | (k == a) | (k == b)
        hats[:, 3 + a] = np.where(on, np.maximum(phi, 0.0), 0.0)
    return (area * jac * value) @ hats


@pytest.mark.parametrize("curved", [False, True], ids=["flat", "quadratic"])
def test_the_hat_integrals_match_brute_force_quadrature(curved):
    points = _face(curved)
    for _ in range(3):
        v = RNG.normal(size=(1, 6)) + 0.3  # changes sign on the face
        ours = _hat_integrals(v, points)[0]
        ref = _brute_force(v, points)
        # the reference's own error: O(4^-level) (its midpoint rule across the kink of v⁺)
        np.testing.assert_allclose(ours, ref, atol=2e-4 * np.abs(ref).max())


def test_the_hat_integrals_of_constants_are_the_hat_shares_and_of_negatives_zero():
    points = _face(False)
    area = 0.5 * np.linalg.norm(np.cross(points[0, 1] - points[0, 0], points[0, 2] - points[0, 0]))
    ours = _hat_integrals(np.full((1, 6), 0.7), points)[0]
    np.testing.assert_allclose(ours, 0.7 * area * np.array(P2_TRIANGLE.hat_share), rtol=1e-13)
    # nodal values in [−0.6, −0.5]: v < 0 on the face (the P2 Lebesgue constant is 5/3; a
    # P2 function with negative nodal values may still be positive inside, −φ_v is)
    negative = -0.55 + 0.05 * RNG.uniform(-1, 1, size=(4, 6))
    assert (_hat_integrals(negative, np.repeat(points, 4, 0)) == 0).all()
    assert (surface_penetration(np.repeat(points, 4, 0), negative) == 0).all()


@cache
def _solved(name: str, n: int, alpha: float | None):
    fields = {"full": full_contact_fields, "transition": transition_fields}[name]()
    return solve(cube_problem(fields, n, alpha))


def test_in_full_contact_with_the_transformed_basis_eta6_and_eta7_vanish():
    """Condition (b) in full contact: u_h·n = ψ_h on all of Γ_C, every row in full contact,
    η6 = 0 exactly (no semi-contact node, and d_p = 0 with ψ_h) and η7 at round-off; (a) on the
    same mesh lifts vertices off (semi-contact rows, η6 > 0) and penetrates between nodes."""
    result = _solved("full", 3, None)
    assert (result.classes == FULL_CONTACT).all()
    est = estimate(result)
    error = result.errors()["error_energy"]
    assert est.eta_terms[5] == 0.0
    assert est.eta_terms[6] <= 1e-10 * error
    gap = result.contact.facet_normal_gap(result.u)
    assert np.abs(gap).max() <= 1e-13
    nodal = _solved("full", 3, 0.0)
    est_a = estimate(nodal)
    assert (nodal.classes == SEMI_CONTACT).sum() > 0
    assert est_a.eta_terms[5] > 0.1 * error and est_a.eta_terms[6] > 0.05 * error


def test_eta6_lives_on_semi_contact_nodes_and_eta7_where_the_solution_penetrates():
    """The transition problem (contact inside a circle no mesh line follows): η6's node
    contributions are at the nodes of faces with a semi-contact row, and only where s_p d_p is;
    η7's face shares vanish on every face where u_h·n − ψ_h ≤ 0 (sampled finely)."""
    result = _solved("transition", 3, None)
    cs = result.contact
    classes = result.classes
    assert {FULL_CONTACT, SEMI_CONTACT, NO_CONTACT} <= set(classes.tolist())
    est = estimate(result)
    assert est.eta_terms[5] > 0
    semi_nodes = cs.node[classes == SEMI_CONTACT]
    eta6_nodes = np.flatnonzero(est.eta2_node[5])
    assert eta6_nodes.size > 0 and np.isin(eta6_nodes, semi_nodes).all()
    # η7's shares by face, recomputed: zero where the quadratic gap is nowhere positive
    gap = cs.facet_normal_gap(result.u)
    shares = surface_penetration(result.space.node_points[cs.faces], gap)
    s = np.random.default_rng(0).dirichlet(np.ones(3), size=2000)[:, 1:]
    sampled = (gap @ basis(s).T).max(axis=1)
    assert (shares[sampled <= 0] == 0).all()
    np.testing.assert_allclose(shares.sum(), est.eta_terms[6] ** 2, rtol=1e-12)


def test_the_node_classes_on_faces_follow_section_4():
    """A row is in contact when active; in full contact when every node of every contact face
    at its node is in contact (a loop over the faces here, the package's vectorized)."""
    result = _solved("transition", 2, 0.0)
    cs = result.contact
    expected = np.where(result.active, SEMI_CONTACT, NO_CONTACT)
    for f in range(len(cs.faces)):  # a plain loop: the independent reading
        rows = cs.facet_local[f]
        if not result.active[rows[rows >= 0]].all() or (rows < 0).any():
            for r in rows[rows >= 0]:
                expected[r] = min(expected[r], SEMI_CONTACT) if result.active[r] else NO_CONTACT
    full = result.active.copy()
    for f in range(len(cs.faces)):
        rows = cs.facet_local[f]
        if (rows < 0).any() or not result.active[rows].all():
            full[rows[rows >= 0]] = False
    expected[full] = FULL_CONTACT
    np.testing.assert_array_equal(result.classes, expected)


def test_the_transformed_pressure_balances_the_normal_stress_better():
    """The consistent η5 with (b)'s own p̃ = Λ̃/w̃ against the P1-lumped recovered pressure on
    the full-contact cube (docs/method.md, *Three dimensions: the estimator on tetrahedra and
    faces*: 1.79 against 3.33 times the error at n = 4): p̃ is the default; (a) has none
    (its vertex weights vanish) and takes the recovered one."""
    result = _solved("full", 4, None)
    transformed = estimate_3d(result, pressure="transformed").eta_terms[4]
    recovered = estimate_3d(result, pressure="recovered").eta_terms[4]
    assert transformed < 0.7 * recovered
    assert estimate(result).eta_terms[4] == transformed
    nodal = _solved("full", 3, 0.0)
    np.testing.assert_array_equal(
        eta5_pressure(nodal, "transformed"), nodal.contact.recovered_pressure(nodal.contact_force)
    )
    with pytest.raises(ValueError, match="eta5 pressure"):
        eta5_pressure(nodal, "lumped")


def test_the_obstacle_term_beside_eta_vanishes_for_an_affine_obstacle():
    """``osc_ψ = (Σ_F |∫_F λ̃_h (ψ − ψ_h)|)^{1/2}``: at the square root of round-off for the
    patch test's affine ψ (ψ = ψ_h); for the full-contact cube's curved ψ of the order of
    h^{3/2} (measured 0.139, 0.163, 0.182 times the error at n = 2, 3, 4), not in η_h."""
    from .cube import patch_fields

    patch = solve(cube_problem(patch_fields(), 2))
    assert estimate(patch).obstacle_oscillation <= 1e-8
    ratios = []
    for n in (2, 3):
        result = _solved("full", n, None)
        est = estimate(result)
        assert np.isclose(est.eta**2, (est.eta_terms**2).sum())  # osc is beside η, not in it
        ratios.append(est.obstacle_oscillation / result.errors()["error_energy"])
    assert 0.1 < ratios[0] < ratios[1] < 0.2, ratios
