"""The built-in ``two-spheres`` (docs/method.md, *Two bodies in three dimensions*): the turned
lower ball, the coarse solve's KKT conditions and its Hertz errors, bad input refused."""

from __future__ import annotations

import numpy as np
import pytest

from signorini import solve
from signorini.examples.hertz3d import graded_eighth_ball
from signorini.examples.two_spheres3d import (
    turned_ball,
    two_spheres,
    two_spheres_metrics,
    two_spheres_solution,
)
from signorini.fem.material import Material


def _volumes(points, cells):
    p = points[cells]
    return (
        np.einsum("ci,ci->c", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    )


def test_turned_ball_is_the_ball_about_minus_r():
    """A rotation: the same positive cell volumes; the parts on the planes they name; the
    sphere's vertices at distance R from (0, 0, −R), the pole at the origin, z ∈ [−R, 0]."""
    ball = graded_eighth_ball(1, 2.0, 0.5, 0.5, 0.0)
    turned = turned_ball(ball)
    v0, v1 = _volumes(ball.points, ball.cells), _volumes(turned.points, turned.cells)
    assert (v1 > 0).all()
    np.testing.assert_allclose(v1, v0, rtol=1e-13)
    x = turned.points
    assert x[:, 2].min() == pytest.approx(-2.0) and x[:, 2].max() == pytest.approx(0.0, abs=1e-15)
    for part, axis in (("x0", 0), ("y0", 1)):
        on = np.unique(turned.boundary[turned.boundary_part == turned.part_index(part)])
        assert np.abs(x[on, axis]).max() < 1e-14
    on = np.unique(turned.boundary[turned.boundary_part == turned.part_index("sphere")])
    np.testing.assert_allclose(np.linalg.norm(x[on] - [0, 0, -2.0], axis=1), 2.0, rtol=1e-13)
    assert turned.curves[turned.part_index("sphere")].center.tolist() == [0.0, 0.0, -2.0]


def test_hertz_for_two_spheres_reduces_to_one_on_a_rigid_plane():
    """R2 → ∞ and E2 → ∞ give the sphere on a rigid plane: a = (3 P R / (4 E*))^{1/3}."""
    soft, rigid = Material.from_young(1.0, 0.3), Material.from_young(1e12, 0.3)
    a, p0 = two_spheres_solution(1e-3, (1.0, 1e12), (soft, rigid))
    e_star = 1.0 / (1 - 0.3**2)
    assert a == pytest.approx((3e-3 / (4 * e_star)) ** (1 / 3), rel=1e-9)
    assert p0 == pytest.approx(3e-3 / (2 * np.pi * a**2), rel=1e-12)


@pytest.mark.parametrize("slave", ["upper", "lower"])
def test_coarse_two_spheres_kkt_and_hertz(slave):
    """On the default coarse mesh (h = 0.1 at the poles, a ≈ 0.08: under two cells across the
    contact radius) the discrete KKT conditions hold to round-off, and a and p0 lie within
    the coarse mesh's resolution of Hertz: |a_h / a − 1| ≤ 0.05 (the radius moment averages
    the pressure), |p0_h / p0 − 1| ≤ 0.25 (the lumped pressure at the pole averages over
    one cell of size h ≈ a, p0 (1 − r²/a²)^{1/2} losing up to a quarter there)."""
    result = solve(two_spheres(slave=slave))
    cs, force = result.contact, result.contact_force
    gap = cs.relative_gap(result.u)
    scale = np.abs(force).max()
    assert (force >= -1e-10 * scale).all()
    assert (gap <= 1e-10 * 0.01).all()
    assert np.abs(force * gap).max() <= 1e-10 * scale * 0.01
    m = two_spheres_metrics(result)
    assert abs(m["a_rel_error"]) <= 0.05
    assert abs(m["p0_rel_error"]) <= 0.25


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radii": (1.0, -1.0)}, "radii"),
        ({"depth": 0.0}, "depth"),
        ({"depth": "x"}, "depth"),
        ({"slave": "left"}, "slave"),
        ({"cap": 5.0}, "cap"),
    ],
)
def test_bad_input_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        two_spheres(**kwargs)


def _coupling(h=0.07):
    from signorini.contact.mortar3d import mortar_coupling_3d
    from signorini.fem.space3d import P2TetSpace

    problem = two_spheres(h_contact=h)
    space = P2TetSpace(problem.mesh)
    return space, mortar_coupling_3d(space, "upper.cap", "lower.sphere")


def test_rim_rows_scaled_to_coverage_one(monkeypatch):
    """At the symmetry planes the projected master misses slivers of the slave (coverage
    1 − 2·10⁻³ on this mesh without the scaling); the rim rows are scaled so that every row
    transfers constants exactly, and no interior row is touched."""
    import signorini.contact.mortar3d as m3

    space, scaled = _coupling()
    assert np.abs(scaled.coverage - 1).max() <= 1e-12
    monkeypatch.setattr(m3, "_rim_scaled", lambda space, slave, M, *rest: M)
    raw = m3.mortar_coupling_3d(space, "upper.cap", "lower.sphere")
    off = np.abs(raw.coverage - 1)
    assert 1e-4 < off.max() <= m3.RIM_COVERAGE
    x = space.node_points[raw.slave_nodes]
    touched = off > 1e-12
    # touched rows lie on, or one face from, the symmetry planes
    assert np.minimum(x[touched, 0], x[touched, 1]).max() < 0.1
    np.testing.assert_array_equal(raw.M[~touched].toarray(), scaled.M[~touched].toarray())


def test_multiplier_moment_is_the_integral_of_the_interpolant():
    """``Σ_j D_jj r̃²_j = ∫_Γs r²_h`` (the identity behind ``a_h``: a uniform multiplier,
    Λ̃_j = D_jj), the right side from the straight faces directly: the P2 vertex functions
    integrate to 0 on a flat triangle and the midpoint functions to |F| / 3."""
    space, c = _coupling(h=0.1)
    x = space.node_points
    r2 = np.sum(x[:, :2] ** 2, axis=1)
    f = c.slave_faces
    tri = x[f[:, :3]]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    direct = float(np.sum(area / 3 * r2[f[:, 3:]].sum(axis=1)))
    alpha = c.alpha
    rt = r2.copy()
    for e, a, b in ((3, 0, 1), (4, 1, 2), (5, 2, 0)):
        rt[f[:, e]] = (r2[f[:, e]] - alpha * (r2[f[:, a]] + r2[f[:, b]])) / (1 - 2 * alpha)
    assert float(c.D @ rt[c.slave_nodes]) == pytest.approx(direct, rel=1e-12)


@pytest.mark.slow
def test_two_spheres_converge_to_hertz():
    """Graded meshes h = 0.07, 0.05, 0.035 at the poles (26k–71k unknowns, about a minute):
    the lumped peak pressure's error falls with h (its bias is −O(h²/a²), as hertz-3d's), and
    on the finest the contact radius is within 1 % of Hertz's for two spheres."""
    errors = []
    for h in (0.07, 0.05, 0.035):
        m = two_spheres_metrics(solve(two_spheres(h_contact=h)))
        errors.append((m["a_rel_error"], m["p0_rel_error"]))
        print(f"h = {h}: a {m['a_rel_error']:+.3%}, p0 {m['p0_rel_error']:+.3%}")
    p0 = np.abs([e[1] for e in errors])
    assert p0[0] > p0[1] > p0[2]
    assert abs(errors[-1][0]) < 0.01
