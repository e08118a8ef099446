"""η7 on a surface (signorini.estimator.surface.penetration): the guaranteed localised bound
against a brute-force Sobolev–Slobodeckij norm on the unit square, zero where v ≤ 0, the
face norms against independent quadrature, invariance under rigid motions."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.estimator.h_half_norm import localised_bound2
from signorini.estimator.surface import (
    face_norms2_positive_part,
    surface_penetration,
    surface_weights,
)

from .slobodeckij import l2_norm2, seminorm2
from .square import quadratic_at, square_faces

#: quadratics q in (x, y) on the unit square, v = q⁺: positive throughout, a ramp whose zero
#: line crosses the cells, a cap bounded by a circle, a small spot at the centre
CASES = {
    "positive": np.array([1.0, 0.5, 0.0, 0.0, 0.0, -0.3]),
    "ramp": np.array([-0.35, 1.0, 0.0, 0.0, 0.0, 0.0]),
    "cap": np.array([-0.2, 1.0, 1.0, -1.0, 0.0, -1.0]),
    "spot": np.array([-0.45, 1.0, 1.0, -1.0, 0.0, -1.0]),
}


def test_the_brute_force_norm_is_converged():
    c = CASES["cap"]
    coarse, fine = seminorm2(c, 8, 4, 8, 6), seminorm2(c, 16, 4, 12, 8)
    assert abs(coarse - fine) < 1e-3 * fine


@pytest.mark.parametrize("n", [4, 8])
def test_the_bound_is_above_the_norm_on_a_flat_square(n):
    points = square_faces(n)
    ratios = {}
    for name, c in CASES.items():
        v = quadratic_at(c, points)
        exact = seminorm2(c, 8, 4, 8, 6) + l2_norm2(c)
        bound = surface_penetration(points, v).sum()
        unit = localised_bound2(face_norms2_positive_part(points, v))[0]
        ratios[name] = (np.sqrt(bound / exact), np.sqrt(unit / exact))
        assert bound >= exact, f"{name}: G/η7 = {ratios[name][0]:.3f} < 1"
    print(
        f"\nn = {n}: "
        + ", ".join(f"{k} G/η7 {g:.2f} (B/η7 {b:.2f})" for k, (g, b) in ratios.items())
    )


def test_zero_where_v_is_not_positive():
    points = square_faces(4)
    c = CASES["spot"]
    shares = surface_penetration(points, quadratic_at(c, points))
    # the largest q on each face, sampled on a fine barycentric grid (q is the face's v)
    i, j = np.meshgrid(np.arange(41), np.arange(41), indexing="ij")
    keep = i + j <= 40
    bary = np.stack([i[keep], j[keep], 40 - i[keep] - j[keep]], axis=1) / 40
    top = quadratic_at(c, np.einsum("qa,fai->fqi", bary, points[:, :3])).max(axis=1)
    assert (shares[top < 0] == 0).all() and (shares[top > 1e-3] > 0).all()
    assert 0 < (shares > 0).sum() < len(shares)
    v = quadratic_at(c, points)
    assert np.array_equal(surface_penetration(points, -np.abs(v) - 1e-3), np.zeros(len(v)))
    assert np.array_equal(surface_penetration(points, np.zeros_like(v)), np.zeros(len(v)))


def test_face_norms_against_independent_quadrature():
    points = square_faces(4)
    for name, c in CASES.items():
        norms = face_norms2_positive_part(points, quadratic_at(c, points))
        assert norms.l2.sum() == pytest.approx(l2_norm2(c, 32, 6), rel=1e-7), name
    # ∇(1 + x − 2y) has |∇v|² = 5 on the whole square (area 1)
    norms = face_norms2_positive_part(points, quadratic_at([3.0, 1.0, -2.0, 0, 0, 0], points))
    assert norms.gradient.sum() == pytest.approx(5.0, rel=1e-13)
    assert np.allclose(norms.h, np.sqrt(0.5) / 4, rtol=1e-14)


def test_weights_of_a_uniform_mesh():
    near, far = surface_weights(square_faces(4))
    assert np.allclose(near, 4 * np.pi, rtol=1e-14) and np.allclose(far, 4 * np.pi, rtol=1e-14)


def test_weights_of_some_faces_are_those_of_the_whole_set():
    """Graded faces (radii from 0.4 to 1.6 of the uniform ones): the weights asked for a subset
    of faces equal, bit for bit, those of the whole set on it."""
    points = square_faces(8)
    points = points * (1.0 + 0.6 * np.sin(3.0 * points[..., :1]))  # graded in x
    near, far = surface_weights(points)
    subset = np.array([0, 5, 17, 64, len(points) - 1])
    near_sub, far_sub = surface_weights(points, faces=subset)
    assert np.array_equal(near_sub[subset], near[subset])
    assert np.array_equal(far_sub[subset], far[subset])
    assert not np.allclose(near, near[0])  # the grading reaches the weights
    empty = surface_weights(points, faces=np.array([], dtype=int))
    assert np.isfinite(empty[0]).all() and np.isfinite(empty[1]).all()


def test_invariant_under_a_rigid_motion():
    points = square_faces(4)
    v = quadratic_at(CASES["cap"], points)
    a, b = 0.7, -0.4
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    moved = points @ (rx @ rz).T + np.array([3.0, -2.0, 5.0])
    assert np.allclose(surface_penetration(moved, v), surface_penetration(points, v), rtol=1e-10)


@pytest.mark.parametrize(
    ("points", "v", "kw", "word"),
    [
        (np.zeros((2, 6, 2)), np.zeros((2, 6)), {}, "points"),
        (np.zeros((2, 6, 3)), np.zeros((3, 6)), {}, "v must"),
        (np.full((1, 6, 3), np.nan), np.zeros((1, 6)), {}, "finite"),
        (square_faces(1), np.zeros((2, 6)), {"delta_factor": 0.0}, "delta_factor"),
    ],
)
def test_bad_input_is_refused(points, v, kw, word):
    with pytest.raises(ValueError, match=word):
        surface_penetration(points, v, **kw)
