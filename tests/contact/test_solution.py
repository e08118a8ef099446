"""The SOLVE step (:mod:`signorini.contact.solution`) against closed forms and independent
computations.

- patch tests: quadratic displacements (with and without contact) are reproduced at all nodes;
- the KKT conditions of (3.2), checked on a Cartesian system assembled here independently;
- the same discrete problem solved by scipy.optimize (trust-constr) and by an exact dual NNLS;
- rotation invariance, warm start, and bad input.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from contact_problems import (
    contact_patch_field,
    independent_system,
    patch_problem,
    random_quadratic,
    rotation,
)
from scipy.optimize import LinearConstraint, minimize, nnls

from signorini.contact.solution import solve
from signorini.examples import example_6_1, example_6_2
from signorini.fem.material import Material
from signorini.fem.norms import energy_error2, h1_seminorm_error2
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.problem import (
    Contact,
    ContactProblem,
    Dirichlet,
    ExactSolution,
    Neumann,
    ProblemError,
)

MATERIAL = Material.from_young(7.0, 0.28)
EXAMPLES = {"6.1": example_6_1, "6.2": example_6_2}


def nvb_mesh(mesh: Mesh, seed: int, steps: int = 3, targets: np.ndarray | None = None) -> Mesh:
    """An adaptive-like mesh: NVB towards two points (by default random points on the
    boundary) plus a few random cells."""
    rng = np.random.default_rng(seed)
    if targets is None:
        lo, hi = mesh.points.min(0), mesh.points.max(0)
        t, side = rng.random(2), rng.integers(0, 4, size=2)
        unit = np.where(
            side[:, None] % 2 == 0,
            np.column_stack([t, side // 2]),
            np.column_stack([1 - side // 2, t]),
        )  # a point on each of two sides
        targets = lo + (hi - lo) * unit
    for step in range(steps):
        c = mesh.points[mesh.cells].mean(axis=1)
        d = np.min(np.linalg.norm(c[:, None] - targets[None], axis=-1), axis=1)
        marked = (d < 0.4 * 0.7**step) | (rng.random(mesh.n_cells) < 0.05)
        mesh = refine_nvb(mesh, marked).mesh
    return mesh


def example_mesh(problem, kind: str, seed: int = 0) -> Mesh:
    if kind == "initial":
        return problem.mesh
    if kind == "uniform":
        return refine_uniform(problem.mesh).mesh
    # towards a point of Γ_C (the end of the contact zone in Example 6.2) and a corner
    targets = {"example-6.1": [[0.3, 0.0], [0.0, 1.0]], "example-6.2": [[1.0, 0.18], [0.0, 0.0]]}
    return nvb_mesh(problem.mesh, seed, steps=4, targets=np.array(targets[problem.name]))


def rotated_mesh(mesh: Mesh, R: np.ndarray, sides: dict[str, object]) -> Mesh:
    """The mesh with points ``R x``; parts chosen by predicates on the unrotated coordinates."""

    def part(pred):
        return lambda x: pred(x @ R)

    return Mesh.from_arrays(
        mesh.points @ R.T, mesh.cells, {name: part(p) for name, p in sides.items()}
    )


def square_sides(x1: float = 1.0, y1: float = 1.0, tol: float = 1e-9) -> dict[str, object]:
    return {
        "bottom": lambda x: np.abs(x[:, 1]) < tol,
        "right": lambda x: np.abs(x[:, 0] - x1) < tol,
        "top": lambda x: np.abs(x[:, 1] - y1) < tol,
        "left": lambda x: np.abs(x[:, 0]) < tol,
    }


# --------------------------------------------------------------------------------- patch tests
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_patch_test_without_contact(seed):
    rng = np.random.default_rng(seed)
    mesh = nvb_mesh(rectangle(0, 2, 0, 1, nx=4, ny=2, pattern="right"), seed)
    u = random_quadratic(rng)
    pb = patch_problem(mesh, MATERIAL, u, {"left": "D", "bottom": "D", "top": "N", "right": "N"})
    r = solve(pb)
    exact = u.value(r.space.node_points)
    err = np.abs(r.u - exact).max() / np.abs(exact).max()
    print(f"seed {seed}: {r.ndof} unknowns, max nodal error / max |u| = {err:.1e}")
    assert r.contact.size == 0 and r.contact_force.size == 0
    assert err < 1e-10


@pytest.mark.parametrize("angle", [0.0, 30.0, 200.0])
def test_contact_patch_test(angle):
    """A quadratic with u·n = ψ, σ_t = 0 and σ_nn < 0 on Γ_C is the discrete solution."""
    rng = np.random.default_rng(int(angle))
    R = rotation(angle)
    base = nvb_mesh(refine_uniform(rectangle(0, 2, 0, 1, nx=4, ny=2)).mesh, int(angle) + 7)
    mesh = rotated_mesh(base, R, square_sides(x1=2.0))
    u = contact_patch_field(rng, MATERIAL).rotated(R)
    pb = patch_problem(
        mesh,
        MATERIAL,
        u,
        {"top": "D", "left": "N", "right": "N", "bottom": "C"},
        normal=R @ [0.0, -1.0],
    )
    r = solve(pb)
    exact = u.value(r.space.node_points)
    err = np.abs(r.u - exact).max() / np.abs(exact).max()
    print(
        f"angle {angle}: {r.contact.size} constrained nodes, {int(r.active.sum())} active, "
        f"max nodal error / max |u| = {err:.1e}, min Λ = {r.contact_force.min():.3e}"
    )
    assert r.contact.size >= 17
    assert r.active.all()
    assert np.all(r.contact_force > 0)
    assert err < 1e-10


def test_large_gap_equals_the_neumann_problem():
    """With an obstacle out of reach Γ_C is traction free: Λ = 0 and u solves the Neumann
    problem (solved here with scipy directly)."""
    mesh = nvb_mesh(rectangle(nx=4, ny=4), 3)
    conditions = {"left": Dirichlet((0.05, 0.02)), "top": Neumann((0.3, -0.2)), "bottom": Neumann()}
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {**conditions, "right": Contact(gap=10.0)},
        body_force=lambda x: np.stack([x[..., 1], -x[..., 0]], axis=-1),
    )
    r = solve(pb)
    S = independent_system(pb, mesh)
    free = np.setdiff1d(np.arange(S.F.size), S.dirichlet)
    x = np.zeros(S.F.size)
    x[S.dirichlet] = S.dirichlet_values
    x[free] = spla.spsolve(S.K[free][:, free].tocsc(), (S.F - S.K @ x)[free])
    err = np.abs(r.u.ravel() - x).max() / np.abs(x).max()
    print(
        f"large gap: {r.report.iterations} PDAS iteration(s), difference to the linear solve "
        f"{err:.1e}"
    )
    assert not r.active.any() and np.all(r.contact_force == 0)
    assert r.report.iterations == 1
    assert err < 1e-10


# ------------------------------------------------------------------------------------ KKT
def kkt(system, u):
    """Relative KKT residuals of nodal displacements ``u`` for a Cartesian system."""
    x = u.ravel()
    res = system.F - system.K @ x
    absK = abs(system.K)
    force = max(np.abs(system.F).max(), (absK @ np.abs(x)).max())
    disp = max(np.abs(x).max(), np.abs(system.gap).max(initial=0))
    rz = res.reshape(-1, 2)[system.nodes]
    lam = np.einsum("kc,kc->k", rz, system.normal)
    tangent = np.column_stack([-system.normal[:, 1], system.normal[:, 0]])
    slack = np.einsum("kc,kc->k", u[system.nodes], system.normal) - system.gap
    other = np.ones(u.shape[0], dtype=bool)
    other[system.nodes] = False
    other[system.dirichlet[::2] // 2] = False
    return (
        lam,
        {
            "primal u·n − ψ ≤ 0": max(slack.max(), 0) / disp,
            "dual Λ ≥ 0": max(-lam.min(), 0) / force,
            "complementarity": np.abs(lam * slack).max() / (force * disp),
            "tangential": np.abs(np.einsum("kc,kc->k", rz, tangent)).max() / force,
            "interior": np.abs(res.reshape(-1, 2)[other]).max() / force,
            "dirichlet": np.abs(x[system.dirichlet] - system.dirichlet_values).max() / disp,
        },
        force,
    )


@pytest.mark.parametrize("kind", ["initial", "uniform", "nvb"])
@pytest.mark.parametrize("name", ["6.1", "6.2"])
def test_kkt_on_an_independent_system(name, kind):
    pb = EXAMPLES[name]()
    mesh = example_mesh(pb, kind, seed=len(name) + len(kind))
    r = solve(pb, mesh)
    S = independent_system(pb, mesh)
    assert np.array_equal(S.nodes, r.contact.nodes)
    assert np.allclose(S.normal, r.contact.normal) and np.allclose(S.gap, r.contact.gap)
    lam, res, force = kkt(S, r.u)
    worst = max(res.values())
    print(
        f"Example {name}, {kind} mesh ({r.ndof} unknowns, {int(r.active.sum())}/"
        f"{r.contact.size} active): worst KKT residual {worst:.1e}; "
        + ", ".join(f"{k} {v:.0e}" for k, v in res.items())
    )
    assert worst < 1e-10
    assert np.abs(lam - r.contact_force).max() < 1e-10 * force
    # Λ > 0 exactly on the active set (no degenerate node in these examples)
    assert np.array_equal(lam > 1e-8 * force, r.active)


@pytest.mark.parametrize("seed", [0, 1])
def test_kkt_two_contact_parts_and_a_dirichlet_corner(seed):
    """A block between two obstacles (bottom and top, non-constant gaps) touching both;
    Γ_C meets Γ_D at two corners, whose nodes are not constrained."""
    mesh = nvb_mesh(rectangle(0, 2, 0, 1, nx=4, ny=2), seed)
    pb = ContactProblem(
        mesh,
        MATERIAL,
        {
            "left": Dirichlet((0.1, -0.01)),
            "right": Neumann((0.4, 0.2)),
            "bottom": Contact(gap=lambda x: 0.01 + 0.02 * x[..., 0] ** 2),
            "top": Contact(gap=lambda x: -0.01 - 0.04 * x[..., 0]),
        },
        body_force=lambda x: np.array([0.0, -0.2]),
    )
    r = solve(pb)
    S = independent_system(pb, mesh)
    assert np.array_equal(S.nodes, r.contact.nodes)
    assert not np.isin(r.contact.nodes, S.dirichlet // 2).any()
    assert np.allclose(S.normal, r.contact.normal) and np.allclose(S.gap, r.contact.gap)
    lam, res, force = kkt(S, r.u)
    worst = max(res.values())
    n_bottom = int(np.sum(r.active & (r.contact.normal[:, 1] < 0)))
    print(
        f"seed {seed}: {r.ndof} unknowns, active {n_bottom} on the bottom and "
        f"{int(r.active.sum()) - n_bottom} on the top of {r.contact.size}, "
        f"worst KKT residual {worst:.1e}"
    )
    assert 0 < n_bottom < r.active.sum() < r.contact.size  # both obstacles touched, not all
    assert worst < 1e-10
    assert np.abs(lam - r.contact_force).max() < 1e-10 * force


# ---------------------------------------------------------------------------- independent QP
def reduced_qp(system):
    """``min ½ xᵀ K x − bᵀ x`` over the free DOFs, with rows ``B x ≤ ψ``."""
    n = system.F.size
    free = np.ones(n, dtype=bool)
    free[system.dirichlet] = False
    x_d = np.zeros(n)
    x_d[system.dirichlet] = system.dirichlet_values
    K = system.K[free][:, free].tocsc()
    b = (system.F - system.K @ x_d)[free]
    index = np.full(n, -1)
    index[free] = np.arange(free.sum())
    k = system.nodes.size
    cols = index[(2 * system.nodes[:, None] + np.arange(2)).ravel()]
    B = sp.csr_matrix(
        (system.normal.ravel(), (np.repeat(np.arange(k), 2), cols)), shape=(k, int(free.sum()))
    )
    return K, b, B, free, x_d


@pytest.mark.slow
@pytest.mark.parametrize("name", ["6.1", "6.2"])
def test_agrees_with_scipy_trust_constr(name):
    pb = EXAMPLES[name]()
    r = solve(pb)
    S = independent_system(pb, pb.mesh)
    K, b, B, free, x_d = reduced_qp(S)
    scale = K.diagonal().mean()
    K1, b1 = K / scale, b / scale
    out = minimize(
        lambda x: 0.5 * x @ (K1 @ x) - b1 @ x,
        np.zeros(K.shape[0]),
        jac=lambda x: K1 @ x - b1,
        hess=lambda x: K1,
        method="trust-constr",
        constraints=[LinearConstraint(B, -np.inf, S.gap)],
        options={"gtol": 1e-12, "xtol": 1e-14, "barrier_tol": 1e-13, "maxiter": 3000},
    )
    x = x_d.copy()
    x[free] = out.x
    diff = np.abs(x - r.u.ravel()).max() / np.abs(r.u).max()
    print(
        f"Example {name}: {K.shape[0]} unknowns, trust-constr {out.nit} iterations "
        f"(status {out.status}), max |u_qp − u_pdas| / max |u| = {diff:.1e}"
    )
    assert diff < 1e-6


@pytest.mark.parametrize("kind", ["initial", "uniform", "nvb"])
@pytest.mark.parametrize("name", ["6.1", "6.2"])
def test_agrees_with_exact_dual_nnls(name, kind):
    """The dual problem ``min_{Λ ≥ 0} ½ Λᵀ S Λ − Λᵀ (B K⁻¹ b − ψ)``, ``S = B K⁻¹ Bᵀ``, solved
    exactly by Lawson–Hanson NNLS on ``‖Lᵀ Λ − L⁻¹(B K⁻¹ b − ψ)‖``, ``S = L Lᵀ``."""
    pb = EXAMPLES[name]()
    mesh = example_mesh(pb, kind, seed=11)
    r = solve(pb, mesh)
    S = independent_system(pb, mesh)
    K, b, B, free, x_d = reduced_qp(S)
    lu = spla.splu(K)
    KiBt = lu.solve(B.T.toarray())
    Kib = lu.solve(b)
    L = np.linalg.cholesky(B @ KiBt)
    lam, _ = nnls(L.T, sl.solve_triangular(L, B @ Kib - S.gap, lower=True), maxiter=10 * b.size)
    x = x_d.copy()
    x[free] = Kib - KiBt @ lam
    du = np.abs(x - r.u.ravel()).max() / np.abs(r.u).max()
    dl = np.abs(lam - r.contact_force).max() / np.abs(lam).max()
    print(
        f"Example {name}, {kind}: {K.shape[0]} unknowns, {lam.size} constraints: "
        f"max |Δu|/max|u| = {du:.1e}, max |ΔΛ|/max Λ = {dl:.1e}"
    )
    assert du < 1e-10 and dl < 1e-9
    assert np.array_equal(lam > 0, r.active)


# ------------------------------------------------------------------------ rotation invariance
def rotated_example_6_2(mesh: Mesh, angle: float) -> ContactProblem:
    pb = example_6_2()
    R = rotation(angle)
    gap = pb.conditions["right"].gap
    return ContactProblem(
        mesh=rotated_mesh(mesh, R, square_sides()),
        material=pb.material,
        conditions={
            "left": Dirichlet(tuple(R @ [0.1, 0.0])),
            "top": Neumann(),
            "bottom": Neumann(),
            "right": Contact(gap=lambda x: gap(x @ R), normal=tuple(R @ [1.0, 0.0])),
        },
        name="example-6.2-rotated",
    )


@pytest.mark.parametrize("kind", ["initial", "nvb"])
def test_rotation_invariance(kind):
    angle = 30.0
    R = rotation(angle)
    pb = example_6_2()
    mesh = example_mesh(pb, kind, seed=5)
    ref = solve(pb, mesh)
    rot_pb = rotated_example_6_2(mesh, angle)
    rot = solve(rot_pb)
    assert np.array_equal(rot.contact.nodes, ref.contact.nodes)
    du = np.abs(rot.u - ref.u @ R.T).max() / np.abs(ref.u).max()
    dl = np.abs(rot.contact_force - ref.contact_force).max() / ref.contact_force.max()
    print(
        f"{kind} mesh, rotated by {angle}°: max |u_rot − R u| / max |u| = {du:.1e}, "
        f"max |ΔΛ| / max Λ = {dl:.1e}, active {int(ref.active.sum())} = "
        f"{int(rot.active.sum())}"
    )
    assert np.array_equal(rot.active, ref.active)
    assert du < 1e-10 and dl < 1e-10
    assert np.allclose(rot.contact.normal, R @ [1.0, 0.0], atol=1e-15)


# ---------------------------------------------------------------------------- warm start etc.
@pytest.mark.parametrize("kind", ["initial", "nvb"])
@pytest.mark.parametrize("name", ["6.1", "6.2"])
def test_warm_start_from_the_solution_takes_one_iteration(name, kind):
    pb = EXAMPLES[name]()
    mesh = example_mesh(pb, kind, seed=2)
    r = solve(pb, mesh)
    again = solve(pb, mesh, u0=r.u)
    print(
        f"Example {name}, {kind}: cold start {r.report.iterations} iterations, warm start "
        f"{again.report.iterations}"
    )
    assert again.report.iterations == 1
    assert np.array_equal(again.active, r.active)
    assert np.abs(again.u - r.u).max() <= 1e-12 * np.abs(r.u).max()


def test_warm_start_after_refinement_saves_iterations():
    pb = example_6_2()
    coarse = solve(pb)
    ref = refine_uniform(pb.mesh)
    u0 = coarse.space.prolongate(coarse.u, ref)
    cold = solve(pb, ref.mesh)
    warm = solve(pb, ref.mesh, u0=u0)
    print(
        f"Example 6.2 after one refinement: cold {cold.report.iterations}, warm "
        f"{warm.report.iterations} iterations"
    )
    assert warm.report.iterations < cold.report.iterations
    assert np.abs(warm.u - cold.u).max() <= 1e-12 * np.abs(cold.u).max()


def test_unknown_counts():
    pb = example_6_1()
    r = solve(pb)
    # 4 x 4 squares: 25 vertices + 56 edges = 81 nodes; 9 Dirichlet nodes on the top
    assert r.space.n_dofs == 162 and r.ndof == 162 - 18


@pytest.mark.parametrize("shape", [(80, 2), (81,), (162,), (81, 3)])
def test_u0_of_the_wrong_shape(shape):
    pb = example_6_1()
    with pytest.raises(ValueError, match=r"u0 must have shape \(81, 2\)"):
        solve(pb, u0=np.zeros(shape))


def test_u0_with_nan():
    pb = example_6_1()
    u0 = np.zeros((81, 2))
    u0[3, 1] = np.nan
    with pytest.raises(ValueError, match="u0 contains NaN"):
        solve(pb, u0=u0)


def test_errors_check_the_exact_gradient():
    pb = example_6_1(nx=2)
    r = solve(pb)
    # checking the user's gradient does not change the numbers
    u_cell = r.space.cell_values(r.u)
    e2 = energy_error2(r.space.vertices, u_cell, pb.exact.gradient, pb.material)
    h2 = h1_seminorm_error2(r.space.vertices, u_cell, pb.exact.gradient)
    assert r.errors() == {"error_energy": np.sqrt(e2.sum()), "error_h1": np.sqrt(h2.sum())}
    bad = ContactProblem(
        pb.mesh,
        pb.material,
        pb.conditions,
        body_force=pb.body_force,
        exact=ExactSolution(pb.exact.displacement, lambda x: x),
        name=pb.name,
    )
    with pytest.raises(ProblemError, match=r"the exact gradient must return shape \(\d+, 2, 2\)"):
        solve(bad).errors()
