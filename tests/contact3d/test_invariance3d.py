"""Mirror and rotation invariance of the Hertz sphere in 3D (issue 38, "How it is verified"):
the eighth model with symmetry rollers is the lower half ball's solution on the mirrored mesh,
and the problem rotated as a whole (mesh, sphere, obstacle, oblique rollers) gives the
rotated answer, to round-off, under either discrete contact condition."""

from __future__ import annotations

import numpy as np
import pytest
from contact3d_problems import DIRECT, mirrored, rotation
from scipy.spatial import cKDTree

from signorini.contact.solution import ContactResult, solve
from signorini.examples.hertz3d import DEPTH_3D, graded_eighth_ball, hertz_3d
from signorini.fem.material import Material
from signorini.mesh.builders3d import eighth_ball
from signorini.mesh.mesh import Mesh
from signorini.mesh.surfaces import Sphere
from signorini.problem import Contact, ContactProblem, Dirichlet
from signorini.problem.conditions import Roller
from signorini.problem.obstacles3d import HalfSpace

MATERIAL = Material.from_young(1.0, 0.3)
#: the coarse graded eighth ball of hertz_3d(h_contact=0.2): 2547 unknowns
EIGHTH = {"n": 2, "radius": 1.0, "h_contact": 0.2, "grading": 0.5, "patch": 0.15}


def _press(
    mesh: Mesh, rollers: tuple[str, ...], alpha: float | None, depth: float = DEPTH_3D
) -> ContactProblem:
    """The ball of ``mesh`` pressed by its clamped top ``u = (0, 0, −δ)`` onto the plane
    z = 0 (the top holds the tangential rigid motions of the half ball), ``rollers`` on
    its symmetry planes."""
    conditions = {name: Roller() for name in rollers}
    conditions["z1"] = Dirichlet((0.0, 0.0, -depth))
    plane = HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    conditions["sphere"] = Contact(obstacle=plane, face_alpha=alpha)
    return ContactProblem(mesh=mesh, material=MATERIAL, conditions=conditions)


def _rows(result: ContactResult) -> np.ndarray:
    """``(k, 3)`` the points of the contact rows' nodes."""
    return result.space.node_points[result.contact.node]


def _straight(mesh: Mesh) -> Mesh:
    """``mesh`` with straight (affine) cells: its parts carry no surface."""
    parts = {p: mesh.facets[mesh.part_facets(p)] for p in mesh.part_names}
    return Mesh.from_arrays(mesh.points, mesh.cells, parts)


def _check_mirror(eighth: Mesh, alpha: float | None, depth: float, rtol: float) -> None:
    """The eighth ball (rollers on x0, y0) and the lower half ball made of it and its
    mirror images in x = 0 and y = 0 (no rollers): the eighth's u equals the half ball's at
    every P2 node of the eighth to ``rtol`` of max|u|, the half ball's u is mirror symmetric
    to the same, the active sets agree and a row on one (two) symmetry planes carries a half
    (a quarter) of the half ball's force at its node."""
    quarter, _ = mirrored(eighth, 0)
    half, _ = mirrored(quarter, 1)
    assert half.n_cells == 4 * eighth.n_cells and "x0" not in half.part_names
    assert abs(half.volume.sum() - 4 * eighth.volume.sum()) <= 1e-12 * half.volume.sum()
    small = solve(_press(eighth, ("x0", "y0"), alpha, depth), solver=DIRECT)
    whole = solve(_press(half, (), alpha, depth), solver=DIRECT)
    assert whole.problem.rollers == {} and small.report.kkt.max <= 1e-10
    assert whole.report.kkt.max <= 1e-10 and small.active.sum() >= 4
    tree = cKDTree(whole.space.node_points)
    distance, node = tree.query(small.space.node_points)
    assert distance.max() <= 1e-14
    scale = np.abs(whole.u).max()
    np.testing.assert_allclose(small.u, whole.u[node], rtol=0, atol=rtol * scale)
    for axis in (0, 1):  # the half ball's u at the mirrored nodes is the mirrored u
        flip = np.ones(3)
        flip[axis] = -1.0
        _, image = tree.query(whole.space.node_points * flip)
        np.testing.assert_allclose(whole.u[image] * flip, whole.u, rtol=0, atol=rtol * scale)
    distance, row = cKDTree(_rows(whole)).query(_rows(small))
    assert distance.max() <= 1e-14
    np.testing.assert_array_equal(small.active, whole.active[row])
    assert whole.active.sum() > small.active.sum()
    share = 1.0 / 2.0 ** (_rows(small)[:, :2] == 0.0).sum(axis=1)
    f = np.abs(whole.contact_force).max()
    np.testing.assert_allclose(
        small.contact_force, share * whole.contact_force[row], rtol=0, atol=10 * rtol * f
    )
    assert np.isclose(4 * small.total_contact_force, whole.total_contact_force, rtol=10 * rtol)


@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b", "a"])
def test_eighth_model_is_the_half_ball_on_the_mirrored_affine_mesh(alpha):
    """Straight cells (eighth_ball(3) without its sphere, δ = 0.08: 6 rows in contact):
    equal to round-off (measured 4e-15 of max|u|)."""
    _check_mirror(_straight(eighth_ball(3, center=(0.0, 0.0, 1.0))), alpha, 0.08, 1e-12)


def test_eighth_model_is_the_half_ball_on_the_mirrored_curved_mesh():
    """Isoparametric cells on the sphere: equal to the quadrature's asymmetry (measured
    6.4e-9 of max|u| against the eighth, 8.2e-9 against its own mirror image; straight
    cells give 4e-15). The conical product rules of the tetrahedron
    (:mod:`signorini.fem.quadrature`) are not invariant under a permutation of the vertices,
    and the mirrored cells list theirs with 1 and 2 swapped: on a curved cell, whose
    stiffness integrand is not a polynomial, the rule's error differs between a cell and
    its mirror image."""
    _check_mirror(eighth_ball(3, center=(0.0, 0.0, 1.0)), None, 0.08, 2e-8)


@pytest.mark.slow
@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b", "a"])
def test_hertz_eighth_is_the_half_ball_on_the_mirrored_graded_mesh(alpha):
    """hertz-3d's graded mesh (h_contact = 0.2), the top clamped: to 5e-9 (measured: the
    eighth against the half ball 1.5e-10 and 1.6e-10 for (b) and (a), the half ball against
    its own mirror image 1.1e-9: the quadrature's asymmetry on curved cells)."""
    _check_mirror(graded_eighth_ball(**EIGHTH), alpha, DEPTH_3D, 5e-9)


def _rotated_hertz(R: np.ndarray, alpha: float | None) -> ContactProblem:
    """hertz-3d on its coarse mesh rotated by ``R``: the sphere, the plane and the rollers
    (oblique planes) with it, the sliding top as a roller ``u·n = −δ`` on its plane."""
    base = graded_eighth_ball(**EIGHTH)
    parts = {p: base.facets[base.part_facets(p)] for p in base.part_names}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts).with_curve(
        "sphere", Sphere(R @ [0.0, 0.0, 1.0], 1.0)
    )
    plane = HalfSpace([0.0, 0.0, 0.0], R @ [0.0, 0.0, 1.0])
    conditions = {
        "x0": Roller(),
        "y0": Roller(),
        "z1": Roller(value=-DEPTH_3D),
        "sphere": Contact(obstacle=plane, face_alpha=alpha),
    }
    return ContactProblem(mesh=mesh, material=MATERIAL, conditions=conditions)


@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b", "a"])
def test_hertz_rotated_as_a_whole_gives_the_rotated_answer(alpha):
    """hertz-3d's eighth (sliding top) rotated by 0.7 rad about x then z: the rotated u at
    the same P2 nodes to 1e-10 relative, the same active set and contact forces; the
    rotation R = I gives hertz-3d's own problem (the top's roller is its u_z = −δ)."""
    R = rotation()
    axis = solve(_rotated_hertz(np.eye(3), alpha), solver=DIRECT)
    own = solve(hertz_3d(h_contact=EIGHTH["h_contact"], face_alpha=alpha), solver=DIRECT)
    np.testing.assert_allclose(axis.u, own.u, rtol=0, atol=1e-13 * np.abs(own.u).max())
    tilted = solve(_rotated_hertz(R, alpha), solver=DIRECT)
    assert axis.problem.rollers == {} and set(tilted.problem.rollers) == {"x0", "y0", "z1"}
    assert axis.report.kkt.max <= 1e-10 and tilted.report.kkt.max <= 1e-10
    np.testing.assert_allclose(tilted.space.node_points, axis.space.node_points @ R.T, atol=1e-14)
    scale = np.abs(axis.u).max()
    np.testing.assert_allclose(tilted.u, axis.u @ R.T, rtol=0, atol=1e-10 * scale)
    assert axis.active.sum() >= 4
    np.testing.assert_array_equal(tilted.active, axis.active)
    f = np.abs(axis.contact_force).max()
    np.testing.assert_allclose(tilted.contact_force, axis.contact_force, rtol=0, atol=1e-9 * f)
    assert np.isclose(axis.total_contact_force, tilted.total_contact_force, rtol=1e-10)
