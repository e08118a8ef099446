"""A shape of one's own: a few lines subclassing the exported ``signorini.Obstacle`` give the
same discrete solution as the obstacle given by a gap function or as a built-in shape."""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini import (
    Contact,
    ContactProblem,
    Dirichlet,
    Disc,
    HalfPlane,
    Material,
    Neumann,
    Obstacle,
    rectangle,
    solve,
)


class Cylinder(Obstacle):
    """A rigid cylinder: the signed distance to its circle and the direction to its centre."""

    def __init__(self, center, radius):
        self.center, self.radius = np.asarray(center, dtype=float), float(radius)

    def _gap_and_direction(self, x):
        to_center = self.center - x
        distance = np.hypot(to_center[:, 0], to_center[:, 1])
        return distance - self.radius, to_center / distance[:, None]


class Floor(Obstacle):
    """The half-plane ``y <= -depth``."""

    def __init__(self, depth):
        self.depth = float(depth)

    def _gap_and_direction(self, x):
        return x[:, 1] + self.depth, np.tile([0.0, -1.0], (x.shape[0], 1))


def pressed_block(bottom: Contact) -> ContactProblem:
    """A block pressed down (and sideways) onto whatever ``bottom`` states."""
    return ContactProblem(
        rectangle(0.0, 2.0, 0.0, 1.0, nx=8, ny=4),
        Material.from_young(1.0, 0.3),
        {
            "left": Neumann(),
            "right": Neumann(),
            "top": Dirichlet((0.004, -0.02)),
            "bottom": bottom,
        },
    )


def assert_same_solution(a, b):
    np.testing.assert_array_equal(a.active, b.active)
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-13 * np.abs(a.u).max())
    scale = np.abs(a.contact_force).max()
    np.testing.assert_allclose(a.contact_force, b.contact_force, rtol=0, atol=1e-11 * scale)


def test_the_base_is_exported_and_asks_for_the_one_method():
    assert signorini.Obstacle is signorini.problem.Obstacle is Obstacle
    assert issubclass(Disc, Obstacle) and issubclass(HalfPlane, Obstacle)
    with pytest.raises(TypeError, match="_gap_and_direction"):
        type("Shapeless", (Obstacle,), {})()
    # the base checks the points before the shape sees them
    with pytest.raises(ValueError, match=r"x must have shape \(n, 2\)"):
        Floor(0.1).gap_and_direction(np.zeros((3, 3)))


def test_a_custom_cylinder_solves_as_the_built_in_disc():
    own = solve(pressed_block(Contact(obstacle=Cylinder((1.0, -12.5), 12.5))))
    built_in = solve(pressed_block(Contact(obstacle=Disc((1.0, -12.5), 12.5))))
    # a partial contact zone: the comparison sees both kinds of node
    assert 0 < own.active.sum() < own.active.size
    assert own.total_contact_force > 0
    assert_same_solution(own, built_in)


def test_a_custom_floor_solves_as_the_gap_function_and_the_half_plane():
    depth = 0.01
    own = solve(pressed_block(Contact(obstacle=Floor(depth))))
    by_gap = solve(pressed_block(Contact(gap=lambda x: np.full(x.shape[0], depth))))
    by_shape = solve(pressed_block(Contact(obstacle=HalfPlane((0.0, -depth), (0.0, 1.0)))))
    assert own.active.any() and own.total_contact_force > 0
    # the bottom went down by the depth where it touches the floor
    bottom = own.contact.nodes[own.active]
    np.testing.assert_allclose(own.u[bottom, 1], -depth, rtol=1e-10)
    assert_same_solution(own, by_gap)
    assert_same_solution(own, by_shape)


class Broken(Obstacle):
    """A shape whose own method divides by zero."""

    def _gap_and_direction(self, x):
        return 1 / 0


@pytest.mark.parametrize(
    ("obstacle", "message"),
    [
        (
            signorini.SignedDistance(lambda x: 1 / 0),
            r"the obstacle of contact part 'bottom': SignedDistance\(phi=<lambda>.*\): phi\(x\) "
            r"raised ZeroDivisionError: division by zero \(called with points x of shape \(",
        ),
        (
            Broken(),
            r"the obstacle <.*Broken.*> of contact part 'bottom' raised ZeroDivisionError in "
            r"gap_and_direction: division by zero",
        ),
    ],
    ids=["signed-distance", "own-shape"],
)
def test_an_obstacle_that_raises_is_named_with_its_part_and_error(obstacle, message):
    # before: a bare ZeroDivisionError from inside the contact set
    with pytest.raises(signorini.ProblemError, match=message) as info:
        solve(pressed_block(Contact(obstacle=obstacle)))
    cause = info.value.__cause__
    while cause is not None and not isinstance(cause, ZeroDivisionError):
        cause = cause.__cause__
    assert isinstance(cause, ZeroDivisionError)


class Returns(Obstacle):
    """A shape that returns what it is given, whatever the points."""

    def __init__(self, answer):
        self.answer = answer

    def __repr__(self):
        return "Returns()"

    def _gap_and_direction(self, x):
        return self.answer(x)


@pytest.mark.parametrize(
    ("answer", "message"),
    [
        (
            lambda x: (x[:, 1], np.tile([0.0, -1.0], (len(x) + 1, 1))),
            r"must return psi of shape \(\d+,\) and n of shape \(\d+, 2\) for x of shape",
        ),
        (
            lambda x: (x[:, 1] / 0.0, np.tile([0.0, -1.0], (len(x), 1))),
            r"is not finite at x\[0\] = \[0\.0, 0\.0\] \(psi nan",
        ),
        (
            lambda x: (x[:, 1], np.tile([0.0, -2.0], (len(x), 1))),
            r"must return unit directions n; at x\[0\] = .* it returned \[0\.0, -2\.0\] of "
            r"length 2",
        ),
    ],
    ids=["shape", "nan", "not-unit"],
)
def test_a_shape_of_ones_own_that_answers_wrongly_is_refused_naming_it(answer, message):
    # before: a wrong shape or NaN went on into the contact set (NumPy's broadcasting errors,
    # or NaN gaps), a direction of length 2 halved the constraint silently
    with (
        np.errstate(divide="ignore", invalid="ignore"),
        pytest.raises(
            signorini.ProblemError,
            match=r"the obstacle of contact part 'bottom': Returns\(\): gap_and_direction.*"
            + message,
        ),
    ):
        solve(pressed_block(Contact(obstacle=Returns(answer))))
