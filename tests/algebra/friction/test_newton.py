"""Frictional contact solver (signorini.algebra.friction.newton) against independent computations.

The systems are the rotated P2 systems of a block pressed onto a curved obstacle and pulled
sideways (:func:`contact_problems.pressed_block`): contact in the middle, open ends, stick
and slip zones.
"""

from __future__ import annotations

import re
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.optimize as so
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from contact_problems import pressed_block
from linalg_problems import block_spd

from signorini.algebra import (
    SOLVERS,
    available_backends,
    make_solver,
    pardiso_solver,
    solve_pdas,
    superlu_solver,
)
from signorini.algebra.errors import FrictionConvergenceError
from signorini.algebra.friction.kkt import check_friction
from signorini.algebra.friction.newton import INACTIVE, SLIP, STICK, FrictionOptions, solve_friction
from signorini.algebra.friction.system import CoupledSystem
from signorini.problem.friction_laws import Coulomb, Tresca

#: The laws as the solver asks them; each node's data is its weight (Tresca: the bound s,
#: Coulomb: the coefficient F), so the data the objects were built with is not used here.
TRESCA = Tresca(0.0)
TRESCA_IN_CONTACT = Tresca(0.0, everywhere=False)
COULOMB = Coulomb(0.0)
OPTIONS = ("max_iter", "kkt_tol", "c")


@cache
def block():
    """16 x 8 squares, 1122 DOFs, 33 contact nodes."""
    return pressed_block(16, 8, shift=0.01)


def args(S):
    return S.K, S.F, S.normal, S.tangent, S.gap, S.dirichlet, S.dirichlet_values


def run(S, law, weight, *, reference=None, K=None, law_index=None, **kwargs):
    """solve_friction on the system ``S`` (or with the matrix ``K``) with one law, the weight
    per node, and the keyword arguments of solve_friction or FrictionOptions."""
    system = args(S) if K is None else (K, *args(S)[1:])
    problem = check_friction(
        *system, laws=law, weight=weight, law_index=law_index, reference=reference
    )
    options = {key: kwargs.pop(key) for key in OPTIONS if key in kwargs}
    return solve_friction(problem, options=FrictionOptions(**options), **kwargs)


@cache
def frictionless():
    S = block()
    return solve_pdas(S.K, S.F, S.normal, S.gap, S.dirichlet, S.dirichlet_values)


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


# ----------------------------------------------------------------------------------------------
# Tresca
# ----------------------------------------------------------------------------------------------


def tresca_by_duality(S, bound):
    """The minimiser of ``1/2 x^T K x − F^T x + Σ s |x_t|`` subject to ``x_n ≤ g``, ``x_D``
    fixed, through its dual: ``Λ`` minimises ``1/2 Λ^T S Λ − Λ^T h`` over ``Λ_n ≥ 0``,
    ``|Λ_t| ≤ s`` with ``S = B K_ff⁻¹ B^T`` and ``h = B K_ff⁻¹ F_f − (g, 0)``, solved exactly
    by bounded-variable least squares on the Cholesky factor of ``S``; then
    ``x_f = K_ff⁻¹ (F_f − B^T Λ)``. A node with ``s = 0`` has no tangential multiplier.
    Dense, and no part of the package is used. Returns ``x``, ``Λ_n``, ``Λ_t``."""
    K = S.K.toarray()
    n, m = K.shape[0], S.normal.size
    bound = np.broadcast_to(bound, (m,))
    rubs = bound > 0
    d = S.dirichlet
    free = np.setdiff1d(np.arange(n), d)
    Kff = K[np.ix_(free, free)]
    Ff = S.F[free] - K[np.ix_(free, d)] @ S.dirichlet_values
    where = np.full(n, -1)
    where[free] = np.arange(free.size)
    rows = np.concatenate([S.normal, S.tangent[rubs]])
    B = np.zeros((rows.size, free.size))
    B[np.arange(rows.size), where[rows]] = 1.0
    chol = sl.cho_factor(Kff)
    L = np.linalg.cholesky(B @ sl.cho_solve(chol, B.T))
    h = B @ sl.cho_solve(chol, Ff) - np.concatenate([S.gap, np.zeros(rubs.sum())])
    lower = np.concatenate([np.zeros(m), -bound[rubs]])
    upper = np.concatenate([np.full(m, np.inf), bound[rubs]])
    fit = so.lsq_linear(
        L.T, sl.solve_triangular(L, h, lower=True), bounds=(lower, upper), method="bvls", tol=1e-14
    )
    x = np.zeros(n)
    x[d] = S.dirichlet_values
    x[free] = sl.cho_solve(chol, Ff - B.T @ fit.x)
    lam_t = np.zeros(m)
    lam_t[rubs] = fit.x[m:]
    return x, fit.x[:m], lam_t


def energy(S, x, bound):
    return 0.5 * x @ (S.K @ x) - S.F @ x + bound * np.abs(x[S.tangent]).sum()


def test_classical_tresca_is_the_minimiser_computed_by_duality():
    S = block()
    bound = 0.1 * frictionless().multiplier.max()
    r = run(S, TRESCA, bound)
    x_ref, lam_n, lam_t = tresca_by_duality(S, bound)
    counts = np.bincount(r.state, minlength=3)
    assert counts.min() >= 3, f"states INACTIVE, STICK, SLIP occur {counts} times"
    assert ((r.state == INACTIVE) & (r.direction == 0)).sum() >= 3  # stuck out of contact too
    err = rel(r.x, x_ref)
    assert err < 1e-7, f"x differs from the minimiser by {err:.2e} (relative)"
    assert rel(r.multiplier_n, lam_n) < 1e-7, rel(r.multiplier_n, lam_n)
    assert rel(r.multiplier_t, lam_t) < 1e-7, rel(r.multiplier_t, lam_t)
    # no feasible point does better: x is not beaten by the reference nor by perturbations
    e = energy(S, r.x, bound)
    assert e <= energy(S, x_ref, bound) + 1e-12 * abs(e), (e, energy(S, x_ref, bound))
    rng = np.random.default_rng(0)
    free = np.setdiff1d(np.arange(S.K.shape[0]), S.dirichlet)
    for _ in range(5):
        y = r.x.copy()
        y[free] += 1e-4 * np.abs(r.x).max() * rng.standard_normal(free.size)
        y[S.normal] = np.minimum(y[S.normal], S.gap)
        assert energy(S, y, bound) > e
    assert r.symmetric and r.kkt.max < 1e-10, r.kkt


@pytest.mark.parametrize("seed", range(10))
def test_classical_tresca_on_random_node_blocked_systems(seed):
    """Random SPD matrices with 2 x 2 node blocks (not elasticity), random loads, gaps and
    bounds on 8 of 30 nodes: the minimiser by duality."""
    rng = np.random.default_rng(seed)
    K = block_spd(6, 5, rng, shift=0.05)
    n = K.shape[0]
    nodes = rng.choice(n // 2, 8, replace=False)
    S = SimpleNamespace(
        K=K,
        F=rng.standard_normal(n),
        normal=2 * nodes,
        tangent=2 * nodes + 1,
        gap=0.3 * rng.standard_normal(8),
        dirichlet=np.zeros(0, dtype=int),
        dirichlet_values=np.zeros(0),
    )
    bound = rng.uniform(0.0, 1.0, 8)
    r = run(S, TRESCA, bound)
    x, _, lam_t = tresca_by_duality(S, bound)
    assert rel(r.x, x) < 1e-10, rel(r.x, x)
    assert np.abs(r.multiplier_t - lam_t).max() < 1e-10 * np.abs(S.F).max()


def test_tresca_in_contact_only_is_classical_tresca_with_the_bound_cut_to_the_contact_set():
    S = block()
    bound = 0.2 * frictionless().multiplier.max()
    r = run(S, TRESCA_IN_CONTACT, bound)
    in_contact = r.state != INACTIVE
    assert not np.any(r.multiplier_t[~in_contact]), "friction force out of contact"
    counts = np.bincount(r.state, minlength=3)
    assert counts.min() >= 3, counts
    x_ref, _, _ = tresca_by_duality(S, bound * in_contact)
    assert rel(r.x, x_ref) < 1e-7, rel(r.x, x_ref)


@pytest.mark.parametrize("law", [TRESCA_IN_CONTACT, COULOMB])
def test_zero_friction_reproduces_the_frictionless_solver(law):
    S = block()
    ref = frictionless()
    r = run(S, law, 0.0)
    assert np.array_equal(r.state != INACTIVE, ref.active)
    assert rel(r.x, ref.x) < 1e-13, rel(r.x, ref.x)
    assert rel(r.multiplier_n, ref.multiplier) < 1e-12, rel(r.multiplier_n, ref.multiplier)
    assert not np.any(r.multiplier_t) and not np.any(r.state == STICK)
    assert r.iterations == ref.iterations, (r.iterations, ref.iterations)


def test_a_very_large_bound_sticks_every_contact_node():
    S = block()
    r = run(S, TRESCA_IN_CONTACT, 1e6)
    active = r.state != INACTIVE
    assert np.array_equal(r.state[active], np.full(active.sum(), STICK))
    assert active.sum() > 10
    # the linear solve with both DOFs of the contact nodes held, independently
    n = S.K.shape[0]
    held = np.concatenate([S.dirichlet, S.normal[active], S.tangent[active]])
    values = np.concatenate([S.dirichlet_values, S.gap[active], np.zeros(active.sum())])
    free = np.setdiff1d(np.arange(n), held)
    x = np.zeros(n)
    x[held] = values
    K = S.K.tocsc()
    x[free] = spla.spsolve(K[free][:, free], S.F[free] - K[free][:, held] @ values)
    assert rel(r.x, x) < 1e-10, rel(r.x, x)
    lam_n = (S.F - S.K @ x)[S.normal]
    assert lam_n[active].min() > 0 and (x[S.normal] - S.gap)[~active].max() < 0
    assert np.abs(r.multiplier_t).max() < 1e6


# ----------------------------------------------------------------------------------------------
# Coulomb
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("coefficient", [0.2, 0.5])
def test_coulomb_meets_both_laws_and_is_a_fixed_point_of_tresca(coefficient):
    S = block()
    r = run(S, COULOMB, coefficient)
    assert not r.symmetric
    assert r.kkt.max <= 1e-10, r.kkt
    counts = np.bincount(r.state, minlength=3)
    assert counts.min() >= 3, f"states INACTIVE, STICK, SLIP occur {counts} times"
    # the laws, node by node, from x alone
    lam = S.F - S.K @ r.x
    lam_n, lam_t, slide = lam[S.normal], lam[S.tangent], r.x[S.tangent]
    scale, disp = lam_n.max(), np.abs(r.x).max()
    stick, slip = r.state == STICK, r.state == SLIP
    assert np.abs(slide[stick]).max() < 1e-12 * disp
    assert np.all(np.abs(lam_t[stick]) <= coefficient * lam_n[stick] + 1e-12 * scale)
    assert np.abs(np.abs(lam_t[slip]) - coefficient * lam_n[slip]).max() < 1e-12 * scale
    assert np.all(lam_t[slip] * slide[slip] > 0), "slip along the friction force"
    # Tresca with the bound F Λ_n has the same solution
    t = run(S, TRESCA_IN_CONTACT, coefficient * r.multiplier_n)
    assert rel(t.x, r.x) < 1e-9, rel(t.x, r.x)
    assert np.array_equal(t.state, r.state)


@pytest.mark.skipif("pardiso" not in available_backends(), reason="PARDISO is not installed")
def test_coulomb_superlu_and_pardiso_agree():
    S = block()
    a = run(S, COULOMB, 0.5, solver=superlu_solver)
    b = run(S, COULOMB, 0.5, solver=pardiso_solver)
    assert (a.backend, b.backend) == ("scipy", "pardiso")
    assert rel(a.x, b.x) < 1e-11, rel(a.x, b.x)
    assert a.iterations == b.iterations and a.n_factorizations == b.n_factorizations
    assert b.n_analyses == 1 and 1 <= b.n_factorizations < b.iterations  # and updates


@pytest.mark.parametrize("backend", available_backends())
def test_a_kept_solver_analyses_the_pattern_once_across_calls(backend):
    S = block()
    with make_solver(SOLVERS[backend], symmetric=False) as solver:
        first = run(S, COULOMB, 0.5, solver=solver)
        second = run(S, COULOMB, 0.2, solver=solver)
    assert (first.n_analyses, second.n_analyses) == (1, 0)
    assert 1 <= second.n_factorizations <= second.iterations
    with make_solver(SOLVERS[backend]) as solver:
        first = run(S, TRESCA_IN_CONTACT, 1e-3, solver=solver)
        second = run(S, TRESCA_IN_CONTACT, 2e-3, solver=solver)
    assert (first.n_analyses, second.n_analyses) == (1, 0)


def test_a_load_step_from_its_own_solution_does_not_slip():
    """With ``x_ref`` the converged tangential displacement and the same load, the law acts on
    a zero slip increment: the same solution, and every contact node sticks or is at its
    bound without moving."""
    S = block()
    r = run(S, COULOMB, 0.5)
    again = run(S, COULOMB, 0.5, reference=r.x[S.tangent])
    assert rel(again.x, r.x) < 1e-10, rel(again.x, r.x)
    assert again.kkt.max < 1e-10
    shifted = run(S, COULOMB, 0.5, reference=r.x[S.tangent] + 1e-3)
    assert rel(shifted.x, r.x) > 1e-3  # the reference is used


# ----------------------------------------------------------------------------------------------
# warm start, failure, input
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("law, weight", [(TRESCA, 0.05), (TRESCA_IN_CONTACT, 0.05), (COULOMB, 0.5)])
def test_warm_start_from_the_converged_states_takes_one_solve(law, weight):
    S = block()
    if law is not COULOMB:
        weight *= frictionless().multiplier.max() * 2
    r = run(S, law, weight)
    assert r.iterations > 2
    again = run(S, law, weight, state0=r.state, direction0=r.direction)
    assert again.iterations == 1, again.history
    assert rel(again.x, r.x) < 1e-13
    from_x = run(S, law, weight, x0=r.x)
    assert from_x.iterations <= 2, from_x.history


def test_non_convergence_raises_with_the_history():
    S = block()
    with pytest.raises(FrictionConvergenceError, match="max_iter = 2") as err:
        run(S, COULOMB, 0.5, max_iter=2)
    assert err.value.reason == "max_iter" and len(err.value.history) == 2
    assert "iteration history" in str(err.value)
    with pytest.raises(FrictionConvergenceError, match="KKT residual") as err:
        run(S, COULOMB, 0.5, kkt_tol=1e-30)
    assert err.value.reason == "kkt" and err.value.x.shape == S.F.shape


@pytest.mark.parametrize(
    "change, message",
    [
        ({"weight": -0.1}, "weight must be non-negative"),
        ({"weight": np.nan}, "weight has non-finite"),
        ({"weight": np.ones(3)}, r"weight must have shape \(33,\)"),
        ({"gap": np.zeros(5)}, r"gap must have shape \(33,\)"),
        ({"tangent": "normal"}, "normal and tangent share 33 DOFs"),
        ({"tangent": "dirichlet"}, "tangent must name one DOF per"),
        ({"tangent": "first dirichlet"}, "tangent and dirichlet share 1 DOFs"),
        ({"laws": "tresca"}, "laws must be a friction law or a sequence of them"),
        ({"laws": (TRESCA, 0.3)}, "laws must be a friction law or a sequence of them"),
        ({"law_index": np.full(33, 1)}, r"law_index must lie in \[-1, 1\)"),
        ({"law_index": np.zeros(5, dtype=int)}, r"law_index must be an integer array"),
        ({"state0": np.full(33, 3)}, "state0 must have shape"),
        ({"state0": np.full(33, SLIP)}, "direction0 is needed"),
        ({"max_iter": 0}, "max_iter must be a positive integer"),
        ({"c": -1.0}, "c must be positive"),
        ({"kkt_tol": 0.0}, "kkt_tol must be a positive number"),
        ({"reference": np.inf}, "reference has non-finite"),
        ({"problem": "the system"}, "problem must be a FrictionProblem"),
    ],
)
def test_bad_input_is_named(change, message):
    S = block()
    data = dict(
        zip(
            ["K", "F", "normal", "tangent", "gap", "dirichlet", "dirichlet_values"],
            args(S),
            strict=True,
        )
    )
    data.update(laws=TRESCA_IN_CONTACT, weight=1.0)
    change = dict(change)
    if change.get("tangent") == "normal":
        change["tangent"] = S.normal
    elif change.get("tangent") == "dirichlet":
        change["tangent"] = S.dirichlet
    elif change.get("tangent") == "first dirichlet":
        change["tangent"] = np.concatenate([S.tangent[:-1], S.dirichlet[:1]])
    solve_keys = ("state0", "direction0", "problem")
    solve_args = {key: change.pop(key) for key in solve_keys if key in change}
    options = {key: change.pop(key) for key in OPTIONS if key in change}
    data.update(change)
    with pytest.raises(ValueError, match=message):
        problem = solve_args.pop("problem", None) or check_friction(**data)
        solve_friction(problem, options=FrictionOptions(**options), **solve_args)


def _coulomb_variants(state: np.ndarray, direction: np.ndarray) -> list[tuple[np.ndarray, ...]]:
    """States ``(active, stick, direction)``: the given ones, then variants a few nodes away
    from them (a slip direction flipped; a sticking node slipping and a slipping one
    sticking; a node out of contact sticking and a sticking one leaving contact), then five
    sticking nodes leaving contact (ten DOFs released)."""
    slip, stick, out = (np.flatnonzero(state == s) for s in (SLIP, STICK, INACTIVE))
    variants = []
    for change in ({slip[0]: (SLIP, -direction[slip[0]])},
                   {stick[0]: (SLIP, 1), slip[1]: (STICK, 0)},
                   {out[0]: (STICK, 0), stick[1]: (INACTIVE, 0)},
                   {k: (INACTIVE, 0) for k in stick[2:7]}):  # fmt: skip
        s, d = state.copy(), direction.astype(float)
        for node, (new, sign) in change.items():
            s[node], d[node] = new, sign
        variants.append((s != INACTIVE, s == STICK, d))
    return [(state != INACTIVE, state == STICK, direction.astype(float)), *variants]


@pytest.mark.parametrize("backend", available_backends())
def test_coulomb_systems_a_few_nodes_away_are_solved_by_a_low_rank_update(backend):
    """Coulomb's LU systems whose states differ from the factorized ones at a few nodes
    (held DOFs released and held, a slip direction flipped) are solved with that LU and a
    low-rank correction, no new factorization, to round-off of a new factorization's solution;
    ten changed DOFs (beyond ``max_update``) are refactorized."""
    S = block()
    r = run(S, COULOMB, 0.5)
    problem = check_friction(*args(S), laws=COULOMB, weight=0.5)
    states = _coulomb_variants(r.state, r.direction)
    with (
        make_solver(SOLVERS[backend], symmetric=False) as lu,
        make_solver(SOLVERS[backend], symmetric=False) as fresh,
    ):
        system = CoupledSystem(problem, lu)
        for k, (active, stick, direction) in enumerate(states):
            x = system.solve(active, stick, direction)
            y = CoupledSystem(problem, fresh, max_update=0).solve(active, stick, direction)
            assert rel(x, y) < 1e-11, (k, rel(x, y))
            assert lu.n_factorizations == (1 if k < len(states) - 1 else 2), k
    assert fresh.n_factorizations == len(states)


@pytest.mark.skipif("pardiso" not in available_backends(), reason="PARDISO is not installed")
def test_an_update_that_fails_its_residual_check_is_refactorized(monkeypatch):
    """With a residual bound no update meets, every changed system is factorized anew: the
    same solution, a factorization per system."""
    import signorini.algebra.active_system as active_system

    S = block()
    r = run(S, COULOMB, 0.5)
    problem = check_friction(*args(S), laws=COULOMB, weight=0.5)
    states = _coulomb_variants(r.state, r.direction)[:3]
    with make_solver(pardiso_solver, symmetric=False) as lu:
        expected = [CoupledSystem(problem, lu).solve(*s) for s in states]
    monkeypatch.setattr(active_system, "UPDATE_RTOL", 0.0)
    with make_solver(pardiso_solver, symmetric=False) as lu:
        system = CoupledSystem(problem, lu)
        for s, y in zip(states, expected, strict=True):
            assert rel(system.solve(*s), y) < 1e-11
        assert lu.n_factorizations == len(states)


def test_the_coulomb_matrix_keeps_the_pattern_of_a_non_blocked_k():
    """A K whose normal and tangential rows have different columns: the tangential rows are
    widened, and the result still meets both laws."""
    S = block()
    coo = S.K.tocoo()
    row, col = S.normal[5], S.normal[5] + 40  # an explicit zero in the normal row only
    assert S.K[row, col] == 0 and S.K[row + 1, col] == 0
    K = sp.csr_matrix(
        (np.append(coo.data, 0.0), (np.append(coo.row, row), np.append(coo.col, col))),
        shape=S.K.shape,
    )
    assert K.nnz == S.K.nnz + 1
    r = run(S, COULOMB, 0.5, K=K)
    ref = run(S, COULOMB, 0.5)
    assert rel(r.x, ref.x) < 1e-12


def test_the_tangent_is_a_basis_of_one_column_in_2d():
    """``tangent (m, d − 1)``: in 2D ``(m, 1)``; a 1-D tangent (indices or a mask) is that
    column, and both give the same solve bit for bit."""
    S = block()
    K, F, normal, tangent, gap, dirichlet, values = args(S)
    weight = 0.3 * np.ones(normal.size)
    line = check_friction(*args(S), laws=COULOMB, weight=weight)
    basis = check_friction(
        K, F, normal, tangent[:, None], gap, dirichlet, values, laws=COULOMB, weight=weight
    )
    mask = np.zeros(K.shape[0], dtype=bool)
    mask[tangent] = True
    masked = check_friction(K, F, normal, mask, gap, dirichlet, values, laws=COULOMB, weight=weight)
    for problem in (line, basis, masked):
        assert problem.tangent.shape == (normal.size, 1) and problem.tangent.dtype == np.int64
        np.testing.assert_array_equal(problem.tangent_2d, np.sort(tangent))
    assert np.array_equal(line.tangent, basis.tangent)
    a, b = solve_friction(line), solve_friction(basis)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.state, b.state)


@pytest.mark.parametrize(
    "shape, error, message",
    [
        ("two columns", NotImplementedError, "2 tangential DOFs per node (d = 3)"),
        ("one row short", ValueError, "tangent must be (m, d - 1) = (33, d - 1)"),
        ("no column", ValueError, "tangent must be (m, d - 1)"),
        ("three axes", ValueError, "tangent must be (m,) or (m, d - 1)"),
        ("floats", ValueError, "tangent must hold integer DOF indices"),
    ],
)
def test_a_tangent_basis_of_the_wrong_shape_is_refused(shape, error, message):
    S = block()
    K, F, normal, tangent, gap, dirichlet, values = args(S)
    free = np.setdiff1d(np.arange(K.shape[0]), np.concatenate([normal, tangent, dirichlet]))
    column = tangent[:, None]
    bad = {
        "two columns": np.column_stack([tangent, free[: tangent.size]]),
        "one row short": column[:-1],
        "no column": column[:, :0],
        "three axes": column[:, :, None],
        "floats": column.astype(float),
    }[shape]
    with pytest.raises(error, match=re.escape(message)):
        check_friction(K, F, normal, bad, gap, dirichlet, values, laws=TRESCA, weight=0.1)
