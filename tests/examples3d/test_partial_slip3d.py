"""``partial-slip-3d`` (Cattaneo–Mindlin in 3D): the half ball pressed, then pulled along x,
through two load steps of ``solve`` (docs/method.md, *Friction in three dimensions*)."""

from __future__ import annotations

import numpy as np
import pytest
from examples3d.friction_runs import checked_run

from signorini.contact.solution import SLIP, STICK, solve
from signorini.examples.partial_slip3d import partial_slip_3d_metrics, partial_slip_3d_path


@pytest.mark.slow
def test_a_central_stick_disc_inside_a_slip_annulus_near_mindlins_radius():
    """On the default mesh (h = 0.1 R at the pole: about two cells across the contact
    radius a ≈ 0.097 R, 10 996 unknowns, 19 stick rows) c/a from the zero of the stick rows'
    deficit d² (a² − r²) = c² − r² is within 0.03 of Mindlin's (1 − Q/(F P))^{1/3} (measured
    0.882 against 0.895, gap 0.013), the fitted slope within 0.25 of Mindlin's −1 (measured
    −0.949), and the stick set's area within 0.07 (measured 0.940, gap 0.045); the finer
    levels' numbers are in docs/method.md, *Friction in three dimensions: the disc law*.
    Q/(F P) = 0.283 is the friction force along the pull alone. The states form a disc
    inside an annulus: every stick row is nearer the axis than the farthest slip row, and
    the mean radius of the slip rows exceeds that of the stick rows."""
    steps = partial_slip_3d_path()
    result = None
    for step in steps:  # a loop over load steps
        result = solve(step, step.mesh, previous=result)
        assert result.report.kkt.max <= 1e-10
    m = partial_slip_3d_metrics(result)
    assert 0.2 < m["q_over_fp"] < 0.8  # partial slip
    x = result.space.node_points[result.contact.node]
    r = np.hypot(x[:, 0], x[:, 1])
    stick, slip = result.state == STICK, result.state == SLIP
    assert stick.any() and slip.any()
    assert r[stick].max() < r[slip].max() and r[stick].mean() < r[slip].mean()
    assert abs(m["c_over_a"] - m["c_over_a_theory"]) <= 0.03
    assert abs(m["deficit_slope"] + 1.0) <= 0.25
    assert abs(m["c_over_a_area"] - m["c_over_a_theory"]) <= 0.07


@pytest.mark.slow
def test_the_run_records_the_states_in_its_history_and_vtu(tmp_path, capsys):
    """``signorini run partial-slip-3d --uniform`` (one level, about 11k unknowns): the
    history's friction columns, described in history.md, agree with the example's own counts
    and with the level's VTU file read back; the tangential KKT residuals meet 1e-12."""
    out = tmp_path / "run"
    args = ["partial-slip-3d", "--uniform", "--max-ndof", "12000", "--no-figures"]
    row, _ = checked_run(args, out)
    capsys.readouterr()
    described = (out / "history.md").read_text()
    table = {line.split("`")[1] for line in described.splitlines() if line.startswith("| `")}
    assert table - {"linear_iterations"} == set(row)


def _turned_path(angle: float, h_contact: float):
    """The half ball turned by ``angle`` about z (its mirror plane and its pull too), its top
    held at (0, 0, −δ) then (ξ cos θ, ξ sin θ, −δ); returns the results of both steps and the
    rotation R (points ``x R^T``)."""
    from signorini.examples.partial_slip3d import (
        COEFFICIENT_3D,
        POISSON_3D,
        PRESS_3D,
        PULL_3D,
        half_ball,
    )
    from signorini.fem.material import Material
    from signorini.mesh.mesh import Mesh
    from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
    from signorini.problem.conditions import Roller
    from signorini.problem.obstacles3d import HalfSpace

    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    base = half_ball(2, 1.0, h_contact, 0.12)
    parts = {p: base.facets[base.part_facets(p)] for p in base.part_names}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    mesh = mesh.with_curve("sphere", base.curves[base.part_names.index("sphere")])
    contact = Contact(
        obstacle=HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), friction=Coulomb(COEFFICIENT_3D)
    )
    results = []
    for xi in (0.0, PULL_3D):  # a loop over load steps
        cond = {p: Neumann((0.0, 0.0, 0.0)) for p in mesh.part_names}
        move = R @ np.array([xi, 0.0, -PRESS_3D])
        cond.update(y0=Roller(), z1=Dirichlet(tuple(move.tolist())), sphere=contact)
        problem = ContactProblem(mesh, Material.from_young(1.0, POISSON_3D), cond)
        results.append(solve(problem, mesh, previous=results[-1] if results else None))
    return results, R


@pytest.mark.slow
def test_a_pull_along_a_turned_direction_gives_the_turned_answer():
    """The whole problem turned by 0.6 rad about z (the mirror plane y = 0 becomes a roller on
    a plane that is not a coordinate plane, held in its face normal's frame): the node frames'
    tangents differ from the unturned ones, the disc law is isotropic, so the displacement
    turned back equals the unturned one to solver tolerance (1e-8 relative), the stick/slip
    states are identical and c/a (both estimates, and Mindlin's along the turned pull) are
    equal (docs/method.md, *Friction in three dimensions: the disc law*)."""
    answers = []
    for angle in (0.0, 0.6):  # a loop over the two orientations
        (press, pull), R = _turned_path(angle, 0.15)
        assert pull.report.kkt.max <= 1e-10
        m = partial_slip_3d_metrics(pull, direction=(np.cos(angle), np.sin(angle)))
        answers.append((pull.u @ R, pull.state, m))
    (u0, s0, m0), (u1, s1, m1) = answers
    np.testing.assert_array_equal(s0, s1)
    assert (s0 == STICK).any() and (s0 == SLIP).any()
    assert np.abs(u1 - u0).max() <= 1e-8 * np.abs(u0).max()
    for key in ("c_over_a", "c_over_a_area", "c_over_a_theory", "a"):
        assert m1[key] == pytest.approx(m0[key], rel=1e-8, abs=1e-10), key
