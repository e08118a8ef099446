"""The quadrature of {v > 0} on P2 faces (signorini.estimator.surface.positive_part): exact
where v keeps its sign and for linear v, against an independent scan-line reference where a
quadratic changes sign (the accuracy stated in the module), the refined face's hats."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from signorini.estimator.surface import (
    face_monomials,
    positive_region_rule,
    refined_face_hats,
)
from signorini.estimator.surface.positive_part import PIECE_NODES
from signorini.fem.facet_element import P2_TRIANGLE
from signorini.fem.p2 import REFERENCE_NODES, basis
from signorini.fem.quadrature import triangle_rule

from .scanline import integrate, piece_of

#: the largest relative errors of the area and of the integrals with a factor v, measured
#: 1.7e-6 and 2.9e-9 over 600 random quadratics (seed 8; 2.6e-8 and 2.3e-10 over the 60 of
#: seed 0), with a margin of 3 to 6 (module notes of positive_part)
AREA_BOUND, MOMENT_BOUND = 1e-5, 1e-8


def monomial_values(c, s):
    """v at points ``s (k, m, 2)`` from monomial coefficients (the reference's own)."""
    x, y = s[..., 0], s[..., 1]
    c = c[:, None]
    return (
        c[..., 0]
        + c[..., 1] * x
        + c[..., 2] * y
        + c[..., 3] * x * x
        + c[..., 4] * x * y
        + (c[..., 5] * y * y)
    )


def moments(v, rule):
    """∫_{v>0} 1, ∫_{v>0} v and ∫_{v>0} v φ_p (k, 6) of the rule."""
    k = len(v)
    vq = np.einsum("ma,ma->m", basis(rule.s), v[rule.face])
    hats = refined_face_hats(rule.s, rule.piece)
    area = np.bincount(rule.face, rule.w, k)
    first = np.bincount(rule.face, rule.w * vq, k)
    hat = np.stack([np.bincount(rule.face, rule.w * vq * hats[:, a], k) for a in range(6)], 1)
    return area, first, hat


def piece_integrals(f, degree=8):
    """∫ over each of the 4 triangles of the once-refined face of ``f(s (m, 2), piece)``, by
    the triangle rule mapped onto it (exact for polynomials of the rule's degree)."""
    xi, w = triangle_rule(degree)
    out = 0.0
    for p in range(4):
        a, b, c = REFERENCE_NODES[PIECE_NODES[p]]
        s = a + xi @ np.stack([b - a, c - a])
        jac = abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
        values = f(s, np.full(len(s), p))
        out = out + (w * jac).reshape((-1,) + (1,) * (values.ndim - 1)) * values
    return out.sum(axis=0)


def test_face_monomials_are_the_p2_function():
    rng = np.random.default_rng(1)
    v = rng.normal(size=(4, 6))
    s = rng.random((7, 2)) * 0.5
    expected = basis(s) @ v.T  # (7, 4)
    got = monomial_values(face_monomials(v), np.broadcast_to(s, (4, 7, 2)))
    assert np.allclose(got.T, expected, rtol=0, atol=1e-14)


def test_refined_face_hats_nodal_linear_and_their_integrals_are_the_hat_shares():
    for p in range(4):
        corners = REFERENCE_NODES[PIECE_NODES[p]]
        at = refined_face_hats(corners, np.full(3, p))
        expected = np.zeros((3, 6))
        expected[np.arange(3), PIECE_NODES[p]] = 1.0
        assert np.allclose(at, expected, atol=1e-15)
        # linear on the piece: the value at the centroid is the corners' mean
        centre = refined_face_hats(corners.mean(axis=0, keepdims=True), np.array([p]))
        assert np.allclose(centre, at.mean(axis=0), atol=1e-15)
    s = np.random.default_rng(2).random((50, 2)) * 0.5
    assert np.allclose(refined_face_hats(s, piece_of(s)).sum(axis=1), 1.0, atol=1e-14)
    m = piece_integrals(lambda s, p: refined_face_hats(s, p))
    assert np.allclose(m, 0.5 * np.array(P2_TRIANGLE.hat_share), rtol=1e-14)


def test_constant_sign_is_exact_and_negative_faces_are_empty():
    rng = np.random.default_rng(3)
    v = 2.0 + 0.3 * rng.normal(size=(20, 6))  # positive on the whole face
    c = face_monomials(v)
    assert (
        monomial_values(
            c, np.broadcast_to(triangle_rule(10)[0], (20,) + triangle_rule(10)[0].shape)
        )
        > 0
    ).all()
    rule = positive_region_rule(v, 3)
    area, first, hat = moments(v, rule)
    assert np.allclose(area, 0.5, rtol=1e-14)
    # ∫ s₁^a s₂^b over the reference triangle = a! b! / (a + b + 2)!
    mono = np.array(
        [
            math.factorial(a) * math.factorial(b) / math.factorial(a + b + 2)
            for a, b in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
        ]
    )
    assert np.allclose(first, c @ mono, rtol=1e-13)
    exact = piece_integrals(
        lambda s, p: (basis(s) @ v.T)[:, :, None] * refined_face_hats(s, p)[:, None]
    )
    assert np.allclose(hat, exact, rtol=1e-13)
    assert np.allclose(first, hat.sum(axis=1), rtol=1e-13)
    empty = positive_region_rule(-v, 3)
    assert empty.w.size == 0 and empty.n_faces == 20
    zero = positive_region_rule(np.zeros((3, 6)), 3)
    assert zero.w.size == 0


def test_points_lie_in_their_piece_with_positive_weights():
    v = np.random.default_rng(4).normal(size=(40, 6))
    rule = positive_region_rule(v, 4)
    assert (rule.w > 0).all() and (np.diff(rule.face) >= 0).all()
    corners = REFERENCE_NODES[PIECE_NODES[rule.piece]]  # (m, 3, 2)
    lam = np.linalg.solve(
        np.concatenate([np.swapaxes(corners, 1, 2), np.ones((len(rule.w), 1, 3))], axis=1),
        np.concatenate([rule.s, np.ones((len(rule.w), 1))], axis=1)[..., None],
    )
    assert lam.min() > -1e-12
    # and where v > 0, to the accuracy of the cut
    vq = np.einsum("ma,ma->m", basis(rule.s), v[rule.face])
    assert vq.min() > -1e-3 * np.abs(v).max()


def sign_change_errors(n_faces: int, seed: int = 0):
    """The largest relative errors of the area, ∫v and ∫v φ_p over random quadratics against
    the scan-line reference, and the points per face."""
    v = np.random.default_rng(seed).normal(size=(n_faces, 6))
    c = face_monomials(v)
    rule = positive_region_rule(v, 3)
    area, first, hat = moments(v, rule)

    def reference(face, s):
        h = refined_face_hats(s.reshape(-1, 2), piece_of(s).ravel()).reshape(s.shape[:2] + (6,))
        vs = monomial_values(c[face], s)[..., None]
        return np.concatenate([np.ones_like(vs), vs, vs * h], axis=-1)

    ref = integrate(c, reference, n_outer=32)
    e_area = np.abs(area - ref[:, 0]) / ref[:, 0].clip(1e-3)
    e_first = np.abs(first - ref[:, 1]) / ref[:, 1].clip(1e-3)
    e_hat = np.abs(hat - ref[:, 2:]).max(axis=1) / ref[:, 2:].max(axis=1).clip(1e-3)
    changing = int((np.ptp(np.sign(v), axis=1) > 0).sum())
    print(
        f"\nrelative errors over {n_faces} faces ({changing} change sign at nodes): area "
        f"{e_area.max():.1e}, ∫v {e_first.max():.1e}, ∫v φ_p {e_hat.max():.1e}; "
        f"{len(rule.w) / n_faces:.0f} points a face"
    )
    return e_area.max(), e_first.max(), e_hat.max()


def test_the_scan_line_reference_is_converged():
    c = face_monomials(np.random.default_rng(7).normal(size=(20, 6)))
    one = lambda f, s: np.ones(s.shape[:2])  # noqa: E731
    coarse, fine = integrate(c, one, n_outer=32), integrate(c, one, n_outer=96, n_inner=12)
    assert np.abs(coarse - fine).max() < 1e-11


def test_sign_change_against_the_scan_line_reference():
    e_area, e_first, e_hat = sign_change_errors(60)
    assert e_area < AREA_BOUND
    assert e_first < MOMENT_BOUND
    assert e_hat < MOMENT_BOUND


@pytest.mark.slow
def test_sign_change_against_the_scan_line_reference_many_faces():
    e_area, e_first, e_hat = sign_change_errors(600, seed=8)
    assert e_area < AREA_BOUND
    assert e_first < MOMENT_BOUND
    assert e_hat < MOMENT_BOUND


def clipped_polygon(corners, g):
    """The polygon {g > 0} of a triangle for a linear g (Sutherland–Hodgman, one plane)."""
    out = []
    for p, q in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        gp, gq = g(p), g(q)
        if gp > 0:
            out.append(p)
        if (gp > 0) != (gq > 0):
            out.append(p + gp / (gp - gq) * (q - p))
    return np.array(out)


def polygon_area_and_centroid(poly):
    x, y = poly[:, 0], poly[:, 1]
    xs, ys = np.roll(x, -1), np.roll(y, -1)
    cr = x * ys - xs * y
    area = cr.sum() / 2
    return area, np.array([((x + xs) * cr).sum(), ((y + ys) * cr).sum()]) / (6 * area)


def test_linear_v_is_exact_against_the_cut_polygon():
    rng = np.random.default_rng(5)
    g = rng.normal(size=(30, 3))  # v = g0 + g1 s1 + g2 s2
    v = g[:, :1] + g[:, 1:] @ REFERENCE_NODES.T
    rule = positive_region_rule(v, 2)
    area, first, _ = moments(v, rule)
    for f in range(len(v)):
        lin = lambda s, f=f: g[f, 0] + g[f, 1:] @ s  # noqa: E731
        poly = clipped_polygon(REFERENCE_NODES[:3], lin)
        a, centroid = polygon_area_and_centroid(poly) if len(poly) else (0.0, np.zeros(2))
        assert area[f] == pytest.approx(a, rel=1e-12, abs=1e-15)
        assert first[f] == pytest.approx(a * lin(centroid), rel=1e-11, abs=1e-15)


def relabel(perm):
    """The P2 node order after the vertices ``perm`` become vertices 0, 1, 2."""
    edges = {frozenset((k, (k + 1) % 3)): 3 + k for k in range(3)}
    mids = [edges[frozenset((perm[k], perm[(k + 1) % 3]))] for k in range(3)]
    return np.array(list(perm) + mids)


def test_invariant_under_relabelling_the_vertices():
    v = np.random.default_rng(6).normal(size=(30, 6))
    area, first, hat = moments(v, positive_region_rule(v, 3))
    for perm in itertools.permutations(range(3)):
        order = relabel(perm)
        a2, f2, h2 = moments(v[:, order], positive_region_rule(v[:, order], 3))
        assert np.allclose(a2, area, rtol=AREA_BOUND, atol=AREA_BOUND)
        assert np.allclose(f2, first, rtol=MOMENT_BOUND, atol=MOMENT_BOUND)
        assert np.allclose(h2, hat[:, order], rtol=MOMENT_BOUND, atol=MOMENT_BOUND)


@pytest.mark.parametrize("tiny", [1e-12, 1e-17, 1e-30, 1e-100, 1e-200])
def test_a_root_beside_a_corner_gives_finite_weights_and_areas_that_add_up(tiny):
    """A vertex value of ``±tiny`` puts the side roots at ``ρ ~ tiny`` from it: the rays'
    exit ``1/ρ`` once overflowed (infinite weights from 10⁻¹⁷ on). ``{v > 0}`` and
    ``{−v > 0}`` tile the triangle (area 1/2), and the corner's own region is small: about
    ``tiny²/2`` on the first face, ``0.46 tiny^{3/2}`` on the second (its side 2–0 leaves the
    corner with zero slope, so the root there is at ``(tiny/2)^{1/2}``)."""
    v = np.array([[tiny, -1.0, -1.0, -0.5, -1.0, -0.5], [-tiny, 1.0, 2.0, 0.5, 1.5, 0.5]])
    with np.errstate(over="raise", invalid="raise"):
        plus, minus = positive_region_rule(v, 3), positive_region_rule(-v, 3)
    assert np.isfinite(plus.w).all() and np.isfinite(minus.w).all()
    area_plus = np.bincount(plus.face, weights=plus.w, minlength=2)
    area_minus = np.bincount(minus.face, weights=minus.w, minlength=2)
    assert np.allclose(area_plus + area_minus, 0.5, rtol=AREA_BOUND, atol=0.0)
    corner = np.array([area_plus[0], area_minus[1]])  # the tiny corner's side of the cut
    assert (corner >= 0.0).all() and (corner <= tiny**1.5).all()


@pytest.mark.parametrize(
    ("v", "degree", "depth", "word"),
    [
        (np.zeros((3, 5)), 3, 1, "shape"),
        (np.full((2, 6), np.nan), 3, 1, "non-finite"),
        (np.zeros((2, 6)), -1, 1, "degree"),
        (np.zeros((2, 6)), 3, -2, "depth"),
        (np.zeros((2, 6)), 3, 1.5, "depth"),
    ],
)
def test_bad_input_is_refused(v, degree, depth, word):
    with pytest.raises(ValueError, match=word):
        positive_region_rule(v, degree, depth=depth)
