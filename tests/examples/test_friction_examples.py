"""The friction examples through the adaptive loop: Example 6.2 with Coulomb friction and the
partial-slip cylinder (signorini.examples.paper_friction, signorini.examples.partial_slip).

Each must converge at the optimal rate (η_h like Ndof⁻¹), refine at the stick–slip
transition points, and meet the KKT conditions of both laws on every level; the partial-slip
cylinder's stick zone must follow Cattaneo–Mindlin, c/a = √(1 − Q/(F P)), on its final level.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini import adaptive
from signorini.examples import (
    EXAMPLES,
    PARTIAL_SLIP_METRICS,
    example_6_2_coulomb,
    partial_slip,
    partial_slip_path,
)
from signorini.examples.partial_slip import POISSON
from signorini.output import fitted_slope
from signorini.problem import Coulomb

#: the examples' budgets: about 25 and 17 levels, a few seconds each
BUDGET_62, BUDGET_SLIP = 30_000, 20_000
#: Dundurs' β of the cylinder against the rigid plane
BETA = (1 - 2 * POISSON) / (2 * (1 - POISSON))


@pytest.fixture(scope="module")
def coulomb_levels():
    return list(adaptive(example_6_2_coulomb(), max_ndof=BUDGET_62))


@pytest.fixture(scope="module")
def slip_levels():
    steps = partial_slip_path()
    return list(
        adaptive(steps[-1], path=steps[:-1], max_ndof=BUDGET_SLIP, metrics=PARTIAL_SLIP_METRICS)
    )


def slope_of(levels, last: int = 5) -> float:
    ndof = np.array([lv.record.ndof for lv in levels], dtype=float)
    return fitted_slope(ndof, np.array([lv.record.eta for lv in levels]), last=last)


def transitions(result, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """The points where the node state changes along Γ_C (midway between the two nodes,
    coordinate ``axis``): the contact ends and the stick–slip transitions; and the states
    on either side, ``(m, 2)``."""
    x = result.space.node_points[result.contact.nodes, axis]
    order = np.argsort(x)
    x, state = x[order], result.state[order]
    change = np.flatnonzero(state[1:] != state[:-1])
    return 0.5 * (x[change] + x[change + 1]), np.stack([state[change], state[change + 1]], 1)


def contact_edges(result, axis: int) -> tuple[np.ndarray, np.ndarray]:
    """Midpoint coordinate ``axis`` and length of every contact edge."""
    mesh, edges = result.mesh, result.contact.facets
    ends = mesh.points[mesh.edges[edges]]
    return ends[:, :, axis].mean(axis=1), mesh.edge_length[edges]


def check_refined_at_transitions(result, axis: int, zone: tuple[float, float]) -> None:
    """At every transition point the mesh is refined locally: the contact edge nearest to it
    is at most half the largest contact edge within a quarter of the contact zone's width
    ``zone`` from it (Γ_C's edges on either side)."""
    points, sides = transitions(result, axis)
    mid, length = contact_edges(result, axis)
    window = 0.25 * (zone[1] - zone[0])
    print(f"transitions (states) and contact edges within {window:.3f}:")
    for p, (s0, s1) in zip(points, sides, strict=True):
        nearest = length[np.argmin(np.abs(mid - p))]
        around = length[np.abs(mid - p) <= window].max()
        print(f"  at {p:+.4f} ({s0}→{s1}): nearest edge {nearest:.2e}, largest around {around:.2e}")
        assert nearest <= 0.5 * around, (p, nearest, around)
    assert {1, 2} <= set(sides.ravel().tolist()), "no stick–slip transition"


def check_kkt(levels) -> None:
    worst = max(
        max(
            r.kkt_primal,
            r.kkt_dual,
            r.kkt_complementarity,
            r.kkt_stationarity,
            r.kkt_tangential_bound,
            r.kkt_tangential_complementarity,
        )
        for r in (lv.record for lv in levels)
    )
    print(f"largest KKT residual of both laws over the levels: {worst:.1e}")
    assert worst <= 1e-10, worst


@pytest.mark.slow
def test_example_6_2_coulomb_rate_refinement_and_kkt(coulomb_levels):
    levels = coulomb_levels
    print("\nlevel  Ndof    η_h       η8        stick slip  iterations")
    for lv in levels[-6:]:
        r = lv.record
        print(
            f"{r.level:3d} {r.ndof:6d}  {r.eta:.3e}  {r.eta_8:.2e}  {r.n_stick:4d} {r.n_slip:4d}"
            f"  {r.pdas_iterations}"
        )
    slope = slope_of(levels)
    print(f"η_h slope over the last 5 levels: {slope:.3f}")
    assert slope <= -0.9, f"η_h slope {slope:.3f} > −0.9"
    check_kkt(levels)
    last = levels[-1].result
    assert last.problem.conditions["right"].friction == Coulomb(0.3)
    assert levels[-1].record.n_stick > 0 and levels[-1].record.n_slip > 0
    check_refined_at_transitions(last, axis=1, zone=(0.2, 0.8))


@pytest.mark.slow
def test_partial_slip_rate_refinement_kkt_and_cattaneo_mindlin(slip_levels):
    levels = slip_levels
    print("\nlevel  Ndof    η_h       c/a     theory  Q/(F P)  iterations (both steps)")
    for lv in levels:
        r, e = lv.record, lv.record.extra
        print(
            f"{r.level:3d} {r.ndof:6d}  {r.eta:.3e}  {e['c_over_a']:.4f}  "
            f"{e['c_over_a_theory']:.4f}  {e['q_over_fp']:.4f}  {r.pdas_iterations}"
        )
    slope = slope_of(levels)
    print(f"η_h slope over the last 5 levels: {slope:.3f}")
    assert slope <= -0.9, f"η_h slope {slope:.3f} > −0.9"
    check_kkt(levels)
    last, final = levels[-1].result, levels[-1].record.extra
    a = final["a"]
    check_refined_at_transitions(last, axis=0, zone=(-a, a))
    # c/a: each stick end lies halfway between a stick and a slip node, within h/4 of the
    # discrete transition (P2 nodes h/2 apart on an edge of length h), so c carries h/4 and
    # c/a an error of h/(4a) from the mesh, h the contact edges at the stick ends; the
    # theory is for a half-plane with β = 0 (β = 0.0196 here, a/R = 0.08): at h/a = 0.048
    # the solve level measures c/a within 0.001 of it (tests/contact/test_partial_slip.py),
    # so 0.005 is added for the model
    points, sides = transitions(last, axis=0)
    ends = points[(sides == 1).any(axis=1)]
    mid, length = contact_edges(last, axis=0)
    h = max(length[np.argmin(np.abs(mid - p))] for p in ends)
    tol = h / (4 * a) + 0.005
    measured, theory = final["c_over_a"], final["c_over_a_theory"]
    print(
        f"β = {BETA:.4f}, a = {a:.4f}, Q/(F P) = {final['q_over_fp']:.4f}: c/a measured "
        f"{measured:.4f}, Cattaneo–Mindlin {theory:.4f}, difference {measured - theory:+.4f}, "
        f"tolerance h/(4a) + 0.005 = {tol:.4f} (h = {h:.2e} at the stick ends)"
    )
    assert abs(measured - theory) <= tol, (measured, theory, tol)
    assert 0.6 < final["q_over_fp"] < 0.8 and 0.07 < a < 0.09, final


def test_partial_slip_is_a_load_path_of_two_steps_on_one_mesh():
    """The registry gives the press as the step before the example's problem (the pull),
    and the loop refuses a path that is not one."""
    before = EXAMPLES["partial-slip"].steps_before()
    problem = partial_slip()
    assert len(before) == 1 and before[0].conditions["top"].value[0] == 0.0
    assert problem.conditions["top"].value[0] > 0 and EXAMPLES["example-6.2"].steps_before() is None
    with pytest.raises(ValueError, match="path must be a sequence of ContactProblem"):
        adaptive(problem, path=before[0])
    with pytest.raises(ValueError, match="another mesh"):
        adaptive(problem, path=[partial_slip_path(h_bottom=0.05)[0]])


def test_example_6_2_friction_laws_give_the_stated_stick_and_slip_zones():
    """On the initial mesh refined three times (2 048 cells, h = 1/32 on Γ_C): Coulomb F = 0.3
    sticks around the kink y = 1/2 and slips towards the ends of the contact zone; Tresca
    s = 30 slips around the kink (but at it) and sticks at the ends; both have about the
    frictionless contact zone y ≈ 0.19 … 0.81, to an edge (examples/paper_friction.py)."""
    from signorini import solve
    from signorini.contact.solution import SLIP, STICK
    from signorini.examples import example_6_2, example_6_2_tresca
    from signorini.mesh.refine import refine_uniform

    mesh = example_6_2().mesh
    for _ in range(3):
        mesh = refine_uniform(mesh).mesh
    frictionless = solve(example_6_2(), mesh)
    y0 = frictionless.space.node_points[frictionless.contact.nodes, 1][frictionless.active]
    for problem, centre, ends in (
        (example_6_2_coulomb(), STICK, SLIP),
        (example_6_2_tresca(), SLIP, STICK),
    ):
        r = solve(problem, mesh)
        points, sides = transitions(r, axis=1)
        y = r.space.node_points[r.contact.nodes, 1]
        in_contact = y[r.state > 0]
        print(f"\n{problem.name}: transitions at y = {np.round(points, 3)}")
        print(
            f"contact on [{in_contact.min():.4f}, {in_contact.max():.4f}], frictionless "
            f"[{y0.min():.4f}, {y0.max():.4f}]"
        )
        assert abs(in_contact.min() - y0.min()) <= 1 / 32 + 1e-12
        assert abs(in_contact.max() - y0.max()) <= 1 / 32 + 1e-12
        ring = (np.abs(y - 0.5) > 0.05) & (np.abs(y - 0.5) < 0.15)
        edge = r.state > 0
        edge &= (y < in_contact.min() + 0.03) | (y > in_contact.max() - 0.03)
        assert np.all(r.state[ring] == centre), (problem.name, r.state[ring])
        assert np.all(r.state[edge] == ends), (problem.name, r.state[edge])
        assert r.report.kkt.max < 1e-10
