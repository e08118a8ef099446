"""Ill-conditioned stiffness matrices: a material close to incompressible and a sliver cell
give the right contact forces, with KKT residuals that say how many digits they have
(docs/method.md, *Solver*)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from signorini.algebra import (
    SOLVERS,
    IllConditionedWarning,
    SolverRequest,
    available_backends,
    kkt_residuals,
)
from signorini.algebra.active_system import ActiveSetSystem
from signorini.algebra.pdas import KKT_WARN
from signorini.algebra.qp import check_qp
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.paper import example_6_2
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

BACKENDS = available_backends()


def pressed_square(nu: float) -> ContactProblem:
    """Example 6.2's square and obstacle (2112 unknowns) with E = 500 and Poisson ratio nu."""
    base = example_6_2()
    mesh = refine_uniform(refine_uniform(base.mesh).mesh).mesh
    return ContactProblem(mesh, Material.from_young(500.0, nu), base.conditions, name="square")


@pytest.mark.parametrize("backend", BACKENDS)
def test_near_incompressible_contact_forces_are_compressive(backend):
    """ν = 0.499999999: PDAS stopped after 2 iterations with tensile forces of 5 % of the total
    (8.1 of 133.4) and a KKT residual of 3e-11: its round-off band was relative to c max|x|,
    which grows like λ. Now the active set is that of ν = 0.4999999 and the forces agree with
    it to the round-off of forces (the forces change with 1 − 2ν by 1.1 per unit, 2e-7 here).

    The residuals are honest and at round-off: the equilibrium residual is that of evaluating
    ``F − K x`` itself, about eps ``max |K| |x|`` (which is λ/μ ≈ 5e8 times the forces), so it
    reads 1.0e-6 to 1.4e-6 of the forces (by CPU and backend), on the edge of KKT_WARN: the
    warning must then say what the residuals say, whichever side they fall."""
    reference = solve(pressed_square(0.4999999), solver=SOLVERS[backend])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = solve(pressed_square(0.499999999), solver=SOLVERS[backend])
    kkt = result.report.kkt
    # the round-off of F − K x: (k + 1) eps max(|F|, |K| |x|) for rows of at most k entries
    ulps = np.diff(assemble(pressed_square(0.499999999), result.mesh).K.indptr).max() + 1
    round_off = ulps * np.finfo(float).eps * kkt.round_off_scale
    force = result.contact_force
    assert force.min() >= 0.0
    assert np.array_equal(result.active, reference.active)
    total = result.total_contact_force
    tolerance = 2.2e-7 * total + 2 * round_off
    assert abs(total - reference.total_contact_force) <= tolerance
    np.testing.assert_allclose(force, reference.contact_force, rtol=0, atol=tolerance)
    # the residuals are at round-off, measured against the forces, not against |K| |x|
    assert kkt.stationarity <= round_off / kkt.force_scale
    assert kkt.dual <= round_off / kkt.contact_force_scale
    material = pressed_square(0.499999999).material
    assert kkt.round_off_scale >= 0.1 * material.lam / material.mu * kkt.force_scale
    warned = [w for w in caught if issubclass(w.category, IllConditionedWarning)]
    assert bool(warned) == (kkt.max > KKT_WARN), (kkt.max, [str(w.message) for w in warned])


def test_a_tensile_force_is_a_kkt_violation_on_any_scale():
    """The KKT residuals of a point with a tensile contact force (one more node held at the
    obstacle than at the solution) read it relative to the contact force, not to max |K||x|
    (9e10 here: the former scale read 3e-11 for a tensile force of 5 %)."""
    problem = pressed_square(0.499999999)
    result = solve(problem)
    assembled = assemble(problem, result.mesh)
    cs = assembled.contact
    qp = check_qp(
        assembled.K, assembled.F, cs.constrained_dofs, cs.gap, assembled.dirichlet,
        assembled.dirichlet_values,
    )  # fmt: skip
    active = result.active.copy()
    edge = np.flatnonzero(active)
    active[edge[0] - 1] = active[edge[-1] + 1] = True  # hold the two next nodes as well
    with SOLVERS["scipy"](SolverRequest()) as solver:
        x, multiplier = ActiveSetSystem(qp, solver).solve(active)
    tensile = -multiplier[active].min()
    total = np.maximum(multiplier[active], 0.0).sum()
    assert tensile > 0.01 * total
    kkt = kkt_residuals(
        assembled.K, assembled.F, x, cs.constrained_dofs, cs.gap, assembled.dirichlet,
        assembled.dirichlet_values,
    )  # fmt: skip
    assert kkt.round_off_scale > 1e9 * kkt.force_scale
    assert kkt.dual == pytest.approx(tensile / total, rel=1e-6)


def needle_mesh(delta: float) -> Mesh:
    """The unit square (4 × 4 union jack) with one more boundary point at (0.25 + delta, 0):
    the cell on the bottom edge [0.25, 0.5] is split into a needle of aspect about
    0.25 / delta and a regular cell."""
    base = rectangle(0, 1, 0, 1, nx=4, ny=4)
    points, cells = base.points, base.cells
    on_bottom = points[:, 1] == 0.0
    a = np.flatnonzero(on_bottom & (points[:, 0] == 0.25))[0]
    b = np.flatnonzero(on_bottom & (points[:, 0] == 0.5))[0]
    k = np.flatnonzero(np.isin(cells, [a, b]).sum(axis=1) == 2)[0]
    v = np.setdiff1d(cells[k], [a, b])[0]
    points = np.vstack([points, [0.25 + delta, 0.0]])
    p = len(points) - 1
    cells = np.vstack([np.delete(cells, k, axis=0), [a, p, v], [p, b, v]])
    parts = {
        "top": lambda x: x[:, 1] == 1.0,
        "left": lambda x: x[:, 0] == 0.0,
        "right": lambda x: x[:, 0] == 1.0,
        "bottom": lambda x: (x[:, 1] == 0.0) & (x[:, 0] > 0.0) & (x[:, 0] < 1.0),
    }
    return Mesh.from_arrays(points, cells, parts)


def needle_problem(delta: float, centre: float) -> ContactProblem:
    """A block pressed down by 0.01 onto the parabola ψ = 0.3 (x − centre)² (one or a few
    nodes in contact), on :func:`needle_mesh`."""
    conditions = {
        "left": Neumann(),
        "right": Neumann(),
        "top": Dirichlet((0.0, -0.01)),
        "bottom": Contact(gap=lambda x: 0.3 * (x[:, 0] - centre) ** 2),
    }
    return ContactProblem(needle_mesh(delta), Material.from_young(500.0, 0.3), conditions)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("centre", [0.25, 0.375])
def test_a_sliver_cell_gives_the_right_contact_force(backend, centre):
    """A needle of aspect 1e9 next to the contact zone: the total contact force was 5.5 %
    (centre 0.25) and 4.4 % (0.375) off with tensile nodal forces and a KKT residual of 1e-10,
    for the same reason as near incompressibility (the needle's stiffness, 1e9 times the rest,
    entered the round-off band). The discrete solutions of needles of aspect 2.5e6 and 1e9
    agree to 1e-5; the KKT residual says the forces have about 6 digits (above 1e-6 an
    IllConditionedWarning says so)."""
    reference = solve(needle_problem(1e-7, centre), solver=SOLVERS[backend])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IllConditionedWarning)
        result = solve(needle_problem(2.5e-10, centre), solver=SOLVERS[backend])
    assert result.contact_force.min() >= 0.0
    assert np.array_equal(result.active, reference.active)
    total = reference.total_contact_force
    assert abs(result.total_contact_force - total) <= 1e-5 * total
    assert 1e-8 < result.report.kkt.max <= 1e-5
