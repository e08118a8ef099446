"""Force control of a semi-coercive body (docs/method.md, *Force control*): the Hertz
quarter disc pressed by a prescribed force P, held sideways by a roller and vertically by
the contact alone; a load the contact cannot carry is refused naming the free motion."""

import numpy as np
import pytest

from signorini import adaptive
from signorini.contact.solution import solve
from signorini.examples.hertz_half import hertz_quarter, hertz_quarter_metrics
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.output import fitted_slope
from signorini.problem import (
    Contact,
    ContactProblem,
    Coulomb,
    Dirichlet,
    HalfPlane,
    Neumann,
    ProblemError,
    Roller,
)

#: P per unit thickness on the whole cylinder: a / R ≈ 0.1 with E = 1, ν = 0.3
FORCE = 0.0084


def test_hertz_quarter_under_a_prescribed_force_matches_hertz_adaptively():
    problem = hertz_quarter(force=FORCE)
    assert problem.rigid_motions.shape == (1, 3)  # the vertical translation
    levels = list(adaptive(problem, max_ndof=2200, metrics=hertz_quarter_metrics))
    print("\nlevel   ndof   force      a/R      a error   p0 error")
    for level in levels:
        r, e = level.record, level.record.extra
        print(
            f"{r.level:5d} {r.ndof:6d} {e['force']:.6g} {e['a']:.5f} "
            f"{100 * e['a_rel_error']:+8.3f} % {100 * e['p0_rel_error']:+8.3f} %"
        )
    final = levels[-1].record.extra
    # the contact carries exactly the prescribed force (equilibrium along the free motion)
    assert final["force"] == pytest.approx(FORCE, rel=1e-9)
    assert 0.09 < final["a"] < 0.11
    assert abs(final["a_rel_error"]) < 0.01, f"a off Hertz by {final['a_rel_error']:.3%}"
    assert abs(final["p0_rel_error"]) < 0.01, f"p0 off Hertz by {final['p0_rel_error']:.3%}"
    assert len(levels) >= 8
    ndof = [level.record.ndof for level in levels]
    eta = [level.record.eta for level in levels]
    slope = fitted_slope(ndof, eta, last=5)
    assert -1.3 < slope < -0.7, f"η slope {slope:.2f}, expected about −1"


def test_a_load_that_pulls_the_body_away_is_refused_naming_the_motion():
    problem = hertz_quarter(force=-FORCE, h_bottom=0.1)
    with pytest.raises(
        ProblemError, match=r"pulls the body away.*translation along \(0\.0, 1\.0\).*'arc'"
    ):
        solve(problem)


def test_no_load_along_the_free_motion_is_refused():
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    conditions = {
        "top": Neumann((0.0, 0.0)),
        "right": Neumann((0.0, 0.0)),
        "left": Roller(),
        "bottom": Contact(gap=0.0),
    }
    problem = ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions)
    with pytest.raises(ProblemError, match=r"does not press the body.*along \(0\.0, 1\.0\)"):
        solve(problem)


def test_motion_that_no_contact_holds_is_refused_at_build_time():
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    material = Material.from_young(1.0, 0.3)
    free = {"top": Neumann((0.0, -0.1)), "right": Neumann((0.0, 0.0))}
    # a flat contact never holds the translation along itself
    with pytest.raises(
        ProblemError, match=r"needs a Dirichlet part.*translation along \(1\.0, 0\.0\).*'bottom'"
    ):
        ContactProblem(mesh, material, {**free, "left": Neumann(), "bottom": Contact()})
    # u_y held along y = 0 holds the vertical translation and the rotation, not u_x
    with pytest.raises(
        ProblemError, match=r"translation along \(1\.0, 0\.0\).*there is no contact part"
    ):
        ContactProblem(
            mesh, material, {**free, "left": Neumann(), "bottom": Dirichlet((None, 0.0))}
        )
    # held both ways by rollers: coercive, no free motion
    p = ContactProblem(mesh, material, {**free, "left": Roller(), "bottom": Roller()})
    assert p.rigid_motions.shape == (0, 3)
    assert np.isfinite(solve(p).u).all()


def test_semi_coercive_body_with_friction_carries_its_weight():
    # u_x held along the top holds the horizontal translation; the vertical translation and
    # the rotation about a point of the top are held by the frictional foundation the block
    # rests on under its own weight
    mesh = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    conditions = {
        "top": Dirichlet((0.0, None)),
        "left": Neumann(),
        "right": Neumann(),
        "bottom": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(0.3)),
    }
    weight = 0.05
    problem = ContactProblem(
        mesh, Material.from_young(1.0, 0.3), conditions, body_force=lambda x: (0.0, -weight)
    )
    assert problem.rigid_motions.shape == (2, 3)
    result = solve(problem)
    assert result.total_contact_force == pytest.approx(2.0 * weight, rel=1e-10)
    # symmetric about x = 1: the friction forces cancel
    assert abs(result.tangential_force.sum()) <= 1e-10 * result.total_contact_force


def test_friction_at_a_node_a_roller_holds_tangentially_is_refused():
    problem = hertz_quarter(force=FORCE, h_bottom=0.1)
    arc = Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(0.3))
    problem = ContactProblem(problem.mesh, problem.material, {**problem.conditions, "arc": arc})
    with pytest.raises(ProblemError, match=r"'arc' has friction at the node \(0\.0, 0\.0\)"):
        solve(problem)
