"""Nested iteration of cold solves (:mod:`signorini.contact.nested`): the same discrete
solution as PDAS from the empty active set, in fewer fine iterations; the coarse mesh has
the fine mesh's cells at Γ_C; warm starts, ``nested=False``, small meshes and friction are
untouched."""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import problem_contact_set

from signorini import adaptive
from signorini.contact.nested import NESTED_MAX_SHARE, NESTED_MIN_NDOF, coarse_mesh, transfer_active
from signorini.contact.solution import solve
from signorini.examples import example_6_2
from signorini.examples.punch import punch
from signorini.fem.space import P2Space
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.problem import ContactProblem, Neumann


@pytest.fixture(scope="module")
def fine():
    """Example 6.2 and the last mesh of its adaptive loop within 10^5 unknowns."""
    problem = example_6_2()
    mesh = None
    for level in adaptive(problem, max_ndof=100_000):
        mesh = level.result.mesh
    return problem, mesh


@pytest.fixture(scope="module")
def cold(fine):
    problem, mesh = fine
    return solve(problem, mesh, nested=False)


def _agreement(a, b) -> tuple[float, float]:
    du = np.abs(a.u - b.u).max() / np.abs(b.u).max()
    dl = np.abs(a.contact_force - b.contact_force).max() / np.abs(b.contact_force).max()
    return float(du), float(dl)


@pytest.mark.slow
def test_nested_solve_is_the_cold_solution_in_fewer_iterations(fine, cold):
    problem, mesh = fine
    nested = solve(problem, mesh)
    assert nested.ndof > 80_000 and "nested" in nested.timings
    assert "nested" not in cold.timings
    du, dl = _agreement(nested, cold)
    assert du <= 1e-10 and dl <= 1e-10, (du, dl)
    assert np.array_equal(nested.active, cold.active)
    assert nested.report.kkt.max <= 1e-9, nested.report.kkt.max
    # the empty start needs 12 iterations here; the coarse active set at most 3
    its = (nested.report.iterations, cold.report.iterations)
    assert its[0] <= 3 and its[1] >= 3 * its[0], its


@pytest.mark.slow
def test_coarse_mesh_has_the_fine_cells_at_the_contact_part(fine):
    problem, mesh = fine
    coarse = coarse_mesh(problem.mesh, mesh, problem.contact_parts)
    assert coarse is not None and coarse.n_cells <= NESTED_MAX_SHARE * mesh.n_cells
    # same contact nodes, at the same points
    fine_cs = problem_contact_set(problem, P2Space(mesh))
    coarse_cs = problem_contact_set(problem, P2Space(coarse))
    fine_points = P2Space(mesh).node_points[fine_cs.nodes]
    coarse_points = P2Space(coarse).node_points[coarse_cs.nodes]
    order = np.lexsort(fine_points.T), np.lexsort(coarse_points.T)
    assert np.array_equal(fine_points[order[0]], coarse_points[order[1]])
    # every cell with a vertex on the contact part is a cell of the fine mesh
    on_contact = np.zeros(coarse.n_points, dtype=bool)
    part = coarse.part_index(problem.contact_parts[0])
    on_contact[coarse.boundary[coarse.boundary_part == part].ravel()] = True
    touching = coarse.cells[on_contact[coarse.cells].any(axis=1)]
    fine_cells = {tuple(sorted(map(tuple, mesh.points[c]))) for c in mesh.cells}
    assert all(tuple(sorted(map(tuple, coarse.points[c]))) in fine_cells for c in touching)


def test_a_mesh_that_is_not_a_refinement_still_gets_the_same_solution():
    """Interior points moved: no coarse cell is found in the fine mesh, the coarse solve
    runs on the initial mesh, and the solution is the one from the empty active set."""
    problem = example_6_2()
    mesh = refine_uniform(refine_uniform(refine_uniform(problem.mesh).mesh).mesh).mesh
    mesh = refine_uniform(mesh).mesh
    rng = np.random.default_rng(3)
    points = mesh.points.copy()
    inside = np.all((points > 1e-9) & (points < 1 - 1e-9), axis=1)
    points[inside] += 1e-3 * rng.uniform(-1, 1, size=(inside.sum(), 2))
    moved = Mesh(points, mesh.cells, mesh.boundary, mesh.boundary_part, mesh.part_names)
    assert moved.n_cells > problem.mesh.n_cells
    assert coarse_mesh(problem.mesh, moved, problem.contact_parts).n_cells == (problem.mesh.n_cells)
    if problem.free_ndof(moved) < NESTED_MIN_NDOF:
        pytest.skip("mesh below the nested threshold")
    nested, cold = solve(problem, moved), solve(problem, moved, nested=False)
    assert "nested" in nested.timings
    du, dl = _agreement(nested, cold)
    assert du <= 1e-10 and dl <= 1e-10, (du, dl)


@pytest.mark.slow
def test_warm_starts_small_meshes_and_the_switch_leave_pdas_alone(fine, cold):
    problem, mesh = fine
    warm = solve(problem, mesh, u0=cold.u)
    assert "nested" not in warm.timings and warm.report.iterations == 1
    small = refine_uniform(refine_uniform(problem.mesh).mesh).mesh
    assert problem.free_ndof(small) < NESTED_MIN_NDOF
    assert "nested" not in solve(problem, small).timings
    conditions = {**problem.conditions, "right": Neumann()}
    no_contact = ContactProblem(problem.mesh, problem.material, conditions)
    assert "nested" not in solve(no_contact, mesh).timings


def test_transfer_to_the_same_mesh_is_the_identity_also_at_a_corner():
    problem = punch(nx=8)
    space = P2Space(problem.mesh)
    cs = problem_contact_set(problem, space)
    assert cs.second.any()  # the wall meets the top at a corner: two constraints
    rng = np.random.default_rng(0)
    for _ in range(5):
        active = rng.random(cs.size) < 0.5
        assert np.array_equal(transfer_active(space, cs, active, space, cs), active)
