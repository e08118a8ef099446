"""The paper's Examples 6.1 and 6.2 (signorini.examples) solved on uniform meshes.

Example 6.1 has a known solution: the energy and H¹ errors must decay like Ndof⁻¹ (P2,
smooth solution), the total contact force tends to ∫_0^1 3(2 − x) dx = 4.5 and the pressure to
3(2 − x). Example 6.2 has none: its contact zone must be one interval around y = 1/2 whose
ends and total force settle under refinement.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.examples import EXAMPLES, example_6_1, example_6_2, get_example
from signorini.fem.material import stress
from signorini.fem.p2 import physical_points
from signorini.fem.quadrature import triangle_rule
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.refine import refine_uniform
from signorini.output import fitted_slope
from signorini.problem import Contact, Dirichlet, Neumann

# 4 x 4 squares and four uniform refinements: up to 33,024 unknowns (Example 6.1: ~4 s, so
# its tests are marked slow; Example 6.2: ~2 s)
LEVELS = 5


def uniform_levels(problem, levels):
    mesh, out = problem.mesh, []
    for level in range(levels):
        if level:
            mesh = refine_uniform(mesh).mesh
        out.append(solve(problem, mesh))
    return out


@pytest.fixture(scope="module")
def levels_6_1():
    return uniform_levels(example_6_1(), LEVELS)


@pytest.fixture(scope="module")
def levels_6_2():
    return uniform_levels(example_6_2(), LEVELS)


# -------------------------------------------------------------------------------- Example 6.1
def test_example_6_1_data_are_consistent():
    """u solves its own problem: f = −div σ(u) (by central differences of the exact stress),
    u = 0 on the top, u·n = 0, σ_t = 0 and σ_nn = 3(x − 2) < 0 on the bottom."""
    pb = example_6_1()
    exact, mat = pb.exact, pb.material
    assert (mat.lam, mat.mu) == (1.0, 1.0)
    rng = np.random.default_rng(0)
    x = rng.uniform(0.1, 0.9, size=(20, 2))
    h = 1e-4
    div = np.zeros((20, 2))
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        ds = (stress(mat, exact.gradient(x + e)) - stress(mat, exact.gradient(x - e))) / (2 * h)
        div += ds[:, :, j]
    assert np.allclose(pb.body_force(x), -div, atol=1e-6)
    t = np.linspace(0, 1, 11)
    top = np.column_stack([t, np.ones_like(t)])
    bottom = np.column_stack([t, np.zeros_like(t)])
    assert np.abs(exact.displacement(top)).max() < 1e-15
    assert np.abs(exact.displacement(bottom)).max() < 1e-15
    sig = stress(mat, exact.gradient(bottom))
    assert np.abs(sig[:, 0, 1]).max() < 1e-15
    assert np.allclose(sig[:, 1, 1], 3 * (t - 2), atol=1e-14)
    assert isinstance(pb.conditions["top"], Dirichlet)
    assert isinstance(pb.conditions["left"], Neumann)
    assert isinstance(pb.conditions["bottom"], Contact)
    assert np.allclose(pb.contact_normals["bottom"], [0, -1])


@pytest.mark.slow
def test_example_6_1_converges_like_ndof_to_the_minus_one(levels_6_1):
    ndof = np.array([r.ndof for r in levels_6_1])
    errs = [r.errors() for r in levels_6_1]
    energy = np.array([e["error_energy"] for e in errs])
    h1 = np.array([e["error_h1"] for e in errs])
    for r, e, s in zip(ndof, energy, h1, strict=True):
        print(f"Ndof {r:6d}  energy error {e:.4e}  H1 error {s:.4e}")
    slope_e = fitted_slope(ndof, energy, last=3)
    slope_h = fitted_slope(ndof, h1, last=3)
    print(f"fitted slopes over the last three levels: energy {slope_e:.4f}, H1 {slope_h:.4f}")
    assert ndof[-1] > 30_000
    assert -1.1 <= slope_e <= -0.9, f"energy error slope {slope_e:.3f}, expected -1"
    assert -1.1 <= slope_h <= -0.9, f"H1 error slope {slope_h:.3f}, expected -1"
    # and level by level: halving h divides both errors by about 4
    assert np.all(np.abs(energy[-3:-1] / energy[-2:] - 4) < 0.2)
    assert np.all(np.abs(h1[-3:-1] / h1[-2:] - 4) < 0.2)


@pytest.mark.slow
def test_example_6_1_contact_force_and_pressure(levels_6_1):
    force = np.array([r.total_contact_force for r in levels_6_1])
    p_err = []
    for r in levels_6_1:
        x = r.space.node_points[r.contact.nodes, 0]
        p_err.append(np.abs(r.pressure - 3 * (2 - x)).max())
        assert r.active.all() and r.report.kkt.max < 1e-12
    p_err = np.array(p_err)
    for r, f, e in zip(levels_6_1, force, p_err, strict=True):
        print(
            f"Ndof {r.ndof:6d}  ΣΛ = {f:.10f}  |ΣΛ − 4.5| = {abs(f - 4.5):.2e}  "
            f"max |p_z − 3(2 − x)| = {e:.2e}"
        )
    assert np.all(np.diff(np.abs(force - 4.5)) < 0)
    assert abs(force[-1] - 4.5) < 1e-6
    # p_z → p at the nodes like h² (each uniform refinement divides the error by about 4)
    assert np.all(p_err[1:] / p_err[:-1] < 0.3)
    assert p_err[-1] < 2e-4
    # the paper's density s_z is 2/3 and 4/3 of the pressure, not the pressure
    r = levels_6_1[-1]
    x = r.space.node_points[r.contact.nodes, 0]
    v = r.contact.is_vertex
    assert np.allclose(r.density[v], 2 / 3 * 3 * (2 - x[v]), rtol=1e-3)
    assert np.allclose(r.density[~v], 4 / 3 * 3 * (2 - x[~v]), rtol=1e-3)


# -------------------------------------------------------------------------------- Example 6.2
def test_example_6_2_data():
    pb = example_6_2()
    mat = pb.material
    assert mat.young == pytest.approx(500.0, rel=1e-14)
    assert mat.poisson == pytest.approx(0.3, rel=1e-14)
    assert mat.mu == pytest.approx(500 / 2.6, rel=1e-14)
    assert mat.lam == pytest.approx(500 * 0.3 / (1.3 * 0.4), rel=1e-14)
    gap = pb.conditions["right"].gap
    y = np.array([0.0, 0.25, 0.5, 1.0])
    x = np.column_stack([np.ones_like(y), y])
    assert np.allclose(gap(x), [0.05, -0.075, -0.2, 0.05], atol=1e-15)
    assert pb.conditions["left"].value == (0.1, 0.0)
    assert np.allclose(pb.contact_normals["right"], [1, 0])
    assert pb.body_force is None and pb.exact is None


def contact_zone(r):
    """Active nodes on x = 1 sorted by y: (y of each node, active flags)."""
    y = r.space.node_points[r.contact.nodes, 1]
    order = np.argsort(y)
    return y[order], r.active[order]


def test_example_6_2_contact_zone_is_one_interval(levels_6_2):
    lows, highs, force = [], [], []
    for r in levels_6_2:
        y, active = contact_zone(r)
        idx = np.flatnonzero(active)
        spacing = np.diff(y).max()
        lows.append(y[idx[0]])
        highs.append(y[idx[-1]])
        force.append(r.total_contact_force)
        print(
            f"Ndof {r.ndof:6d}: contact zone [{lows[-1]:.6f}, {highs[-1]:.6f}] "
            f"({idx.size} of {y.size} nodes, spacing {spacing:.5f}), ΣΛ = {force[-1]:.8f}, "
            f"{r.report.iterations} PDAS iterations"
        )
        assert idx[-1] - idx[0] + 1 == idx.size, "the active set has a gap"
        assert lows[-1] < 0.5 < highs[-1]
        assert abs((lows[-1] - 0.5) + (highs[-1] - 0.5)) <= spacing + 1e-12
        # Λ > 0 inside the zone, 0 outside; the obstacle is never penetrated
        lam = r.contact_force[np.argsort(r.space.node_points[r.contact.nodes, 1])]
        assert np.all(lam[idx] > 0) and np.all(lam[~active] == 0)
        assert r.report.kkt.max < 1e-12
    lows, highs, force = map(np.array, (lows, highs, force))
    spacing = 0.125 / 2.0 ** np.arange(LEVELS)  # node spacing on x = 1 at each level
    d_force = np.abs(np.diff(force))
    d_low = np.abs(np.diff(lows))
    print("successive changes of ΣΛ:", np.array2string(d_force, precision=4))
    print(
        "successive changes of the lower end:", d_low, "of the upper end:", np.abs(np.diff(highs))
    )
    assert np.all(np.diff(d_force) < 0), "the total contact force does not settle"
    assert np.all(d_low <= spacing[:-1] + 1e-12) and np.all(d_low[-2:] <= 0.02)
    assert np.allclose(lows + highs, 1.0, atol=1e-12)  # symmetric mesh: exactly symmetric
    assert 0.16 < lows[-1] < 0.19
    with pytest.raises(ValueError, match="example-6.2 has no exact solution"):
        levels_6_2[0].errors()


def test_example_6_2_solution_is_symmetric(levels_6_2):
    """The union-jack mesh is symmetric about y = 1/2, so u_x(x, 1 − y) = u_x(x, y) and
    u_y(x, 1 − y) = −u_y(x, y)."""
    r = levels_6_2[2]
    x = r.space.node_points

    def code(p):  # node coordinates are multiples of 1/64 here: exact integer codes
        k = np.round(p * 256).astype(np.int64)
        return k[:, 0] * 1024 + k[:, 1]

    codes = code(x)
    mirror = code(np.column_stack([x[:, 0], 1 - x[:, 1]]))
    order = np.argsort(codes)
    pos = order[np.searchsorted(codes[order], mirror)]
    assert np.array_equal(codes[pos], mirror)
    scale = np.abs(r.u).max()
    assert np.abs(r.u[pos, 0] - r.u[:, 0]).max() < 1e-12 * scale
    assert np.abs(r.u[pos, 1] + r.u[:, 1]).max() < 1e-12 * scale
    assert np.abs(r.u[:, 1]).max() > 1e-3 * scale  # not trivially symmetric


# ------------------------------------------------------------------------------------ lookup
def test_get_example():
    assert set(EXAMPLES) == {
        "example-6.1",
        "example-6.2",
        "example-6.2-tresca",
        "example-6.2-coulomb",
        "hertz",
        "punch",
        "partial-slip",
        "two-cylinders",
        "stacked-blocks",
        "hertz-pair",
        "elasticity-3d",
        "hertz-3d",
        "example-6.1-3d",
        "example-6.2-3d",
        "punch-3d",
        "stacked-cubes",
        "two-spheres",
        "partial-slip-3d",
        "partial-slip-spheres",
    }
    for name in EXAMPLES:
        assert get_example(name).name == name
    with pytest.raises(ValueError, match="unknown example 'example-6.3'"):
        get_example("example-6.3")


@pytest.mark.parametrize("example", [example_6_1, example_6_2])
def test_initial_mesh_size(example):
    """``nx`` × ``nx`` squares, each cut in two by a union-jack diagonal: 2 nx² cells of
    area 1/(2 nx²) on the grid of spacing 1/nx, mirror-symmetric about both centre lines,
    each side one boundary part of nx edges; the problem's data do not depend on nx."""
    default = example()

    def cells_as_points(points, cells):
        return sorted(tuple(sorted(map(tuple, np.round(points[c], 12)))) for c in cells)

    for nx in (2, 4, 6):
        pb = example(nx=nx)
        mesh = pb.mesh
        assert (mesh.n_cells, mesh.n_points) == (2 * nx**2, (nx + 1) ** 2)
        np.testing.assert_allclose(mesh.points * nx, np.round(mesh.points * nx), atol=1e-12)
        np.testing.assert_allclose(mesh.area, 0.5 / nx**2, rtol=1e-13)
        cells = cells_as_points(mesh.points, mesh.cells)
        for mirror in ([-1.0, 1.0], [1.0, -1.0]):
            flipped = (mesh.points - 0.5) * mirror + 0.5
            assert cells_as_points(flipped, mesh.cells) == cells
        for name in ("left", "right", "top", "bottom"):
            assert mesh.part_facets(name).size == nx
        assert pb.material == default.material and pb.conditions.keys() == default.conditions.keys()


def test_example_6_1_error_falls_with_the_initial_mesh_size():
    """Halving h of the initial mesh divides the energy error by about 4 (P2, smooth u)."""
    errors = [solve(example_6_1(nx=nx)).errors()["error_energy"] for nx in (4, 8)]
    print(f"energy error nx=4 {errors[0]:.4e}, nx=8 {errors[1]:.4e}")
    assert 3.5 < errors[0] / errors[1] < 4.5, f"ratio {errors[0] / errors[1]:.3f}, expected 4"


def test_example_6_1_energy_error_obeys_galerkin_orthogonality():
    """Every constrained node of Example 6.1 is in contact and u·n = 0 on Γ_C exactly, so u_h is
    the Galerkin projection onto {v_h : v_h·n = 0 on Γ_C} and
    a(u − u_h, u − u_h) = a(u, u) − a(u_h, u_h): an independent check of the error norm,
    the loads and the solver together."""
    problem = example_6_1()
    mesh = problem.mesh
    for _ in range(2):
        r = solve(problem, mesh)
        space = r.space
        K = assemble_stiffness(space.vertices, space.cell_dofs, space.n_dofs, problem.material)
        a_h = r.u.ravel() @ (K @ r.u.ravel())
        xi, w = triangle_rule(14)
        G = problem.exact.gradient(physical_points(space.vertices, xi))
        eps = 0.5 * (G + np.swapaxes(G, -1, -2))
        a = np.einsum("q,mqij,mqij,m->", w, stress(problem.material, G), eps, 2 * mesh.area)
        e2 = r.errors()["error_energy"] ** 2
        print(f"Ndof {r.ndof}: a(e,e) = {e2:.12e}, a(u,u) - a(u_h,u_h) = {a - a_h:.12e}")
        assert abs(e2 - (a - a_h)) <= 1e-8 * e2
        mesh = refine_uniform(mesh).mesh
