"""Isoparametric P2 cells on curved boundary parts: convergence on an annulus sector with a
Dirichlet arc, linear fields, rigid-body modes, and straight meshes left untouched."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from fem_problems import GradientField, stress_of

from signorini.contact.system import assemble
from signorini.fem import iso
from signorini.fem.loads import assemble_body_force, assemble_facet_load
from signorini.fem.mapping import IsoparametricCells, QuadraticFacets
from signorini.fem.material import Material
from signorini.fem.norms import energy_error2
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness, element_blocks
from signorini.mesh import Circle, Mesh, MeshError, rectangle
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.problem import ContactProblem, Dirichlet, Neumann

MATERIAL = Material.from_young(1.0, 0.3)
A = 1.5  # u = grad(-cos(A x) cos(A y) / A)


FIELD = GradientField(A, MATERIAL)
exact_u, exact_grad, body_force = FIELD.u, FIELD.grad, FIELD.body_force


def stress(x, grad):
    return stress_of(grad(x), MATERIAL)


def annulus_sector(n_r: int = 2, n_t: int = 4) -> Mesh:
    """1 <= r <= 2, 0 <= theta <= pi/2; parts inner, outer (arcs), bottom, left."""
    r, t = np.meshgrid(np.linspace(1, 2, n_r + 1), np.linspace(0, np.pi / 2, n_t + 1))
    p = np.column_stack([(r * np.cos(t)).ravel(), (r * np.sin(t)).ravel()])
    p[np.isclose(t.ravel(), np.pi / 2), 0] = 0.0
    k = lambda i, j: i * (n_r + 1) + j  # noqa: E731
    cells = []
    for i in range(n_t):
        for j in range(n_r):
            cells += [
                [k(i, j), k(i, j + 1), k(i + 1, j + 1)],
                [k(i, j), k(i + 1, j + 1), k(i + 1, j)],
            ]
    rr = lambda x: np.hypot(x[:, 0], x[:, 1])  # noqa: E731
    return Mesh.from_arrays(
        p,
        np.array(cells),
        {
            "inner": lambda x: rr(x) < 1.2,
            "outer": lambda x: rr(x) > 1.8,
            "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
            "left": lambda x: np.abs(x[:, 0]) < 1e-12,
        },
    )


def curved_sector() -> Mesh:
    return (
        annulus_sector()
        .with_curve("inner", Circle((0, 0), 1))
        .with_curve("outer", Circle((0, 0), 2))
    )


def problem(mesh: Mesh, u=exact_u, grad=exact_grad, f=body_force) -> ContactProblem:
    def g(x, normal):
        return np.einsum("nij,nj->ni", stress(x, grad), normal)

    return ContactProblem(
        mesh,
        MATERIAL,
        {"outer": Dirichlet(u), "inner": Neumann(g), "bottom": Neumann(g), "left": Neumann(g)},
        body_force=f,
    )


def solve_linear(pb: ContactProblem, mesh: Mesh) -> tuple[P2Space, np.ndarray]:
    a = assemble(pb, mesh)
    u = np.zeros(a.space.n_dofs)
    u[a.dirichlet] = a.dirichlet_values
    free = np.setdiff1d(np.arange(a.space.n_dofs), a.dirichlet)
    rhs = a.F[free] - a.K[free][:, a.dirichlet] @ a.dirichlet_values
    u[free] = spla.spsolve(a.K[free][:, free].tocsc(), rhs)
    return a.space, u


def energy_slope() -> tuple[float, list[float]]:
    mesh = curved_sector()
    pb = problem(mesh)
    ndof, err = [], []
    for level in range(6):
        if level:
            mesh = refine_uniform(mesh).mesh
        if level < 2:
            continue
        space, u = solve_linear(pb, mesh)
        e2 = energy_error2(space.mapping, space.cell_values(u), exact_grad, MATERIAL)
        ndof.append(space.n_dofs)
        err.append(float(np.sqrt(e2.sum())))
    return float(np.polyfit(np.log(ndof), np.log(err), 1)[0]), err


@pytest.mark.slow
def test_isoparametric_cells_give_the_optimal_rate_with_a_dirichlet_arc_and_chords_do_not(
    monkeypatch,
):
    iso_slope, iso_err = energy_slope()
    # straight chords: the same meshes, nodes and data (u_D taken on the arc), but every cell
    # assembled as the straight triangle of its vertices (as before isoparametric cells)
    monkeypatch.setattr(iso, "curved_facets", lambda mesh: np.zeros(0, dtype=np.int64))
    chord_slope, chord_err = energy_slope()
    print(f"energy error vs Ndof: isoparametric slope {iso_slope:.3f} {iso_err}")
    print(f"energy error vs Ndof: straight chords slope {chord_slope:.3f} {chord_err}")
    assert -1.1 <= iso_slope <= -0.9
    assert chord_slope > -0.9
    assert iso_err[-1] < 0.5 * chord_err[-1]


def test_a_linear_field_has_zero_energy_residual_on_curved_cells():
    B = np.array([[0.3, -0.7], [0.2, 0.5]])
    c = np.array([0.1, -0.4])
    mesh = refine_uniform(curved_sector()).mesh

    def u_lin(x):
        return x @ B.T + c

    def grad_lin(x):
        return np.broadcast_to(B, (len(x), 2, 2))

    pb = problem(mesh, u_lin, grad_lin, None)
    a = assemble(pb, mesh)
    assert a.space.curved is not None and a.space.curved[0].size > 0
    u = a.space.interpolate(u_lin).ravel()
    residual = a.K @ u - a.F
    free = np.setdiff1d(np.arange(a.space.n_dofs), a.dirichlet)
    scale = np.abs(a.F).max()
    print(f"linear field: max |K u - F| on free DOFs = {np.abs(residual[free]).max():.2e}")
    assert np.abs(residual[free]).max() <= 1e-13 * scale
    # and the discrete solution is the linear field
    space, uh = solve_linear(pb, mesh)
    assert np.abs(uh - u).max() <= 1e-12


def test_curved_stiffness_is_symmetric_with_exactly_three_rigid_body_modes():
    mesh = curved_sector()
    space = P2Space(mesh)
    K = assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, MATERIAL)
    straight = assemble_stiffness(space.vertices, space.cell_dofs, space.n_dofs, MATERIAL)
    assert abs(K - K.T).max() <= 1e-14 * abs(K).max()
    assert abs(K - straight).max() > 1e-3 * abs(K).max()  # the curved cells do differ
    # the same node-block pattern as the affine assembly
    assert np.array_equal(K.indptr, straight.indptr)
    assert np.array_equal(K.indices, straight.indices)
    ev = np.linalg.eigvalsh(K.toarray())
    assert np.sum(ev < 1e-10 * ev[-1]) == 3
    assert ev[3] > 1e-4 * ev[-1]
    x = space.node_points
    modes = [
        np.tile([1.0, 0.0], space.n_nodes),
        np.tile([0.0, 1.0], space.n_nodes),
        np.column_stack([-x[:, 1], x[:, 0]]).ravel(),
    ]
    for m in modes:
        assert np.abs(K @ m).max() <= 1e-13 * abs(K).max() * np.abs(m).max()


def test_curved_cells_are_the_cells_touching_a_curved_arc():
    mesh = refine_uniform(curved_sector()).mesh
    cells = iso.curved_cells(mesh)
    arcs = np.concatenate([mesh.part_facets("inner"), mesh.part_facets("outer")])
    assert np.array_equal(cells, np.unique(mesh.facet2cell[arcs, 0]))
    assert cells.size == arcs.size  # no cell has two edges on the arcs here
    assert P2Space(annulus_sector()).curved is None


def test_the_isoparametric_area_of_the_sector_converges_like_h4():
    # sum of det J w over the curved cells + affine areas -> 3 pi / 4 at order h^4
    errors = []
    mesh = curved_sector()
    for _ in range(4):
        space = P2Space(mesh)
        one = lambda x: np.broadcast_to([1.0, 0.0], x.shape)  # noqa: E731
        F = assemble_body_force(space.mapping, space.cell_dofs, space.n_dofs, one, 4)
        errors.append(abs(F[0::2].sum() - 0.75 * np.pi))
        mesh = refine_uniform(mesh).mesh
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    print(f"area errors {errors}, rates {rates}")
    assert np.all(rates > 3.8)


def test_curved_edge_load_integrates_along_the_arc():
    # a unit traction on the quarter circle of radius 1: total force = the arc length pi / 2
    mesh = curved_sector()
    space = P2Space(mesh)
    edges = mesh.part_facets("inner")
    nodes = space.facet_nodes(edges)
    dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(-1, 6)
    one = lambda x, n: np.broadcast_to([1.0, 0.0], x.shape)  # noqa: E731
    ends = mesh.points[nodes[:, :2]]
    arc = QuadraticFacets(space.node_points[nodes])
    G = assemble_facet_load(arc, dofs, space.n_dofs, one, 8)
    chord = assemble_facet_load(ends, dofs, space.n_dofs, one, 8)
    print(f"arc length {G[0::2].sum()}, chords {chord[0::2].sum()}, exact {np.pi / 2}")
    assert abs(G[0::2].sum() - np.pi / 2) < 2e-4
    assert abs(chord[0::2].sum() - np.pi / 2) > 1e-2
    # the normal passed to the traction is the arc's outward normal (towards the origin)
    seen = []
    assemble_facet_load(arc, dofs, space.n_dofs, lambda x, n: seen.append((x, n)) or 0 * x, 8)
    x, n = seen[0]
    assert np.abs(np.hypot(*x.reshape(-1, 2).T) - 1).max() < 1e-3
    assert np.abs(n + x / np.hypot(x[..., 0], x[..., 1])[..., None]).max() < 2e-2


def test_a_mesh_without_curves_assembles_bit_identically():
    rng = np.random.default_rng(4)
    mesh = rectangle(nx=4, ny=3)
    for _ in range(3):
        mesh = refine_nvb(mesh, rng.random(mesh.n_cells) < 0.4).mesh
    space = P2Space(mesh)
    assert space.curved is None
    conditions = {"left": Dirichlet(exact_u), "bottom": Neumann(), "right": Neumann()}
    conditions["top"] = Neumann()
    a = assemble(ContactProblem(mesh, MATERIAL, conditions, body_force=body_force), mesh)
    K = assemble_stiffness(space.vertices, space.cell_dofs, space.n_dofs, MATERIAL)
    assert np.array_equal(a.K.data, K.data) and np.array_equal(a.K.indices, K.indices)
    f = lambda x: body_force(x.reshape(-1, 2)).reshape(x.shape)  # noqa: E731
    F = assemble_body_force(space.vertices, space.cell_dofs, space.n_dofs, f, 8)
    assert np.array_equal(a.F, F)


def test_curved_stiffness_quadrature_degree_is_converged():
    # degree 2 and the chosen degree give the same energy up to a small relative change
    space = P2Space(refine_uniform(curved_sector()).mesh)
    cells, nodes = space.curved
    cells = IsoparametricCells(nodes, cells)
    k2 = element_blocks(cells, MATERIAL, degree=2)
    k = element_blocks(cells, MATERIAL)
    k10 = element_blocks(cells, MATERIAL, degree=10)
    rel = lambda a, b: np.abs(a - b).max() / np.abs(b).max()  # noqa: E731
    print(
        f"curved stiffness vs degree 10: degree 2 {rel(k2, k10):.1e}, degree "
        f"{iso.STIFFNESS_DEGREE} {rel(k, k10):.1e}"
    )
    assert rel(k, k10) < 1e-5 < rel(k2, k10) < 1e-2


def test_the_body_force_is_called_only_at_points_of_the_curved_domain():
    # the chords of the inner arc r = 1 cut outside the annulus: f must not be called there
    mesh = refine_uniform(curved_sector()).mesh
    space = P2Space(mesh)
    seen = []

    def f(x):
        seen.append(np.hypot(x[..., 0], x[..., 1]))
        return np.broadcast_to([1.0, 0.0], x.shape)

    F = assemble_body_force(space.mapping, space.cell_dofs, space.n_dofs, f, 8)
    assert len(seen) == 1 and seen[0].min() >= 1.0
    assert abs(F[0::2].sum() - 0.75 * np.pi) < 1e-5
    assemble_body_force(space.vertices, space.cell_dofs, space.n_dofs, f, 8)
    assert seen[1].min() < 1.0  # the straight cells' points do leave the annulus


def test_solve_errors_and_estimate_run_on_a_mesh_with_curved_cells():
    from signorini.contact.solution import solve
    from signorini.estimator.residual import estimate
    from signorini.problem import ExactSolution

    mesh = refine_uniform(refine_uniform(curved_sector()).mesh).mesh
    pb = problem(mesh)
    pb = ContactProblem(
        mesh,
        MATERIAL,
        pb.conditions,
        body_force=body_force,
        exact=ExactSolution(exact_u, exact_grad),
    )
    result = solve(pb, mesh)
    space, u = solve_linear(pb, mesh)
    assert np.abs(result.u.ravel() - u).max() <= 1e-10
    e2 = energy_error2(space.mapping, space.cell_values(u), exact_grad, MATERIAL)
    assert result.errors()["error_energy"] == pytest.approx(np.sqrt(e2.sum()), rel=1e-8)
    eta = estimate(result)  # affine formulas on the curved cells, for now
    assert np.isfinite(eta.eta) and eta.eta > 0


def test_a_cell_folding_over_along_a_curve_is_refused_naming_it():
    # outside the unit circle, the opposite vertex closer to the arc than the arc's bulge
    p = np.array([[1.0, 0.0], [0.0, 1.0], [0.8, 0.8]])
    on_chord = lambda x: np.abs(x[:, 0] + x[:, 1] - 1) < 1e-9  # noqa: E731
    mesh = Mesh.from_arrays(
        p, np.array([[0, 2, 1]]), {"hole": on_chord, "rest": lambda x: ~on_chord(x)}
    ).with_curve("hole", Circle((0, 0), 1))
    with pytest.raises(MeshError, match=r"1 cell\(s\) along a curved .* \(first: cell 0, "):
        _ = P2Space(mesh).curved
    pb = ContactProblem(mesh, MATERIAL, {"hole": Neumann(), "rest": Dirichlet()})
    with pytest.raises(MeshError, match="refine the mesh near the curve before attaching it"):
        assemble(pb, mesh)
