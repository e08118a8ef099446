"""3D contact on the iterative path: PDAS with the ``amg`` backend under the inexact active
set rule (loose solves, one confirming tight solve) equals the direct path; the rigid modes
the multigrid takes are the kernel of the system in the solver's variables; the node classes
of Section 4 on faces."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from signorini.algebra.backends.selection import SOLVERS
from signorini.algebra.inexact import KKT_RTOL
from signorini.contact.contact_set import FULL_CONTACT, NO_CONTACT, SEMI_CONTACT
from signorini.contact.rigid_modes import system_rigid_modes
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.hertz3d import hertz_3d


@cache
def _hertz():
    """A small hertz-3d case (h_contact = 0.2 R: 2547 unknowns), assembled once."""
    problem = hertz_3d(h_contact=0.2)
    return problem, assemble(problem, problem.mesh)


@cache
def _direct():
    problem, assembled = _hertz()
    return solve(problem, assembled=assembled, solver=SOLVERS["scipy"])


def test_rigid_modes_are_the_kernel_in_the_solvers_variables():
    """Six modes ỹ = P⁻¹ Q⁻¹ r (frames at the contact and roller nodes, then the transformed
    face basis): K̃ ỹ = 0 to round-off before the held DOFs are fixed."""
    _, assembled = _hertz()
    modes = system_rigid_modes(assembled)
    assert modes.shape == (assembled.space.n_dofs, 6) and np.linalg.matrix_rank(modes) == 6
    K = assembled.K
    assert np.abs(K @ modes).max() <= 1e-13 * abs(K).max() * np.abs(modes).max()


def test_amg_path_gives_the_direct_active_set_and_displacement():
    problem, assembled = _hertz()
    direct = _direct()
    amg = solve(problem, assembled=assembled, solver=SOLVERS["amg"])
    assert amg.report.backend == "amg" and sum(amg.report.linear_iterations) > 0
    assert direct.active.sum() >= 4 and np.array_equal(amg.active, direct.active)
    # the inexact rule: the loose iteration's set confirmed by one more, tight, solve
    assert amg.report.iterations >= direct.report.iterations + 1
    assert amg.report.kkt.max <= KKT_RTOL
    scale = np.abs(direct.u).max()
    np.testing.assert_allclose(amg.u, direct.u, rtol=0, atol=1e-9 * scale)
    force = np.abs(direct.contact_force).max()
    np.testing.assert_allclose(amg.contact_force, direct.contact_force, rtol=0, atol=1e-8 * force)


def test_node_classes_on_faces():
    """A row is in full contact where it is active and every contact face through its node has
    all six nodes in contact, semi where active otherwise, none where inactive (paper,
    Section 4), checked face by face against the rows' active set."""
    result = _direct()
    cs = result.contact
    classes = result.classes
    assert classes.shape == (cs.n_rows,)
    assert set(np.unique(classes)) <= {NO_CONTACT, SEMI_CONTACT, FULL_CONTACT}
    gap = cs.facet_normal_gap(result.u)
    for row in range(cs.n_rows):  # a brute force over the few rows of this small case
        faces = np.flatnonzero((cs.facet_local == row).any(axis=1))
        in_contact = [
            all(result.active[j] if j >= 0 else gap[f, i] >= -1e-12 for i, j in
                enumerate(cs.facet_local[f]))
            for f in faces
        ]  # fmt: skip
        expected = (
            NO_CONTACT if not result.active[row]
            else FULL_CONTACT if all(in_contact) else SEMI_CONTACT
        )  # fmt: skip
        assert classes[row] == expected, row
    assert (classes == SEMI_CONTACT).sum() == result.active.sum()  # a small zone: all rim


def test_node_classes_of_a_block_in_full_contact():
    from contact3d_problems import DIRECT, pressed_block

    result = solve(pressed_block(np.eye(3)), solver=DIRECT)
    assert result.active.all()
    np.testing.assert_array_equal(result.classes, FULL_CONTACT)


@pytest.mark.parametrize("alpha", [0.0], ids=["a"])
def test_amg_path_with_condition_a(alpha):
    """Condition (a) (α = 0, nodal constraints at all P2 nodes) on the same path."""
    problem = hertz_3d(h_contact=0.3, face_alpha=alpha)
    direct = solve(problem, solver=SOLVERS["scipy"])
    amg = solve(problem, solver=SOLVERS["amg"])
    assert np.array_equal(amg.active, direct.active) and amg.report.kkt.max <= KKT_RTOL
    np.testing.assert_allclose(amg.u, direct.u, rtol=0, atol=1e-9 * np.abs(direct.u).max())
