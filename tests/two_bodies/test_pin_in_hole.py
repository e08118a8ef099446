"""Coulomb friction on realistic geometry: the pin in a plate's hole
(:func:`signorini.examples.pin.pin_in_hole`, two deformable bodies, curved conforming
contact, Coulomb 0.2), where the semismooth Newton method's node states cycle.

- On level 2 of the adaptive run the states cycle between two nodes sticking and slipping;
  the iteration goes on one node at a time (the least-index rule) and converges. The
  solution is checked node by node against Coulomb's laws from ``Λ = F − K x`` of an
  assembly of its own, and against Tresca's problem with the bound ``F Λ_n`` (Coulomb's
  solution is a fixed point of it), solved by the same method but a problem of another kind.
- From the wild iterates of a very large constant ``c`` (100 times the mean diagonal of K)
  the coupled iteration cycles even one node at a time, and the fixed point on the slip
  bound finishes at the solution of the default ``c``.
"""

from __future__ import annotations

import logging
from functools import cache

import numpy as np
import pytest

from signorini.algebra.friction.kkt import check_friction
from signorini.algebra.friction.newton import FrictionOptions, solve_friction
from signorini.algebra.friction.result import SLIP, STICK
from signorini.contact import solve
from signorini.contact.system import assemble
from signorini.examples.pin import pin_in_hole
from signorini.loop import AdaptiveOptions, adaptive
from signorini.mesh.refine import refine_uniform
from signorini.problem.friction_laws import Tresca

COEFFICIENT = 0.2


def frictional_problem(problem, mesh, law=None, weight=None):
    """The algebraic problem of ``problem`` on ``mesh`` (as :func:`~signorini.contact.solve`
    poses it), its assembly, and optionally another law and weights on every node."""
    a = assemble(problem, mesh)
    cs = a.contact
    friction = cs.friction
    p = check_friction(
        a.K, a.F, 2 * cs.nodes, 2 * cs.nodes + 1, cs.gap, a.dirichlet, a.dirichlet_values,
        laws=friction.laws if law is None else law,
        weight=friction.weight if weight is None else weight,
        law_index=friction.index if law is None else None,
    )  # fmt: skip
    return p, a


@cache
def cycling_level():
    """Level 2 of the adaptive run of the default pin, and the log of its solves."""
    records = []
    handler = logging.Handler()
    handler.emit = records.append
    logger = logging.getLogger("signorini.algebra.friction.newton")
    logger.addHandler(handler)
    old = logger.level
    logger.setLevel(logging.INFO)
    try:
        problem = pin_in_hole()
        *_, level = adaptive(problem, options=AdaptiveOptions(max_levels=3))
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old)
    return problem, level.result, [r.getMessage() for r in records]


def test_the_pin_converges_where_the_coulomb_states_cycle():
    problem, r, log = cycling_level()
    assert any("states cycle" in line and "one node at a time" in line for line in log), log
    assert r.report.method == "semismooth-newton"
    assert r.report.kkt.max < 1e-10, r.report.kkt
    counts = np.bincount(r.state, minlength=3)
    assert counts[STICK] >= 1 and counts[SLIP] >= 30, counts
    # Coulomb's laws node by node, from an assembly of the same mesh
    p, a = frictional_problem(problem, r.mesh)
    x = r.report.x
    lam = a.F - a.K @ x
    lam_n, lam_t = lam[p.normal], lam[p.tangent_2d]
    slide = x[p.tangent_2d] - p.reference
    scale, disp = lam_n.max(), np.abs(x).max()
    stick, slip = r.state == STICK, r.state == SLIP
    assert np.all(x[p.normal] <= p.gap + 1e-12 * disp)
    assert np.all(lam_n >= -1e-10 * scale)
    assert np.abs(slide[stick]).max() < 1e-12 * disp
    assert np.all(np.abs(lam_t[stick]) <= COEFFICIENT * lam_n[stick] + 1e-10 * scale)
    assert np.abs(np.abs(lam_t[slip]) - COEFFICIENT * lam_n[slip]).max() < 1e-10 * scale
    assert np.all(lam_t[slip] * slide[slip] > 0), "slip along the friction force"
    # Tresca with the bound F Λ_n, acting in contact only, has the same solution
    bound = COEFFICIENT * np.maximum(lam_n, 0.0)
    t, _ = frictional_problem(problem, r.mesh, Tresca(0.0, everywhere=False), bound)
    tresca = solve_friction(t)
    assert np.abs(tresca.x - x).max() < 1e-9 * disp, np.abs(tresca.x - x).max() / disp
    assert np.array_equal(tresca.state, r.state)


@pytest.mark.slow
def test_the_pin_runs_past_the_level_where_it_stopped():
    *_, last = adaptive(pin_in_hole(), options=AdaptiveOptions(max_ndof=12_000))
    assert last.record.level >= 8 and last.result.report.kkt.max < 1e-10


def test_the_fixed_point_finishes_from_the_wild_iterates_of_a_large_c():
    problem = pin_in_hole(n_theta=24, shift=0.02, press=0.02, rotation=0.0, young=(1.0, 1.0))
    mesh = refine_uniform(problem.mesh).mesh
    p, _ = frictional_problem(problem, mesh)
    reference = solve_friction(p)
    assert reference.method == "semismooth-newton"
    d = float(p.qp.diagonal()[p.normal].mean())
    r = solve_friction(p, options=FrictionOptions(c=100.0 * d))
    assert r.method == "fixed-point"
    assert r.kkt.max < 1e-10, r.kkt
    disp = np.abs(reference.x).max()
    assert np.abs(r.x - reference.x).max() < 1e-9 * disp, np.abs(r.x - reference.x).max() / disp
    assert np.array_equal(r.state, reference.state)
    # and the two-body solve of the same mesh is that solution too
    assert np.abs(solve(problem, mesh).report.x - reference.x).max() < 1e-12 * disp
