"""Friction laws (signorini.problem.friction_laws): their data checks, and the per-constraint
friction data of the contact set (law, its weight: Tresca bound s_z = ∫ s ψ_z ds, Coulomb
coefficient)."""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import corner_problem, problem_contact_set

from signorini.contact.solution import solve
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann, Tresca
from signorini.problem.fields import ProblemError

MATERIAL = Material.from_young(10.0, 0.3)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Tresca(-1.0), r"Tresca\(bound=...\) must be a finite number >= 0.*got -1\.0"),
        (lambda: Tresca(float("nan")), r"Tresca\(bound=...\) must be .*got nan"),
        (lambda: Tresca("0.3"), r"Tresca\(bound=...\) must be .*got '0\.3'"),
        (lambda: Tresca(lambda: 1.0), r"Tresca\(bound=...\)"),
        (lambda: Tresca(1.0, everywhere="yes"), r"Tresca\(everywhere=...\) must be True or Fa"),
        (lambda: Coulomb(-0.2), r"Coulomb\(coefficient=...\) must be a finite number >= 0"),
        (lambda: Coulomb(float("inf")), r"Coulomb\(coefficient=...\) must be"),
        (lambda: Contact(friction=0.3), r"Contact\(friction=...\) must be None, Tresca"),
    ],
)
def test_bad_friction_data_is_refused(build, message):
    with pytest.raises(ProblemError, match=message):
        build()


def bottom_contact(friction) -> ContactProblem:
    return ContactProblem(
        rectangle(0.0, 2.0, 0.0, 1.0, nx=4, ny=2),
        MATERIAL,
        {
            "left": Neumann(),
            "right": Neumann(),
            "top": Dirichlet((0.01, -0.02)),
            "bottom": Contact(friction=friction),
        },
    )


def test_tresca_bound_is_the_integral_of_s_times_the_basis_function():
    # s linear in x: the Gauss rule integrates s ψ_z exactly; s_z = ∫ s ψ_z ds
    pb = bottom_contact(Tresca(lambda x: 1.0 + 0.5 * x[:, 0]))
    cs = problem_contact_set(pb, P2Space(pb.mesh))
    assert cs.friction.laws == (pb.conditions["bottom"].friction,)
    assert (cs.friction.index == 0).all()
    x = P2Space(pb.mesh).node_points[cs.nodes][:, 0]
    # reference: on each edge [a, b] of length h, ∫ (1 + x/2) ψ_j dx in closed form
    h = 0.5
    expected = np.zeros(cs.size)
    s = lambda y: 1.0 + 0.5 * y  # noqa: E731
    for a in np.arange(0.0, 2.0, h):  # the 4 edges, in closed form (not the code's rule)
        b, m = a + h, a + h / 2
        # on τ ∈ [0, 1]: ψ_start = (1 − τ)(1 − 2τ), ψ_end = τ(2τ − 1), ψ_mid = 4τ(1 − τ),
        # s = s(a) + (s(b) − s(a)) τ
        ds = s(b) - s(a)
        integrals = {
            a: h * s(a) / 6,
            b: h * (s(a) / 6 + ds / 6),
            m: h * (2 * s(a) / 3 + ds / 3),
        }
        for node_x, value in integrals.items():
            expected[np.abs(x - node_x) < 1e-12] += value
    assert np.abs(cs.friction.weight - expected).max() < 1e-14


def test_constant_tresca_bound_is_s_times_w_z_and_coulomb_coefficient_per_constraint():
    pb = bottom_contact(Tresca(0.3))
    cs = problem_contact_set(pb, P2Space(pb.mesh))
    assert np.allclose(cs.friction.weight, 0.3 * cs.basis_integral, rtol=1e-14, atol=0)
    pb = bottom_contact(Coulomb(0.4))
    cs = problem_contact_set(pb, P2Space(pb.mesh))
    assert cs.friction.laws == (Coulomb(0.4),) and (cs.friction.index == 0).all()
    assert (cs.friction.weight == 0.4).all()
    pb = bottom_contact(None)
    cs = problem_contact_set(pb, P2Space(pb.mesh))
    assert (cs.friction.index == -1).all() and not cs.has_friction


def test_negative_bound_function_names_the_part():
    pb = bottom_contact(Tresca(lambda x: 0.5 - x[:, 0]))
    with pytest.raises(
        ProblemError, match="the Tresca bound of contact part 'bottom' must be >= 0"
    ):
        problem_contact_set(pb, P2Space(pb.mesh))


@pytest.mark.parametrize("shapes", [False, True], ids=["gap", "shape"])
@pytest.mark.parametrize("which", ["bottom", "right", "both"])
def test_friction_at_a_corner_is_refused_when_the_problem_is_built(which, shapes):
    # the rigid corner's vertex (1, 0) carries one constraint per part: no tangent is left for
    # a friction law (before: refused only inside solve, after the assembly)
    base = corner_problem(shapes=shapes)
    conditions = dict(base.conditions)
    for part in ("bottom", "right") if which == "both" else (which,):
        conditions[part] = Contact(obstacle=base.conditions[part].obstacle, friction=Coulomb(0.5))
    with pytest.raises(ProblemError) as info:
        ContactProblem(base.mesh, base.material, conditions, body_force=base.body_force)
    msg = str(info.value)
    assert "the vertex (1, 0) is a corner of contact parts 'bottom' and 'right'" in msg, msg
    named = ["bottom", "right"] if which == "both" else [which]
    assert f"and {named} have friction" in msg, msg


def test_friction_where_two_parts_continue_each_other_is_accepted():
    # the bottom split at x = 0.5 into two frictional parts on one floor: one direction at
    # (0.5, 0), no corner; the solve equals that of the unsplit frictional bottom
    base = corner_problem()
    tol = 1e-12
    split = Mesh.from_arrays(
        base.mesh.points,
        base.mesh.cells,
        {
            "left": lambda x: np.abs(x[:, 0]) < tol,
            "top": lambda x: np.abs(x[:, 1] - 1) < tol,
            "right": lambda x: np.abs(x[:, 0] - 1) < tol,
            "a": lambda x: (np.abs(x[:, 1]) < tol) & (x[:, 0] <= 0.5 + tol),
            "b": lambda x: (np.abs(x[:, 1]) < tol) & (x[:, 0] >= 0.5 - tol),
        },
    )
    conditions = {k: v for k, v in base.conditions.items() if k != "bottom"}
    conditions["right"] = Neumann()
    two = dict(conditions, a=Contact(friction=Coulomb(0.5)), b=Contact(friction=Coulomb(0.5)))
    one = dict(conditions, bottom=Contact(friction=Coulomb(0.5)))
    split_result = solve(ContactProblem(split, base.material, two, body_force=base.body_force))
    whole = solve(ContactProblem(base.mesh, base.material, one, body_force=base.body_force))
    assert np.abs(split_result.u - whole.u).max() <= 1e-12 * np.abs(whole.u).max()
