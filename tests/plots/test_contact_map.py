"""The figures of a 3D contact run: the pressure over Γ_C as a map (its projection plane, its
window and the contact zone's boundary where the active flag changes), Hertz's pressure
along the line y = 0 through the zone, and the plane obstacle under the deformed body where
the magnified body touches it."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from matplotlib.contour import ContourSet
from matplotlib.figure import Figure

from signorini.contact.solution import solve
from signorini.examples.hertz3d import hertz_3d, hertz_3d_metrics, hertz_3d_pressure
from signorini.fem.space import space_of
from signorini.loop.arrays3d import surface_arrays
from signorini.mesh.builders3d import box
from signorini.plots.body3d import plane_offset, plane_squares, plot_body_3d
from signorini.plots.contact_map import contact_window, plane_axes, plot_contact_map
from signorini.plots.run_figures import pressure_figure

from .figure_checks import check_written

ZONE = 0.3  # the synthetic contact zone's radius about (0.5, 0.5) on the face z = 0


@cache
def hertz(h_contact: float):
    return solve(hertz_3d(h_contact=h_contact))


@pytest.fixture
def figures(captured, monkeypatch):
    """What the figures saved as PNG show (after the layout checks of ``captured``): per
    figure its axes' labels, aspect, limits and title, the contour lines' vertices, the
    colorbar's label and the 3D collections' drawn corners and zorders."""
    seen: list[dict] = []
    checked = Figure.savefig

    def keep(fig, fname, *args, **kwargs):
        if str(fname).endswith(".png"):
            ax = fig.axes[0]
            contours = [c for c in ax.collections if isinstance(c, ContourSet)]
            seen.append(
                {
                    "labels": (ax.get_xlabel(), ax.get_ylabel()),
                    "aspect": ax.get_aspect(),
                    "limits": (ax.get_xlim(), ax.get_ylim()),
                    "title": ax.get_title(),
                    "colorbar": fig.axes[1].get_ylabel() if len(fig.axes) > 1 else "",
                    "boundary": [
                        np.vstack([p.vertices for p in c.get_paths() if len(p.vertices)])
                        for c in contours
                    ],
                    "zorders": [c.get_zorder() for c in ax.collections],
                }
            )  # fmt: skip
        return checked(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    return seen


def flat_face(n: int):
    """The P2 nodes of the face z = 0 of the unit square's slab (n × n × 1 cubes): points,
    faces (f, 6) as rows of points, the constraint direction −e_z."""
    mesh = box(n, n, 1, upper=(1.0, 1.0, 1.0 / n))
    tri6 = space_of(mesh, "P2").facet_nodes(mesh.part_facets("z0"))
    nodes, local = np.unique(tri6, return_inverse=True)
    points = space_of(mesh, "P2").node_points[nodes]
    return points, local.reshape(tri6.shape), np.tile([0.0, 0.0, -1.0], (nodes.size, 1))


def test_the_projection_plane():
    axes, labels = plane_axes([0.0, 0.0, -2.0])
    np.testing.assert_array_equal(axes, [[1, 0, 0], [0, 1, 0]])
    assert labels == ["$x$", "$y$"]
    assert plane_axes([1.0, 0.0, 0.0])[1] == ["$y$", "$z$"]
    n = np.array([1.0, 2.0, 2.0]) / 3.0
    axes, labels = plane_axes(n)
    np.testing.assert_allclose(axes @ axes.T, np.eye(2), atol=1e-15)
    np.testing.assert_allclose(axes @ n, 0.0, atol=1e-15)
    np.testing.assert_allclose(np.cross(n, axes[0]), axes[1], atol=1e-15)
    assert labels == [r"$s_1$", r"$s_2$"]


def test_the_window_is_the_zone_with_a_margin():
    uv = np.array([[0.0, 0.0], [1.0, 1.0], [0.4, 0.4], [0.6, 0.5]])
    low, high = contact_window(uv, np.array([False, False, True, True]))
    np.testing.assert_allclose(low, [0.4 - 0.12, 0.4 - 0.12])
    np.testing.assert_allclose(high, [0.6 + 0.12, 0.5 + 0.12])
    low, high = contact_window(uv, np.zeros(4, bool))
    np.testing.assert_array_equal([low, high], [[0, 0], [1, 1]])


def test_the_map_draws_the_zone_where_the_flag_changes(tmp_path, figures):
    """A disc of contact of radius 0.3 on a mesh of h = 1/8: the drawn boundary lies
    within one mesh size of the circle, and the window holds it."""
    points, faces, normal = flat_face(8)
    r = np.hypot(points[:, 0] - 0.5, points[:, 1] - 0.5)
    pressure = np.maximum(1.0 - (r / ZONE) ** 2, 0.0)
    written = plot_contact_map(points, faces, pressure, r < ZONE, normal, tmp_path / "map")
    check_written(written, tmp_path / "map")
    drawn = figures[-1]
    (boundary,) = drawn["boundary"]
    rho = np.hypot(*(boundary - 0.5).T)
    assert np.abs(rho - ZONE).max() <= 1.0 / 8
    assert drawn["labels"] == ("$x$", "$y$") and drawn["aspect"] == 1.0
    assert "units of $E$" in drawn["colorbar"]
    (x0, x1), (y0, y1) = drawn["limits"]
    assert x0 <= 0.5 - ZONE and x1 >= 0.5 + ZONE and y0 <= 0.5 - ZONE and y1 >= 0.5 + ZONE


def test_the_map_refuses_mismatched_arrays(tmp_path):
    points, faces, normal = flat_face(2)
    with pytest.raises(ValueError, match="pressure and active must have shape"):
        plot_contact_map(points, faces, np.zeros(3), np.zeros(3, bool), normal, tmp_path / "m")
    with pytest.raises(ValueError, match="turned towards the obstacle"):
        plot_contact_map(points, faces, points[:, 0], points[:, 0] > 0.5, -normal, tmp_path / "m")


def test_the_map_of_hertz(tmp_path, figures):
    """The drawn zone of the Hertz sphere lies around its contact radius a."""
    s = surface_arrays(hertz(0.15))
    assert len(s["planes"]) == 1
    np.testing.assert_array_equal(s["planes"][0][1], [0.0, 0.0, 1.0])
    a = hertz_3d_metrics(hertz(0.15))["a"]
    plot_contact_map(
        s["points"], s["faces"], s["recovered_pressure"], s["active"], s["normal"],
        tmp_path / "hertz", title="hertz-3d",
    )  # fmt: skip
    (boundary,) = figures[-1]["boundary"]
    rho = np.hypot(*boundary.T)
    assert 0.6 * a < rho.min() and rho.max() < 1.6 * a
    assert (tmp_path / "hertz.png").stat().st_size > 10_000


def test_hertz_along_the_line_y0_converges():
    """The line's nodes are the rows on y = 0 in order of x, their values the recovered
    pressure; the distance to Hertz's p0 √(1 − r²/a²) over r ≤ 0.8 a falls with the mesh."""

    def distance(h):
        known = hertz_3d_pressure(hertz(h))
        a, p0 = known.x_reference[-1], known.reference[0]
        assert known.joined and known.x[0] == 0.0 and (np.diff(known.x) > 0).all()
        assert known.pressure[0] == hertz_3d_metrics(hertz(h))["p0"]
        hertz_p = p0 * np.sqrt(np.maximum(1.0 - (known.x / a) ** 2, 0.0))
        inside = known.x <= 0.8 * a
        return np.abs(known.pressure - hertz_p)[inside].max() / p0

    coarse, fine = distance(0.15), distance(0.1)
    assert fine < 0.5 * coarse and fine < 0.15


def test_hertz_line_figure(tmp_path, captured):
    written = pressure_figure("hertz-3d", tmp_path, hertz_3d_pressure(hertz(0.1)))
    check_written(written, tmp_path / "hertz-3d_pressure")
    drawn = captured[-1]
    assert drawn["xlabel"] == [r"$r = x$ (along $y = 0$)"]
    x, p = drawn["lines"]["$p_h$"]
    np.testing.assert_array_equal(x, hertz_3d_pressure(hertz(0.1)).x)


def test_the_plane_where_the_magnified_body_touches_it():
    """Nodes in contact on z = 0 pressed by u_z = −ψ from their gaps ψ: drawn at s = 5 they
    sit at (1 − s) ψ, the plane at the deepest, (1 − 5) max ψ."""
    psi = np.array([0.0, 0.01, 0.03])
    x = np.column_stack([psi, psi, psi])
    u = np.column_stack([np.zeros(3), np.zeros(3), -psi])
    plane = (np.zeros(3), np.array([0.0, 0.0, 1.0]))
    assert plane_offset(plane, x, u, 5.0) == pytest.approx(-4 * 0.03, rel=1e-15)
    assert plane_offset(plane, x, u, 1.0) == 0.0
    assert plane_offset(plane, np.zeros((0, 3)), np.zeros((0, 3)), 5.0) == 0.0


def test_the_body_with_its_plane(tmp_path, figures):
    r = hertz(0.15)
    s = surface_arrays(r)
    n = r.mesh.points.shape[0]
    faces = r.space.facet_nodes(r.mesh.boundary_facet)[:, :3]
    on = s["active"]
    written = plot_body_3d(
        r.mesh.points, faces, r.u[:n], r.nodal_stress[:n], tmp_path / "body",
        planes=s["planes"], touching=(s["points"][on], s["displacement"][on]),
    )  # fmt: skip
    check_written(written, tmp_path / "body")
    drawn = figures[-1]
    assert drawn["zorders"] == [0, 1]  # the plane first, behind the body seen from above
    scale = float(drawn["title"].split("× ")[1].split(",")[0])
    offset = plane_offset(s["planes"][0], s["points"][on], s["displacement"][on], scale)
    assert offset < 0.0
    drawn_body = r.mesh.points + scale * r.u[:n]
    low, high = drawn_body.min(axis=0), drawn_body.max(axis=0)
    (square,) = plane_squares(
        s["planes"], (s["points"][on], s["displacement"][on]), scale, low, high
    )
    np.testing.assert_allclose(square[:, 2], offset, rtol=1e-12)
    assert (square[:, :2].min(axis=0) < low[:2]).all() and (
        square[:, :2].max(axis=0) > high[:2]
    ).all()


def test_the_rendering_runs_apart_and_its_failure_costs_the_picture_only(tmp_path, monkeypatch):
    """The PyVista rendering runs in a child process: one that ends by a signal or an error
    (VTK without EGL or OSMesa) gives the note, one that writes the PNG gives the file. The
    child here writes a stand-in (PyVista itself is an optional extra)."""
    import importlib.util

    from signorini.plots import body3d

    find_spec = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: object() if name == "pyvista" else find_spec(name, *a),
    )
    r = hertz(0.15)
    n = r.mesh.points.shape[0]
    faces = r.space.facet_nodes(r.mesh.boundary_facet)[:, :3]
    body = (r.mesh.points, faces, r.u[:n], r.nodal_stress[:n])
    monkeypatch.setattr(body3d, "RENDER", "import os, signal; os.kill(os.getpid(), signal.SIGSEGV)")
    written, note = body3d.render_body_3d(*body, tmp_path / "crash")
    assert written == [] and "exit status -11" in note and "EGL or OSMesa" in note
    stand_in = (
        "import sys, numpy as np; s = np.load(sys.argv[1]); "
        "assert s['squares'].shape == (1, 4, 3) and s['cells'].size == 4 * s['value'].size; "
        "open(sys.argv[2], 'wb').write(b'png')"
    )
    monkeypatch.setattr(body3d, "RENDER", stand_in)
    s = surface_arrays(r)
    written, note = body3d.render_body_3d(*body, tmp_path / "drawn", planes=s["planes"])
    assert written == [tmp_path / "drawn.png"] and note == ""
