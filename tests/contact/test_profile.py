"""Tests of :meth:`ContactResult.contact_profile`: the contact part's nodes in boundary order.

The references are computed independently: the order and the arc length from the coordinates
(contact parts are straight), Λ_z from the residual of the Cartesian system assembled in
``contact_problems.independent_system`` (``K u − F = −Λ_z n`` at a contact node), and the
pressure of Example 6.1 from its exact solution, ``−σ_22(x, 0) = 3 (2 − x)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import independent_system

from signorini.contact.solution import solve
from signorini.examples import example_6_1, example_6_2
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_nvb
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

CASES = {"6.1": (example_6_1, "bottom", (1.0, 0.0)), "6.2": (example_6_2, "right", (0.0, 1.0))}


def random_nvb(mesh, seed: int, steps: int = 4, fraction: float = 0.3):
    rng = np.random.default_rng(seed)
    for _ in range(steps):
        mesh = refine_nvb(mesh, rng.random(mesh.n_cells) < fraction).mesh
    return mesh


def node_forces(problem, mesh, result) -> np.ndarray:
    """``−(K u − F)_z · n`` at every node ``(n_nodes,)`` from the independent assembly."""
    system = independent_system(problem, mesh)
    residual = (system.K @ result.u.ravel() - system.F).reshape(-1, 2)
    return residual


@pytest.mark.parametrize("name", sorted(CASES))
@pytest.mark.parametrize("seed", [0, 1])
def test_profile_against_independent_computations(name, seed):
    build, part, tangent = CASES[name]
    problem = build()
    mesh = random_nvb(problem.mesh, seed)
    result = solve(problem, mesh)
    prof = result.contact_profile(part)
    normal = problem.contact_normals[part]

    # every P2 node of the part once, ordered along the counter-clockwise tangent
    edges = mesh.part_facets(part)
    expected_nodes = np.unique(np.concatenate([mesh.edges[edges].ravel(), mesh.n_points + edges]))
    np.testing.assert_array_equal(np.sort(prof.nodes), expected_nodes)
    along = prof.points @ np.array(tangent)
    assert np.all(np.diff(along) > 0)
    np.testing.assert_allclose(prof.points @ normal, prof.points[0] @ normal, atol=1e-15)
    np.testing.assert_array_equal(prof.points, result.space.node_points[prof.nodes])
    np.testing.assert_array_equal(prof.chain, 0)
    # arc length = cumulative distance between consecutive nodes = distance from the start
    step = np.linalg.norm(np.diff(prof.points, axis=0), axis=1)
    np.testing.assert_allclose(prof.s, np.concatenate([[0.0], np.cumsum(step)]), rtol=1e-15)
    np.testing.assert_allclose(prof.s, along - along[0], rtol=0, atol=1e-15)
    assert prof.s[-1] == pytest.approx(1.0, rel=1e-14)

    # Λ_z is the residual of the independently assembled Cartesian system, along −n
    residual = node_forces(problem, mesh, result)
    scale = np.abs(prof.contact_force).max()
    np.testing.assert_allclose(
        prof.contact_force, -residual[prof.nodes] @ normal, rtol=0, atol=1e-10 * scale
    )
    np.testing.assert_allclose(
        residual[prof.nodes] @ np.array(tangent), 0.0, rtol=0, atol=1e-10 * scale
    )
    # the part's total force; p_z Σ w_z = Λ_z
    assert prof.contact_force.sum() == pytest.approx(result.total_contact_force, rel=1e-13)
    loc = result.contact.local(prof.nodes)
    np.testing.assert_allclose(
        prof.pressure * result.contact.basis_integral[loc], prof.contact_force, rtol=1e-14
    )
    # gap and normal displacement
    gap = problem.conditions[part].gap_field()(prof.points)
    np.testing.assert_allclose(prof.gap, np.broadcast_to(gap, prof.s.shape), rtol=0, atol=1e-15)
    np.testing.assert_allclose(prof.normal_displacement, result.u[prof.nodes] @ normal, rtol=1e-15)
    np.testing.assert_allclose(prof.normal_gap, prof.normal_displacement - prof.gap, atol=1e-15)
    # the same profile without naming the only contact part
    np.testing.assert_array_equal(result.contact_profile().nodes, prof.nodes)


def test_example_6_1_pressure_is_the_exact_normal_stress():
    """p_z → −σ_22(x, 0) = 3 (2 − x) (exact: σ_22 = (λ + 2μ)(x − 2) q'(y), q'(0) = 1)."""
    errors = []
    for nx in (4, 8, 16):
        problem = example_6_1(nx)
        prof = solve(problem).contact_profile("bottom")
        errors.append(np.abs(prof.pressure - 3 * (2 - prof.points[:, 0])).max())
    assert errors[-1] < 2e-3, errors
    assert errors[0] / errors[1] > 3 and errors[1] / errors[2] > 3, errors


def two_chain_problem() -> ContactProblem:
    """The unit square pressed down by its top; the bottom touches the obstacle only on
    x < 1/4 and x > 3/4 (two pieces of one contact part), the middle is free."""
    base = rectangle(nx=8, ny=8)
    pairs = {name: base.facets[base.part_facets(name)] for name in base.part_names}
    mid = base.points[pairs["bottom"]].mean(axis=1)[:, 0]
    inner = (mid > 0.25) & (mid < 0.75)
    pairs["free"] = pairs["bottom"][inner]
    pairs["bottom"] = pairs["bottom"][~inner]
    mesh = Mesh.from_arrays(base.points, base.cells, pairs)
    return ContactProblem(
        mesh=mesh,
        material=Material.from_young(100.0, 0.3),
        conditions={
            "top": Dirichlet((0.0, -0.01)),
            "left": Neumann((0.0, 0.0)),
            "right": Neumann((0.0, 0.0)),
            "free": Neumann((0.0, 0.0)),
            "bottom": Contact(gap=0.0, normal=(0.0, -1.0)),
        },
        name="two-chains",
    )


def test_a_part_of_two_pieces_gives_two_chains():
    problem = two_chain_problem()
    mesh = random_nvb(problem.mesh, 3, steps=2)
    result = solve(problem, mesh)
    prof = result.contact_profile("bottom")
    x = prof.points[:, 0]
    assert np.all(np.diff(x) > 0)
    np.testing.assert_array_equal(prof.chain, (x > 0.5).astype(int))
    # s is the distance from the first node: it jumps by the free middle's length
    np.testing.assert_allclose(prof.s, x, atol=1e-15)
    jump = np.flatnonzero(np.diff(prof.chain))
    assert jump.size == 1 and prof.s[jump[0] + 1] - prof.s[jump[0]] == pytest.approx(0.5)
    assert prof.contact_force.sum() == pytest.approx(result.total_contact_force, rel=1e-13)
    assert result.total_contact_force > 0
    residual = node_forces(problem, mesh, result)
    np.testing.assert_allclose(
        prof.contact_force,
        residual[prof.nodes, 1],
        rtol=0,
        atol=1e-10 * prof.contact_force.max(),
    )


def test_dirichlet_end_points_have_no_contact_force():
    """Example-6.1-like square clamped on the left: the bottom's first node is a Dirichlet
    node, listed with NaN force and pressure but with its gap and displacement."""
    problem = example_6_1()
    conditions = dict(problem.conditions)
    conditions["left"] = Dirichlet((0.0, 0.0))
    clamped = ContactProblem(
        mesh=problem.mesh,
        material=problem.material,
        conditions=conditions,
        body_force=problem.body_force,
        name="clamped-left",
    )
    prof = solve(clamped).contact_profile("bottom")
    assert prof.points[0].tolist() == [0.0, 0.0]
    assert np.isnan(prof.contact_force[0]) and np.isnan(prof.pressure[0])
    assert np.isfinite(prof.contact_force[1:]).all()
    assert prof.gap[0] == 0.0 and prof.normal_displacement[0] == 0.0


def test_profile_names_a_wrong_part():
    result = solve(example_6_2())
    with pytest.raises(ValueError, match=r"part: 'left' is not a contact part .*\['right'\]"):
        result.contact_profile("left")


def test_profile_without_a_part_needs_a_single_contact_part():
    problem = ContactProblem(
        mesh=rectangle(nx=4, ny=4),
        material=Material.from_young(100.0, 0.3),
        conditions={
            "left": Dirichlet((0.0, 0.0)),
            "right": Neumann((0.0, 0.0)),
            "bottom": Contact(gap=0.1),
            "top": Contact(gap=0.1),
        },
        name="two-parts",
    )
    result = solve(problem)
    with pytest.raises(ValueError, match=r"part: the problem has contact parts .*; name one"):
        result.contact_profile()
    top = result.contact_profile("top")
    assert np.all(np.diff(top.points[:, 0]) < 0)  # counter-clockwise: right to left on top
    np.testing.assert_allclose(top.s, 1.0 - top.points[:, 0], atol=1e-15)
