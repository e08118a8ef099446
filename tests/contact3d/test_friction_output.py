"""The output of a 3D frictional run (docs/method.md, *Friction in three dimensions: the
disc law*): the history's friction columns, named as in 2D, and the VTU point fields of the
node states and the slip directions, read back with meshio and checked against the result
and against the Cartesian reaction ``F − K u`` of the system without the contact part, an
independent computation of the friction force's direction."""

from __future__ import annotations

from dataclasses import replace

import meshio
import numpy as np
from contact3d_problems import MATERIAL

from signorini.algebra.friction.result import SLIP, STICK
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.loop.record import COLUMNS_3D_FRICTION, level_record
from signorini.mesh.builders3d import box
from signorini.output.vtu import von_mises
from signorini.output.vtu3d import FRICTION_FIELDS_3D, write_vtu_3d
from signorini.problem.conditions import Contact, Dirichlet, Neumann
from signorini.problem.friction_laws import Coulomb
from signorini.problem.obstacles3d import HalfSpace
from signorini.problem.problem import ContactProblem


def _pulled_block():
    """box(2) pressed, then its top moved along x (Coulomb F = 0.3, condition (a) so that a
    row's force is its node's); the pull's result and the system without the contact."""
    mesh = box(2, 2, 2)
    result = None
    for shift in (0.0, 0.004):  # a loop over load steps
        cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
        cond.update(
            z1=Dirichlet((shift, 0.0, -0.01)),
            z0=Contact(
                obstacle=HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                friction=Coulomb(0.3),
                face_alpha=0.0,
            ),
        )
        problem = ContactProblem(mesh, MATERIAL, cond)
        result = solve(problem, mesh, previous=result)
    plain = replace(problem, conditions={**cond, "z0": Neumann((0.0, 0.0, 0.0))})
    return result, assemble(plain, mesh)


def test_history_counts_the_states_and_carries_the_tangential_kkt():
    result, _ = _pulled_block()
    row = level_record(0, result, None).row()
    assert row["n_stick"] == int((result.state == STICK).sum()) > 0
    assert row["n_slip"] == int((result.state == SLIP).sum()) > 0
    assert row["n_stick"] + row["n_slip"] == row["n_active"]
    kkt = result.report.kkt
    assert row["kkt_tangential_bound"] == kkt.tangential_bound <= 1e-12
    assert row["kkt_tangential_complementarity"] == kkt.tangential_complementarity <= 1e-12
    assert {"n_stick", "n_slip", "kkt_tangential_bound"} <= set(COLUMNS_3D_FRICTION)


def test_vtu_states_and_slip_directions_read_back(tmp_path):
    result, plain = _pulled_block()
    path = write_vtu_3d(tmp_path / "level.vtu", result, von_mises)
    data = meshio.read(path).point_data
    assert set(FRICTION_FIELDS_3D) <= set(data)
    state, direction = data["contact_state"], data["slip_direction"]
    node = result.contact.node
    np.testing.assert_array_equal(state[node], result.state)
    off = np.ones(state.size, dtype=bool)
    off[node] = False
    assert (state[off] == -1).all() and not direction[off].any()
    assert not direction[node[result.state != SLIP]].any()
    # slipping nodes: the unit direction of the friction force, in the plane z = 0, equal to
    # that of the tangential part of the Cartesian reaction F − K u (the half-space's n = e_z)
    slip = node[result.state == SLIP]
    reaction = (plain.F - plain.K @ result.u.ravel()).reshape(-1, 3)[slip]
    tangential = reaction * np.array([1.0, 1.0, 0.0])
    expected = tangential / np.linalg.norm(tangential, axis=1)[:, None]
    np.testing.assert_allclose(direction[slip], expected, atol=1e-8)
    # the pull along +x: the friction force on the obstacle's side points along +x overall
    assert direction[slip, 0].sum() > 0
