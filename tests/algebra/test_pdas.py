"""Primal-dual active set solver (signorini.algebra.pdas) against independent QP solutions."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.optimize as so
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from linalg_problems import block_spd, p2_elasticity, random_spd_dense

from signorini.algebra.linsolve import available_backends, make_solver
from signorini.algebra.pdas import (
    PDASConvergenceError,
    PDASResult,
    kkt_residuals,
    solve_pdas,
)
from signorini.contact.node_frames import rotate_frames, to_cartesian

BACKEND_LIST = available_backends()

# A 4 x 4 SPD problem on which plain PDAS (c = mean diagonal) cycles: found by a random search
# over matrices with one decimal; the bounds are on all four DOFs.
CYCLING_K = np.array(
    [
        [2.4, -1.2, -2.4, 1.8],
        [-1.2, 4.6, 4.2, -3.8],
        [-2.4, 4.2, 5.2, -2.8],
        [1.8, -3.8, -2.8, 7.0],
    ]
)
CYCLING_F = np.array([0.0, 0.8, -0.1, -0.5])
CYCLING_G = np.array([0.3, 0.4, -0.1, 1.4])


def brute_force_qp(K, F, c, g, d=(), xd=()):
    """Exact minimizer by enumerating all 2^m active sets (dense, independent of the package).

    For each candidate set S the bounds on S are equalities, the rest is dropped; the unique
    KKT point (strict convexity) is the candidate that is feasible with non-negative
    multipliers. Returns (x, lam, active).
    """
    K = np.asarray(K.toarray() if sp.issparse(K) else K, dtype=float)
    n = K.shape[0]
    c = np.asarray(c)
    d = np.asarray(d, dtype=int)
    best = None
    for bits in itertools.product([False, True], repeat=c.size):
        S = np.array(bits, dtype=bool)
        fixed = np.zeros(n, dtype=bool)
        fixed[d] = True
        fixed[c[S]] = True
        x = np.zeros(n)
        x[d] = xd
        x[c[S]] = g[S]
        free = ~fixed
        rhs = F[free] - K[np.ix_(free, fixed)] @ x[fixed]
        x[free] = np.linalg.solve(K[np.ix_(free, free)], rhs)
        lam = F[c] - K[c] @ x
        scale = np.abs(F).max() + np.abs(K).max() * np.abs(x).max() + 1e-300
        if (x[c] - g <= 1e-10 * (np.abs(g).max() + np.abs(x).max() + 1e-300)).all() and (
            lam[S] >= -1e-10 * scale
        ).all():
            assert best is None or np.allclose(best[0], x, atol=1e-8), "two KKT points"
            best = (x, np.where(S, lam, 0.0), S)
    assert best is not None
    return best


def random_problem(rng, n, m, n_dirichlet=0, dense=True):
    if dense:
        K = sp.csr_matrix(random_spd_dense(n, rng))
    else:
        K = block_spd(n // 2, 1, rng, shift=0.05)
        n = K.shape[0]
    perm = rng.permutation(n)
    c = perm[:m]
    d = perm[m : m + n_dirichlet]
    F = rng.standard_normal(n)
    g = 0.3 * rng.standard_normal(m)
    xd = 0.2 * rng.standard_normal(n_dirichlet)
    return K, F, c, g, d, xd


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
    assert isinstance(result, PDASResult)
    assert np.array_equal(result.x, [0.5, 2.0, 0.0, -4.0])
    assert np.allclose(result.lam, [0.5, 0.0, 1.0], rtol=0, atol=1e-15)
    assert np.array_equal(result.active, [True, False, True])
    assert result.iterations == 2  # unconstrained solve, then the violated set
    assert result.method == "pdas"
    assert result.c_scale == 1.0
    assert_kkt(result, 1e-15)


def test_kkt_residuals_closed_form():
    K = sp.identity(3, format="csr")
    F = np.array([1.0, 2.0, 0.0])
    c, g = np.array([0, 1]), np.array([0.5, 5.0])
    x = np.array([0.6, 2.0, 0.0])  # violates x_0 <= 0.5 by 0.1, multiplier 0.4
    kkt = kkt_residuals(K, F, x, c, g)
    assert kkt.disp_scale == 5.0  # max(|x|, |g|)
    assert kkt.force_scale == 2.0  # max(|F|, |K||x|)
    assert np.isclose(kkt.primal, 0.1 / 5.0)
    assert kkt.dual == 0.0
    assert np.isclose(kkt.complementarity, 0.4 * 0.1 / (2.0 * 5.0))
    assert kkt.stationarity == 0.0
    x2 = np.array([0.5, 2.0, 0.3])  # free row residual -0.3; x_0 at the bound
    kkt2 = kkt_residuals(K, F, x2, c, g, dirichlet=[2], dirichlet_values=0.1)
    assert np.isclose(kkt2.dirichlet, 0.2 / 5.0)
    assert kkt2.stationarity == 0.0  # row 2 is a Dirichlet row, not a free one
    kkt3 = kkt_residuals(K, np.array([0.0, 2.0, 0.0]), np.array([0.5, 2.0, 0.0]), c, g)
    assert np.isclose(kkt3.dual, 0.5 / 2.0)  # multiplier -0.5 at the active bound
    assert np.isclose(kkt3.max, 0.25)


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
    result = solve_pdas(K, F, c, g, d, xd, fallback=True)
    assert_kkt(result)
    assert np.array_equal(result.x[d], xd)
    assert np.array_equal(result.x[c[result.active]], g[result.active])
    assert (result.lam[~result.active] == 0).all()
    assert (result.lam >= 0).all()
    assert result.n_analyses == 1
    # every iteration either refactorizes or reuses the factor with a low-rank update
    assert result.n_factorizations + result.n_updates == result.n_solves == result.iterations


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1), n=st.integers(2, 12), m=st.integers(1, 8), n_d=st.integers(0, 2)
)
def test_matches_brute_force(seed, n, m, n_d):
    m = min(m, n)
    n_d = min(n_d, n - m)
    rng = np.random.default_rng(seed)
    K, F, c, g, d, xd = random_problem(rng, n, m, n_d)
    x_ref, lam_ref, active_ref = brute_force_qp(K, F, c, g, d, xd)
    result = solve_pdas(K, F, c, g, d, xd, fallback=True)
    scale = np.abs(x_ref).max() + 1e-300
    assert np.abs(result.x - x_ref).max() < 1e-9 * scale
    assert np.abs(result.lam - lam_ref).max() < 1e-8 * (np.abs(lam_ref).max() + 1)


@pytest.mark.parametrize("seed", range(5))
def test_degenerate_constraints_do_not_flip(seed):
    # x* is the unconstrained minimizer and sits exactly on half of the bounds (lam = 0 there,
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
    cold = solve_pdas(K, F, c, g, d, xd, backend=backend)
    assert cold.iterations >= 2 and cold.active.any()
    warm = solve_pdas(K, F, c, g, d, xd, active0=cold.active, backend=backend)
    assert (warm.iterations, warm.n_solves, warm.n_factorizations) == (1, 1, 1)
    assert np.allclose(warm.x, cold.x, rtol=0, atol=1e-12 * np.abs(cold.x).max())
    from_x = solve_pdas(K, F, c, g, d, xd, x0=cold.x, backend=backend)
    assert from_x.iterations == 1
    assert np.array_equal(from_x.active, cold.active)
    assert warm.backend == backend


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_solver_reuse_across_calls(backend):
    rng = np.random.default_rng(9)
    K, F, c, g, d, xd = random_problem(rng, 80, 20, 4, dense=False)
    solver = make_solver(backend)
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
    # the solver is still usable by the caller afterwards
    x = solver.solve(np.ones(K.shape[0]))
    assert np.isfinite(x).all()


def test_backends_agree():
    if len(BACKEND_LIST) < 2:
        pytest.skip("only one backend available")
    rng = np.random.default_rng(10)
    K, F, c, g, d, xd = random_problem(rng, 120, 50, 10, dense=False)
    a, b = (solve_pdas(K, F, c, g, d, xd, backend=name) for name in BACKEND_LIST)
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
    result = solve_pdas(K, CYCLING_F, np.arange(4), CYCLING_G, fallback=True)
    assert result.method == "primal-active-set"
    assert any(step.method == "primal-active-set" for step in result.history)
    x_ref, lam_ref, active_ref = brute_force_qp(CYCLING_K, CYCLING_F, np.arange(4), CYCLING_G)
    assert np.abs(result.x - x_ref).max() < 1e-12
    assert np.array_equal(result.active, active_ref)
    assert_kkt(result, 1e-14)


def test_max_iter_reached():
    rng = np.random.default_rng(12)
    K, F, c, g, d, xd = random_problem(rng, 50, 25, dense=False)
    full = solve_pdas(K, F, c, g)
    assert full.iterations >= 3
    with pytest.raises(PDASConvergenceError, match="max_iter = 1") as info:
        solve_pdas(K, F, c, g, max_iter=1)
    assert info.value.reason == "max_iter"
    assert len(info.value.history) == 1 and info.value.x.shape == (K.shape[0],)
    rescued = solve_pdas(K, F, c, g, max_iter=1, fallback=True)
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
    assert np.allclose(rz @ normal, result.lam, rtol=0, atol=1e-10 * np.abs(rz).max())
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
        (lambda p: p.update(gap=np.array([0.0, np.nan, 0.0])), "gap has non-finite"),
        (lambda p: p.update(gap=np.zeros(4)), r"gap must have shape \(3,\)"),
        (lambda p: p.update(F=np.zeros(7)), r"F must have shape \(8,\)"),
        (lambda p: p.update(dirichlet=np.r_[p["dirichlet"][0], p["constrained"][1]]), "overlap"),
        (lambda p: p.update(constrained=np.array([0, 0, 1])), "constrained has repeated"),
        (lambda p: p.update(constrained=np.array([0, 1, 9])), "constrained has indices outside"),
        (lambda p: p.update(constrained=np.array([0.0, 1.0, 2.0])), "constrained must hold int"),
        (lambda p: p.update(dirichlet_values=np.ones(3)), "dirichlet_values must have shape"),
        (lambda p: p.update(dirichlet_values=np.inf), "dirichlet_values has non-finite"),
        (lambda p: p.update(K=p["K"][:, :7]), "K must be square"),
        (lambda p: p.update(K=p["K"].toarray()), "K must be a scipy sparse"),
        (lambda p: p.update(c=-1.0), "c must be positive"),
        (lambda p: p.update(max_iter=0), "max_iter must be a positive integer"),
        (lambda p: p.update(active0=np.ones(2, dtype=bool)), "active0 must be a boolean"),
        (lambda p: p.update(x0=np.ones(3)), r"x0 must have shape \(8,\)"),
        (lambda p: p.update(backend="cholmod"), "unknown backend 'cholmod'"),
        (lambda p: p.update(solver="pardiso"), "solver must be an SPDSolver"),
    ],
)
def test_bad_input_names_the_argument(small, change, message):
    K, F, c, g, d, xd = small
    params = {"K": K, "F": F, "constrained": c, "gap": g, "dirichlet": d, "dirichlet_values": xd}
    change(params)
    with pytest.raises(ValueError, match=message):
        solve_pdas(**params)


def test_mask_and_index_forms_agree(small):
    K, F, c, g, d, xd = small
    n = K.shape[0]
    mask_d = np.zeros(n, dtype=bool)
    mask_d[d] = True
    order = np.argsort(d)
    a = solve_pdas(K, F, c, g, d, xd)
    b = solve_pdas(K, F, c, g, mask_d, xd[order])
    full = np.zeros(n)
    full[d] = xd
    e = solve_pdas(K, F, c, g, mask_d, full)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.x, e.x)


def test_no_constraints_is_a_linear_solve():
    rng = np.random.default_rng(4)
    K = block_spd(5, 5, rng)
    F = rng.standard_normal(K.shape[0])
    result = solve_pdas(K, F, np.zeros(0, dtype=int), np.zeros(0))
    assert result.iterations == 1 and result.active.size == 0
    assert np.abs(K @ result.x - F).max() < 1e-10 * np.abs(F).max()


@pytest.mark.parametrize("backend", BACKEND_LIST)
def test_low_rank_updates_agree_with_refactorization(backend):
    """Small active-set changes reuse the factorization (Woodbury) with the same result."""
    rng = np.random.default_rng(21)
    used = 0
    for _ in range(6):
        K, F, c, g, d, xd = random_problem(rng, 120, 12, 6, dense=False)
        exact = solve_pdas(K, F, c, g, d, xd, backend=backend, max_update=0)
        updated = solve_pdas(K, F, c, g, d, xd, backend=backend, max_update=12)
        assert exact.n_updates == 0
        assert updated.n_factorizations + updated.n_updates == updated.iterations
        assert np.array_equal(updated.active, exact.active)
        scale = np.abs(exact.x).max()
        np.testing.assert_allclose(updated.x, exact.x, rtol=0, atol=1e-10 * scale)
        assert_kkt(updated)
        used += updated.n_updates
    print(f"{backend}: {used} iterations solved by low-rank updates")
    assert used > 0


def test_max_update_validation():
    rng = np.random.default_rng(3)
    K, F, c, g, d, xd = random_problem(rng, 10, 3, 1, dense=True)
    with pytest.raises(ValueError, match="max_update must be a non-negative integer"):
        solve_pdas(K, F, c, g, d, xd, max_update=-1)
