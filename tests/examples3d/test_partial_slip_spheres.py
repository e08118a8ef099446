"""``partial-slip-spheres`` (Cattaneo–Mindlin between two bodies of one material): the two
half balls pressed, then pulled along x, through two load steps of ``solve``
(docs/method.md, *Two bodies in three dimensions: friction*)."""

from __future__ import annotations

import numpy as np
import pytest
from examples3d.friction_runs import checked_run

from signorini.contact.solution import SLIP, STICK, solve
from signorini.examples.partial_slip3d import partial_slip_3d_metrics
from signorini.examples.partial_slip_spheres3d import partial_slip_spheres_path
from signorini.examples.two_spheres3d import two_spheres_solution
from signorini.fem.material import Material


@pytest.mark.slow
def test_a_central_stick_disc_between_the_spheres_near_mindlins_radius():
    """On the default mesh (h = 0.1 at the poles, 27 746 unknowns, 22 rows in contact): the
    contact radius within 2 % of Hertz's for the slave's force P (measured 0.7 %), Q/(F P)
    between 0.2 and 0.8 (measured 0.386), the stick rows nearer the axis than the slip rows,
    c/a from the stick rows' deficit within 0.05 of Mindlin's (1 − Q/(F P))^{1/3} (measured
    0.890 against 0.850; the adaptive levels' numbers are in docs/method.md)."""
    result = None
    for step in partial_slip_spheres_path():  # a loop over load steps
        result = solve(step, step.mesh, previous=result)
        assert result.report.kkt.max <= 1e-12
    m = partial_slip_3d_metrics(result)
    assert 0.2 < m["q_over_fp"] < 0.8
    cs = result.contact
    x = result.space.node_points[cs.node]
    r = np.hypot(x[:, 0], x[:, 1])
    stick, slip = result.state == STICK, result.state == SLIP
    assert stick.any() and slip.any()
    assert r[stick].max() < r[slip].max() and r[stick].mean() < r[slip].mean()
    material = Material.from_young(1.0, 0.3)
    force = 2.0 * float(result.contact_force @ np.abs(cs.direction[:, 2]))  # the half balls
    a, _ = two_spheres_solution(force, (1.0, 2.0), (material, material))
    assert abs(m["a"] / a - 1.0) < 0.02
    assert abs(m["c_over_a"] - m["c_over_a_theory"]) <= 0.05


@pytest.mark.slow
def test_the_pair_run_records_the_states_in_its_history_and_vtu(tmp_path, capsys):
    """``signorini run partial-slip-spheres --uniform`` (one level, 27 746 unknowns): the
    history's friction columns agree with the example's own counts and with the level's VTU
    file read back, the slip directions there are unit vectors with the pull's sign at the
    slipping nodes; the tangential KKT residuals meet 1e-12."""
    out = tmp_path / "run"
    args = ["partial-slip-spheres", "--uniform", "--max-ndof", "28000", "--no-figures"]
    _, data = checked_run(args, out)
    capsys.readouterr()
    direction = data["slip_direction"][data["contact_state"] == SLIP]
    np.testing.assert_allclose(np.linalg.norm(direction, axis=1), 1.0, rtol=1e-12)
    assert (direction[:, 0] > 0).all()  # Λ_t / ‖Λ_t‖: along the relative slip, the pull's +x
