"""Force control in 3D: a body held along a rigid motion by its contacts alone carries the
applied force through them; a load that pulls it off is refused naming the motion
(docs/method.md, *Force control*; *Three dimensions: rollers, force control, regions*)."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import DIRECT, pressed_block, rotation

from signorini.contact.solution import solve
from signorini.problem.fields import ProblemError
from signorini.problem.rigid3d import describe_motion_3d


@pytest.mark.parametrize("rotated", [False, True], ids=["axis", "oblique"])
def test_block_on_a_plane_carries_the_applied_force(rotated):
    """The unit cube on rollers x0, y0, pressed by t = 0.1 on z1 and the body force 0.05:
    one free motion (the translation along the normal), held by the contact; the contact
    forces sum to the applied 0.15 and their resultant is the load's normal component."""
    R = rotation() if rotated else np.eye(3)
    problem = pressed_block(R)
    assert problem.rigid_motions.shape == (1, 6)
    normal = tuple(np.round(R @ [0.0, 0.0, 1.0], 6).tolist())
    normal = normal if normal[np.argmax(np.abs(normal))] > 0 else tuple(-np.array(normal) + 0.0)
    assert describe_motion_3d(problem.mesh, problem.rigid_motions[0]) == (
        f"translation along {normal}"
    )
    result = solve(problem, solver=DIRECT)
    assert result.report.kkt.max <= 1e-12
    assert result.total_contact_force == pytest.approx(0.15, rel=1e-12)
    resultant = -result.contact_force @ result.contact.direction
    np.testing.assert_allclose(resultant, R @ [0.0, 0.0, 0.15], rtol=0, atol=1e-12)
    # the body sits on the obstacle: every row active, no penetration
    assert result.active.all()


def test_the_load_that_pulls_the_block_off_is_refused_naming_the_motion():
    with pytest.raises(
        ProblemError, match=r"pulls the body away.*translation along \(0\.0, 0\.0, 1\.0\)"
    ):
        solve(pressed_block(np.eye(3), load=0.2), solver=DIRECT)
    # no load along the motion the contact holds one way only: the position is undetermined
    with pytest.raises(ProblemError, match=r"does not press the body.*translation along"):
        solve(pressed_block(np.eye(3), load=0.05), solver=DIRECT)


def test_describe_motion_names_rotations_about_their_axis():
    problem = pressed_block(np.eye(3))
    mesh = problem.mesh  # centre (0.5, 0.5, 0.5), size 1
    rotation_z = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0])  # ω × (x − c) about e_z
    assert describe_motion_3d(mesh, rotation_z) == (
        "rotation about the axis (0.0, 0.0, 1.0) through (0.5, 0.5, 0.5)"
    )
    shifted = np.array([0.0, 0.5, 0.0, 0.0, 0.0, 1.0])  # zero on the line x = 0, y = 0.5
    assert describe_motion_3d(mesh, shifted) == (
        "rotation about the axis (0.0, 0.0, 1.0) through (0.0, 0.5, 0.5)"
    )
    assert describe_motion_3d(mesh, [0.0, 0.0, 0.3, 0.0, 0.0, 1.0]).startswith("screw motion")
