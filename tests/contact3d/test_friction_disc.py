"""The disc law of 3D friction (docs/method.md, *Friction in three dimensions*): the
semismooth Newton method of :mod:`signorini.algebra.friction.disc` on the system of a
tetrahedral block pressed and sheared onto a half-space, against an independent dual solve
of the Tresca problem, KKT residuals of both laws, and the invariance of the answer under a
rotation about the normal."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from contact3d.independent_tresca import solve_tresca
from contact3d_problems import MATERIAL

from signorini.algebra.friction.disc import check_disc, solve_disc
from signorini.algebra.friction.result import SLIP, STICK
from signorini.contact.system import assemble
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.problem.conditions import Contact, Dirichlet, Neumann
from signorini.problem.fields import ProblemError
from signorini.problem.friction_laws import Coulomb, Tresca
from signorini.problem.obstacles3d import HalfSpace
from signorini.problem.problem import ContactProblem


def _sheared_block(angle: float = 0.0, shift=(0.004, 0.002)):
    """box(2) rotated by ``angle`` about z, its top z1 moved by ``(shift, −0.01)`` (rotated
    too), its bottom z0 on the half-space z ≥ 0 (condition (a)); the assembled system with
    contact and the Cartesian one with z0 traction-free."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    base = box(2, 2, 2)
    parts = {p: base.facets[base.part_facets(p)] for p in base.part_names}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    move = R @ np.array([shift[0], shift[1], -0.01])
    cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
    cond.update(
        z1=Dirichlet(tuple(move.tolist())),
        z0=Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), face_alpha=0.0),
    )
    problem = ContactProblem(mesh, MATERIAL, cond)
    plain = replace(problem, conditions={**cond, "z0": Neumann((0.0, 0.0, 0.0))})
    return assemble(problem, mesh), assemble(plain, mesh), R


def _frames(cs) -> np.ndarray:
    """``(m, 3, 3)`` each row's node frame ``[n t_1 t_2]`` (columns)."""
    return cs.frames[np.searchsorted(cs.frame_nodes, cs.node)]


def _disc(assembled, law, weight, reference=None):
    cs = assembled.contact
    tangent = cs.dof[:, None] + np.array([1, 2])
    return check_disc(
        assembled.K,
        assembled.F,
        cs.dof,
        tangent,
        cs.gap,
        assembled.dirichlet,
        assembled.dirichlet_values,
        laws=law,
        weight=weight,
        reference=reference,
    )


def _data(assembled, R=None):
    """A nodal Tresca bound varying along Γ_C and a Cartesian reference slip ``(m, 3)`` in
    the plane (both given in the unrotated coordinates)."""
    R = np.eye(3) if R is None else R
    points = assembled.space.node_points[assembled.contact.node] @ R
    bound = 1e-4 * (1.0 + points[:, 0] + 0.5 * points[:, 1])
    rho = np.zeros((bound.size, 3))
    rho[:, 0], rho[:, 1] = 1e-4 * points[:, 1], -5e-5
    return bound, rho @ R.T


def test_tresca_equals_an_independent_dual_solve_and_meets_kkt():
    assembled, plain, _ = _sheared_block()
    cs = assembled.contact
    assert np.all(cs.dof % 3 == 0)  # the frame [n t1 t2]: normal DOF first
    bound, rho = _data(assembled)
    reference = np.einsum("mci,mc->mi", _frames(cs)[:, :, 1:], rho)
    result = solve_disc(_disc(assembled, Tresca(1.0), bound, reference))
    assert result.kkt.max <= 1e-12
    assert {STICK, SLIP} <= set(result.state.tolist())  # both branches in play
    other = solve_tresca(
        plain.K, plain.F, plain.dirichlet, plain.dirichlet_values, cs.node, cs.direction,
        cs.psi, bound, rho,
    )  # fmt: skip
    u = cs.displacement(result.x)
    assert np.abs(u - other.u).max() <= 1e-8 * np.abs(other.u).max()
    force = np.einsum(
        "mci,mi->mc", _frames(cs), np.c_[result.normal_force, result.tangential_force]
    )
    assert np.abs(force - other.force).max() <= 1e-8 * np.abs(other.force).max()


def test_coulomb_meets_both_laws_with_stick_slip_and_separation():
    assembled, _, _ = _sheared_block()
    result = solve_disc(_disc(assembled, Coulomb(0.3), 0.3))
    assert result.kkt.max <= 1e-12
    slip = result.state == SLIP
    assert slip.any() and (result.state == STICK).any()
    lam_n, lam_t = result.normal_force, result.tangential_force
    # at slipping nodes ‖Λ_t‖ = F Λ_n and the slip is along Λ_t
    norm = np.linalg.norm(lam_t[slip], axis=1)
    np.testing.assert_allclose(norm, 0.3 * lam_n[slip], rtol=1e-10)
    cs = assembled.contact
    slide = result.x[cs.dof[slip, None] + np.array([1, 2])]
    cosine = np.sum(slide * lam_t[slip], 1) / (np.linalg.norm(slide, axis=1) * norm)
    assert cosine.min() >= 1 - 1e-10


@pytest.mark.parametrize("law, weight", [(Tresca(1.0), None), (Coulomb(0.3), 0.3)])
def test_a_rotation_about_the_normal_rotates_the_answer(law, weight):
    """The block turned by 0.7 rad about z (its load too): the node frames' tangents differ,
    the disc law is isotropic, so the Cartesian answers are the rotated ones."""
    answers = []
    for angle in (0.0, 0.7):
        assembled, _, R = _sheared_block(angle)
        w = _data(assembled, R)[0] if weight is None else weight
        result = solve_disc(_disc(assembled, law, w))
        u = assembled.contact.displacement(result.x).reshape(-1, 3)
        answers.append((u @ R, result.state))  # back in the unrotated coordinates
    (u0, s0), (u1, s1) = answers
    np.testing.assert_array_equal(s0, s1)
    assert np.abs(u1 - u0).max() <= 1e-10 * np.abs(u0).max()


def test_bad_tangent_and_reference_are_named():
    assembled, _, _ = _sheared_block()
    cs = assembled.contact
    with pytest.raises(ValueError, match="tangent must be"):
        check_disc(
            assembled.K, assembled.F, cs.dof, cs.dof + 1, cs.gap, laws=Tresca(1.0), weight=1.0
        )
    with pytest.raises(ValueError, match="reference"):
        _disc(assembled, Tresca(1.0), 1.0, reference=np.zeros(cs.dof.size))
    with pytest.raises(ValueError, match="max_iter"):
        solve_disc(_disc(assembled, Tresca(1.0), 1.0), max_iter=0)


def _block_path(law, shifts=(0.0, 0.004)):
    """box(2) pressed (step 1), then its top moved along x (step 2), through ``solve``."""
    from signorini.contact.solution import solve

    mesh = box(2, 2, 2)
    results = []
    for shift in shifts:  # a loop over load steps
        cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
        cond.update(
            z1=Dirichlet((shift, 0.0, -0.01)),
            z0=Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), friction=law),
        )
        problem = ContactProblem(mesh, MATERIAL, cond)
        results.append(solve(problem, mesh, previous=results[-1] if results else None))
    return results


@pytest.mark.parametrize("law", [Tresca(1e-3), Coulomb(0.3)])
def test_a_load_path_through_solve_meets_both_laws_on_the_slip_increment(law):
    press, pull = _block_path(law)
    for r in (press, pull):
        assert r.report.kkt.max <= 1e-12
        assert r.tangential_force.shape == (r.contact.n_rows, 2)
    # the pull's reference is the press's tangential displacement in the solver's variables
    cs = pull.contact
    y = cs.unknowns(press.u.ravel())
    np.testing.assert_array_equal(pull.tangential_reference, y[cs.friction.tangent])
    # pulled along +x: Λ_t points along the slip, +x (the obstacle acts on the body with −Λ)
    frames = _frames(cs)
    force = np.einsum("kci,ki->kc", frames[:, :, 1:], pull.tangential_force)
    assert force[:, 0].sum() > 0


def _midpoint_weights(mesh, part: str, points: np.ndarray, s: float) -> np.ndarray:
    """``∫ s φ_z`` of the plain P2 basis on the flat faces of ``part`` at ``points (m, 3)``,
    written out: ``s |T| / 3`` from each face at its edge midpoints, 0 at its vertices."""
    faces = mesh.points[mesh.facets[mesh.part_facets(part)]]  # (f, 3 vertices, 3)
    area = 0.5 * np.linalg.norm(
        np.cross(faces[:, 1] - faces[:, 0], faces[:, 2] - faces[:, 0]), axis=1
    )
    mids = 0.5 * (faces + faces[:, [1, 2, 0]])  # (f, 3 edges, 3)
    which = np.linalg.norm(mids.reshape(-1, 1, 3) - points[None], axis=2).argmin(axis=1)
    return np.bincount(which, np.repeat(s * area / 3.0, 3), minlength=points.shape[0])


def test_tresca_under_condition_a_has_the_midpoint_weights_and_the_dual_solution():
    """``face_alpha=0``: the vertex weights ∫ s φ_v vanish (docs/method.md, *Tresca under
    condition (a)*); the solve through ``solve`` equals the independent dual solve with the
    weights written out."""
    from signorini.contact.solution import solve

    s = 2e-3
    mesh = box(2, 2, 2)
    cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
    contact = Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), face_alpha=0.0)
    cond.update(z1=Dirichlet((0.004, 0.0, -0.01)), z0=replace(contact, friction=Tresca(s)))
    result = solve(ContactProblem(mesh, MATERIAL, cond), mesh)
    assert result.report.kkt.max <= 1e-12
    assert {STICK, SLIP} <= set(result.state.tolist())
    cs = result.contact
    weight = _midpoint_weights(mesh, "z0", result.space.node_points[cs.node], s)
    assert (weight == 0).sum() == 9  # the 3 × 3 vertices of z0
    np.testing.assert_allclose(cs.friction.laws.weight, weight, rtol=1e-13, atol=0.0)
    plain = assemble(replace(result.problem, conditions={**cond, "z0": Neumann((0.0,) * 3)}), mesh)
    other = solve_tresca(
        plain.K, plain.F, plain.dirichlet, plain.dirichlet_values, cs.node, cs.direction,
        cs.psi, weight, np.zeros((cs.node.size, 3)),
    )  # fmt: skip
    assert np.abs(result.u.ravel() - other.u).max() <= 1e-8 * np.abs(other.u).max()


def test_tresca_under_condition_a_on_curved_faces_is_refused_naming_face_alpha():
    from signorini.contact.solution import solve
    from signorini.examples.partial_slip3d import partial_slip_3d_path

    press = partial_slip_3d_path(h_contact=0.2)[0]
    sphere = replace(press.conditions["sphere"], friction=Tresca(1e-4), face_alpha=0.0)
    problem = replace(press, conditions={**press.conditions, "sphere": sphere})
    with pytest.raises(ProblemError, match=r"negative at \d+ row.*face_alpha=0"):
        solve(problem, problem.mesh)
