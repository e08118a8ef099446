"""Rigid obstacles as shapes (signorini.problem.obstacles): gap and direction at points."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from signorini.problem.obstacles import Disc, HalfPlane, Polyline, SignedDistance

S2 = np.sqrt(0.5)

#: a groove of width 2 and depth 1 in a foundation below y = 0 (walked right to left)
GROOVE = [[3.0, 0.0], [1.0, 0.0], [1.0, -1.0], [-1.0, -1.0], [-1.0, 0.0], [-3.0, 0.0]]
#: a flat punch of width 2 above y = 0 (walked down its left side, along the bottom, up)
PUNCH = [[-1.0, 2.0], [-1.0, 0.0], [1.0, 0.0], [1.0, 2.0]]


def rotation(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


# --- closed forms ------------------------------------------------------------------------


def test_half_plane_closed_form():
    obstacle = HalfPlane([1.0, 2.0], [3.0, 4.0])  # normalised to (0.6, 0.8)
    x = np.array([[1.0, 2.0], [4.0, 6.0], [1.0, 1.0], [-3.0, 5.0]])
    psi, n = obstacle.gap_and_direction(x)
    np.testing.assert_allclose(psi, [0.0, 5.0, -0.8, 0.0], atol=1e-15)
    np.testing.assert_array_equal(n, np.tile([-0.6, -0.8], (4, 1)))


def test_disc_outside_inside_and_on():
    obstacle = Disc([1.0, -1.0], 2.0)
    x = np.array([[4.0, 3.0], [1.0, 0.0], [3.0, -1.0], [1.0, -3.0]])
    psi, n = obstacle.gap_and_direction(x)
    np.testing.assert_allclose(psi, [3.0, -1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(n, [[-0.6, -0.8], [0.0, -1.0], [-1.0, 0.0], [0.0, 1.0]], atol=1e-15)


def test_polyline_segment_interior_and_end_rays():
    obstacle = Polyline(GROOVE)
    x = np.array([[2.0, 0.5], [0.0, -0.2], [10.0, 1.0], [-10.0, -2.0], [0.9, -0.5]])
    psi, n = obstacle.gap_and_direction(x)
    np.testing.assert_allclose(psi, [0.5, 0.8, 1.0, -2.0, 0.1], atol=1e-15)
    np.testing.assert_allclose(
        n, [[0.0, -1.0], [0.0, -1.0], [0.0, -1.0], [0.0, -1.0], [1.0, 0.0]], atol=1e-15
    )


def test_polyline_sharp_convex_corner_gives_the_vertex_and_the_radial_normal():
    obstacle = Polyline(PUNCH)
    x = np.array([[-2.0, -2.0], [-1.3, -0.4], [2.0, -1.0]])
    psi, n = obstacle.gap_and_direction(x)
    corner = np.array([[-1.0, 0.0], [-1.0, 0.0], [1.0, 0.0]])
    distance = np.linalg.norm(corner - x, axis=1)
    np.testing.assert_allclose(psi, distance, rtol=1e-15)
    np.testing.assert_allclose(n, (corner - x) / distance[:, None], rtol=1e-15, atol=1e-16)


def test_polyline_rounded_corner_gives_the_distance_to_the_arc():
    obstacle = Polyline(PUNCH, radius=0.5)
    center = np.array([-0.5, 0.5])
    x = np.array([[-2.0, -1.0], [-1.0, -1.0], [-0.7, 0.3]])
    psi, n = obstacle.gap_and_direction(x)
    radial = x - center
    r = np.linalg.norm(radial, axis=1)
    np.testing.assert_allclose(psi, r - 0.5, rtol=1e-15)
    np.testing.assert_allclose(n, -radial / r[:, None], rtol=1e-15)
    # beyond the tangent points the flat parts take over
    psi, n = obstacle.gap_and_direction([[-0.2, -1.0], [-1.5, 0.7]])
    np.testing.assert_allclose(psi, [1.0, 0.5], rtol=1e-15)
    np.testing.assert_allclose(n, [[0.0, 1.0], [1.0, 0.0]], atol=1e-16)
    # the arc's own points are on the obstacle
    on_arc = center + 0.5 * np.array([[-np.cos(0.3), -np.sin(0.3)]])
    psi, _ = obstacle.gap_and_direction(on_arc)
    assert abs(psi[0]) < 1e-15


def test_polyline_groove_inner_corner_uses_the_mean_of_both_normals():
    """A point on the bisector of the groove's sharp inner corner (1, -1) is equally close to
    the wall and to the bottom: psi is that distance, n the normalised mean of (1, 0), (0, -1);
    the corner itself gets the same bisector, and a point inside the foundation equally far
    from (2, 0) and the corner counts the corner once."""
    obstacle = Polyline(GROOVE)
    x = np.array([[0.5, -0.5], [1.0, -1.0], [2.0, -1.0], [0.0, 1.0]])
    psi, n = obstacle.gap_and_direction(x)
    np.testing.assert_allclose(psi, [0.5, 0.0, -1.0, np.sqrt(2)], rtol=1e-15)
    np.testing.assert_allclose(n, [[S2, -S2], [S2, -S2], [S2, -S2], [0.0, -1.0]], rtol=1e-15)


def test_polyline_opposite_candidates_take_the_first_in_order():
    """In the middle of a deep slot the two walls' directions cancel; the first wall in the
    polyline's order (x = 1) gives the direction."""
    slot = Polyline([[3.0, 0.0], [1.0, 0.0], [1.0, -5.0], [-1.0, -5.0], [-1.0, 0.0], [-3.0, 0.0]])
    psi, n = slot.gap_and_direction([[0.0, -2.0]])
    np.testing.assert_array_equal(psi, [1.0])
    np.testing.assert_array_equal(n, [[1.0, 0.0]])
    reversed_walls = Polyline([[-3.0, 0.0], [-1.0, 0.0], [-1.0, 5.0], [1.0, 5.0], [1.0, 0.0]])
    psi, n = reversed_walls.gap_and_direction([[0.0, 2.0]])
    np.testing.assert_array_equal(n, [[-1.0, 0.0]])


def test_polyline_corner_arc_centre_sees_the_tangent_points():
    obstacle = Polyline(PUNCH, radius=0.5)
    psi, n = obstacle.gap_and_direction([[-0.5, 0.5]])
    np.testing.assert_allclose(psi, [-0.5], rtol=1e-15)
    np.testing.assert_allclose(n, [[S2, S2]], rtol=1e-15)


# --- degenerate input ----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Disc([0, 0], 0.0), "Disc: radius must be finite and > 0, got 0.0"),
        (lambda: Disc([0, 0], -1), "Disc: radius must be finite and > 0, got -1"),
        (lambda: Disc([0, np.nan], 1), "Disc: center has non-finite entries"),
        (lambda: Disc([0, 0, 0], 1), "Disc: center must have shape (2,), got (3,)"),
        (lambda: HalfPlane([0, 0], [0, 0]), "HalfPlane: normal must be a non-zero vector"),
        (lambda: Polyline([[0, 0]]), "Polyline: points needs at least 2 points, got 1"),
        (lambda: Polyline([0, 0, 1, 1]), "Polyline: points must have shape (m, 2), got (4,)"),
        (
            lambda: Polyline([[0, 0], [1, 0], [1, 0], [2, 1]]),
            "Polyline: points[1] and points[2] are the same point [1.0, 0.0]",
        ),
        (
            lambda: Polyline([[0, 0], [1, 0], [1, 1], [0, 0]]),
            "Polyline: points[0] and points[3] are the same point [0.0, 0.0]",
        ),
        (
            lambda: Polyline([[0, 0], [2, 0], [1, 0]]),
            "Polyline: the polyline turns back on itself at points[1] = [2.0, 0.0]",
        ),
        (
            lambda: Polyline([[0, 0], [2, 0], [2, 1], [1, 1], [1, -1], [0, -2]]),
            "Polyline: the polyline crosses itself: the segments points[0]–points[1] (extended "
            "to a ray) from [0.0, 0.0] to [2.0, 0.0] and points[3]–points[4] from [1.0, 1.0] "
            "to [1.0, -1.0] meet",
        ),
        (  # only the end rays cross: the last one, walked down x = -1, the first at (-1, 0)
            lambda: Polyline([[0, 0], [1, 0], [1, 1], [-1, 1], [-1, 0.5]]),
            "Polyline: the polyline crosses itself: the segments points[0]–points[1] (extended "
            "to a ray) from [0.0, 0.0] to [1.0, 0.0] and points[3]–points[4] (extended to a "
            "ray) from [-1.0, 1.0] to [-1.0, 0.5] meet",
        ),
        (  # touching: the walk returns through a corner
            lambda: Polyline([[0, 0], [2, 0], [2, 1], [1, 1], [1, 0], [0, -2]]),
            "Polyline: the polyline crosses itself: the segments points[0]–points[1]",
        ),
        (  # a collinear overlap of two segments that are not neighbours
            lambda: Polyline([[0, 0], [2, 0], [2, 1], [3, 1], [3, 0], [1, 0], [1, -1]]),
            "Polyline: the polyline crosses itself: the segments points[0]–points[1] (extended "
            "to a ray) from [0.0, 0.0] to [2.0, 0.0] and points[4]–points[5]",
        ),
        (
            lambda: Polyline(PUNCH, radius=1.5),
            "Polyline: radius 1.5 is too large: the rounded corners need 3 of the segment "
            "from points[1] to points[2], which is 2 long",
        ),
        (lambda: Polyline(PUNCH, radius=-1), "Polyline: radius must be finite and >= 0"),
        (lambda: SignedDistance(3.0), "SignedDistance: phi must be callable, got 3.0"),
        (
            lambda: SignedDistance(np.sum, scale=0),
            "SignedDistance: scale must be finite and > 0, got 0",
        ),
    ],
)
def test_degenerate_obstacles_are_rejected(build, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        build()


def test_points_at_the_disc_centre_have_no_direction():
    with pytest.raises(
        ValueError,
        match=re.escape(
            "Disc(center=[1.0, 2.0], radius=3.0): x[1] = [1.0, 2.0] lies at the centre, where "
            "no direction to the closest point exists"
        ),
    ):
        Disc([1, 2], 3).gap_and_direction([[0.0, 0.0], [1.0, 2.0]])


@pytest.mark.parametrize(
    ("x", "message"),
    [
        (np.zeros((3, 3)), "x must have shape (n, 2), got (3, 3)"),
        (np.zeros(2), "x must have shape (n, 2), got (2,)"),
        ([[0.0, 0.0], [np.inf, 1.0]], "x[1] is not finite: [inf  1.]"),
    ],
)
def test_bad_points_are_rejected(x, message):
    obstacle = HalfPlane([0, 0], [0, 1])
    with pytest.raises(
        ValueError, match=re.escape("HalfPlane(point=[0.0, 0.0], normal=[0.0, 1.0]): " + message)
    ):
        obstacle.gap_and_direction(x)


def circle_phi(x):
    return np.hypot(x[:, 0], x[:, 1]) - 1.0


@pytest.mark.parametrize(
    ("phi", "grad", "message"),
    [
        (
            lambda x: x[:, :1],
            None,
            "phi(x) must return shape (2,) for x of shape (2, 2), got (2, 1)",
        ),
        (
            lambda x: np.where(x[:, 0] > 0, x[:, 0], np.nan),
            None,
            "phi(x) is not finite at x[1] = [-1.0, 0.0]",
        ),
        (circle_phi, lambda x: x[:, 0], "grad(x) must return shape (2, 2) for x of shape (2, 2)"),
        (circle_phi, lambda x: 0 * x, "the gradient of phi vanishes at x[0] = [2.0, 0.0]"),
        (lambda x: "a", None, "phi(x) did not return numbers"),
        (
            lambda x: x[:, 0] ** 2 + x[:, 1] ** 2 - 1,
            None,
            "phi is not a signed distance: its difference quotients have length 4 > sqrt(2) "
            "at x[0] = [2.0, 0.0]",
        ),
    ],
)
def test_bad_user_functions_are_rejected(phi, grad, message):
    obstacle = SignedDistance(phi, grad=grad)
    with pytest.raises(ValueError, match=re.escape(message)):
        obstacle.gap_and_direction([[2.0, 0.0], [-1.0, 0.0]])


# --- SignedDistance from each shape's own distance ------------------------------------------


SHAPES = [
    (HalfPlane([0.3, -0.2], [1.0, 2.0]), None),
    (Disc([0.5, 0.5], 1.5), None),
    (Polyline(PUNCH, radius=0.4), "outside"),  # convex: its outside distance is smooth
    (Polyline(GROOVE), "segment interiors"),
]


@pytest.mark.parametrize(("shape", "where"), SHAPES)
def test_signed_distance_of_a_shape_agrees_with_the_shape(shape, where):
    rng = np.random.default_rng(7)
    x = rng.uniform(-3, 3, (400, 2))
    psi, n = shape.gap_and_direction(x)
    if where == "outside":
        x, psi, n = x[psi > 0.05], psi[psi > 0.05], n[psi > 0.05]
    elif where == "segment interiors":
        # keep points well away from the groove's corners and their bisectors
        x = np.column_stack([rng.uniform(-0.8, 0.8, 200), rng.uniform(-0.9, -0.3, 200)])
        x = np.concatenate(
            [x, np.column_stack([rng.uniform(1.5, 3, 100), rng.uniform(-1, 1, 100)])]
        )
        x = x[np.abs(np.abs(x[:, 0]) - 1 + x[:, 1] + 1) > 0.05]
        psi, n = shape.gap_and_direction(x)
    user = SignedDistance(lambda y: shape.gap_and_direction(y)[0], scale=3.0)
    psi_user, n_user = user.gap_and_direction(x)
    np.testing.assert_array_equal(psi_user, psi)
    np.testing.assert_allclose(n_user, n, atol=1e-8)
    given_grad = SignedDistance(
        lambda y: shape.gap_and_direction(y)[0], grad=lambda y: -shape.gap_and_direction(y)[1]
    )
    np.testing.assert_allclose(given_grad.gap_and_direction(x)[1], n, atol=1e-15)


def test_signed_distance_calls_phi_once_for_the_values_and_once_for_the_differences():
    calls = []

    def phi(x):
        calls.append(x.shape)
        return circle_phi(x)

    x = np.random.default_rng(2).uniform(2, 3, (1000, 2))
    psi, n = SignedDistance(phi).gap_and_direction(x)
    assert calls == [(1000, 2), (4000, 2)]
    r = np.linalg.norm(x, axis=1)
    np.testing.assert_allclose(psi, r - 1.0, rtol=1e-15)
    np.testing.assert_allclose(n, -x / r[:, None], atol=1e-9)


def test_signed_distance_step_is_relative_to_the_scale():
    assert SignedDistance(circle_phi, scale=1e-3).step == pytest.approx(6.055454e-9, rel=1e-6)
    # a circle of radius 1e-3: the normal is still right to 1e-8
    small = SignedDistance(lambda x: np.hypot(x[:, 0], x[:, 1]) - 1e-3, scale=1e-3)
    _, n = small.gap_and_direction([[3e-3, 4e-3]])
    np.testing.assert_allclose(n, [[-0.6, -0.8]], atol=1e-8)


# --- invariance --------------------------------------------------------------------------


def build_shapes(R, shift):
    def move(p):
        return np.asarray(p, dtype=float) @ R.T + shift

    return [
        HalfPlane(move([0.3, -0.2]), R @ np.array([1.0, 2.0])),
        Disc(move([0.5, 0.5]), 1.5),
        Polyline(move(PUNCH), radius=0.4),
        Polyline(move(GROOVE)),
    ]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rotation_and_translation_invariance(seed):
    rng = np.random.default_rng(seed)
    R = rotation(rng.uniform(0, 2 * np.pi))
    shift = rng.uniform(-2, 2, 2)
    x = rng.uniform(-3, 3, (500, 2))
    for shape, moved in zip(build_shapes(np.eye(2), 0.0), build_shapes(R, shift), strict=True):
        psi, n = shape.gap_and_direction(x)
        psi_moved, n_moved = moved.gap_and_direction(x @ R.T + shift)
        scale = 5.0  # the size of the points and the obstacles
        assert np.abs(psi_moved - psi).max() <= 1e-14 * scale, repr(shape)
        # a direction taken from coordinates of size 5 at distance |psi| carries a round-off
        # of about eps * 5 / |psi|: the closest point x + psi n moves by round-off only
        error = np.linalg.norm(n_moved - n @ R.T, axis=1)
        assert np.max(error * np.abs(psi)) <= 1e-14 * scale, repr(shape)
        assert error[np.abs(psi) > 0.1].max() <= 1e-14, repr(shape)


# --- properties ---------------------------------------------------------------------------


def boundary_samples(polyline_points, radius, spacing):
    """Dense points on the polyline's boundary (its end segments extended by 10)."""
    shape = Polyline(polyline_points, radius)
    start, end, tangent, *_ = shape._segments
    start = start.copy()
    end = end.copy()
    start[0] -= 10 * tangent[0]
    end[-1] += 10 * tangent[-1]
    parts = []
    for a, b in zip(start, end, strict=True):
        m = int(np.ceil(np.linalg.norm(b - a) / spacing)) + 1
        parts.append(a + np.linspace(0, 1, m)[:, None] * (b - a))
    for c, u1, u2 in zip(*shape._arcs, strict=True):
        a1, a2 = np.arctan2(u1[1], u1[0]), np.arctan2(u2[1], u2[0])
        a2 = a1 + np.mod(a2 - a1, 2 * np.pi)
        m = int(np.ceil(radius * (a2 - a1) / spacing)) + 1
        angle = np.linspace(a1, a2, m)
        parts.append(c + radius * np.column_stack([np.cos(angle), np.sin(angle)]))
    return np.concatenate(parts)


@pytest.mark.parametrize(("points", "radius"), [(PUNCH, 0.0), (PUNCH, 0.7), (GROOVE, 0.3)])
def test_polyline_distance_matches_a_dense_sampling_of_its_boundary(points, radius):
    spacing = 1e-3
    samples = boundary_samples(points, radius, spacing)
    x = np.random.default_rng(3).uniform(-3, 3, (300, 2))
    psi, _ = Polyline(points, radius).gap_and_direction(x)
    nearest = np.min(np.linalg.norm(x[:, None, :] - samples[None, :, :], axis=2), axis=1)
    assert np.all(nearest >= np.abs(psi) - 1e-12)
    assert np.all(nearest <= np.abs(psi) + spacing)


coordinate = st.floats(-4, 4, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(
    x=st.lists(st.tuples(coordinate, coordinate), min_size=2, max_size=20),
    radius=st.sampled_from([0.0, 0.3, 0.9]),
    which=st.sampled_from(["disc", "punch", "groove"]),
)
def test_foot_lies_on_the_boundary_and_psi_is_1_lipschitz(x, radius, which):
    """Outside a convex obstacle (the disc, the punch) the closest point is unique and
    ``x + psi n`` is on the boundary; the groove has ties outside (its mouth, the bisectors of
    its inner corners) where the mean direction misses the boundary, so there only the
    Lipschitz bound is checked."""
    x = np.array(x)
    if which == "disc":
        shape = Disc([0.2, -0.3], 1.0 + radius)
        x = x[np.linalg.norm(x - shape.center, axis=1) > 1e-6]
    else:
        shape = Polyline(PUNCH if which == "punch" else GROOVE, radius=min(radius, 0.5))
    psi, n = shape.gap_and_direction(x)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-15)
    outside = psi > 0
    if which != "groove" and outside.any():
        foot = x[outside] + psi[outside, None] * n[outside]
        foot_psi, _ = shape.gap_and_direction(foot)
        assert np.abs(foot_psi).max() <= 1e-13
        if which == "disc":
            np.testing.assert_allclose(np.linalg.norm(foot - shape.center, axis=1), 1.0 + radius)
    difference = np.abs(psi[:, None] - psi[None, :])
    distance = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=2)
    assert np.all(difference <= distance * (1 + 1e-12) + 1e-14)


def test_wavy_polyline_against_a_segment_loop_and_the_chord_heights():
    """100 segments with sharp convex and reflex corners: |psi| equals the distance to the
    nearest segment from a plain loop (away from the end rays) and psi > 0 exactly below the
    polyline (the obstacle is on the left of the walk from left to right)."""
    s = np.linspace(0, 2 * np.pi, 101)
    points = np.column_stack([s, 0.3 * np.sin(3 * s)])
    x = np.random.default_rng(5).uniform([1, -1], [5, 1], (5000, 2))
    psi, n = Polyline(points).gap_and_direction(x)
    nearest = np.full(len(x), np.inf)
    for a, b in zip(points[:-1], points[1:], strict=True):
        t = np.clip((x - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
        nearest = np.minimum(nearest, np.linalg.norm(a + t[:, None] * (b - a) - x, axis=1))
    np.testing.assert_allclose(np.abs(psi), nearest, rtol=1e-13, atol=1e-15)
    below = x[:, 1] < np.interp(x[:, 0], points[:, 0], points[:, 1])
    np.testing.assert_array_equal(psi > 0, below)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-15)


def test_a_tangent_point_is_one_candidate_not_a_near_tie():
    """Just below the tangent point (1, 0.9) of the punch's right corner arc the arc and the
    wall both reach that point; counted once, the foot x + psi n lies on the arc to round-off
    (counted twice, the two nearly equal directions were averaged and missed it by 3.5e-13)."""
    obstacle = Polyline(PUNCH, radius=0.9)
    x = np.array([[1.965558136088041, 0.8999976312686275]])
    psi, n = obstacle.gap_and_direction(x)
    foot = x + psi[:, None] * n
    assert abs(np.linalg.norm(foot - [0.1, 0.9]) - 0.9) <= 1e-15
    assert abs(obstacle.gap_and_direction(foot)[0][0]) <= 1e-15
