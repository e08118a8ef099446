"""Obstacle motion counts as slip (docs/method.md, *Obstacle motion*): a rigid obstacle
moved along a load path (``shape.moved(d)``) enters the gap and the friction law's slip."""

import numpy as np
import pytest

from signorini.algebra.friction.newton import SLIP
from signorini.contact.load_path import solve_path
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Disc, HalfPlane, Neumann

MESH = rectangle(0.0, 2.0, 0.0, 1.0, 12, 6)
MATERIAL = Material.from_young(100.0, 0.3)
DEPTH, F = 0.02, 0.3
PATH = [0.0, 0.01, 0.02, 0.05, 0.1]


def _step(shape, s: float, drag: bool) -> ContactProblem:
    """The block pressed by ``shape`` moved down by DEPTH; ``drag``: the obstacle moved by
    ``s`` along x, else the base moved by ``−s`` (the same relative motion)."""
    return ContactProblem(
        MESH,
        MATERIAL,
        {
            "bottom": Dirichlet((0.0 if drag else -s, 0.0)),
            "left": Neumann(),
            "right": Neumann(),
            "top": Contact(obstacle=shape.moved((s if drag else 0.0, -DEPTH)), friction=Coulomb(F)),
        },
    )


def _paths(shape):
    drag = solve_path([_step(shape, s, True) for s in PATH])
    base = solve_path([_step(shape, s, False) for s in PATH])
    return drag, base


def test_dragging_a_flat_obstacle_equals_moving_the_base_the_other_way():
    # a flat obstacle moved along itself: the small-deformation gap is the same, so the two
    # paths are the same problem up to a rigid translation of the body
    drag, base = _paths(HalfPlane((0.0, 1.0), (0.0, -1.0)))
    for a, b, s in zip(drag, base, PATH, strict=True):
        total = a.total_contact_force
        assert np.abs(a.contact_force - b.contact_force).max() <= 1e-12 * total
        assert np.abs(a.tangential_force - b.tangential_force).max() <= 1e-12 * total
        assert np.array_equal(a.state, b.state)
        assert np.abs(a.u - (b.u + [s, 0.0])).max() <= 1e-12 * np.abs(a.u).max()
    # in full slip Coulomb's tangential force is F · P
    last = drag[-1]
    assert (last.state[last.active] == SLIP).all()
    assert last.tangential_force.sum() == pytest.approx(F * last.total_contact_force, rel=1e-12)
    assert last.tangential_force.sum() > 1.0


def test_dragging_a_disc_slides_with_coulomb_force():
    drag, base = _paths(Disc((1.0, 2.0), 1.0))
    last = drag[-1]
    P = last.total_contact_force
    # the tangential force of the dragged disc is F · P in full slip (0.0087, 2 % of
    # it, when the obstacle's motion did not count as slip)
    assert (last.state[last.active] == SLIP).all()
    assert last.tangential_force.sum() == pytest.approx(F * P, rel=1e-12)
    # moving the base instead agrees to the small-deformation linearisation of the disc at
    # the body's undeformed points, first order in s / R: exact at s = 0, 0.18 % at s = 0.01
    first = drag[1], base[1]
    assert np.array_equal(first[0].state, first[1].state)
    assert abs(first[0].total_contact_force / first[1].total_contact_force - 1) < 0.005
    assert drag[0].total_contact_force == pytest.approx(base[0].total_contact_force, rel=1e-12)
