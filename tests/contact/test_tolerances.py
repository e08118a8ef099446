"""The round-off tolerances of the solution layer are relative to the quantities they test.

``u·n − ψ`` at a node is the difference of ``u(z)·n`` and ``ψ(z)``: its round-off is relative
to ``max(max|u|, |ψ(z)|)``, not to the largest gap of the part. An obstacle far away (gap 400
at the other end, as for a Hertz-like or curved obstacle) must not make the tests lenient,
and scaling the problem must not change their outcome.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.contact_set import FULL_CONTACT, SEMI_CONTACT
from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

#: the obstacle at the clamped corner (0, 0): 2e-10 below the body, 400 far away
DELTA = 2e-10


def clamped_corner_problem(a: float = 1.0) -> ContactProblem:
    """The unit square (scaled by ``a``) pressed down by its top, clamped on the left; the
    obstacle is ``DELTA`` away at the clamped corner and far away near x = 1."""
    base = rectangle(nx=8, ny=8)
    # validate=False: the mesh layer's own tolerances are not under test here
    mesh = Mesh(
        base.points * a,
        base.cells,
        base.boundary,
        base.boundary_part,
        base.part_names,
        validate=False,
    )
    return ContactProblem(
        mesh=mesh,
        material=Material.from_young(100.0, 0.3),
        conditions={
            "top": Dirichlet((0.0, -0.01 * a)),
            "left": Dirichlet((0.0, 0.0)),
            "right": Neumann((0.0, 0.0)),
            "bottom": Contact(
                gap=lambda x: a * (DELTA + 1e4 * np.maximum(x[..., 0] / a - 0.8, 0) ** 2),
                normal=(0.0, -1.0),
            ),
        },
        name="clamped-corner",
    )


def bottom_nodes(result, xs) -> np.ndarray:
    """Positions in the contact set of the bottom nodes at ``x / a = xs``."""
    pts = result.space.node_points[result.contact.nodes]
    a = result.mesh.points.max()
    return np.array(
        [np.flatnonzero(np.isclose(pts[:, 0] / a, x) & (pts[:, 1] == 0))[0] for x in xs]
    )


@pytest.mark.parametrize("a", [1.0, 1e-12, 1e12])
def test_a_dirichlet_corner_off_the_obstacle_breaks_full_contact(a):
    """u_D·n − ψ = −2e-10 at the corner, 2e-8 of max|u| = 0.01: the corner does not touch,
    so its edge's other nodes are in semi contact (before: the gap 400 far away made the
    tolerance 4e-10 and the corner counted as touching). The same for the scaled problem
    (mesh, data and gap times a)."""
    result = solve(clamped_corner_problem(a))
    near = bottom_nodes(result, [1 / 16, 1 / 8, 3 / 16])
    assert result.active[near].all()
    np.testing.assert_array_equal(result.classes[near], [SEMI_CONTACT, SEMI_CONTACT, FULL_CONTACT])


def test_warm_start_ignores_the_gap_far_away():
    """A warm start 1e-9 (1e-7 of max|u|) off the obstacle at one node does not put that
    node in the initial active set (before: tolerance 1e-10 · 400 = 4e-8)."""
    problem = clamped_corner_problem()
    exact = solve(problem)
    node = bottom_nodes(exact, [1 / 2])[0]
    assert exact.active[node]
    u0 = exact.u.copy()
    u0[exact.contact.nodes[node], 1] += 1e-9  # n = (0, −1): u·n − ψ = −1e-9
    warm = solve(problem, u0=u0)
    assert warm.report.history[0].n_active == exact.active.sum() - 1
    np.testing.assert_array_equal(warm.active, exact.active)
