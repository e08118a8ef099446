"""A user curve's normal (``ProjectedCurve(normal=...)``) on a contact part is checked where
it is evaluated: a unit vector, across the boundary (not its tangent)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle, ProjectedCurve
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError

MATERIAL = Material.from_young(10.0, 0.3)


def _radial(x: np.ndarray) -> np.ndarray:
    return x / np.hypot(x[:, 0], x[:, 1])[:, None]


def _annulus_problem(curve) -> ContactProblem:
    """The quarter annulus 1 ≤ r ≤ 2 pushed out radially by 0.02 at r = 1 against an obstacle
    0.005 outside r = 2 (the outer arc carries ``curve``)."""
    base = rectangle(1.0, 2.0, 0.0, np.pi / 2, nx=4, ny=8)
    r, t = base.points[:, 0], base.points[:, 1]
    radius = lambda x: np.hypot(x[:, 0], x[:, 1])  # noqa: E731
    mesh = Mesh.from_arrays(
        np.column_stack([r * np.cos(t), r * np.sin(t)]),
        base.cells,
        {
            "inner": lambda x: radius(x) < 1.1,
            "outer": lambda x: radius(x) > 1.9,
            "sides": lambda x: (np.abs(x[:, 0]) < 1e-9) | (np.abs(x[:, 1]) < 1e-9),
        },
    )
    mesh = mesh.with_curve("inner", Circle((0, 0), 1.0)).with_curve("outer", curve)
    return ContactProblem(
        mesh,
        MATERIAL,
        {
            "inner": Dirichlet(lambda x: 0.02 * _radial(x)),
            "outer": Contact(gap=0.005),
            "sides": Neumann(),
        },
    )


def _project(x):
    return 2.0 * _radial(x)


def test_a_correct_user_normal_gives_the_circle_s_solution():
    user = solve(_annulus_problem(ProjectedCurve(_project, _radial)))
    circle = solve(_annulus_problem(Circle((0, 0), 2.0)))
    assert user.active.sum() > 0
    assert np.abs(user.u - circle.u).max() < 1e-12 * np.abs(circle.u).max()


def test_a_user_normal_that_is_not_unit_is_refused_naming_the_part_and_point():
    problem = _annulus_problem(ProjectedCurve(_project, lambda x: 2.0 * _radial(x)))
    with pytest.raises(ProblemError) as info:
        solve(problem)
    msg = str(info.value)
    assert "contact part 'outer'" in msg and "of length 2" in msg, msg
    assert "at the point (2, 0)" in msg, msg


def test_a_user_normal_that_is_the_tangent_is_refused():
    def tangent(x):
        n = _radial(x)
        return np.column_stack([-n[:, 1], n[:, 0]])

    with pytest.raises(ProblemError) as info:
        solve(_annulus_problem(ProjectedCurve(_project, tangent)))
    msg = str(info.value)
    # the chord of the 8 edges of the quarter arc turns 5.6° from the normal at its end
    assert "contact part 'outer'" in msg and "84.4° away" in msg, msg
    assert "runs along the boundary" in msg and "node (2, 0)" in msg, msg
