"""Tests of the adaptive loop in :mod:`signorini.loop` on the paper's examples (§6)."""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import fields

import numpy as np
import pytest

from signorini.contact.contact_set import FULL_CONTACT
from signorini.estimator.marking import mark_doerfler
from signorini.examples import example_6_1, example_6_2
from signorini.loop import COLUMNS, Level, LevelRecord, adaptive
from signorini.mesh.refine import refine_nvb
from signorini.output import fitted_slope
from signorini.problem import Coulomb


# ---------------------------------------------------------------------------- helpers
def ndof_at(eta_target: float, ndof, eta) -> float:
    """Unknowns at which a decreasing history first reaches ``eta_target`` (log-log
    interpolation between the two levels around it)."""
    ndof, eta = np.asarray(ndof, dtype=float), np.asarray(eta, dtype=float)
    below = np.flatnonzero(eta <= eta_target)
    assert below.size and below[0] > 0, "the target is not bracketed by the history"
    i = below[0]
    t = np.log(eta[i - 1] / eta_target) / np.log(eta[i - 1] / eta[i])
    return float(np.exp(np.log(ndof[i - 1]) + t * np.log(ndof[i] / ndof[i - 1])))


def dirichlet_nodes_by_coordinates(points: np.ndarray, side: str) -> int:
    x, y = points[:, 0], points[:, 1]
    on = {"top": np.abs(y - 1) < 1e-12, "left": np.abs(x) < 1e-12}[side]
    return int(on.sum())


def check_record(level: Level, has_exact: bool, friction: bool = False) -> None:
    """Every field of the record is filled and agrees with the level's solution."""
    r, res, est = level.record, level.result, level.estimate
    row = r.row()
    assert set(row) == {f.name for f in fields(LevelRecord)} - {"extra"}
    assert not any(k.startswith("t_output") for k in row)  # output timing is the writer's
    for key, value in row.items():
        assert value is not None, key
        if key in ("error_energy", "error_h1", "efficiency") and not has_exact:
            assert math.isnan(value), key
        elif key.startswith("kkt_tangential") and not friction:
            assert math.isnan(value), key
        elif isinstance(value, float):
            assert math.isfinite(value), key
    assert r.ndof == res.ndof and r.ndof_total == res.space.n_dofs
    assert r.n_cells == res.mesh.n_cells
    assert r.eta == est.eta > 0
    terms = [row[f"eta_{k}"] for k in range(1, 9)]
    np.testing.assert_array_equal(terms, est.eta_terms)
    assert math.fsum(t * t for t in terms) == pytest.approx(r.eta**2, rel=1e-12)
    assert (r.eta_8 > 0) == friction
    pdas = res.report
    solves = pdas.iterations if friction else pdas.n_solves  # friction: one solve per step
    assert (r.pdas_iterations, r.n_solves, r.n_factorizations) == (
        pdas.iterations,
        solves,
        pdas.n_factorizations,
    )
    assert (r.n_analyses, r.n_updates) == (pdas.n_analyses, 0 if friction else pdas.n_updates)
    assert r.pdas_iterations >= 1 and r.n_solves >= 1 and r.n_factorizations >= 1
    assert r.n_active == int(res.active.sum()) and r.n_constrained == res.contact.size
    assert r.n_full_contact + r.n_semi_contact + r.n_no_contact == r.n_constrained
    assert r.n_full_contact == int((res.classes == FULL_CONTACT).sum())
    assert r.n_stick + r.n_slip == r.n_active and (r.n_stick > 0) == friction
    assert r.contact_force == pytest.approx(res.contact_force.sum(), rel=1e-14)
    assert r.contact_force > 0
    assert r.backend == pdas.backend != ""
    assert r.t_assemble > 0 and r.t_solve > 0 and r.t_estimate > 0
    if level.marked is not None:
        assert r.n_marked == int(level.marked.sum()) > 0
        assert r.t_mark > 0 and r.t_refine > 0
    if has_exact:
        assert r.error_energy > 0 and r.error_h1 > 0
        assert r.efficiency == pytest.approx(r.eta / r.error_energy, rel=1e-14)


# ---------------------------------------------------------------------------- loop control
def test_budget_is_never_exceeded_and_used_up():
    problem = example_6_2()
    max_ndof = 3000
    levels = list(adaptive(problem, max_ndof=max_ndof, theta=0.4))
    ndof = [lv.record.ndof for lv in levels]
    print(f"adaptive, budget {max_ndof}: ndof {ndof}")
    assert max(ndof) <= max_ndof
    assert all(b > a for a, b in zip(ndof, ndof[1:], strict=False))
    assert all(lv.marked is not None for lv in levels[:-1]) and levels[-1].marked is None
    # the loop stopped because one more step would have broken the budget
    last = levels[-1]
    refined = refine_nvb(last.result.mesh, mark_doerfler(last.estimate.eta2, 0.4)).mesh
    assert problem.free_ndof(refined) > max_ndof
    # uniform refinement: Ndof = 2 (n_nodes − Dirichlet nodes), n_cells = 32 · 4^level
    uniform = list(adaptive(problem, max_ndof=2112, uniform=True))
    assert [lv.record.ndof for lv in uniform] == [144, 544, 2112]
    assert [lv.record.n_cells for lv in uniform] == [32, 128, 512]
    for lv in uniform:
        pts = lv.result.space.node_points
        assert lv.record.ndof == 2 * (len(pts) - dirichlet_nodes_by_coordinates(pts, "left"))


def test_stops_at_tolerance_and_after_max_levels():
    problem = example_6_2()
    tol = 60.0
    levels = list(adaptive(problem, tol=tol, max_ndof=10**6))
    eta = [lv.record.eta for lv in levels]
    print(f"tol {tol}: eta {np.round(eta, 2)}")
    assert eta[-1] <= tol and all(e > tol for e in eta[:-1])
    assert levels[-1].marked is None
    levels = list(adaptive(problem, max_levels=3, max_ndof=10**6))
    assert [lv.record.level for lv in levels] == [0, 1, 2] and levels[-1].marked is None


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"theta": 0.0}, "theta"),
        ({"theta": 1.5}, "theta"),
        ({"theta": float("nan")}, "theta"),
        ({"max_ndof": 0}, "max_ndof"),
        ({"max_ndof": 100}, "initial mesh"),
    ],
)
def test_bad_arguments_raise(kwargs, message):
    with pytest.raises(ValueError, match=message):
        next(adaptive(example_6_2(), **kwargs))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"theta": "0.4"}, r"theta must be a number in \(0, 1\], got '0.4'"),
        ({"theta": "0.4", "uniform": True}, "theta must be a number"),
        ({"max_levels": 0}, "max_levels must be an integer >= 1, got 0"),
        ({"max_levels": -3}, "max_levels must be an integer >= 1, got -3"),
        ({"max_levels": 2.5}, "max_levels must be an integer >= 1, got 2.5"),
        ({"max_ndof": float("nan")}, "max_ndof must be a positive number, got nan"),
        ({"max_ndof": "1000"}, "max_ndof must be a positive number, got '1000'"),
        ({"tol": float("nan")}, "tol must be a number >= 0, got nan"),
        ({"tol": "small"}, "tol must be a number >= 0, got 'small'"),
        ({"tol": -1.0}, "tol must be a number >= 0, got -1"),
        ({"eta5_variant": "other"}, "eta5_variant must be one of"),
        ({"solver": "foo"}, "solver must be an SPDSolver or a solver factory"),
        ({"first_level": 5, "max_levels": 5}, "first_level must be below max_levels=5"),
        ({"uniform": "yes"}, "uniform must be True or False"),
    ],
)
def test_bad_arguments_raise_at_the_call_before_any_work(kwargs, message, monkeypatch):
    """The call itself raises (not the first ``next``), and nothing is solved."""
    import signorini.loop as loop

    def no_solve(*args, **kw):
        raise AssertionError("solve called")

    monkeypatch.setattr(loop, "solve", no_solve)
    with pytest.raises(ValueError, match=message):
        adaptive(example_6_2(), **kwargs)


def test_a_run_continued_from_a_level_gives_the_same_levels():
    """``mesh=level.next_mesh, u0=level.next_u0, first_level=k + 1`` continues the loop
    exactly: the records of the continued run are those of the uninterrupted one."""
    problem = example_6_2()
    full = list(adaptive(problem, max_ndof=2500))
    k = 6
    assert len(full) > k + 3 and full[-1].next_mesh is None and full[-1].next_u0 is None
    start = full[k]
    assert start.next_mesh is full[k + 1].result.mesh
    rest = list(
        adaptive(problem, max_ndof=2500, mesh=start.next_mesh, u0=start.next_u0, first_level=k + 1)
    )
    assert len(rest) == len(full) - k - 1
    for a, b in zip(full[k + 1 :], rest, strict=True):
        ra = {c: v for c, v in a.record.row().items() if not c.startswith("t_")}
        rb = {c: v for c, v in b.record.row().items() if not c.startswith("t_")}
        assert ra == rb
        np.testing.assert_array_equal(a.result.u, b.result.u)
    # without the warm start the continued level needs more PDAS iterations (cold start)
    cold = next(adaptive(problem, max_ndof=2500, mesh=start.next_mesh, first_level=k + 1))
    print("warm/cold PDAS iterations:", rest[0].record.pdas_iterations, cold.record.n_solves)
    assert cold.record.n_solves > rest[0].record.n_solves


def test_level_record_docs_name_every_field_and_what_ndof_counts():
    names = [f.name for f in fields(LevelRecord)]
    doc = LevelRecord.__doc__
    missing = [n for n in names if not re.search(rf"\b{n}\b", doc)]
    assert not missing, f"LevelRecord's docstring lacks {missing}"
    assert set(COLUMNS) == set(names) - {"extra"}
    assert "Dirichlet" in COLUMNS["ndof"] and "excluded" in COLUMNS["ndof"]
    assert "free" in doc and "``ndof_total`` minus 2 for every node" in " ".join(doc.split())
    level_fields = [f.name for f in fields(Level)]
    assert not [n for n in level_fields if f"{n} :" not in Level.__doc__]
    # the count the description states, on the initial mesh of Example 6.2 (4 x 4 squares,
    # clamped on the left: 9 Dirichlet nodes on x = 0)
    level = next(adaptive(example_6_2(), max_levels=1))
    mesh = level.result.mesh
    assert level.record.ndof_total == 2 * (mesh.n_points + mesh.n_edges) == 162
    assert level.record.ndof == 162 - 2 * 9


@pytest.mark.slow
def test_warm_start_needs_few_pdas_solves():
    """Example 6.2: from level 5 on, the prolongated solution's contact set is nearly right,
    so PDAS needs at most 2 solves per level on average (cold starts need several)."""
    problem = example_6_2()
    solves = {}
    for warm in (True, False):
        levels = list(adaptive(problem, max_ndof=8000, warm_start=warm))
        solves[warm] = np.array([lv.record.n_solves for lv in levels])
    warm_mean, cold_mean = solves[True][6:].mean(), solves[False][6:].mean()
    print(
        f"PDAS solves per level after level 5: warm {warm_mean:.2f} {solves[True].tolist()}, "
        f"cold {cold_mean:.2f} {solves[False].tolist()}"
    )
    assert len(solves[True]) > 10
    assert warm_mean <= 2.0
    assert cold_mean >= 2 * warm_mean


@pytest.mark.parametrize(("example", "has_exact"), [(example_6_1, True), (example_6_2, False)])
def test_records_have_every_field_filled(example, has_exact):
    levels = list(adaptive(example(), max_ndof=2500))
    assert len(levels) >= 4
    for lv in levels:
        check_record(lv, has_exact)
    assert [lv.record.level for lv in levels] == list(range(len(levels)))


def test_free_ndof_counts_non_dirichlet_unknowns():
    problem = example_6_1()
    for lv in adaptive(problem, max_ndof=800):
        pts = lv.result.space.node_points
        expected = 2 * (len(pts) - dirichlet_nodes_by_coordinates(pts, "top"))
        assert problem.free_ndof(lv.result.mesh) == lv.record.ndof == expected


# ---------------------------------------------------------------------------- Example 6.1
@pytest.mark.slow
def test_example_6_1_adaptive_rates_and_efficiency():
    """Adaptive Example 6.1 to ~1e5 unknowns: error and η_h ~ Ndof^{-1}, a steady
    efficiency index and full contact everywhere (η6 = η7 = 0)."""
    max_ndof = 100_000
    recs = []
    for lv in adaptive(example_6_1(), max_ndof=max_ndof):
        r = lv.record
        recs.append(r)
        assert r.eta_6 == 0.0 and r.eta_7 == 0.0
        assert r.n_full_contact == r.n_constrained > 0
        assert r.ndof <= max_ndof
    ndof = [r.ndof for r in recs]
    err = [r.error_energy for r in recs]
    eta = [r.eta for r in recs]
    eff = np.array([r.efficiency for r in recs])
    s_err, s_eta = fitted_slope(ndof, err, 8), fitted_slope(ndof, eta, 8)
    print(
        f"Example 6.1 adaptive: {len(recs)} levels, Ndof {ndof[0]}..{ndof[-1]}, "
        f"slopes over the last 8 levels: error {s_err:.3f}, eta {s_eta:.3f}; "
        f"efficiency {eff.min():.2f}..{eff.max():.2f} (max/min {eff.max() / eff.min():.3f})"
    )
    assert ndof[-1] > max_ndof / 2
    assert s_err <= -0.9, f"error: observed rate {s_err:.3f} over the last 8 levels, not -1"
    assert s_eta <= -0.9, f"eta: observed rate {s_eta:.3f} over the last 8 levels, not -1"
    assert eff.max() / eff.min() < 3


# ---------------------------------------------------------------------------- Example 6.2
@pytest.fixture(scope="module")
def run_6_2():
    """Example 6.2 adaptive to 6e4 unknowns and uniform to 4e4."""
    adaptive_levels = list(adaptive(example_6_2(), max_ndof=60_000))
    uniform_levels = list(adaptive(example_6_2(), max_ndof=40_000, uniform=True))
    return adaptive_levels, uniform_levels


@pytest.mark.slow
def test_example_6_2_adaptive_rate_and_gain_over_uniform(run_6_2):
    adaptive_levels, uniform_levels = run_6_2
    ndof = [lv.record.ndof for lv in adaptive_levels]
    eta = [lv.record.eta for lv in adaptive_levels]
    u_ndof = [lv.record.ndof for lv in uniform_levels]
    u_eta = [lv.record.eta for lv in uniform_levels]
    s_eta = fitted_slope(ndof, eta, 8)
    s_uniform = fitted_slope(u_ndof, u_eta, 2)
    print(
        f"Example 6.2 adaptive: Ndof {ndof[-1]}, eta {eta[-1]:.4f}, slope over the last 8 "
        f"levels {s_eta:.3f}; uniform: Ndof {u_ndof[-1]}, eta {u_eta[-1]:.4f}, last slope "
        f"{s_uniform:.3f}"
    )
    assert s_eta <= -0.9, f"eta: observed rate {s_eta:.3f} over the last 8 levels, not -1"
    # the singularities cap uniform refinement near Ndof^(-1/2) (measured: -0.47)
    assert -0.6 <= s_uniform <= -0.35, f"uniform eta: observed rate {s_uniform:.3f}"
    for target_level in (-2, -1):
        target = u_eta[target_level]
        n_adaptive = ndof_at(target, ndof, eta)
        n_uniform = u_ndof[target_level]
        print(
            f"eta = {target:.4f}: uniform needs {n_uniform} unknowns, adaptive "
            f"{n_adaptive:.0f} (ratio {n_uniform / n_adaptive:.1f})"
        )
        assert n_uniform >= 3 * n_adaptive


@pytest.mark.slow
def test_example_6_2_refines_at_the_singular_points(run_6_2):
    """The smallest cells gather where Γ_D meets Γ_N, (0, 0) and (0, 1), at the two ends of
    the contact zone on x = 1, and at the kink of the obstacle ψ at (1, 1/2)."""
    final = run_6_2[0][-1].result
    mesh = final.mesh
    cs = final.contact
    y = final.space.node_points[cs.nodes, 1]
    in_contact = np.sort(y[final.active])
    y_lo, y_hi = in_contact[0], in_contact[-1]
    # the contact zone is one interval, symmetric about y = 1/2
    inside = (y > y_lo) & (y < y_hi)
    assert final.active[inside].all()
    assert abs(y_lo + y_hi - 1) < 1e-9
    corners = np.array([[0, 0], [0, 1], [1, y_lo], [1, y_hi]])
    kink = np.array([[1.0, 0.5]])
    centre = mesh.points[mesh.cells].mean(axis=1)
    area = mesh.area
    smallest = np.argsort(area)[: mesh.n_cells // 100]

    def radius(points):
        d = np.linalg.norm(centre[smallest, None, :] - points[None], axis=2).min(axis=1)
        return float(d.max())

    r4, r5 = radius(corners), radius(np.vstack([corners, kink]))
    print(
        f"contact zone y in [{y_lo:.5f}, {y_hi:.5f}]; the {smallest.size} smallest cells lie "
        f"within r = {r5:.2e} of the 4 points and the kink (r = {r4:.3f} without the kink)"
    )
    assert r5 < 0.01

    def finest_near(point, radius=0.05):
        near = np.linalg.norm(centre - point, axis=1) < radius
        return float(area[near].min())

    control = np.array(
        [[0.5, 0.0], [0.5, 1.0], [0.0, 0.5], [0.5, 0.5], [1.0, 0.05], [1.0, 0.33], [1.0, 0.67]]
    )
    coarse = min(finest_near(p) for p in control)
    for p in np.vstack([corners, kink]):
        fine = finest_near(p)
        print(f"smallest cell near {np.round(p, 4)}: {fine:.2e} (away from them: {coarse:.2e})")
        assert fine <= coarse / 20


@pytest.mark.parametrize("fallback", [False, True])
def test_fallback_reaches_every_solve(fallback, monkeypatch):
    """The advice of a PDAS failure (finish with the primal active set method) can be given
    to the loop: ``adaptive(..., fallback=True)`` passes it to each level's solve."""
    import signorini.loop as loop

    seen = []
    real = loop.solve

    def spy(*args, **kw):
        seen.append(kw["fallback"])
        return real(*args, **kw)

    monkeypatch.setattr(loop, "solve", spy)
    levels = list(adaptive(example_6_2(), max_ndof=400, fallback=fallback))
    assert len(seen) == len(levels) >= 3 and set(seen) == {fallback}


def test_history_reports_the_kkt_residuals_of_each_level():
    """Every level's record carries its five relative KKT residuals, all at round-off."""
    names = ("primal", "dual", "complementarity", "stationarity", "dirichlet")
    for lv in adaptive(example_6_2(), max_ndof=3000):
        kkt = lv.result.report.kkt
        for name in names:
            value = getattr(lv.record, f"kkt_{name}")
            assert value == getattr(kkt, name), (lv.record.level, name)
            assert 0.0 <= value < 1e-12, (lv.record.level, name, value)
        assert lv.record.row()["kkt_primal"] == lv.record.kkt_primal


def test_adaptive_with_coulomb_friction_records_and_warm_starts():
    """The loop with Coulomb friction: every record field filled (the tangential KKT
    residuals at round-off, stick and slip counts), and each level warm-started from the
    prolongated solution, which takes fewer semismooth Newton steps than a cold start."""
    base = example_6_2()
    conditions = dict(base.conditions)
    conditions["right"] = dataclasses.replace(conditions["right"], friction=Coulomb(0.3))
    problem = dataclasses.replace(base, conditions=conditions)
    levels = list(adaptive(problem, max_ndof=3000))
    for level in levels:
        check_record(level, has_exact=False, friction=True)
        assert level.record.kkt_tangential_complementarity < 1e-12
    print("levels:", [(lv.record.ndof, lv.record.pdas_iterations) for lv in levels])
    k = len(levels) - 2
    start = levels[k]
    cold = next(adaptive(problem, max_ndof=3000, mesh=start.next_mesh, first_level=k + 1))
    warm = levels[k + 1]
    print("warm/cold iterations:", warm.record.pdas_iterations, cold.record.pdas_iterations)
    assert warm.record.pdas_iterations < cold.record.pdas_iterations
    np.testing.assert_allclose(
        warm.result.u, cold.result.u, atol=1e-12 * np.abs(cold.result.u).max()
    )


def test_a_3d_uniform_run_warm_starts_across_the_curved_part():
    """hertz-3d refined uniformly: the bisection puts new vertices on the sphere off the old
    cells' straight edges, and the next level still starts from the prolongated solution
    (fem/prolongation.py in the parents' reference coordinates), not cold."""
    from signorini.examples.hertz3d import hertz_3d

    problem = hertz_3d(h_contact=0.3)
    level = next(adaptive(problem, uniform=True, max_levels=3))
    assert level.next_mesh is not None and level.next_u0 is not None
    n_old = problem.mesh.n_points
    assert level.next_u0.shape == (level.next_mesh.n_points + level.next_mesh.n_edges, 3)
    np.testing.assert_array_equal(level.next_u0[:n_old], level.result.u[:n_old])
