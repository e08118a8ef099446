"""The P2 prolongation on tetrahedra with curved parts (fem/prolongation.py, mesh/nesting.py):
the refined field is the coarse isoparametric field in the parents' reference coordinates,
checked against reference points computed from a straight twin of the refinement."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.examples.hertz3d import graded_eighth_ball
from signorini.fem.p2_tet import basis_barycentric
from signorini.fem.space import space_of
from signorini.mesh.builders3d import eighth_ball, quarter_cylinder
from signorini.mesh.mesh import Mesh
from signorini.mesh.nesting import generations, parent_barycentrics
from signorini.mesh.refine import Refinement, refine_nvb, refine_uniform
from signorini.mesh.refine3d import bisect_mesh, tags_of
from signorini.mesh.tags3d import ATTRIBUTE

RNG = np.random.default_rng(37)


def straight_twin(mesh: Mesh) -> Mesh:
    """The same points, cells, parts and tags with no surface: its bisection cuts the same
    edges (the rule is combinatorial) at the chords' midpoints."""
    twin = Mesh(
        mesh.points, mesh.cells, mesh.boundary, mesh.boundary_part, mesh.part_names,
        validate=False,
    )  # fmt: skip
    setattr(twin, ATTRIBUTE, tags_of(mesh))
    return twin


def towards(mesh: Mesh, part: str) -> np.ndarray:
    marked = np.zeros(mesh.n_cells, dtype=bool)
    marked[mesh.facet2cell[mesh.part_facets(part), 0]] = True
    return marked


def vertices_in_parents(coarse: Mesh, twin_fine: Mesh, parent: np.ndarray) -> np.ndarray:
    """``(n, 4, 4)`` barycentric coordinates of the straight twin's refined vertices in their
    parents, by inverting the parents' affine maps (independent of mesh/nesting.py)."""
    P = coarse.points[coarse.cells[parent]]  # (n, 4, 3)
    X = twin_fine.points[twin_fine.cells]  # (n, 4, 3)
    J = np.swapaxes(P[:, 1:] - P[:, :1], 1, 2)  # columns v_k - v_0
    xi = np.linalg.solve(J[:, None], (X - P[:, :1])[..., None])[..., 0]  # (n, 4, 3)
    return np.concatenate([1 - xi.sum(-1, keepdims=True), xi], axis=-1)


def check_same_function(coarse: Mesh, refinement: Refinement, twin: Refinement) -> float:
    """The largest difference, at random reference points of every child, between the
    prolongated field and the coarse field at the same point of the parent's reference cell;
    a random P2 field on ``coarse``."""
    np.testing.assert_array_equal(twin.mesh.cells, refinement.mesh.cells)
    np.testing.assert_array_equal(twin.parent, refinement.parent)
    V, W = space_of(coarse), space_of(refinement.mesh)
    assert V.curved is not None  # isoparametric cells along the surface
    u = RNG.normal(size=(V.n_nodes, 3))
    v = V.prolongate(u, refinement)
    parent = refinement.parent
    lam = vertices_in_parents(coarse, twin.mesh, parent)  # child vertex -> parent reference
    eta = RNG.dirichlet(np.ones(4), size=(refinement.mesh.n_cells, 5))  # child reference
    fine = np.einsum("cqj,cjd->cqd", basis_barycentric(eta), v[W.cell_nodes])
    at = np.einsum("cqi,cij->cqj", eta, lam)  # the same points in the parent's reference
    coarse_values = np.einsum("cqj,cjd->cqd", basis_barycentric(at), u[V.cell_nodes[parent]])
    return float(np.abs(fine - coarse_values).max() / np.abs(u).max())


def graded() -> Mesh:
    """An eighth ball graded towards its pole by local bisection (220 cells): its closures
    cut edges made in the same step, whose new vertices on the sphere leave the old cells'
    straight edges."""
    return graded_eighth_ball(2, h_contact=0.3, patch=0.15)


def test_three_local_bisections_towards_the_sphere_keep_the_field():
    """The cells at the sphere of the graded eighth ball bisected three times in one step
    (two steps): the later bisections cut edges the first made (on a Kuhn grid they cut only
    old edges), and their new vertices leave the chords."""
    mesh = graded()
    moved, deepest = [], []
    for _ in range(2):
        marked = towards(mesh, "sphere")
        refinement = Refinement(*bisect_mesh(mesh, marked, 3))
        twin = Refinement(*bisect_mesh(straight_twin(mesh), marked, 3))
        moved.append(np.abs(refinement.mesh.points - twin.mesh.points).max())
        deepest.append(generations(mesh.n_points, refinement.parent_edge).max())
        error = check_same_function(mesh, refinement, twin)
        print(f"{refinement.mesh.n_cells} cells: vertices off the chords by {moved[-1]:.2e}, "
              f"generations {deepest[-1]}, field error {error:.1e}")  # fmt: skip
        assert error < 1e-12
        mesh = refinement.mesh
    assert max(moved) > 1e-3  # new vertices left the chords (onto the sphere)
    assert max(deepest) >= 2  # of edges made in the same step


@pytest.mark.parametrize("build", [lambda: eighth_ball(2), graded])
def test_local_refinement_steps_towards_the_sphere_keep_the_field(build):
    mesh = build()
    for _ in range(3):
        marked = towards(mesh, "sphere")
        refinement = refine_nvb(mesh, marked)
        twin = refine_nvb(straight_twin(mesh), marked)
        assert check_same_function(mesh, refinement, twin) < 1e-12
        mesh = refinement.mesh


@pytest.mark.parametrize("build", [graded, lambda: eighth_ball(1), lambda: quarter_cylinder(1)])
def test_uniform_refinement_of_a_curved_mesh_keeps_the_field(build):
    mesh = build()
    refinement = refine_uniform(mesh)
    twin = refine_uniform(straight_twin(mesh))
    assert check_same_function(mesh, refinement, twin) < 1e-12


def test_parent_barycentrics_are_dyadic_and_sum_to_one():
    mesh = graded()
    refinement = refine_uniform(mesh)
    lam = parent_barycentrics(
        mesh.cells,
        refinement.mesh.cells,
        refinement.parent,
        refinement.parent_edge,
        mesh.n_points,
    )
    np.testing.assert_array_equal(lam.sum(-1), 1.0)
    np.testing.assert_array_equal(lam * 8, np.round(lam * 8))  # three bisections: eighths
    assert lam.min() >= 0
    # three bisections of a cell: its new points are of generations 1 to 3
    gen = generations(mesh.n_points, refinement.parent_edge)
    assert gen[: mesh.n_points].max() == 0 and set(np.unique(gen[mesh.n_points :])) == {1, 2, 3}


def test_a_refinement_without_or_with_wrong_parent_edges_is_refused():
    mesh = eighth_ball(1)
    refinement = refine_uniform(mesh)
    V = space_of(mesh)
    u = np.zeros((V.n_nodes, 3))
    bare = Refinement(refinement.mesh, refinement.parent, refinement.edge_point)
    with pytest.raises(ValueError, match="parent_edge"):
        V.prolongate(u, bare)
    wrong = refinement.parent_edge.copy()
    wrong[-1] = [0, refinement.mesh.n_points - 1]  # a point as the end of its own edge
    with pytest.raises(ValueError, match="older points"):
        V.prolongate(u, Refinement(*[getattr(refinement, f) for f in ("mesh", "parent")],
                                   refinement.edge_point, wrong))  # fmt: skip
    shifted = Refinement(
        refinement.mesh, np.roll(refinement.parent, 1), refinement.edge_point,
        refinement.parent_edge,
    )  # fmt: skip
    with pytest.raises(ValueError, match="not a refinement"):
        V.prolongate(u, shifted)
