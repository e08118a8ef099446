"""Rollers and one-component Dirichlet conditions (docs/method.md, *Rollers and components*):
the symmetric half-model of the Hertz half-disc equals the half of the full model."""

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.hertz_half import hertz_quarter, mirrored_half_disc
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.problem import (
    Contact,
    ContactProblem,
    Dirichlet,
    HalfPlane,
    Neumann,
    ProblemError,
    Roller,
)


def _full(quarter: ContactProblem) -> tuple[ContactProblem, np.ndarray]:
    mesh, index = mirrored_half_disc(quarter.mesh)
    conditions = {
        "top": quarter.conditions["top"],
        "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
    }
    return ContactProblem(mesh, quarter.material, conditions), index


def _match(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Index into ``b`` of each point of ``a`` (the same points to round-off)."""
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    at = d.argmin(axis=1)
    assert d[np.arange(len(a)), at].max() < 1e-14
    return at


def test_quarter_disc_with_roller_is_half_of_the_mirrored_half_disc():
    quarter = hertz_quarter(rings=4, h_bottom=0.03)
    full, index = _full(quarter)
    rq, rf = solve(quarter), solve(full)
    scale = np.abs(rf.u).max()
    # displacements at every node of the quarter (vertices and edge midpoints)
    at = _match(rq.space.node_points, rf.space.node_points)
    assert np.array_equal(at[: quarter.mesh.n_points], index)
    assert np.abs(rq.u - rf.u[at]).max() <= 1e-12 * scale
    assert np.abs(rq.u[:, 0][np.abs(rq.space.node_points[:, 0]) == 0.0]).max() == 0.0
    # contact forces and active sets; the axis node carries half its hat function
    pq = rq.space.node_points[rq.contact.nodes]
    row = _match(pq, rf.space.node_points[rf.contact.nodes])
    on_axis = pq[:, 0] == 0.0
    assert on_axis.sum() == 1
    expected = rf.contact_force[row] * np.where(on_axis, 0.5, 1.0)
    total = rf.total_contact_force
    assert np.abs(rq.contact_force - expected).max() <= 1e-11 * total
    assert np.array_equal(rq.active, rf.active[row])
    assert rq.active.sum() >= 5
    assert 2.0 * rq.total_contact_force == pytest.approx(total, rel=1e-12)
    # the axis holds u_x only; at its contact node (frame n = (0, −1), t = (1, 0)) the held
    # u_x is the tangential frame DOF, the normal one stays free for the contact
    a = assemble(quarter, quarter.mesh)
    axis = a.space.part_nodes(["axis"])
    corner = np.isin(axis, a.dirichlet_nodes)  # the top's end (0, R): held in both
    contact = np.isin(axis, a.contact.nodes)
    assert corner.sum() == 1 and contact.sum() == 1
    plain = axis[~corner & ~contact]
    assert np.isin(2 * plain, a.dirichlet).all()
    assert not np.isin(2 * plain + 1, a.dirichlet).any()
    z = axis[contact]
    assert np.isin(2 * z + 1, a.dirichlet).all() and not np.isin(2 * z, a.dirichlet).any()


def test_dirichlet_component_equals_roller_on_an_axis():
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4)
    base = {"top": Neumann((0.3, -0.2)), "right": Neumann((0.0, 0.0))}
    material = Material.from_young(1.0, 0.3)
    results = []
    for left, bottom in [
        (Roller(), Roller(0.01)),
        (Dirichlet((0.0, None)), Dirichlet((None, -0.01))),
    ]:
        p = ContactProblem(mesh, material, {**base, "left": left, "bottom": bottom})
        results.append(solve(p))
    assert np.abs(results[0].u - results[1].u).max() <= 1e-14
    u, x = results[0].u, results[0].space.node_points
    # u_x = 0 on x = 0, u_y = −0.01 (the outward normal of the bottom is −y) on y = 0
    assert np.abs(u[x[:, 0] == 0.0, 0]).max() == 0.0
    assert np.abs(u[x[:, 1] == 0.0, 1] + 0.01).max() <= 1e-15
    # the traction (0.3, −0.2) on the top is carried: u_x grows with x, the body slides
    assert u[:, 0].max() > 0.1


def test_roller_refusals():
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    material = Material.from_young(1.0, 0.3)
    free = {"top": Neumann((0.0, 0.0)), "right": Neumann((0.0, 0.0)), "bottom": Dirichlet()}
    with pytest.raises(ProblemError, match="not both|None"):
        Dirichlet((None, None))
    with pytest.raises(ProblemError, match="Dirichlet"):
        Dirichlet((None, "a"))
    with pytest.raises(ProblemError, match="Roller"):
        Roller("a")
    rotated = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    rotated = type(rotated)(
        rotated.points @ np.array([[0.8, 0.6], [-0.6, 0.8]]),
        rotated.cells,
        rotated.boundary,
        rotated.boundary_part,
        rotated.part_names,
    )
    # a roller on an oblique part holds u·n in a node frame (tests/problem/
    # test_roller_frames.py): the rotated model gives the rotated solution
    free = {**free, "top": Neumann((0.2, -0.1)), "bottom": Dirichlet((0.01, 0.0))}
    turn = np.array([[0.8, 0.6], [-0.6, 0.8]])
    loads = {
        "top": Neumann(tuple(np.array([0.2, -0.1]) @ turn)),
        "bottom": Dirichlet(tuple(np.array([0.01, 0.0]) @ turn)),
    }
    r = solve(ContactProblem(rotated, material, {**free, **loads, "left": Roller(0.02)}))
    plain = solve(ContactProblem(mesh, material, {**free, "left": Roller(0.02)}))
    assert np.abs(r.u - plain.u @ turn).max() <= 1e-13 * np.abs(plain.u).max()
    left = r.space.part_nodes(["left"])
    left = left[~np.isin(left, r.dirichlet_nodes)]
    assert np.abs(r.u[left] @ (np.array([-1.0, 0.0]) @ turn) - 0.02).max() <= 1e-15
    assert ContactProblem(mesh, material, {**free, "left": Roller()}).dirichlet_parts == [
        "bottom",
        "left",
    ]


def test_roller_that_holds_the_contact_direction_is_refused():
    # a roller holding u_y on the left side meets the bottom's contact (direction −y)
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    material = Material.from_young(1.0, 0.3)
    conditions = {
        "top": Dirichlet((0.0, -0.01)),
        "right": Neumann((0.0, 0.0)),
        "left": Dirichlet((None, 0.0)),
        "bottom": Contact(gap=0.0),
    }
    with pytest.raises(ProblemError, match=r"\(0\.0, 0\.0\).*u_y.*'bottom'.*conflict"):
        assemble(ContactProblem(mesh, material, conditions), mesh)
