"""The 3D Hertz example under a prescribed total force (force control): the eighth of a ball
held along z by its contact alone (docs/method.md, *Three dimensions: contact on faces*,
"Hertz in 3D under a prescribed force")."""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from contact3d_problems import DIRECT
from scipy.spatial import cKDTree

from signorini.contact.solution import solve
from signorini.examples import EXAMPLES
from signorini.examples.hertz3d import (
    FORCE_3D,
    hertz_3d,
    hertz_3d_force,
    hertz_3d_metrics,
    hertz_3d_solution,
    prescribed_force,
    top_area,
)
from signorini.fem.material import Material
from signorini.problem import Contact, Dirichlet
from signorini.problem.fields import ProblemError
from signorini.problem.obstacles3d import HalfSpace

VARIANTS = {"b": None, "a": 0.0}
H = 0.2  # 2 306 unknowns


@cache
def pressed(variant: str, force: float = FORCE_3D):
    return solve(hertz_3d(force=force, h_contact=H, face_alpha=VARIANTS[variant]), solver=DIRECT)


def test_hertz_force_inverts_the_contact_radius():
    material = Material.from_young(3.0, 0.2)
    force = hertz_3d_force(0.07, 1.3, material)
    assert hertz_3d_solution(force, 1.3, material)[0] == pytest.approx(0.07, rel=1e-14)
    a, _ = hertz_3d_solution(FORCE_3D, 1.0, Material.from_young(1.0, 0.3))
    assert a == pytest.approx(0.1, rel=1e-14)  # the built-in's a / R


def test_the_top_carries_a_quarter_of_the_force_on_the_meshed_top():
    problem = hertz_3d(force=2.0e-3, h_contact=0.3)
    area = top_area(problem.mesh)
    assert 0.0 < np.pi / 4 - area < 2e-4  # the rim's faces are curved, inside the circle
    assert problem.conditions["z1"].traction == (0.0, 0.0, -2.0e-3 / (4 * area))
    assert prescribed_force(problem) == pytest.approx(2.0e-3, rel=1e-15)
    assert prescribed_force(hertz_3d(h_contact=0.3)) is None  # displacement control
    assert problem.rigid_motions.shape == (1, 6)  # the translation along z, held by contact


@pytest.mark.parametrize("variant", ["b", "a"])
def test_the_contact_force_equals_the_prescribed_force(variant):
    r = pressed(variant)
    assert r.report.kkt.max <= 1e-10
    m = hertz_3d_metrics(r)
    assert m["force"] == pytest.approx(FORCE_3D, rel=1e-15)
    assert 4 * r.total_contact_force == pytest.approx(FORCE_3D, rel=1e-10)
    assert abs(m["force_rel_error"]) <= 1e-10
    # the errors are against Hertz for the prescribed P, not the measured one
    a, p0 = hertz_3d_solution(FORCE_3D, 1.0, r.problem.material)
    assert m["a_rel_error"] == m["a"] / a - 1.0 and m["p0_rel_error"] == m["p0"] / p0 - 1.0


def _interpolant(points: np.ndarray, values: np.ndarray):
    """``g(x)``: ``values`` at the nodes ``points`` it is evaluated at (refused elsewhere)."""
    tree = cKDTree(points)

    def g(x):
        distance, k = tree.query(np.asarray(x).reshape(-1, 3))
        assert distance.max() <= 1e-12
        return values[k].reshape(np.shape(x))

    return g


@pytest.mark.parametrize("variant", ["b", "a"])
def test_force_control_is_displacement_control_of_its_own_top_up_to_a_translation(variant):
    """The force-controlled solution u_F, its top's displacement shifted by −d e_z prescribed
    on z1 and the plane moved to z = −d, is the displacement-controlled solution there: u_D =
    u_F − d e_z at every node, with the same active set and contact forces (the problem of
    u_D is coercive, so u_F being its solution checks the equilibrium, contact conditions and
    the translation that force control found)."""
    r = pressed(variant)
    d = 0.3 * float(np.abs(r.u[:, 2]).max())
    top = r.space.part_nodes(["z1"])
    shifted = r.u[top] - [0.0, 0.0, d]
    problem = r.problem
    conditions = dict(problem.conditions)
    conditions["z1"] = Dirichlet(_interpolant(r.space.node_points[top], shifted))
    plane = HalfSpace([0.0, 0.0, -d], [0.0, 0.0, 1.0])
    conditions["sphere"] = Contact(obstacle=plane, face_alpha=VARIANTS[variant])
    held = solve(replace(problem, conditions=conditions), solver=DIRECT)
    assert held.problem.rigid_motions.shape[0] == 0
    scale = np.abs(r.u).max()
    assert np.abs(held.u - (r.u - [0.0, 0.0, d])).max() <= 1e-9 * scale
    # the rim's rows (on z1, now held) are left out; the rest are the same rows
    rows = np.isin(r.contact.node, held.contact.node)
    assert (~rows).sum() > 0 and not r.active[~rows].any() and not r.contact_force[~rows].any()
    np.testing.assert_array_equal(held.contact.node, r.contact.node[rows])
    np.testing.assert_array_equal(held.active, r.active[rows])
    assert r.active.sum() > 3
    np.testing.assert_allclose(
        held.contact_force, r.contact_force[rows], rtol=0, atol=1e-9 * FORCE_3D
    )


def test_a_force_that_pulls_the_ball_off_is_refused_naming_the_translation():
    with pytest.raises(
        ProblemError, match=r"pulls the body away.*translation along \(0\.0, 0\.0, 1\.0\)"
    ):
        solve(hertz_3d(force=-FORCE_3D, h_contact=0.3), solver=DIRECT)


@pytest.mark.parametrize("force", [0.0, float("nan"), float("inf"), -float("inf"), "1", True])
def test_a_force_not_finite_or_zero_is_refused_naming_force(force):
    with pytest.raises(ValueError, match=r"hertz_3d: force must be"):
        hertz_3d(force=force, h_contact=0.3)
    with pytest.raises(ValueError, match=r"depth .* or force, not both"):
        hertz_3d(depth=0.01, force=FORCE_3D, h_contact=0.3)


def test_the_built_in_is_force_controlled():
    problem = EXAMPLES["hertz-3d"].problem()
    assert prescribed_force(problem) == pytest.approx(FORCE_3D, rel=1e-15)
    assert problem.rigid_motions.shape == (1, 6)
