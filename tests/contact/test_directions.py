"""Per-node constraint directions (docs/method.md, *Contact directions*): obstacles as shapes,
curved and polygonal contact parts, and corners with two constraints, each checked against an
independent solve of the same discrete problem.

The reference solve works in Cartesian DOFs with the constraints ``B u ≤ ψ`` as rows of a
dense matrix (one row per constraint, the direction n_z at the node's two DOFs) and solves the
dual problem ``min ½ λᵀ H λ − cᵀ λ, λ ≥ 0`` with ``H = B K⁻¹ Bᵀ`` by non-negative least
squares (an exact active set method): no node frames, no PDAS.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as la
from contact_problems import corner_problem, problem_contact_set
from scipy.optimize import nnls

from signorini.contact.solution import solve
from signorini.fem.loads import assemble_body_force
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle, ProjectedCurve
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError
from signorini.problem.obstacles import Disc, HalfPlane

MATERIAL = Material.from_young(10.0, 0.3)
TOL = 1e-12


def reference_solution(pb: ContactProblem, mesh: Mesh | None = None):
    """u (n_nodes, 2) and λ (k,) of the discrete problem, by the dual QP and NNLS."""
    mesh = pb.mesh if mesh is None else mesh
    space = P2Space(mesh)
    cs = problem_contact_set(pb, space)
    n = space.n_dofs
    K = assemble_stiffness(space.mapping, space.cell_dofs, n, pb.material).toarray()
    F = np.zeros(n)
    if pb.body_force is not None:
        F = assemble_body_force(space.vertices, space.cell_dofs, n, pb.body_force, degree=6)
    d_nodes = pb.dirichlet_nodes(space)
    u_d = np.zeros((space.n_nodes, 2))
    for name in pb.dirichlet_parts:
        nodes = space.part_nodes([name])
        u_d[nodes] = pb.conditions[name].field()(space.node_points[nodes])
    fixed = np.zeros(n, dtype=bool)
    fixed[2 * d_nodes] = fixed[2 * d_nodes + 1] = True
    free = ~fixed
    B = np.zeros((cs.size, n))
    rows = np.arange(cs.size)
    B[rows, 2 * cs.nodes] = cs.normal[:, 0]
    B[rows, 2 * cs.nodes + 1] = cs.normal[:, 1]
    Kff = K[np.ix_(free, free)]
    rhs = F[free] - K[np.ix_(free, fixed)] @ u_d.ravel()[fixed]
    chol = la.cho_factor(Kff)
    Bf = B[:, free]
    H = Bf @ la.cho_solve(chol, Bf.T)
    c = Bf @ la.cho_solve(chol, rhs) - cs.gap
    L = np.linalg.cholesky(H)
    lam, _ = nnls(L.T, la.solve_triangular(L, c, lower=True), maxiter=50 * cs.size)
    u = u_d.ravel().copy()
    u[free] = la.cho_solve(chol, rhs - Bf.T @ lam)
    return u.reshape(-1, 2), lam


@pytest.mark.parametrize("shapes", [False, True])
def test_corner_has_two_constraints_and_matches_the_dual_qp(shapes):
    pb = corner_problem(shapes=shapes)
    res = solve(pb)
    u_ref, lam_ref = reference_solution(pb)
    scale = np.abs(u_ref).max()
    err_u = np.abs(res.u - u_ref).max() / scale
    err_lam = np.abs(res.contact_force - lam_ref).max() / np.abs(lam_ref).max()
    print(
        f"corner ({'shapes' if shapes else 'gaps'}): |u - u_ref| / |u| = {err_u:.2e}, "
        f"|Λ - λ_ref| / |λ| = {err_lam:.2e}, KKT {res.report.kkt.max:.2e}"
    )
    assert err_u < 1e-10, err_u
    assert err_lam < 1e-10, err_lam
    assert res.report.kkt.max < 1e-10
    x = res.space.node_points[res.contact.nodes]
    corner = np.flatnonzero(np.all(np.abs(x - [1.0, 0.0]) < TOL, axis=1))
    assert corner.size == 2
    assert res.active[corner].all() and (res.contact_force[corner] > 0).all()
    assert np.abs(res.u[res.contact.nodes[corner[0]]]).max() < 1e-12 * scale  # held both ways
    # both zones touch beyond the corner
    for part in (0, 1):
        assert res.active[res.contact.part == part].sum() >= 3


def test_corner_problem_is_rotation_invariant():
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    ref = solve(corner_problem())
    rot = solve(corner_problem(angle, shapes=True))
    err = np.abs(rot.u - ref.u @ R.T).max() / np.abs(ref.u).max()
    print(f"rotation by {angle}: |u_rot - R u| / |u| = {err:.2e}")
    assert err < 1e-10, err
    order_ref = np.lexsort((ref.contact.part, ref.contact.nodes))
    order_rot = np.lexsort((rot.contact.part, rot.contact.nodes))
    lam_ref, lam_rot = ref.contact_force[order_ref], rot.contact_force[order_rot]
    assert np.abs(lam_rot - lam_ref).max() < 1e-10 * lam_ref.max()
    assert np.allclose(rot.contact_force_vector, R @ ref.contact_force_vector, rtol=1e-10)


def test_obstacle_shape_equals_gap_function_on_a_straight_part():
    def problem(bottom):
        return ContactProblem(
            rectangle(nx=4, ny=4),
            MATERIAL,
            {
                "left": Neumann(),
                "right": Neumann(),
                "top": Dirichlet((0.0, -0.05)),
                "bottom": bottom,
            },
        )

    a = solve(problem(Contact(gap=0.01)))
    b = solve(problem(Contact(obstacle=HalfPlane((0.0, -0.01), (0.0, 1.0)))))
    assert np.array_equal(a.contact.normal, b.contact.normal)
    assert np.abs(a.contact.gap - b.contact.gap).max() < 1e-17
    assert np.abs(a.u - b.u).max() < 1e-14 * np.abs(a.u).max()
    assert a.active.any() and np.array_equal(a.active, b.active)
    # the resultant force of the floor on the body points up
    assert b.contact_force_vector[1] > 0 and abs(b.contact_force_vector[0]) < 1e-12


def test_polygonal_part_takes_the_mean_of_its_edges_normals_at_a_vertex():
    m = rectangle(nx=2, ny=2)
    mesh = Mesh.from_arrays(
        m.points,
        m.cells,
        {
            "corner": lambda x: (np.abs(x[:, 1]) < TOL) | (np.abs(x[:, 0] - 1) < TOL),
            "rest": lambda x: (np.abs(x[:, 1] - 1) < TOL) | (np.abs(x[:, 0]) < TOL),
        },
    )

    # the left and top sides sheared towards the corner part, fixed where they meet it (a
    # uniform (0.02, −0.02) would push (0, 0) and (1, 1) into the obstacle: no solution)
    def shear(x):
        return 0.02 * np.column_stack([x[:, 1] * (1 - x[:, 0]), -x[:, 0] * (1 - x[:, 1])])

    pb = ContactProblem(mesh, MATERIAL, {"rest": Dirichlet(shear), "corner": Contact(gap=0.005)})
    space = P2Space(mesh)
    cs = problem_contact_set(pb, space)
    x = space.node_points[cs.nodes]
    at_corner = np.all(np.abs(x - [1.0, 0.0]) < TOL, axis=1)
    assert at_corner.sum() == 1  # one part: one constraint, along the mean normal
    assert np.allclose(cs.normal[at_corner], [[2**-0.5, -(2**-0.5)]], rtol=0, atol=1e-15)
    bottom = np.abs(x[:, 1]) < TOL
    assert np.array_equal(
        cs.normal[bottom & ~at_corner], np.tile([0.0, -1.0], ((bottom & ~at_corner).sum(), 1))
    )
    res = solve(pb)
    u_ref, _ = reference_solution(pb)
    assert np.abs(res.u - u_ref).max() < 1e-10 * np.abs(u_ref).max()
    assert res.active.any() and res.report.kkt.max < 1e-10


def quarter_annulus(n: int = 4) -> Mesh:
    """The quarter annulus 1 ≤ r ≤ 2, 0 ≤ θ ≤ π/2 (a mapped rectangle), its arcs on circles."""
    base = rectangle(1.0, 2.0, 0.0, np.pi / 2, nx=n, ny=2 * n)
    r, t = base.points[:, 0], base.points[:, 1]
    points = np.column_stack([r * np.cos(t), r * np.sin(t)])
    radius = lambda x: np.hypot(x[:, 0], x[:, 1])  # noqa: E731
    mesh = Mesh.from_arrays(
        points,
        base.cells,
        {
            "inner": lambda x: radius(x) < 1.1,
            "outer": lambda x: radius(x) > 1.9,
            "sides": lambda x: (np.abs(x[:, 0]) < TOL) | (np.abs(x[:, 1]) < TOL),
        },
    )
    return mesh.with_curve("inner", Circle((0, 0), 1.0)).with_curve("outer", Circle((0, 0), 2.0))


def test_curved_part_constrains_along_the_curve_normal():
    """An annulus sector pushed outwards from its inner arc against an obstacle at a gap
    along the outer arc's exact normal."""
    mesh = quarter_annulus()
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {
            "inner": Dirichlet(lambda x: 0.02 * x / np.hypot(x[:, 0], x[:, 1])[:, None]),
            "outer": Contact(gap=lambda x: 0.002 + 0.01 * x[:, 0]),
            "sides": Neumann(),
        },
    )
    res = solve(pb)
    cs = res.contact
    x = res.space.node_points[cs.nodes]
    assert np.allclose(np.hypot(x[:, 0], x[:, 1]), 2.0, rtol=0, atol=1e-14)  # P2 nodes on the arc
    assert np.abs(cs.normal - x / 2.0).max() < 1e-15
    u_ref, lam_ref = reference_solution(pb)
    err = np.abs(res.u - u_ref).max() / np.abs(u_ref).max()
    print(f"curved contact part: |u - u_ref| / |u| = {err:.2e}, KKT {res.report.kkt.max:.2e}")
    assert err < 1e-10, err
    assert 0 < res.active.sum() < cs.size
    assert res.report.kkt.max < 1e-10
    # the weights are integrals along the quadratic edges, which are O(h⁴) from the arc of
    # length π (the chords are O(h²) off: 8 chords of 2 · 2 sin(π/32) give 3.1365)
    chords = 8 * 2 * 2 * np.sin(np.pi / 32)
    err_p2, err_chord = abs(cs.basis_integral.sum() - np.pi), abs(chords - np.pi)
    print(f"Σ w_z − π = {err_p2:.2e} (chords: {err_chord:.2e})")
    assert err_p2 < 1e-5 and err_p2 < 1e-2 * err_chord


def test_nearly_parallel_corner_is_refused():
    m = rectangle(nx=2, ny=2)
    mesh = Mesh.from_arrays(
        m.points,
        m.cells,
        {
            "left": lambda x: np.abs(x[:, 0]) < TOL,
            "top": lambda x: np.abs(x[:, 1] - 1) < TOL,
            "a": lambda x: (np.abs(x[:, 1]) < TOL) & (x[:, 0] < 0.5 + TOL),
            "b": lambda x: (
                ((np.abs(x[:, 1]) < TOL) & (x[:, 0] > 0.5 - TOL)) | (np.abs(x[:, 0] - 1) < TOL)
            ),
        },
    )
    slightly = HalfPlane((0.0, 0.0), (0.001, 1.0))
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {"left": Dirichlet(), "top": Neumann(), "a": Contact(), "b": Contact(obstacle=slightly)},
    )
    with pytest.raises(ProblemError, match=r"at \[0\.5, 0\.0\] lies on two contact parts"):
        solve(pb)


def test_curve_without_normal_takes_the_mean_rule():
    """A ProjectedCurve given without its normal: the directions are the polygon's (mean of
    the edges' normals at a vertex), not an error from deep inside."""
    mesh = quarter_annulus()
    project = lambda x: 2.0 * x / np.hypot(x[:, 0], x[:, 1])[:, None]  # noqa: E731
    mesh = mesh.with_curve("outer", ProjectedCurve(project))
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {
            "inner": Dirichlet(lambda x: 0.02 * x / np.hypot(x[:, 0], x[:, 1])[:, None]),
            "outer": Contact(gap=0.005),
            "sides": Neumann(),
        },
    )
    res = solve(pb)
    cs = res.contact
    x = res.space.node_points[cs.nodes]
    # at a vertex between two equal chords the mean normal is the radial direction
    inner_vertex = cs.is_vertex & (x[:, 0] > 1e-9) & (x[:, 1] > 1e-9)
    assert np.abs(cs.normal[inner_vertex] - x[inner_vertex] / 2).max() < 1e-14
    # at a midpoint the chord's normal: radial at the chord's middle, i.e. through the node
    assert np.abs(cs.normal[~cs.is_vertex] - x[~cs.is_vertex] / 2).max() < 1e-14
    assert res.report.kkt.max < 1e-10


def test_obstacle_without_a_distance_at_a_node_names_the_part():
    """A disc whose centre is a contact node gives no direction there."""
    pb = ContactProblem(
        rectangle(nx=2, ny=2),
        MATERIAL,
        {
            "left": Dirichlet(),
            "top": Neumann(),
            "bottom": Neumann(),
            "right": Contact(obstacle=Disc((1.0, 0.5), 0.25)),
        },
    )
    with pytest.raises(ProblemError, match="the obstacle of contact part 'right': Disc"):
        solve(pb)
