"""Primal-dual active set solver (signorini.algebra.pdas) against independent QP solutions."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.optimize as so
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from linalg_problems import (
    CYCLING_F,
    CYCLING_G,
    CYCLING_K,
    block_spd,
    brute_force_qp,
    just_touching_square,
    p2_elasticity,
    random_problem,
    random_spd_dense,
)

from signorini.algebra import (
    SOLVERS,
    PDASConvergenceError,
    PDASOptions,
    available_backends,
    eliminate_symmetric,
    make_solver,
    solve_pdas,
)
from signorini.contact.node_frames import rotate_frames, to_cartesian

BACKEND_LIST = available_backends()


def assert_kkt(result, tol=1e-10):
    kkt = result.kkt
    assert kkt.max < tol, f"KKT residuals too large: {kkt}"


# ----------------------------------------------------------------------------------------------
# closed form
# ----------------------------------------------------------------------------------------------


def test_identity_closed_form():
    # K = I: the minimizer is min(F, g) on constrained DOFs and F elsewhere.
    K = sp.identity(4, format="csr")
    F = np.array([1.0, 2.0, 0.0, -3.0])
    c = np.array([0, 1, 3])
    g = np.array([0.5, 5.0, -4.0])
    result = solve_pdas(K, F, c, g)
    assert np.array_equal(result.x, [0.5, 2.0, 0.0, -4.0])
    assert np.allclose(result.multiplier, [0.5, 0.0, 1.0], rtol=0, atol=1e-15)
    assert np.array_equal(result.active, [True, False, True])
    assert result.iterations == 2  # unconstrained solve, then the violated set
    assert result.method == "pdas"
    assert result.c_scale == 1.0
    assert_kkt(result, 1e-15)


# ----------------------------------------------------------------------------------------------
# random problems
# ----------------------------------------------------------------------------------------------


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(5, 200),
    frac_c=st.floats(0.05, 1.0),
    frac_d=st.floats(0.0, 0.5),
    dense=st.booleans(),
)
def test_kkt_on_random_problems(seed, n, frac_c, frac_d, dense):
    rng = np.random.default_rng(seed)
    n_total = n if dense else 2 * (n // 2)
    m = max(1, int(frac_c * n_total))
    n_d = min(int(frac_d * n_total), n_total - m)
    if n_d == n_total - m and n_d > 0:
        n_d -= 1
    K, F, c, g, d, xd = random_problem(rng, n, m, n_d, dense=dense)
    result = solve_pdas(K, F, c, g, d, xd, options=PDASOptions(fallback=True))
    assert_kkt(result)
    assert np.array_equal(result.x[d], xd)
    assert np.array_equal(result.x[c[result.active]], g[result.active])
    assert (result.multiplier[~result.active] == 0).all()
    assert (result.multiplier >= 0).all()
    assert result.n_analyses == 1
    # every iteration either refactorizes or reuses the factor with a low-rank update
    assert result.n_factorizations + result.n_updates == result.n_solves == result.iterations


def bvls_reference(K, F, c, g, d, xd):
    """The QP as a bounded least-squares problem solved by SciPy's BVLS: with the Dirichlet
    DOFs eliminated and ``K_ff = R^T R``, ``1/2 y^T K_ff y - f^T y = 1/2 |R y - R^{-T} f|^2 +
    const``."""
    K = K.toarray()
    n = K.shape[0]
    free = np.ones(n, dtype=bool)
    free[d] = False
    x = np.zeros(n)
    x[d] = xd
    f = F[free] - K[np.ix_(free, ~free)] @ x[~free]
    R = sl.cholesky(K[np.ix_(free, free)])
    upper = np.full(free.sum(), np.inf)
    upper[np.searchsorted(np.flatnonzero(free), c)] = g
    ref = so.lsq_linear(
        R, sl.solve_triangular(R, f, trans="T"), bounds=(-np.inf, upper), method="bvls", tol=1e-14
    )
    x[free] = ref.x
    return x


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1), n=st.integers(2, 12), m=st.integers(1, 8), n_d=st.integers(0, 2)
)
def test_meets_kkt_and_matches_brute_force_qp(seed, n, m, n_d):
    """On tiny random SPD systems PDAS meets the KKT conditions (checked here, independently
    of the package's residuals) and equals both the enumeration of all active sets and
    SciPy's bounded least squares."""
    m = min(m, n)
    n_d = min(n_d, n - m)
    rng = np.random.default_rng(seed)
    K, F, c, g, d, xd = random_problem(rng, n, m, n_d)
    result = solve_pdas(K, F, c, g, d, xd, options=PDASOptions(fallback=True))
    x, multiplier = result.x, result.multiplier
    # KKT: feasibility, sign, complementarity, stationarity off the bounds, Dirichlet values
    r = F - K @ x
    scale = np.abs(F).max() + np.abs(K.toarray()).max() * np.abs(x).max()
    other = np.setdiff1d(np.arange(n), np.concatenate([c, d]))
    assert (x[c] - g <= 1e-12 * (np.abs(g).max() + np.abs(x).max())).all()
    assert (multiplier >= 0).all() and (multiplier[~result.active] == 0).all()
    assert np.array_equal(x[c[result.active]], g[result.active])
    assert np.abs(multiplier - np.where(result.active, r[c], 0.0)).max() <= 1e-12 * scale
    assert np.abs(r[other]).max(initial=0.0) <= 1e-10 * scale
    assert np.array_equal(x[d], xd)
    # the minimizer by enumeration and by SciPy
    x_ref, multiplier_ref, active_ref = brute_force_qp(K, F, c, g, d, xd)
    x_scale = np.abs(x_ref).max() + 1e-300
    assert np.abs(x - x_ref).max() < 1e-9 * x_scale
    assert np.abs(multiplier - multiplier_ref).max() < 1e-8 * (np.abs(multiplier_ref).max() + 1)
    assert np.abs(x - bvls_reference(K, F, c, g, d, xd)).max() < 1e-8 * x_scale


@pytest.mark.parametrize("seed", range(5))
def test_degenerate_constraints_do_not_flip(seed):
    # x* is the unconstrained minimizer and sits exactly on half of the bounds (multiplier 0 there,
    # x = g): round-off must not make the active set oscillate.
    rng = np.random.default_rng(seed)
    n, m = 40, 20
    K = sp.csr_matrix(random_spd_dense(n, rng))
    x_star = rng.standard_normal(n)
    F = K @ x_star
    c = rng.permutation(n)[:m]
    g = x_star[c] + np.where(np.arange(m) < m // 2, 0.0, 1.0)
    for active0 in (None, np.arange(m) < m // 2, np.ones(m, dtype=bool)):
        result = solve_pdas(K, F, c, g, active0=active0)
        assert result.method == "pdas"
        assert np.abs(result.x - x_star).max() < 1e-10 * np.abs(x_star).max()
        assert_kkt(result, 1e-12)


def test_matches_scipy_slsqp():
    rng = np.random.default_rng(42)
    n, m = 30, 12
    K, F, c, g, _, _ = random_problem(rng, n, m)
    Kd = K.toarray()
    bounds = [(None, None)] * n
    for i, gi in zip(c, g, strict=True):
        bounds[i] = (None, gi)
    ref = so.minimize(
        lambda x: 0.5 * x @ Kd @ x - F @ x,
        np.zeros(n),
        jac=lambda x: Kd @ x - F,
        method="SLSQP",
        bounds=bounds,
        options={"ftol": 1e-14, "maxiter": 500},
    )
    assert ref.success
    result = solve_pdas(K, F, c, g)
    assert result.method == "pdas"
    assert np.abs(result.x - ref.x).max() < 1e-6 * np.abs(ref.x).max()
    objective = 0.5 * result.x @ Kd @ result.x - F @ result.x
    assert objective <= ref.fun + 1e-12 * abs(ref.fun)


# ----------------------------------------------------------------------------------------------
# warm starts, reuse, backends
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_warm_start_from_exact_active_set_takes_one_solve(backend):
    rng = np.random.default_rng(8)
    K, F, c, g, d, xd = random_problem(rng, 60, 30, 5, dense=False)
    cold = solve_pdas(K, F, c, g, d, xd, solver=SOLVERS[backend])
    assert cold.iterations >= 2 and cold.active.any()
    warm = solve_pdas(K, F, c, g, d, xd, active0=cold.active, solver=SOLVERS[backend])
    assert (warm.iterations, warm.n_solves, warm.n_factorizations) == (1, 1, 1)
    assert np.allclose(warm.x, cold.x, rtol=0, atol=1e-12 * np.abs(cold.x).max())
    from_x = solve_pdas(K, F, c, g, d, xd, x0=cold.x, solver=SOLVERS[backend])
    assert from_x.iterations == 1
    assert np.array_equal(from_x.active, cold.active)
    assert warm.backend == backend


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_solver_reuse_across_calls(backend):
    rng = np.random.default_rng(9)
    K, F, c, g, d, xd = random_problem(rng, 80, 20, 4, dense=False)
    solver = make_solver(SOLVERS[backend])
    first = solve_pdas(K, F, c, g, d, xd, solver=solver)
    second = solve_pdas(K, F, c, 0.5 * g, d, xd, solver=solver)
    assert first.n_analyses == 1
    assert second.n_analyses == 0  # same pattern: the analysis is kept by the solver
    assert solver.n_factorizations + first.n_updates + second.n_updates == (
        first.iterations + second.iterations
    )
    assert_kkt(first)
    assert_kkt(second)
    assert second.times["analysis"] == 0.0
    assert set(second.times) == {"analysis", "factorization", "solve", "elimination", "total"}
    # the solver is still the caller's, and still analysed for K: a new factorization of K
    # with the final active set fixed reproduces the second solution, with no new analysis
    fixed = np.zeros(K.shape[0], dtype=bool)
    fixed[d] = True
    fixed[c[second.active]] = True
    values = np.zeros(K.shape[0])
    values[d] = xd
    values[c] = np.where(second.active, 0.5 * g, 0.0)
    A, b = eliminate_symmetric(K, F, fixed, values)
    solver.factorize(A)
    x = solver.solve(b)
    assert np.abs(x - second.x).max() < 1e-10 * np.abs(second.x).max()
    assert solver.n_analyses == 1


def test_backends_agree():
    if len(BACKEND_LIST) < 2:
        pytest.skip("only one backend available")
    rng = np.random.default_rng(10)
    K, F, c, g, d, xd = random_problem(rng, 120, 50, 10, dense=False)
    a, *others = (solve_pdas(K, F, c, g, d, xd, solver=SOLVERS[name]) for name in BACKEND_LIST)
    for b in others:
        assert np.array_equal(a.active, b.active)
        assert np.abs(a.x - b.x).max() < 1e-11 * np.abs(a.x).max()


# ----------------------------------------------------------------------------------------------
# non-convergence
# ----------------------------------------------------------------------------------------------


def test_cycling_is_detected_and_fallback_solves():
    K = sp.csr_matrix(CYCLING_K)
    with pytest.raises(PDASConvergenceError, match="cycles") as info:
        solve_pdas(K, CYCLING_F, np.arange(4), CYCLING_G)
    err = info.value
    assert err.reason == "cycling"
    assert len(err.history) >= 2
    assert "iteration history" in str(err) and "fallback=True" in str(err)
    # the advice names every place it can be given
    assert "adaptive()" in str(err) and "--fallback" in str(err)
    result = solve_pdas(K, CYCLING_F, np.arange(4), CYCLING_G, options=PDASOptions(fallback=True))
    assert result.method == "primal-active-set"
    assert any(step.method == "primal-active-set" for step in result.history)
    x_ref, multiplier_ref, active_ref = brute_force_qp(
        CYCLING_K, CYCLING_F, np.arange(4), CYCLING_G
    )
    assert np.abs(result.x - x_ref).max() < 1e-12
    assert np.array_equal(result.active, active_ref)
    assert_kkt(result, 1e-13)  # relative to the contact force 0.66, not max |K||x| = 4.8


def test_max_iter_reached():
    rng = np.random.default_rng(12)
    K, F, c, g, d, xd = random_problem(rng, 50, 25, dense=False)
    full = solve_pdas(K, F, c, g)
    assert full.iterations >= 3
    with pytest.raises(PDASConvergenceError, match="max_iter = 1") as info:
        solve_pdas(K, F, c, g, options=PDASOptions(max_iter=1))
    assert info.value.reason == "max_iter"
    assert len(info.value.history) == 1 and info.value.x.shape == (K.shape[0],)
    rescued = solve_pdas(K, F, c, g, options=PDASOptions(max_iter=1, fallback=True))
    assert rescued.method == "primal-active-set"
    assert np.abs(rescued.x - full.x).max() < 1e-10 * np.abs(full.x).max()


# ----------------------------------------------------------------------------------------------
# elasticity: a block pushed onto a rigid foundation, in rotated frames
# ----------------------------------------------------------------------------------------------


def test_elastic_block_on_inclined_foundation():
    """P2 block, top pushed by u_D, bottom nodes above a foundation with normal n (tilted)."""
    K, xy = p2_elasticity(4, 4, lam=1.0, mu=1.0)
    n_nodes = len(xy)
    top = np.flatnonzero(xy[:, 1] > 1 - 1e-12)
    bottom = np.flatnonzero(xy[:, 1] < 1e-12)
    angle = np.deg2rad(20.0)
    normal = np.array([np.sin(angle), -np.cos(angle)])  # outward, tilted from (0, -1)
    normals = np.tile(normal, (bottom.size, 1))
    F = np.zeros(2 * n_nodes)
    K_rot, F_rot = rotate_frames(K, F, bottom, normals)
    dirichlet = np.concatenate([2 * top, 2 * top + 1])
    values = np.concatenate([np.full(top.size, 0.02), np.full(top.size, -0.1)])
    gap = 0.01 * xy[bottom, 0]  # the foundation recedes linearly
    result = solve_pdas(K_rot, F_rot, 2 * bottom, gap, dirichlet, values)
    assert result.method == "pdas"
    assert_kkt(result)
    u = to_cartesian(result.x, bottom, normals)
    # penetration u.n - gap <= 0 at every bottom node, equality where active
    un = u[2 * bottom] * normal[0] + u[2 * bottom + 1] * normal[1]
    assert (un - gap <= 1e-12).all()
    assert np.abs((un - gap)[result.active]).max() < 1e-14
    assert result.active.sum() >= bottom.size // 2
    # frictionless: the Cartesian residual at a contact node is parallel to the normal,
    # and its size is the contact force
    r = F - K @ u
    rz = np.column_stack([r[2 * bottom], r[2 * bottom + 1]])
    tangent = np.array([-normal[1], normal[0]])
    assert np.abs(rz @ tangent).max() < 1e-10 * np.abs(rz).max()
    assert np.allclose(rz @ normal, result.multiplier, rtol=0, atol=1e-10 * np.abs(rz).max())
    # cross-check: SLSQP on the Cartesian problem with linear constraints u.n <= gap
    free = np.ones(2 * n_nodes, dtype=bool)
    free[dirichlet] = False
    u_fixed = np.zeros(2 * n_nodes)
    u_fixed[dirichlet] = values
    Kd = K.toarray()
    Kff = Kd[np.ix_(free, free)]
    f = -Kd[np.ix_(free, ~free)] @ u_fixed[~free]
    idx = np.flatnonzero(free)
    A = np.zeros((bottom.size, idx.size))
    rows = np.arange(bottom.size)
    A[rows, np.searchsorted(idx, 2 * bottom)] = normal[0]
    A[rows, np.searchsorted(idx, 2 * bottom + 1)] = normal[1]
    ref = so.minimize(
        lambda y: 0.5 * y @ Kff @ y - f @ y,
        np.zeros(idx.size),
        jac=lambda y: Kff @ y - f,
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": lambda y: gap - A @ y, "jac": lambda y: -A}],
        options={"ftol": 1e-15, "maxiter": 1000},
    )
    assert ref.success
    assert np.abs(u[free] - ref.x).max() < 1e-6 * np.abs(ref.x).max()


# ----------------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------------


@pytest.fixture
def small():
    rng = np.random.default_rng(0)
    K, F, c, g, d, xd = random_problem(rng, 8, 3, 2)
    return K, F, c, g, d, xd


@pytest.mark.parametrize(
    "change,message",
    [
        (lambda p: p.update(F=np.where(np.arange(8) == 2, np.nan, p["F"])), "F has non-finite"),
        (lambda p: p.update(c=-1.0), "c must be positive"),
        (lambda p: p.update(c=np.inf), "c must be positive and finite"),
        (lambda p: p.update(max_iter=0), "max_iter must be a positive integer"),
        (lambda p: p.update(max_iter=True), "max_iter must be a positive integer, got True"),
        (lambda p: p.update(max_update=-1), "max_update must be a non-negative integer"),
        (lambda p: p.update(max_update=2.0), "max_update must be a non-negative integer"),
        (lambda p: p.update(active0=np.ones(2, dtype=bool)), "active0 must be a boolean"),
        (lambda p: p.update(active0=np.ones(3)), "active0 must be a boolean"),
        (lambda p: p.update(x0=np.ones(3)), r"x0 must have shape \(8,\)"),
        (lambda p: p.update(solver=42), r"SPDSolver or a solver factory \(.*\), got 42"),
        (lambda p: p.update(solver="pardiso"), "solver must be an SPDSolver"),
    ],
)
def test_bad_input_names_the_argument(small, change, message):
    K, F, c, g, d, xd = small
    params = {"K": K, "F": F, "constrained": c, "gap": g, "dirichlet": d, "dirichlet_values": xd}
    change(params)
    with pytest.raises(ValueError, match=message):
        options = {key: params.pop(key) for key in ("c", "max_iter", "max_update") if key in params}
        solve_pdas(**params, options=PDASOptions(**options))


def test_no_constraints_is_a_linear_solve():
    rng = np.random.default_rng(4)
    K = block_spd(5, 5, rng)
    F = rng.standard_normal(K.shape[0])
    result = solve_pdas(K, F, np.zeros(0, dtype=int), np.zeros(0))
    assert result.iterations == 1 and result.active.size == 0
    assert np.abs(K @ result.x - F).max() < 1e-10 * np.abs(F).max()


# ----------------------------------------------------------------------------------------------
# degenerate complementarity: the obstacle exactly where the body ends up
# ----------------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_just_touching_converges_cold_and_warm(backend):
    # 33k unknowns: the solution's round-off (|x_c - g| ~ 1e-12 |g|) decided the active set by
    # its sign and PDAS cycled between the empty and the full set
    K, F, c, d, xd = just_touching_square(64)
    x_exact = np.zeros(K.shape[0])
    x_exact[0::2] = 0.1
    m = c.size
    starts = {
        "cold": {},
        "all active": {"active0": np.ones(m, dtype=bool)},
        "half active": {"active0": np.arange(m) % 2 == 0},
        "warm x0": {"x0": x_exact},
    }
    for name, start in starts.items():
        result = solve_pdas(K, F, c, 0.1, d, xd, solver=SOLVERS[backend], **start)
        assert result.method == "pdas", name
        assert result.iterations == 1, (name, [str(s) for s in result.history])
        assert np.abs(result.x - x_exact).max() < 1e-10, name
        assert np.abs(result.multiplier).max() < 1e-9, name
        assert_kkt(result, 1e-10)
