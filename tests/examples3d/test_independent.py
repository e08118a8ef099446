"""Each 3D built-in problem's solution equals an independent computation on the same mesh to
round-off (issue 38): the dual NNLS of :mod:`.independent_qp` against ``solve()``, for the
transformed face basis (b) and the nodal constraints (a)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from examples3d.independent_qp import kkt_residuals, solve_independent

from signorini.contact.solution import solve
from signorini.examples import EXAMPLES
from signorini.examples.hertz3d import hertz_3d
from signorini.examples.paper3d import example_6_1_3d, example_6_2_3d
from signorini.examples.punch3d import punch_3d

#: each problem on a mesh small enough for the dense solve, by condition: None (b), 0 (a);
#: hertz-3d pressed 4 times deeper than its default (a ≈ 0.2 R) on a coarser graded mesh
PROBLEMS = {
    "example-6.1-3d": example_6_1_3d,
    "example-6.2-3d": example_6_2_3d,
    "hertz-3d": lambda face_alpha: hertz_3d(depth=0.04, h_contact=0.3, face_alpha=face_alpha),
    "punch-3d": lambda face_alpha: punch_3d(n=3, face_alpha=face_alpha),
}
CASES = [(name, alpha) for name in PROBLEMS for alpha in (None, 0.0)]
IDS = [f"{name}-{'b' if alpha is None else 'a'}" for name, alpha in CASES]


@cache
def solved(name: str, alpha: float | None):
    result = solve(PROBLEMS[name](face_alpha=alpha))
    return result, *solve_independent(result)


def test_the_default_problems_are_the_registered_ones():
    for name in ("example-6.1-3d", "example-6.2-3d"):
        registered, here = EXAMPLES[name].problem(), PROBLEMS[name](face_alpha=None)
        assert registered.name == here.name == name
        np.testing.assert_array_equal(registered.mesh.cells, here.mesh.cells)
        assert registered.conditions.keys() == here.conditions.keys()


@pytest.mark.parametrize(("name", "alpha"), CASES, ids=IDS)
def test_solution_equals_the_independent_dual_nnls(name, alpha):
    result, qp, other = solved(name, alpha)
    cs = result.contact
    assert float(cs.edges.alpha) == (0.2 if alpha is None else 0.0)
    # partial contact: some rows active, some not
    assert 0 < result.active.sum() < cs.size
    # the independent solution meets its KKT conditions to round-off
    assert max(other.kkt.values()) <= 1e-12, other.kkt
    # the package's solution meets them too, in the independent formulation
    own = kkt_residuals(qp, result.u.ravel(), result.report.multiplier)
    assert max(own.values()) <= 1e-12, own
    scale = np.abs(other.u).max()
    np.testing.assert_allclose(result.u, other.u, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(result.active, other.lam > 0)
    # no degenerate row (zero multiplier and zero slack) that could make the sets differ
    tie = (other.lam <= 1e-9 * other.lam.max()) & (np.abs(other.slack) <= 1e-9 * scale)
    assert not tie.any()
    force = np.abs(other.lam).max()
    np.testing.assert_allclose(result.report.multiplier, other.lam, rtol=0, atol=1e-12 * force)
    np.testing.assert_allclose(result.contact_force, other.force, rtol=0, atol=1e-12 * force)


def test_punch_edge_nodes_carry_both_constraints():
    """Where the zones under the punch and against the wall meet (x = W, z = H), vertices are
    active against both obstacles, with positive multipliers, and there u(z) lies on both:
    u(z)·n_z = ψ(z) for both rows (under (b) too: a vertex's coefficient is its value),
    u_x = 0 on the wall."""
    result, _, other = solved("punch-3d", None)
    cs = result.contact
    x = result.space.node_points[cs.node]
    edge = np.isclose(x[:, 0], 2.0) & np.isclose(x[:, 2], 1.0)
    nodes, count = np.unique(cs.node[edge & result.active], return_counts=True)
    both = nodes[(count == 2) & (nodes < result.mesh.n_points)]
    assert both.size >= 2
    rows = np.flatnonzero(np.isin(cs.node, both))
    assert set(cs.part[rows]) == {0, 1}
    normal = np.einsum("rc,rc->r", cs.direction[rows], result.u[cs.node[rows]])
    np.testing.assert_allclose(normal, cs.psi[rows], rtol=0, atol=1e-14)  # on both obstacles
    wall = rows[cs.part[rows] == 1]
    np.testing.assert_allclose(result.u[cs.node[wall], 0], 0.0, atol=1e-14)
    assert (other.lam[rows] > 0).all()
