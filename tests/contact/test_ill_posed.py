"""Contact data that no displacement can satisfy, refused before any level: a Dirichlet value
that pushes a node shared with a contact part into the obstacle (u_D·n > ψ there), or into a
master body held there too; an obstacle shape deep inside the body, or on its side of the
contact part."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.loop import adaptive
from signorini.mesh.bodies import union
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError, Roller
from signorini.problem.obstacles import Disc, HalfPlane, Polyline

MATERIAL = Material.from_young(10.0, 0.3)


def _held_at_left(value, bottom: Contact) -> ContactProblem:
    """The unit square: its left side moved by ``value``, its bottom on a contact part."""
    return ContactProblem(
        rectangle(nx=4, ny=4),
        MATERIAL,
        {
            "left": Dirichlet(value),
            "bottom": bottom,
            "right": Neumann(),
            "top": Neumann((0.0, -0.1)),
        },
    )


@pytest.mark.parametrize(
    "bottom",
    [Contact(), Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)))],
    ids=["gap", "shape"],
)
def test_dirichlet_value_into_the_obstacle_is_refused_before_any_level(bottom):
    # the left side pushed down by 0.1 into a foundation at gap 0: at (0, 0), u_D·n = 0.1 > ψ
    problem = _held_at_left((0.0, -0.1), bottom)
    for run in (lambda: solve(problem), lambda: next(adaptive(problem))):
        with pytest.raises(ProblemError) as info:
            run()
        msg = str(info.value)
        for text in ("(0, 0)", "'left'", "'bottom'", "u_D·n = 0.1", "ψ = 0", "by 0.1"):
            assert text in msg, msg


def test_a_varying_dirichlet_value_names_the_violating_node():
    # u_D(x) = (0, −0.2 + 0.2 y) is 0 at the top and −0.2 at the bottom; the gap is 0.05
    problem = _held_at_left(
        lambda x: np.column_stack([0.0 * x[:, 0], -0.2 + 0.2 * x[:, 1]]), Contact(gap=0.05)
    )
    with pytest.raises(ProblemError, match=r"\(0, 0\).*u_D·n = 0\.2 .*ψ = 0\.05 by 0\.15"):
        solve(problem)


@pytest.mark.parametrize("value", [(0.0, 0.1), (0.3, 0.0), (0.0, -0.05)])
def test_admissible_dirichlet_values_at_the_shared_node_are_solved(value):
    # lifted, moved along the foundation, or pushed down by exactly the gap 0.05
    result = solve(_held_at_left(value, Contact(gap=0.05)))
    un = -result.u[:, 1]  # u·n with n = (0, −1) on the bottom
    bottom = np.isclose(result.space.node_points[:, 1], 0.0)
    assert un[bottom].max() <= 0.05 * (1 + 1e-9)


def _on_foundation(bottom: Contact) -> ContactProblem:
    """The unit square held at its top, its bottom on a contact part."""
    return ContactProblem(
        rectangle(nx=4, ny=4),
        MATERIAL,
        {"top": Dirichlet((0.0, 0.0)), "bottom": bottom, "left": Neumann(), "right": Neumann()},
    )


@pytest.mark.parametrize("depth", [0.4, 0.5, 2.0])
def test_an_obstacle_deep_inside_the_body_is_refused(depth):
    # the foundation's surface at y = depth inside the unit square (diagonal √2; the bound
    # is 0.25 √2 = 0.354): the linearised constraint would pull the bottom up by `depth`
    problem = _on_foundation(Contact(obstacle=HalfPlane((0.0, depth), (0.0, 1.0))))
    with pytest.raises(ProblemError) as info:
        solve(problem)
    msg = str(info.value)
    assert f"contact part 'bottom' starts {depth:g} deep" in msg, msg
    assert "move the body out by at most 0 " in msg, msg
    assert "size 1.41421" in msg and "0.25" in msg


def test_a_deep_overlap_that_the_dirichlet_data_move_out_of_is_solved():
    # the same foundation 0.5 deep, the top moved up by 0.45: the body is lifted out of it,
    # the bottom ends on the surface y = 0.5 with little strain
    problem = ContactProblem(
        rectangle(nx=4, ny=4),
        MATERIAL,
        {
            "top": Dirichlet((0.0, 0.45)),
            "bottom": Contact(obstacle=HalfPlane((0.0, 0.5), (0.0, 1.0))),
            "left": Neumann(),
            "right": Neumann(),
        },
    )
    result = solve(problem)
    bottom = np.isclose(result.space.node_points[:, 1], 0.0)
    assert np.abs(result.u[bottom, 1] - 0.5).max() < 1e-12


@pytest.mark.parametrize(
    ("depth", "shape"), [(0.0, True), (0.2, True), (0.35, True), (0.2, False), (2.0, False)]
)
def test_a_small_initial_overlap_or_a_gap_function_is_solved(depth, shape):
    # shapes up to a quarter of the diagonal (Example 6.2 of the paper starts 0.2 deep), gap
    # functions at any depth (the linear model's own data): the bottom is pushed out to the
    # foundation's surface, u_y = depth on the bottom to round-off
    obstacle = HalfPlane((0.0, depth), (0.0, 1.0))
    result = solve(_on_foundation(Contact(obstacle=obstacle) if shape else Contact(gap=-depth)))
    bottom = np.isclose(result.space.node_points[:, 1], 0.0)
    assert np.abs(-result.u[bottom, 1] + depth).max() <= 1e-10 * max(depth, 1e-300) or (
        depth == 0.0 and np.abs(result.u).max() == 0.0
    )


def _pinched(tilt: float) -> ContactProblem:
    """The block (0, 2) × (0, 1) held at its top; the bottom's left half "a" above a floor
    (direction (0, −1)), its right half "b" under an obstacle at y ≥ 0.2 tilted by ``tilt``
    (direction about (0, 1)): at (1, 0) the two directions are (nearly) opposite."""
    tol = 1e-9
    m = rectangle(0.0, 2.0, 0.0, 1.0, nx=4, ny=2)
    on_bottom = lambda x: np.abs(x[:, 1]) < tol  # noqa: E731
    mesh = Mesh.from_arrays(
        m.points,
        m.cells,
        {
            "a": lambda x: on_bottom(x) & (x[:, 0] <= 1 + tol),
            "b": lambda x: on_bottom(x) & (x[:, 0] >= 1 - tol),
            "top": lambda x: np.abs(x[:, 1] - 1) < tol,
            "sides": lambda x: (np.abs(x[:, 0]) < tol) | (np.abs(x[:, 0] - 2) < tol),
        },
    )
    above = HalfPlane((1.0, 0.2), (np.sin(tilt), -np.cos(tilt)))
    return ContactProblem(
        mesh,
        MATERIAL,
        {
            "top": Dirichlet((0.0, -0.01)),
            "sides": Neumann(),
            "a": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
            "b": Contact(obstacle=above),
        },
    )


@pytest.mark.parametrize("tilt", [0.0, 0.005])
def test_opposite_directions_at_a_node_are_refused_naming_both_parts(tilt):
    # before: numpy.linalg.LinAlgError "Singular matrix" from the corner frame (or, 0.005 rad
    # from opposite, a frame with condition number ~1e5 squared)
    with pytest.raises(ProblemError) as info:
        solve(_pinched(tilt))
    msg = str(info.value)
    assert "node at (1, 0) lies on contact parts 'a' and 'b'" in msg, msg
    assert "opposite" in msg, msg


def test_a_corner_far_from_opposite_is_solved():
    # tilted by 0.1 rad from opposite: a (sharp) corner, two constraints solved exactly
    result = solve(_pinched(0.1))
    assert result.report.kkt.max < 1e-10


def _floated(bottom: Contact) -> ContactProblem:
    """The unit square under force control: held sideways by a roller on its left, pressed
    down by a traction on its top, held vertically by its bottom's contact alone."""
    return ContactProblem(
        rectangle(nx=2, ny=2),
        MATERIAL,
        {
            "top": Neumann((0.0, -0.1)),
            "right": Neumann(),
            "left": Roller(),
            "bottom": bottom,
        },
    )


def test_a_reversed_half_plane_normal_under_force_control_is_refused_by_direction():
    # the floor at y = −0.5 with its normal pointing down, away from the body: the whole
    # square is inside the obstacle. Before: NumPy's "zero-size array to reduction operation
    # maximum" from the overlap check, which has no Dirichlet node to read
    problem = _floated(Contact(obstacle=HalfPlane((0.0, -0.5), (0.0, -1.0))))
    with pytest.raises(
        ProblemError,
        match=r"HalfPlane.*contact part 'bottom' lies on the body's side.*ψ = -0\.5.*"
        r"n_z = \(0, 1\).*points into the body, n_z·n = -1 .*n = \(0, -1\)",
    ):
        solve(problem)


def test_a_deep_overlap_under_force_control_is_refused_by_depth():
    # the floor 0.5 deep, its normal right: no Dirichlet node moves the body out of it
    problem = _floated(Contact(obstacle=HalfPlane((0.0, 0.5), (0.0, 1.0))))
    with pytest.raises(
        ProblemError, match=r"'bottom' starts 0\.5 deep .*move the body out by at most 0 "
    ):
        solve(problem)


@pytest.mark.parametrize("centre", [(0.5, 0.1), (0.5, 0.01), (0.3, 0.2)])
def test_a_disc_centred_inside_the_body_is_refused_by_direction(centre):
    # overlaps of 0.2, 0.29 and 0.1, all below the depth bound 0.354: before, the bottom was
    # pulled down through the disc (u_y = −0.2 at (0.5, 0)), its directions n_z = (0, 1)
    problem = _on_foundation(Contact(obstacle=Disc(centre, 0.3)))
    with pytest.raises(
        ProblemError, match=r"Disc.*'bottom' lies on the body's side.*points into the body"
    ):
        solve(problem)
    with pytest.raises(ProblemError, match="lies on the body's side"):
        next(adaptive(problem))


#: a punch below the square, x in [0.2, 0.8], y <= 0.1 (walked with the obstacle on the left)
PUNCH = [(0.8, -1.0), (0.8, 0.1), (0.2, 0.1), (0.2, -1.0)]


@pytest.mark.parametrize(
    "obstacle",
    [
        Disc((0.5, -0.25), 0.3),  # a cylinder pressed 0.05 into the bottom from below
        Disc((0.5, -0.3), 0.3),  # touching
        Polyline(PUNCH),  # a punch from below, 0.1 into the bottom
        Polyline(PUNCH, radius=0.15),
        HalfPlane((0.0, 0.2), (0.1, 1.0)),  # a tilted floor, 0.2 deep at most
    ],
    ids=["disc-in", "disc-touching", "punch-sharp", "punch-rounded", "tilted-floor"],
)
def test_an_obstacle_outside_the_body_overlapping_it_is_solved(obstacle):
    # directions out of the body, or along it beside the punch's side walls (n_z·n = 0)
    result = solve(_on_foundation(Contact(obstacle=obstacle)))
    assert result.report.kkt.max < 1e-8


def _stacked(upper_left, lower_left) -> ContactProblem:
    """Two blocks: "upper" on [0, 1] × [1, 2] on "lower" on [0, 1] × [0, 1] (non-matching
    edges), the lower's bottom held, both left sides given, the upper's bottom the slave."""
    upper = rectangle(0.0, 1.0, 1.0, 2.0, 4, 4, pattern="right")
    lower = rectangle(0.0, 1.0, 0.0, 1.0, 5, 5, pattern="right")
    return ContactProblem(
        union({"upper": upper, "lower": lower}),
        MATERIAL,
        {
            "upper.top": Neumann(),
            "upper.left": Dirichlet(upper_left),
            "upper.right": Neumann(),
            "upper.bottom": Contact(master="lower.top"),
            "lower.bottom": Dirichlet(),
            "lower.left": lower_left,
            "lower.right": Neumann(),
        },
    )


def test_dirichlet_value_into_the_master_is_refused_as_into_an_obstacle():
    # the upper's left side pushed down by 0.1 onto the lower's held corner (0, 1): as the
    # one body's check refuses it against an obstacle. Before: accepted (no check on a slave)
    problem = _stacked((0.0, -0.1), Dirichlet((0.0, 0.0)))
    with pytest.raises(ProblemError) as info:
        solve(problem)
    msg = str(info.value)
    for text in (
        "node at (0, 1) lies on Dirichlet part 'upper.left' and contact part 'upper.bottom'",
        "relative to the node of master part 'lower.top' facing it at (0, 1), held at u_D = "
        "(0, 0), u_D = (0, -0.1) moves it by u_D·n = 0.1",
        "beyond the gap ψ = 0 by 0.1",
    ):
        assert text in msg, msg


@pytest.mark.parametrize(
    ("upper_left", "lower_left"),
    [
        ((0.0, 0.1), Dirichlet((0.0, 0.0))),  # lifted off the master's held corner
        ((0.0, -0.1), Dirichlet((0.0, -0.1))),  # both corners moved down together
        ((0.0, -0.01), Neumann()),  # the master's corner is free to give way
    ],
    ids=["lifted", "together", "master-free"],
)
def test_admissible_dirichlet_values_beside_a_slave_are_solved(upper_left, lower_left):
    result = solve(_stacked(upper_left, lower_left))
    assert result.report.kkt.max < 1e-8
