"""The rigid motions in a system's unknowns (signorini.contact.rigid_modes): the assembled
matrix, before its Dirichlet DOFs are fixed, annihilates them, in node frames and in the
relative displacement of two bodies; back in Cartesian displacements they are each body's
translations and rotation."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.algebra import superlu_solver
from signorini.algebra.sparse import abs_matvec
from signorini.contact import assemble, solve
from signorini.contact.node_frames import to_cartesian
from signorini.contact.rigid_modes import system_rigid_modes
from signorini.contact.two_body import physical
from signorini.examples import example_6_2, example_6_2_tresca, two_cylinders
from signorini.mesh.bodies import body_of_cells


@pytest.mark.parametrize("make,bodies", [(example_6_2, 1), (two_cylinders, 2)])
def test_the_assembled_matrix_annihilates_the_rigid_motions_of_each_body(make, bodies):
    problem = make()
    a = assemble(problem, problem.mesh)
    modes = system_rigid_modes(a)
    assert modes.shape == (a.K.shape[0], 3 * bodies)
    assert a.frame_nodes.size >= 5  # the contact nodes are in frames
    for k in range(modes.shape[1]):
        defect = np.abs(a.K @ modes[:, k]).max() / abs_matvec(a.K, modes[:, k]).max()
        assert defect < 1e-13, f"mode {k}: max|K m| / max|K||m| = {defect:.1e}"
    # the rows in a frame differ from the Cartesian motion: the frames are applied
    cartesian = modes.copy()
    frame_dofs = np.concatenate([2 * a.frame_nodes, 2 * a.frame_nodes + 1])
    space = a.space
    cell_body = body_of_cells(space.mesh)
    body = np.zeros(space.n_nodes, dtype=int)
    body[space.cell_nodes.ravel()] = np.repeat(cell_body, space.cell_nodes.shape[1])
    points = space.node_points
    for k in range(modes.shape[1]):
        u = physical(
            to_cartesian(modes[:, k], a.frame_nodes, a.frames).reshape(-1, 2), a.contact.transfer
        )
        mine = body == k // 3
        centre = points[mine].mean(axis=0)
        expected = np.zeros_like(u)
        if k % 3 < 2:
            expected[mine, k % 3] = 1.0
        else:
            expected[mine] = np.column_stack(
                [-(points[mine, 1] - centre[1]), points[mine, 0] - centre[0]]
            )
        assert np.abs(u - expected).max() < 1e-12
        cartesian[:, k] = expected.ravel()
    # Example 6.2's contact normal is (1, 0): its frames are the identity; the cylinders'
    # normals turn along the arc, and their rows differ from the Cartesian motion
    turned = np.abs(cartesian[frame_dofs] - modes[frame_dofs]).max()
    assert turned == 0 if bodies == 1 else turned > 0.1


@pytest.mark.parametrize("make", [two_cylinders, example_6_2_tresca])
def test_the_contact_layer_offers_the_rigid_motions_to_the_factory(make):
    """The request of the frictionless (two cylinders) and the frictional (Tresca) path
    carries the rigid motions of the assembled system, computed when the backend asks."""
    requests = []

    def factory(request):
        requests.append(request)
        return superlu_solver(request)

    problem = make()
    solve(problem, solver=factory)
    assert len(requests) == 1 and requests[0].symmetric
    a = assemble(problem, problem.mesh)
    np.testing.assert_array_equal(requests[0].rigid_modes(), system_rigid_modes(a))


@pytest.mark.parametrize("alpha", [None, 0.0])
def test_on_3d_contact_faces_the_modes_are_the_solver_variables_of_the_rigid_motions(alpha):
    """hertz-3d (contact on the sphere, frames and the transformed face basis): ``R ỹ`` is the
    Cartesian motion (``R`` the system's change of unknowns) and ``Rᵀ K R`` annihilates ``ỹ``,
    for condition (b) (α = 1/5) and (a) (α = 0, frames only)."""
    from signorini.examples import hertz_3d
    from signorini.problem.rigid3d import rigid_modes_3d

    problem = hertz_3d(face_alpha=alpha, h_contact=0.2)
    a = assemble(problem, problem.mesh)
    modes = system_rigid_modes(a)
    assert modes.shape == (a.K.shape[0], 6) and a.frame_nodes.size >= 10
    points = a.space.node_points
    expected = rigid_modes_3d(points - points.mean(axis=0))  # (n_nodes, 3, 6)
    back = a.contact.operator @ modes
    np.testing.assert_allclose(back, expected.reshape(-1, 6), atol=1e-12)
    for k in range(6):
        defect = np.abs(a.K @ modes[:, k]).max() / abs_matvec(a.K, modes[:, k]).max()
        assert defect < 1e-12, f"mode {k}: max|K m| / max|K||m| = {defect:.1e}"
    # the frames turn with the sphere's normals: the rows differ from the Cartesian motion
    assert np.abs(modes - expected.reshape(-1, 6)).max() > 0.05
