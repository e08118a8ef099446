"""The deformed body and the contact pressure (:mod:`signorini.plots.deformed`)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.mesh.builders import rectangle
from signorini.plots import ContactDrawing, plot_deformed
from signorini.plots.contact_line import contact_coordinate, free_boundary_ends
from signorini.plots.deformed import NODE_STATES, displacement_scale

from .figure_checks import check_written


@pytest.mark.slow
def test_deformed_figure_with_pressure_and_obstacle(tmp_path, captured):
    mesh = rectangle(nx=6, ny=6)
    p, c = mesh.points, mesh.cells
    u = np.column_stack([0.05 * p[:, 1], -0.02 * p[:, 0]])
    u_p2 = np.vstack([u, np.full((10, 2), 99.0)])  # P2 rows after the vertices are ignored
    right = p[np.isclose(p[:, 0], 1.0)]
    pressure = 1.0 - np.abs(right[:, 1] - 0.5)
    written = plot_deformed(
        p, c, u_p2, tmp_path / "deformed", ContactDrawing(right, pressure), scale=3.0
    )
    check_written(written, tmp_path / "deformed")
    (info,) = captured
    assert info["legend"] == ["reference"]
    assert info["titles"][0] == "deformed body, displacement \u00d73"
    # the body is drawn at p + 3 u: x in [0, 1.15], y in [-0.06, 1]
    lim = info["data_lim"][0]
    assert (lim.x0, lim.y0, lim.x1, lim.y1) == pytest.approx((0.0, -0.06, 1.15, 1.0))
    # the reference boundary is the mesh's boundary, undeformed
    boundary = np.array(info["segments"]["reference"])

    def unordered(segments):
        return sorted(tuple(sorted(map(tuple, np.round(s, 12)))) for s in segments)

    assert unordered(boundary) == unordered(p[mesh.boundary])
    # the pressure is drawn against y on x = 1, in order
    x, y = info["lines"]["$p_h$"]
    order = np.argsort(right[:, 1])
    np.testing.assert_array_equal(x, right[order, 1])
    np.testing.assert_array_equal(y, pressure[order])
    assert info["xlabel"][:2] == [r"$x$", r"$y$"]


@pytest.mark.slow
def test_deformed_figure_with_obstacle_only(tmp_path, captured):
    mesh = rectangle(nx=2, ny=2)
    y = np.linspace(0.0, 1.0, 11)
    obstacle = np.column_stack([1.0 - 0.2 + 0.5 * np.abs(y - 0.5), y])
    u = np.zeros(2 * mesh.n_points)  # interleaved layout
    plot_deformed(mesh.points, mesh.cells, u, tmp_path / "d", obstacle=obstacle, title="t")
    (info,) = captured
    assert info["legend"] == ["reference", "obstacle"]
    assert info["titles"][0] == "t\ndisplacement at true scale"
    np.testing.assert_array_equal(np.column_stack(info["lines"]["obstacle"]), obstacle)


def test_deformed_figure_rejects_bad_arrays(tmp_path):
    mesh = rectangle(nx=2, ny=2)
    p, c = mesh.points, mesh.cells
    with pytest.raises(ValueError, match="displacement"):
        plot_deformed(p, c, np.zeros((3, 2)), tmp_path / "x")
    with pytest.raises(ValueError, match="together"):
        plot_deformed(p, c, np.zeros_like(p), tmp_path / "x", ContactDrawing(pressure=np.ones(3)))
    with pytest.raises(ValueError, match="pressure must have shape"):
        plot_deformed(p, c, np.zeros_like(p), tmp_path / "x", ContactDrawing(p[:3], np.ones(4)))
    assert not any(tmp_path.iterdir())


def test_contact_coordinate_is_arclength_on_a_slanted_boundary():
    s = np.array([0.0, 0.3, 0.45, 1.0])
    d = np.array([3.0, 4.0]) / 5.0
    pts = np.array([2.0, -1.0]) + s[:, None] * d
    order = np.array([2, 0, 3, 1])
    t, label = contact_coordinate(pts[order])
    np.testing.assert_allclose(t, s[order], atol=1e-14)
    assert label.startswith("$s$")
    t, label = contact_coordinate(np.column_stack([s, np.zeros(4)]))
    assert label == r"$x$" and np.array_equal(t, s)
    t, label = contact_coordinate(np.column_stack([np.ones(4), s]))
    assert label == r"$y$" and np.array_equal(t, s)


@pytest.mark.parametrize(
    ("size", "u_max", "scale"),
    [
        (1.0, 0.88, 0.1),  # Example 6.1: drawn at true scale the body folds over itself
        (1.0, 0.2, 1.0),  # Example 6.2: readable as it is
        (2.0, 0.03, 5.0),  # the inclined block: 1.5 % of its length, magnified
        (1.0, 0.019, 5.0),
        (1.0, 0.26, 0.2),
        (10.0, 40.0, 0.02),
        (1.0, 0.0, 1.0),
    ],
)
def test_displacement_scale(size, u_max, scale):
    points = np.array([[0.0, 0.0], [size, 0.0], [0.0, 0.5 * size]])
    u = np.array([[0.0, 0.0], [0.6 * u_max, -0.8 * u_max], [0.1 * u_max, 0.0]])
    assert displacement_scale(points, u) == pytest.approx(scale, rel=1e-12)
    drawn = scale * u_max / size
    assert drawn <= 0.25 and (u_max == 0 or drawn >= 0.02)  # visible, and not folding over


@pytest.mark.slow
def test_obstacle_from_the_gap_is_drawn_with_the_gaps_scaled(tmp_path, captured):
    """The surface ``z + ψ(z) n_z`` of the small-deformation model drawn as the drawn body
    meets it, ``z + s ψ(z) n_z`` (at true scale the magnified body would pass through it, or
    float above it), and the title says both are scaled."""
    mesh = rectangle(nx=4, ny=4)
    p, c = mesh.points, mesh.cells
    u = np.column_stack([np.zeros(len(p)), -0.5 * (1.0 - p[:, 1])])  # |u| up to 0.5
    bottom = p[np.isclose(p[:, 1], 0.0)][::-1]  # in reverse order
    gap = 0.05 + 0.1 * bottom[:, 0]
    normal = np.tile([0.0, -1.0], (len(bottom), 1))
    plot_deformed(
        p, c, u, tmp_path / "d", ContactDrawing(bottom, np.ones(5), gap=gap, normal=normal)
    )
    (info,) = captured
    assert " ".join(info["titles"][0].split()) == (
        "deformed body, displacement and obstacle gaps \u00d70.2"
    )
    x, y = info["lines"]["obstacle, gaps \u00d70.2"]
    np.testing.assert_allclose(x, bottom[::-1, 0])  # ordered along the boundary
    np.testing.assert_allclose(y, -0.2 * gap[::-1])
    with pytest.raises(ValueError, match="gap and normal"):
        plot_deformed(p, c, u, tmp_path / "x", ContactDrawing(bottom, gap=gap))
    with pytest.raises(ValueError, match="scale must be"):
        plot_deformed(p, c, u, tmp_path / "x", scale="big")


def test_free_boundary_ends_lie_between_active_and_inactive_neighbours():
    s = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    d = np.array([0.6, 0.8])
    pts = s[:, None] * d
    active = np.array([False, True, True, False, False])
    shuffled = np.array([3, 0, 4, 2, 1])
    ends = free_boundary_ends(pts[shuffled], active[shuffled])
    np.testing.assert_allclose(ends, [0.125 * d, 0.625 * d])
    assert free_boundary_ends(pts, np.ones(5, bool)).shape == (0, 2)
    with pytest.raises(ValueError, match="active must have shape"):
        free_boundary_ends(pts, active[:3])


@pytest.mark.slow
def test_stick_and_slip_nodes_are_marked(tmp_path, captured):
    """With node states the stick and slip nodes are marked on the drawn body (at
    ``contact_points + scale * contact_displacement``; inactive ones not) and on the friction
    stress, which is drawn with the pressure; without them the figure has neither."""
    mesh = rectangle(nx=4, ny=2)
    p, c = mesh.points, mesh.cells
    u = np.column_stack([0.01 * p[:, 1], -0.02 * (1.0 - p[:, 1])])
    bottom = np.column_stack([np.linspace(0.0, 1.0, 9), np.zeros(9)])  # vertices and midpoints
    u_bottom = np.column_stack([np.zeros(9), np.full(9, -0.02)])
    codes = np.array([0, 0, 2, 1, 1, 1, 2, 2, 0])
    state = np.array(NODE_STATES)[codes]  # the labels "inactive", "stick", "slip"
    pressure = np.array([0, 0, 1, 2, 3, 2, 1, 0.5, 0.0])
    p_t = np.array([0, 0, 0.5, 0.4, 0.1, -0.2, 0.5, 0.25, 0.0])

    def contact(**friction):
        return ContactDrawing(bottom, pressure, **friction)

    plot_deformed(
        p, c, u, tmp_path / "f",
        contact(state=state, contact_displacement=u_bottom, tangential_pressure=p_t), scale=5.0,
    )  # fmt: skip
    plot_deformed(p, c, u, tmp_path / "n", contact(), scale=5.0)
    friction, frictionless = captured
    assert friction["legend"] == ["reference", "stick", "slip", "$p_h$", "$p_{t,h}$"]
    drawn = bottom + 5.0 * u_bottom
    for label, value in (("stick", 1), ("slip", 2)):
        np.testing.assert_array_equal(
            np.column_stack(friction["lines"][label]), drawn[codes == value]
        )
    np.testing.assert_array_equal(friction["lines"]["$p_{t,h}$"][1], p_t)
    # the friction stress panel: its curve on top, the stick and the slip nodes in a strip at
    # the bottom of the axes (axes coordinates), where they hide no curve
    (x_pt, y_pt), (x_stick, y_stick), (x_slip, y_slip) = friction["lines_by_axes"][-1][1:4]
    np.testing.assert_array_equal(x_stick, bottom[codes == 1, 0])
    np.testing.assert_array_equal(y_stick, 0.04)
    np.testing.assert_array_equal(x_slip, bottom[codes == 2, 0])
    np.testing.assert_array_equal(y_slip, 0.09)
    z_pressure, z_pt, z_stick, z_slip = friction["zorders_by_axes"][-1][:4]
    assert min(z_pressure, z_pt) > max(z_stick, z_slip)
    assert friction["ylabel"][-1] == "contact stresses"
    assert frictionless["legend"] == ["reference"]
    assert list(frictionless["lines"]) == ["$p_h$"]
    assert frictionless["ylabel"][-1] == "contact pressure $p_h$"
    with pytest.raises(ValueError, match="state needs contact_points and contact_displacement"):
        plot_deformed(p, c, u, tmp_path / "x", contact(state=state), scale=5.0)
    with pytest.raises(ValueError, match="state must hold"):
        plot_deformed(
            p, c, u, tmp_path / "x", contact(state=codes, contact_displacement=u_bottom), scale=5.0
        )
    with pytest.raises(ValueError, match="tangential_pressure must have shape"):
        plot_deformed(p, c, u, tmp_path / "x", contact(tangential_pressure=p_t[:3]), scale=5.0)


@pytest.mark.slow
def test_obstacle_from_gaps_is_left_out_where_the_gap_is_far(tmp_path, captured):
    """A half-disc over a plane, drawn ten times magnified: the plane where the magnified
    body meets it, ``x + 10 ψ n`` (the curve ``y = −9 ψ`` the magnified gaps of the curved
    side trace, through the touching point), only near the contact zone: where the drawn
    gap ``10 ψ`` is at most 0.1 of the body's size 2 (``MAGNIFIED_REACH``)."""
    theta = np.linspace(np.pi, 2 * np.pi, 41)
    arc = np.column_stack([np.cos(theta), 1 + np.sin(theta)])
    points = np.vstack([[0.0, 1.0], arc])
    cells = np.column_stack([np.zeros(40, int), np.arange(2, 42), np.arange(1, 41)])
    u = np.zeros_like(points)
    gap = arc[:, 1]  # the distance to the plane y = 0
    normal = np.tile([0.0, -1.0], (41, 1))
    plot_deformed(
        points, cells, u, tmp_path / "d", ContactDrawing(arc, gap=gap, normal=normal), scale=10.0
    )
    (info,) = captured
    (label,) = [k for k in info["lines"] if k.startswith("obstacle")]
    x, y = info["lines"][label]
    shown = np.isfinite(y)
    order = np.argsort(arc[:, 0], kind="stable")
    assert np.all(10.0 * gap[order][shown] <= 0.1 * 2.0) and not shown.all() and shown.any()
    np.testing.assert_allclose(y[shown], -9.0 * gap[order][shown], rtol=0, atol=1e-15)
    assert 0.0 in y[shown]  # the touching point, where the body is drawn
    assert info["data_lim"][0].y0 >= -0.18 - 1e-12  # not down to 1 − 10 · 1 = −9
