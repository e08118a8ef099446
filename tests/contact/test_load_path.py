"""Quasi-static load paths (signorini.contact.load_path, ``solve(..., previous=...)``): the
law on the slip increment, the warm start, and what is refused."""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import graded_half_disc

from signorini.contact.load_path import solve_path
from signorini.contact.solution import INACTIVE, SLIP, STICK, solve
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann, Tresca
from signorini.problem.obstacles import Disc, HalfPlane

MESH = rectangle(0.0, 2.0, 0.0, 1.0, nx=16, ny=8)
COULOMB = Coulomb(0.5)


def block(shift: float, push: float = 0.02, friction=COULOMB, mesh=MESH) -> ContactProblem:
    """The block (0, 2) × (0, 1) (E = 1, ν = 0.3) pushed down by ``push`` and sideways by
    ``shift`` at its top onto a rigid cylinder touching the middle of its bottom."""
    return ContactProblem(
        mesh,
        Material.from_young(1.0, 0.3),
        {
            "left": Neumann(),
            "right": Neumann(),
            "top": Dirichlet((shift, -push)),
            "bottom": Contact(obstacle=Disc((1.0, -12.5), 12.5), friction=friction),
        },
    )


def tangential(res) -> np.ndarray:
    """``u(z)·t_z`` per constraint."""
    n = res.contact.normal
    return np.einsum("kc,kc->k", res.u[res.contact.nodes], np.column_stack([-n[:, 1], n[:, 0]]))


@pytest.mark.parametrize("friction", [Coulomb(0.3), Tresca(0.005)], ids=["coulomb", "tresca"])
def test_the_law_acts_on_the_slip_increment(friction):
    """Step 2 of press-then-pull: its reference is step 1's ``u·t``; its stick nodes keep
    that tangential displacement, its slip nodes move along their force from it, at the
    bound; KKT of both laws."""
    first, second = solve_path([block(0.0, friction=friction), block(0.01, friction=friction)])
    reference = tangential(first)
    assert np.array_equal(first.tangential_reference, np.zeros(first.contact.size))
    assert np.allclose(second.tangential_reference, reference, rtol=0, atol=1e-15)
    slip = tangential(second) - reference
    stick, slipping = second.state == STICK, second.state == SLIP
    scale = np.abs(second.u).max()
    print(
        f"\n{friction}: stick {stick.sum()}, slip {slipping.sum()}, max |slip| on stick "
        f"{np.abs(slip[stick]).max() / scale:.1e} (relative), KKT {second.report.kkt.max:.1e}"
    )
    assert stick.any() and slipping.any()
    assert np.abs(slip[stick]).max() <= 1e-12 * scale
    assert (slip[slipping] * second.tangential_force[slipping] >= -1e-12 * scale).all()
    assert np.abs(slip[slipping]).max() > 1e-3 * scale
    assert second.report.kkt.max < 1e-10


def test_a_repeated_step_is_one_solve_of_the_same_solution():
    """Warm start from the previous step's states: the same load again is converged at
    once, with the same displacement; without friction the same holds for PDAS."""
    for friction in (Coulomb(0.5), None):
        first = solve(block(0.01, friction=friction))
        again = solve(block(0.01, friction=friction), previous=first)
        du = np.abs(again.u - first.u).max() / np.abs(first.u).max()
        print(f"{friction}: {first.report.iterations} then {again.report.iterations}, Δu {du:.1e}")
        assert again.report.iterations == 1
        assert du < 1e-12, du
        assert np.array_equal(again.state, first.state)


def test_friction_switched_on_after_a_frictionless_step():
    """Press without friction, then pull with Coulomb friction: the frictionless step's
    displacement is the warm start and its u·t the reference (its tangential slip under the
    press is not undone)."""
    first, second = solve_path([block(0.0, friction=None), block(0.01)])
    assert np.abs(tangential(first)).max() > 0
    np.testing.assert_allclose(second.tangential_reference, tangential(first), rtol=0, atol=1e-15)
    stick = second.state == STICK
    assert stick.any()
    np.testing.assert_allclose(tangential(second)[stick], tangential(first)[stick], atol=1e-15)
    assert second.report.kkt.max < 1e-10


def test_unloading_reverses_the_slip():
    """Pull, then move the top back: the nodes that slip in the last step slip against the
    pull (force Λ_t < 0), and the end state differs from the static solve of its load."""
    steps = solve_path([block(0.0), block(0.012), block(0.006)])
    back = steps[-1]
    slipping = back.state == SLIP
    assert slipping.any()
    assert (back.tangential_force[slipping] < 0).all()
    static = solve(block(0.006))
    assert (static.tangential_force[static.state == SLIP] > 0).all()
    Q_path, Q_static = back.tangential_force.sum(), static.tangential_force.sum()
    print(f"\nQ after unloading {Q_path:.5e}, static {Q_static:.5e}")
    assert Q_static - Q_path > 0.01 * abs(Q_static)


def test_load_paths_are_checked():
    with pytest.raises(ValueError, match="problems is empty"):
        solve_path([])
    with pytest.raises(ValueError, match="sequence of ContactProblem"):
        solve_path(block(0.0))
    with pytest.raises(ValueError, match=r"problems\[1\] must be a ContactProblem"):
        solve_path([block(0.0), "block"])
    other = rectangle(0.0, 2.0, 0.0, 1.0, nx=8, ny=4)
    with pytest.raises(ValueError, match=r"problems\[1\] is posed on another mesh"):
        solve_path([block(0.0), block(0.01, mesh=other)])
    free = ContactProblem(
        MESH,
        Material.from_young(1.0, 0.3),
        {"left": Neumann(), "right": Contact(gap=1.0), "top": Dirichlet(), "bottom": Neumann()},
    )
    with pytest.raises(ValueError, match=r"problems\[1\] has the contact parts \['right'\]"):
        solve_path([block(0.0), free])
    first = solve(block(0.0))
    with pytest.raises(ValueError, match="previous was solved on another mesh"):
        solve(block(0.01, mesh=other), previous=first)
    with pytest.raises(ValueError, match="previous has the contact parts"):
        solve(free, previous=first)
    with pytest.raises(ValueError, match="previous must be the ContactResult"):
        solve(block(0.01), previous=first.u)
    assert (first.state != INACTIVE).any()


def test_a_step_on_the_chords_of_a_curved_mesh_is_refused():
    """Same points and cells, but the arc's midpoints on its circle in one mesh and on the
    chords in the other: another discrete problem, refused as a previous step."""
    graded = graded_half_disc(1.0, 0.25, zone=0.1)
    chords = Mesh.from_arrays(
        graded.points,
        graded.cells,
        {"top": lambda x: x[:, 1] > 1 - 1e-12, "arc": lambda x: x[:, 1] < 1 - 1e-12},
    )
    curved = chords.with_curve("arc", Circle((0.0, 1.0), 1.0))

    def pressed(mesh):
        obstacle = HalfPlane((0.0, 0.0), (0.0, 1.0))
        return ContactProblem(
            mesh,
            Material.from_young(1.0, 0.3),
            {"top": Dirichlet((0.0, -0.01)), "arc": Contact(obstacle=obstacle, friction=COULOMB)},
        )

    first = solve(pressed(chords))
    assert np.array_equal(chords.cells, curved.cells)
    assert np.array_equal(chords.points, curved.points)
    with pytest.raises(ValueError, match="previous was solved on another mesh"):
        solve(pressed(curved), previous=first)
