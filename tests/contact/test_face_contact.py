"""3D frictionless contact on P2 faces: conditions (a) and (b) by the package's blocks and
``algebra.solve_pdas``, against the independent study code (studies/faces3d) on the Kuhn
cube; the constant-pressure patch test; the frames."""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from face_problems import full_contact, patch, transition

from signorini.algebra.pdas import solve_pdas
from signorini.contact.face_contact import face_contact_set
from signorini.contact.node_frames3d import row_frames, tangent_completion
from signorini.fem.elasticity3d import assemble_body_force_3d, assemble_face_load_3d
from signorini.fem.material import Material
from signorini.fem.space3d import P2TetSpace
from signorini.fem.stiffness3d import assemble_stiffness_3d
from signorini.mesh.builders3d import box, eighth_ball
from signorini.mesh.mesh import Mesh
from signorini.problem.conditions import Contact
from signorini.problem.fields import ProblemError
from signorini.problem.obstacles import Disc
from signorini.problem.obstacles3d import HalfSpace

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "studies"))

from faces3d import contact as study  # noqa: E402
from faces3d import manufactured as study_data  # noqa: E402
from faces3d import measures as study_measures  # noqa: E402
from faces3d.mesh import cube_mesh  # noqa: E402

PROBLEMS = {"full": full_contact, "transition": transition, "patch": patch}
STUDY = {"full": study_data.full_contact, "transition": study_data.transition}


@cache
def assembled(name: str, n: int):
    """The package's stiffness, loads and held data of a manufactured problem on box(n)."""
    exact = PROBLEMS[name]()
    space = P2TetSpace(box(n, n, n))
    material = Material.from_lame(exact.lam, exact.mu)
    K = assemble_stiffness_3d(space.mapping, space.cell_dofs, space.n_dofs, material)
    F = assemble_body_force_3d(space, exact.f, degree=7)
    sides = np.concatenate([space.mesh.part_facets(p) for p in ("x0", "x1", "y0", "y1")])
    F += assemble_face_load_3d(
        space, sides, lambda p, nrm: np.einsum("...ij,...j->...i", exact.stress(p), nrm), degree=8
    )
    tangential = np.array([1.0, 1.0, 0.0])
    F += assemble_face_load_3d(
        space,
        space.mesh.part_facets("z0"),
        lambda p: -exact.stress(p)[..., :, 2] * tangential,
        degree=8,
    )
    held = np.zeros((space.n_nodes, 3), dtype=bool)
    top = space.part_nodes(["z1"])
    held[top] = True
    values = np.zeros((space.n_nodes, 3))
    values[top] = exact.u(space.node_points[top])
    return exact, space, K, F, held, values


def solved(name: str, n: int, alpha: float, F: np.ndarray | None = None):
    """The package's solution of condition α: ``(contact set, PDAS result, u, Λ)``; the loads
    ``F`` when given (the study's, renumbered), else the package's own."""
    exact, space, K, F_own, held, values = assembled(name, n)
    F = F_own if F is None else F
    contact = {"z0": Contact(gap=lambda x: exact.psi(x))}
    cs = face_contact_set(space, contact, held, values, alpha=alpha)
    Kt, Ft = cs.system(K, F)
    result = solve_pdas(Kt, Ft, cs.dof, cs.gap, cs.held_dofs, cs.held_values)
    u = cs.displacement(result.x)
    return cs, result, u, cs.force(K, F, u)


def _matched(points: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``(n,)`` the index in ``reference`` of each point (the same node sets)."""
    key = np.round(points * 1e9).astype(np.int64)
    ref = np.round(reference * 1e9).astype(np.int64)
    a, b = np.lexsort(key.T[::-1]), np.lexsort(ref.T[::-1])
    out = np.empty(points.shape[0], dtype=np.int64)
    out[a] = b
    assert np.array_equal(key, ref[out])
    return out


@cache
def study_solution(name: str, n: int, alpha: float):
    mesh = cube_mesh(n)
    problem = study.assemble(mesh, STUDY[name]())
    return mesh, problem, study.solve_pdas(problem, alpha)


@pytest.mark.parametrize("name", ["full", "transition"])
@pytest.mark.parametrize("alpha", [0.0, 0.2], ids=["a-nodal", "b-transformed"])
def test_conditions_a_and_b_equal_the_independent_study(name, alpha):
    n = 2
    mesh, problem, ref = study_solution(name, n, alpha)
    space, F_own = assembled(name, n)[1:4:2]
    to_study = _matched(space.node_points, mesh.points)
    # the same discrete problem: the study's loads (its quadrature) in the package's numbering
    F = problem.F.reshape(-1, 3)[to_study].ravel()
    if name == "full":  # smooth data: the two quadratures agree (the transition's f is C⁰)
        np.testing.assert_allclose(F_own, F, atol=1e-4 * np.abs(F).max())
    cs, result, u, force = solved(name, n, alpha, F)
    np.testing.assert_array_equal(to_study[cs.node].size, problem.nodes.size)
    row = np.searchsorted(problem.nodes, to_study[cs.node])
    assert np.array_equal(problem.nodes[row], to_study[cs.node])
    scale = np.abs(ref.u).max()
    np.testing.assert_allclose(u.reshape(-1, 3), ref.u[to_study], atol=1e-12 * scale, rtol=0)
    assert np.array_equal(result.active, ref.active[row])
    f_scale = np.abs(ref.force).max()
    np.testing.assert_allclose(force, ref.force[row], atol=1e-11 * f_scale, rtol=0)
    np.testing.assert_allclose(result.multiplier, ref.multiplier[row], atol=1e-11 * f_scale, rtol=0)
    assert result.kkt.max <= 1e-10
    # the pressures: the P1-lumped one at the vertices, (b)'s own p̃ at every node
    vertex = cs.node < space.mesh.n_points
    p_scale = np.abs(STUDY[name]().pressure(space.node_points[cs.node])).max()
    p1 = study_measures.recovered_pressure(problem, ref.force, 0.5)[row]
    np.testing.assert_allclose(
        cs.recovered_pressure(force)[vertex], p1[vertex], atol=1e-10 * p_scale, rtol=0
    )
    if alpha > 0:  # (b): Λ̃ = T Λ is the multiplier
        np.testing.assert_allclose(cs.edges.transformed(force), result.multiplier, atol=1e-13)
        own = study_measures.recovered_pressure(problem, ref.force, alpha)[row]
        np.testing.assert_allclose(cs.pressure(force), own, atol=1e-10 * p_scale, rtol=0)


@pytest.mark.parametrize("alpha", [0.0, 0.2, 0.3], ids=["a", "b", "b-0.3"])
def test_constant_pressure_patch_test_is_exact(alpha):
    exact, space, *_ = assembled("patch", 2)
    cs, result, u, force = solved("patch", 2, alpha)
    u_exact = exact.u(space.node_points).ravel()
    np.testing.assert_allclose(u, u_exact, atol=1e-13 * np.abs(u_exact).max())
    np.testing.assert_allclose(cs.recovered_pressure(force), 0.1, rtol=1e-11)
    if alpha > 0:
        np.testing.assert_allclose(cs.pressure(force), 0.1, rtol=1e-11)
        assert (cs.transformed_integral > 0).all()
    else:
        with pytest.raises(ValueError, match="integrate to zero"):
            cs.pressure(force)
    # the weights: w = Σ_F ∫ ψ_z, the transformed ones T w = Σ_F shares |F|, all of Γ_C
    area = space.mesh.part_measure("z0")
    assert np.isclose(cs.basis_integral.sum(), area) and np.isclose(cs.hat_integral.sum(), area)
    assert np.isclose(cs.transformed_integral.sum(), area)
    vertex = cs.node < space.mesh.n_points
    np.testing.assert_allclose(cs.basis_integral[vertex], 0.0, atol=1e-15)


def test_frames_are_right_handed_rotations():
    rng = np.random.default_rng(3)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    for pole in range(3):
        Q = tangent_completion(n, pole)
        np.testing.assert_allclose(
            Q.transpose(0, 2, 1) @ Q, np.broadcast_to(np.eye(3), Q.shape), atol=1e-14
        )
        np.testing.assert_allclose(np.linalg.det(Q), 1.0, atol=1e-14)
        np.testing.assert_array_equal(Q[:, :, 0], n)
    # continuity: a small turn of n away from the equator n_k = 0 turns the frame by as much
    m = n + 1e-7 * rng.normal(size=n.shape)
    m /= np.linalg.norm(m, axis=1)[:, None]
    far = np.abs(n[:, 2]) > 0.1
    jump = np.abs(tangent_completion(m) - tangent_completion(n)).max(axis=(1, 2))
    assert jump[far].max() < 1e-4
    # a flat part normal to -e_z: the tangents are axes
    np.testing.assert_array_equal(
        tangent_completion(np.array([[0.0, 0.0, -1.0]]))[0], [[0, 1, 0], [0, 0, -1], [-1, 0, 0]]
    )
    # two rows: y = A u with rows n, m, (n × m)/|n × m|
    rows = np.zeros((1, 3, 3))
    rows[0, 0], rows[0, 1] = [0.0, 0.0, -1.0], [-1.0, 0.0, 0.0]
    Q = row_frames(rows, np.array([2]), np.array([2]))
    np.testing.assert_allclose(np.linalg.inv(Q[0])[:2], rows[0, :2], atol=1e-15)


def test_rows_at_corners_held_nodes_and_shapes():
    """Two contact parts meeting at an edge, a roller beside them, a shape's directions; the
    cube pressed into both half-spaces solves with KKT ≤ 1e-10 and pushes at the corner."""
    space = P2TetSpace(box(2, 2, 2))
    x = space.node_points
    held = np.zeros((space.n_nodes, 3), dtype=bool)
    values = np.zeros((space.n_nodes, 3))
    top = space.part_nodes(["z1"])
    held[top] = True
    values[top] = [-0.01, 0.0, -0.02]
    held[space.part_nodes(["y0"]), 1] = True  # a roller u_y = 0 on y = 0
    contact = {
        "z0": Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])),
        "x0": Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])),
    }
    cs = face_contact_set(space, contact, held, values, alpha=0.2)
    on = np.isclose(x[cs.node], 0.0)
    corner = on[:, 0] & on[:, 2]
    nodes, count = np.unique(cs.node[corner], return_counts=True)
    assert (count == 2).all() and nodes.size == 5  # 3 vertices, 2 midpoints of the edge
    np.testing.assert_array_equal(cs.direction[cs.part == 0], np.tile([0, 0, -1.0], (25, 1)))
    assert not np.isin(cs.node, top).any()  # Dirichlet nodes: no row
    Q = dict(zip(cs.frame_nodes.tolist(), cs.frames, strict=True))
    roller = cs.frame_nodes[np.isclose(x[cs.frame_nodes, 1], 0.0)]
    for z in roller:  # rows (contact..., e_y): the held DOF is the frame's last row
        A = np.linalg.inv(Q[int(z)])
        assert np.isin(3 * z + np.flatnonzero(np.abs(A[:, 1]) == 1.0), cs.held_dofs).all()
    K = assemble_stiffness_3d(
        space.mapping, space.cell_dofs, space.n_dofs, Material.from_young(1.0, 0.3)
    )
    Kt, Ft = cs.system(K, np.zeros(space.n_dofs))
    result = solve_pdas(Kt, Ft, cs.dof, cs.gap, cs.held_dofs, cs.held_values)
    assert result.kkt.max <= 1e-10
    u = cs.displacement(result.x).reshape(-1, 3)
    np.testing.assert_allclose(u[top], values[top], atol=1e-15)
    np.testing.assert_allclose(u[space.part_nodes(["y0"]), 1], 0.0, atol=1e-15)
    assert (u[cs.node[cs.part == 0], 2] >= -1e-14).all()  # no penetration of z ≥ 0 (ψ = z)
    force = cs.force(K, np.zeros(space.n_dofs), cs.displacement(result.x))
    assert result.active[corner].all() and (cs.edges.transformed(force)[corner] > 0).all()
    # a roller along the normal holds u·n: no row there
    held[space.part_nodes(["z0"]), 2] = True
    again = face_contact_set(space, {"z0": contact["z0"]}, held, values)
    assert again.node.size == 0


def _pressed(R: np.ndarray, alpha: float):
    """The cube of box(2) rotated by ``R``, pressed into two half-spaces (faces z0, x0) by
    u_D on z1: (Cartesian u (n_nodes, 3), Λ, active set)."""
    base = box(2, 2, 2)
    parts = {p: base.facets[base.part_facets(p)] for p in ("x0", "x1", "y0", "y1", "z0", "z1")}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    space = P2TetSpace(mesh)
    held = np.zeros((space.n_nodes, 3), dtype=bool)
    values = np.zeros((space.n_nodes, 3))
    top = space.part_nodes(["z1"])
    held[top] = True
    values[top] = R @ np.array([-0.01, 0.003, -0.02])
    contact = {
        "z0": Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], R @ [0.0, 0.0, 1.0])),
        "x0": Contact(obstacle=HalfSpace([0.0, 0.0, 0.0], R @ [1.0, 0.0, 0.0])),
    }
    cs = face_contact_set(space, contact, held, values, alpha=alpha)
    K = assemble_stiffness_3d(
        space.mapping, space.cell_dofs, space.n_dofs, Material.from_young(1.0, 0.3)
    )
    Kt, Ft = cs.system(K, np.zeros(space.n_dofs))
    result = solve_pdas(Kt, Ft, cs.dof, cs.gap, cs.held_dofs, cs.held_values)
    assert result.kkt.max <= 1e-10
    u = cs.displacement(result.x)
    return u.reshape(-1, 3), cs.force(K, np.zeros(space.n_dofs), u), result.active


@pytest.mark.parametrize("alpha", [0.0, 0.2], ids=["a", "b"])
def test_oblique_contact_is_the_axis_aligned_one_rotated(alpha):
    c, s = np.cos(0.7), np.sin(0.7)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]]
    )
    u, force, active = _pressed(np.eye(3), alpha)
    u_rot, force_rot, active_rot = _pressed(R, alpha)
    assert active.any() and np.array_equal(active, active_rot)
    np.testing.assert_allclose(u_rot, u @ R.T, atol=1e-13 * np.abs(u).max())
    np.testing.assert_allclose(force_rot, force, atol=1e-12 * np.abs(force).max())


def test_gap_function_on_a_curved_part_takes_the_surface_normal():
    """The eighth ball's sphere part with a gap function: the outward radial normal at every
    node (midpoints on the sphere too); the symmetry rollers u_x = 0, u_y = 0 beside it add
    their held rows; the Hertz plane below as a shape gives the direction −e_z everywhere."""
    space = P2TetSpace(eighth_ball(2))
    x = space.node_points
    held = np.zeros((space.n_nodes, 3), dtype=bool)
    held[space.part_nodes(["x0"]), 0] = True
    held[space.part_nodes(["y0"]), 1] = True
    values = np.zeros((space.n_nodes, 3))
    cs = face_contact_set(space, {"sphere": Contact(gap=0.01)}, held, values)
    normal = x[cs.node] / np.linalg.norm(x[cs.node], axis=1)[:, None]
    np.testing.assert_allclose(cs.direction, normal, atol=1e-12)
    np.testing.assert_allclose(cs.psi, 0.01)
    both = held[cs.node].sum(axis=1) == 2  # the rim's pole end: on both symmetry planes
    assert both.any()
    for z, Q in zip(cs.frame_nodes, cs.frames, strict=True):
        A = np.linalg.inv(Q)
        h = np.flatnonzero(held[z])
        np.testing.assert_allclose(A[1 : 1 + h.size], np.eye(3)[h], atol=1e-15)
    plane = HalfSpace([0.0, 0.0, -1.05], [0.0, 0.0, 1.0])
    shaped = face_contact_set(space, {"sphere": Contact(obstacle=plane)}, held, values)
    np.testing.assert_array_equal(shaped.direction, np.tile([0.0, 0.0, -1.0], (cs.n_rows, 1)))
    np.testing.assert_allclose(shaped.psi, x[shaped.node, 2] + 1.05)
    with pytest.raises(ProblemError, match="plane shape"):
        face_contact_set(space, {"sphere": Contact(obstacle=Disc([0, 0], 1.0))}, held, values)


@pytest.mark.parametrize("alpha", [None, 0.0], ids=["b-default", "a"])
def test_solve_runs_3d_contact_as_the_blocks_do(alpha):
    """``solve()`` on a ContactProblem with two contact parts of half-spaces equals the
    blocks' solution (condition (b), the default), and its pressure is the transformed one."""
    from signorini.contact.solution import solve
    from signorini.problem.conditions import Dirichlet, Neumann
    from signorini.problem.problem import ContactProblem

    mesh = box(2, 2, 2)
    conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
    conditions.update(
        z1=Dirichlet((-0.01, 0.003, -0.02)),
        z0=Contact(obstacle=HalfSpace([0, 0, 0], [0, 0, 1.0]), face_alpha=alpha),
        x0=Contact(obstacle=HalfSpace([0, 0, 0], [1.0, 0, 0]), face_alpha=alpha),
    )
    result = solve(ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions))
    u, force, active = _pressed(np.eye(3), 0.2 if alpha is None else alpha)
    assert result.report.kkt.max <= 1e-10
    cs = result.contact
    assert cs.parts == ("x0", "z0")  # the problem's order: at the corner the rows swap places
    assert active.all() == result.active.all() and active.sum() == result.active.sum()
    np.testing.assert_allclose(result.u, u, atol=1e-13 * np.abs(u).max())
    np.testing.assert_allclose(  # the same forces, two of them swapped at each corner node
        np.sort(result.contact_force), np.sort(force), atol=1e-12 * np.abs(force).max()
    )
    np.testing.assert_allclose(result.total_contact_force, force.sum(), rtol=1e-12)
    assert cs.edges.alpha == (0.2 if alpha is None else alpha)
    assert np.isfinite(cs.recovered_pressure(result.contact_force)).all()
    if alpha == 0.0:  # (a): no nodal pressure at the vertices
        with pytest.raises(ValueError, match="integrate to zero"):
            _ = result.pressure
        return
    np.testing.assert_allclose(
        result.pressure,
        cs.edges.transformed(result.contact_force) / cs.transformed_integral,
        rtol=1e-12,
    )
