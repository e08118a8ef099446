"""Boundary curves: projection, normals, halfway points; curves on meshes and under refinement."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from signorini.fem.space import P2Space
from signorini.mesh import Circle, Line, Mesh, MeshError, ProjectedCurve, rectangle
from signorini.mesh import curves as curves_module
from signorini.mesh.curves import QuadraticBoundary
from signorini.mesh.refine import refine_nvb, refine_uniform


def disc(k: int = 8, radius: float = 1.0, center=(0.0, 0.0)) -> Mesh:
    """The disc fanned around its centre into ``k`` triangles; the whole boundary is "arc"."""
    t = 2 * np.pi * np.arange(k) / k
    p = np.vstack([[0.0, 0.0], np.column_stack([np.cos(t), np.sin(t)])]) * radius + center
    c = np.array([[0, 1 + j, 1 + (j + 1) % k] for j in range(k)])
    return Mesh.from_arrays(p, c, {"arc": lambda x: np.ones(len(x), bool)})


def on_circle_error(mesh: Mesh, part: str, center, radius) -> float:
    v = np.unique(mesh.facets[mesh.part_facets(part)])
    r = np.hypot(*(mesh.points[v] - center).T)
    return float(np.abs(r / radius - 1).max())


def test_uniform_refinement_of_a_disc_stays_on_the_circle_and_the_area_converges_like_h2():
    center, radius = np.array([0.3, -0.2]), 2.0
    mesh = disc(8, radius, center).with_curve("arc", Circle(center, radius))
    straight = disc(8, radius, center)
    n_cells, error, straight_error = [], [], []
    for _ in range(6):
        mesh = refine_uniform(mesh).mesh
        straight = refine_uniform(straight).mesh
        assert on_circle_error(mesh, "arc", center, radius) <= 1e-14
        assert mesh.area.min() > 0
        n_cells.append(mesh.n_cells)
        error.append(np.pi * radius**2 - mesh.area.sum())
        straight_error.append(np.pi * radius**2 - straight.area.sum())
    slope = np.polyfit(np.log(n_cells), np.log(error), 1)[0]
    print(f"area error vs n_cells: slope {slope:.3f} on the circle; chords: {straight_error}")
    assert -1.05 <= slope <= -0.95
    assert np.allclose(straight_error, straight_error[0])  # chords never approach the disc
    assert isinstance(mesh.curves[0], Circle)


def test_adaptive_refinement_of_a_disc_keeps_boundary_vertices_on_the_circle():
    rng = np.random.default_rng(3)
    mesh = disc(6).with_curve("arc", Circle((0, 0), 1))
    for _ in range(12):
        mesh = refine_nvb(mesh, rng.random(mesh.n_cells) < 0.3).mesh
        assert on_circle_error(mesh, "arc", (0, 0), 1) <= 1e-14
        assert mesh.area.min() > 0
    assert mesh.n_cells > 500


def test_a_quarter_disc_keeps_straight_sides_straight_and_its_arc_on_the_circle():
    t = np.linspace(0, np.pi / 2, 5)
    p = np.vstack([[0, 0], np.column_stack([np.cos(t), np.sin(t)])])
    p[-1] = [0.0, 1.0]  # cos(π/2) is not 0 in floating point
    c = np.array([[0, 1 + j, 2 + j] for j in range(4)])
    mesh = Mesh.from_arrays(
        p,
        c,
        {
            "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
            "left": lambda x: np.abs(x[:, 0]) < 1e-12,
            "arc": lambda x: np.hypot(x[:, 0], x[:, 1]) > 0.5,
        },
    ).with_curve("arc", Circle((0, 0), 1))
    for _ in range(4):
        mesh = refine_uniform(mesh).mesh
    assert on_circle_error(mesh, "arc", (0, 0), 1) <= 1e-14
    assert np.all(mesh.points[np.unique(mesh.facets[mesh.part_facets("bottom")]), 1] == 0)
    assert np.all(mesh.points[np.unique(mesh.facets[mesh.part_facets("left")]), 0] == 0)


def test_a_straight_mesh_refines_exactly_as_without_curves():
    rng = np.random.default_rng(0)
    plain = rectangle(nx=3, ny=2)
    lined = plain.with_curve("bottom", Line((0, 0), (1, 0))).with_curve("top", Line((1, 1), (0, 1)))
    for _ in range(5):
        marked = rng.random(plain.n_cells) < 0.4
        plain, lined = refine_nvb(plain, marked).mesh, refine_nvb(lined, marked).mesh
        assert np.array_equal(plain.points, lined.points)
        assert np.array_equal(plain.cells, lined.cells)
        assert np.array_equal(plain.boundary, lined.boundary)
    assert plain.curves == (None,) * 4
    assert plain.curved_midpoints is plain.edge_midpoints
    assert np.array_equal(P2Space(lined).node_points, P2Space(plain).node_points)


def test_p2_edge_nodes_of_curved_edges_lie_on_the_curve_and_prolongation_follows_the_parent():
    mesh = disc(8).with_curve("arc", Circle((0, 0), 1))
    space = P2Space(mesh)
    arc = mesh.part_facets("arc")
    mid = space.node_points[mesh.n_points + arc]
    assert np.abs(np.hypot(*mid.T) - 1).max() <= 1e-15
    inner = np.setdiff1d(np.arange(mesh.n_edges), arc)
    assert np.array_equal(space.node_points[mesh.n_points + inner], mesh.edge_midpoints[inner])
    assert np.array_equal(space.node_points[: mesh.n_points], mesh.points)
    # a P2 function is carried over as the parent cell's quadratic in its own coordinates:
    # the new vertex on a curved edge takes the value of the edge's midpoint node
    u = np.random.default_rng(1).random((space.n_nodes, 2))
    refinement = refine_uniform(mesh)
    fine_u = space.prolongate(u, refinement)
    new = refinement.edge_point[arc]
    assert np.allclose(fine_u[new], u[mesh.n_points + arc], rtol=0, atol=1e-14)
    assert np.allclose(fine_u[: mesh.n_points], u[: mesh.n_points], rtol=0, atol=1e-14)


def test_a_projected_circle_refines_like_the_circle():
    project = lambda x: x / np.hypot(x[:, 0], x[:, 1])[:, None]  # noqa: E731
    a = disc(8).with_curve("arc", Circle((0, 0), 1))
    b = disc(8).with_curve("arc", ProjectedCurve(project))
    for _ in range(3):
        a, b = refine_uniform(a).mesh, refine_uniform(b).mesh
    assert np.allclose(a.points, b.points, rtol=0, atol=1e-15)
    assert np.array_equal(a.cells, b.cells)


angles = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    cx=st.floats(-100, 100),
    cy=st.floats(-100, 100),
    radius=st.floats(1e-3, 1e3),
    a=angles,
    turn=st.floats(-3.1, 3.1),
    scale=st.floats(0.01, 10.0),
)
def test_circle_projection_normal_and_halfway_points(cx, cy, radius, a, turn, scale):
    circle = Circle((cx, cy), radius)
    c = np.array([cx, cy])
    unit = lambda phi: np.array([[np.cos(phi), np.sin(phi)]])  # noqa: E731
    p, q = c + radius * unit(a), c + radius * unit(a + turn)
    x = c + scale * radius * unit(a)  # off the circle, on the ray through p
    tol = 1e-13 * (radius + np.hypot(cx, cy))
    assert np.abs(circle.project(x) - p).max() <= tol
    assert np.abs(circle.project(p) - p).max() <= tol
    assert np.allclose(circle.normal(p), unit(a), rtol=0, atol=tol / radius)
    assert abs(float(circle.tangent(p)[0] @ circle.normal(p)[0])) <= 1e-15
    m = circle.halfway(p, q)
    assert abs(np.hypot(*(m - c)[0]) - radius) <= tol
    # halfway along the shorter arc: as far from p as from q, and at the arc's midpoint
    assert np.abs(m - (c + radius * unit(a + turn / 2))).max() <= 10 * tol + 1e-12 * radius
    assert abs(np.hypot(*(m - p)[0]) - np.hypot(*(m - q)[0])) <= 10 * tol


def test_circle_halfway_takes_the_shorter_arc_across_the_branch_cut():
    circle = Circle((0, 0), 1)
    p = np.array([[np.cos(3.0), np.sin(3.0)]])
    q = np.array([[np.cos(-3.0), np.sin(-3.0)]])  # the short way runs through angle π
    assert np.allclose(circle.halfway(p, q), [[-1.0, 0.0]], atol=1e-15)
    assert np.allclose(circle.halfway(q, p), [[-1.0, 0.0]], atol=1e-15)


def test_line_projection_normal_and_halfway():
    line = Line((0, 0), (2, 0))
    assert np.array_equal(line.project([[1.0, 3.0], [-5.0, -1.0]]), [[1, 0], [-5, 0]])
    assert np.array_equal(line.normal([[1.0, 0.0]]), [[0.0, -1.0]])  # right of a -> b
    assert np.array_equal(line.tangent([[1.0, 0.0]]), [[1.0, 0.0]])
    assert np.array_equal(line.halfway([[0.0, 0.0]], [[1.0, 0.0]]), [[0.5, 0.0]])


def test_with_curve_refuses_a_part_off_the_curve_naming_the_vertex_and_distance():
    mesh = disc(8)
    with pytest.raises(MeshError, match=r"vertex \d+ .* of part 'arc' lies 0\.1 from Circle"):
        mesh.with_curve("arc", Circle((0, 0), 1.1))
    with pytest.raises(MeshError, match="the mesh has no boundary part 'outer'"):
        mesh.with_curve("outer", Circle((0, 0), 1))
    with pytest.raises(MeshError, match="part 'arc' must be a Curve .* got tuple"):
        mesh.with_curve("arc", ((0, 0), 1))
    assert mesh.with_curve("arc", Circle((0, 0), 1 + 1e-10)).curves[0].radius == 1 + 1e-10


def test_curve_arguments_are_checked():
    with pytest.raises(MeshError, match=r"curves needs one Curve or None per part \(1\)"):
        Mesh(disc(4).points, disc(4).cells, disc(4).boundary, [0] * 4, ["arc"], curves=[3])
    with pytest.raises(MeshError, match="Circle: radius must be a positive number, got -1"):
        Circle((0, 0), -1)
    with pytest.raises(MeshError, match=re.escape("Circle: center must be two finite numbers")):
        Circle((0, 0, 0), 1)
    with pytest.raises(MeshError, match="Line: a and b are the same point"):
        Line((1, 1), (1, 1))
    with pytest.raises(MeshError, match="ProjectedCurve: project must be a function"):
        ProjectedCurve(3)
    bad = ProjectedCurve(lambda x: x[:, 0])
    with pytest.raises(MeshError, match=r"project must return finite points of shape \(8, 2\)"):
        disc(8).with_curve("arc", bad)
    with pytest.raises(MeshError, match="ProjectedCurve: no normal function was given"):
        ProjectedCurve(lambda x: x).normal(np.zeros((1, 2)))


def test_refinement_refuses_a_mesh_too_coarse_for_its_curve():
    # one triangle whose long edge lies on an arc bulging past the opposite vertex
    p = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, 0.1]])
    mesh = Mesh.from_arrays(
        p, [[0, 1, 2]], {"bottom": np.array([[0, 1]]), "rest": np.array([[1, 2], [2, 0]])}
    ).with_curve("bottom", Circle((0, -0.5), np.sqrt(1.25)))
    with pytest.raises(MeshError, match=r"part\(s\) \['bottom'\] .* initial mesh is too coarse"):
        refine_uniform(mesh)
    with pytest.raises(MeshError, match="too coarse for the curve"):
        refine_nvb(mesh, [0])


def test_the_adaptive_loop_runs_on_a_quarter_disc_with_a_curved_neumann_part():
    from signorini.fem.material import Material
    from signorini.loop import adaptive
    from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

    t = np.linspace(0, np.pi / 2, 5)
    p = np.vstack([[0, 0], np.column_stack([np.cos(t), np.sin(t)])])
    p[-1] = [0.0, 1.0]
    c = np.array([[0, 1 + j, 2 + j] for j in range(4)])
    mesh = Mesh.from_arrays(
        p,
        c,
        {
            "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
            "left": lambda x: np.abs(x[:, 0]) < 1e-12,
            "arc": lambda x: np.hypot(x[:, 0], x[:, 1]) > 0.5,
        },
    ).with_curve("arc", Circle((0, 0), 1))
    problem = ContactProblem(
        mesh=mesh,
        material=Material.from_lame(1.0, 1.0),
        conditions={
            "left": Dirichlet((0.0, 0.0)),
            "arc": Neumann((0.0, -0.05)),
            "bottom": Contact(gap=0.02, normal=(0.0, -1.0)),
        },
    )
    levels = list(adaptive(problem, max_ndof=1500))
    final = levels[-1].result.mesh
    assert len(levels) >= 5 and final.n_cells > 4 * mesh.n_cells
    assert on_circle_error(final, "arc", (0, 0), 1) <= 1e-14
    assert final.area.min() > 0


def wavy_pieces(k: int = 12) -> np.ndarray:
    """``(k, 3, 2)`` quadratic pieces [start, end, midpoint] through points of the closed
    curve r(φ) = 1 + 0.2 cos 3φ, counter-clockwise: a curve whose curvature changes sign."""
    phi = 2 * np.pi * np.arange(2 * k + 1) / (2 * k)
    x = (1 + 0.2 * np.cos(3 * phi))[:, None] * np.column_stack([np.cos(phi), np.sin(phi)])
    return np.stack([x[0:-1:2], x[2::2], x[1::2]], axis=1)


def piece_at(edges: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``(k, n, 2)``: every piece at the parameters ``t (n,)`` (power form, independently)."""
    a, b, m = edges[:, 0, None], edges[:, 1, None], edges[:, 2, None]
    t = t[None, :, None]
    return a + t * (4 * m - 3 * a - b) + t**2 * (2 * (a + b - 2 * m))


@pytest.mark.slow
@pytest.mark.parametrize("nearest_samples", [24, 2])  # 2: most points compare all pieces
def test_quadratic_boundary_projection_is_the_nearest_point_of_the_pieces(
    monkeypatch, nearest_samples
):
    monkeypatch.setattr(curves_module, "NEAREST_SAMPLES", nearest_samples)
    edges = wavy_pieces()
    curve = QuadraticBoundary(edges)
    rng = np.random.default_rng(7)
    x = np.vstack([rng.uniform(-1.5, 1.5, (400, 2)), [[0.0, 0.0]], edges[:, 0], edges[:, 2]])
    y = curve.project(x)
    t = np.linspace(0, 1, 4001)
    dense = piece_at(edges, t).reshape(-1, 2)  # spacing <= 2e-4
    brute = np.hypot(*(x[:, None] - dense[None]).transpose(2, 0, 1)).min(1)
    d = np.hypot(*(y - x).T)
    on_curve = np.hypot(*(y[:, None] - dense[None]).transpose(2, 0, 1)).min(1)
    print(
        f"projection: max (|y - x| - brute force) {np.max(d - brute):.2e}, "
        f"max (brute force - |y - x|) {np.max(brute - d):.2e}, off the dense curve "
        f"{on_curve.max():.2e}"
    )
    assert np.all(d <= brute + 1e-13)  # no sampled point of the pieces is nearer
    assert np.all(brute - d <= 1e-6)  # and beats the samples by no more than their spacing allows
    assert on_curve.max() <= 2e-4  # y lies on the pieces
    np.testing.assert_array_equal(y[-2 * len(edges) : -len(edges)], edges[:, 0])  # vertices
    np.testing.assert_allclose(y[-len(edges) :], edges[:, 2], rtol=0, atol=1e-15)  # midpoints


def test_quadratic_boundary_halfway_is_the_parameter_midpoint_of_the_piece():
    edges = wavy_pieces()
    curve = QuadraticBoundary(edges)
    # an initial edge's own ends, in either order: exactly the given midpoint
    np.testing.assert_array_equal(curve.halfway(edges[:, 0], edges[:, 1]), edges[:, 2])
    np.testing.assert_array_equal(curve.halfway(edges[:, 1], edges[:, 0]), edges[:, 2])
    # two points of one piece at parameters s, t: the piece at (s + t) / 2
    rng = np.random.default_rng(3)
    s, t = rng.random(len(edges)), rng.random(len(edges))
    k = np.arange(len(edges))
    p = piece_at(edges, s)[k, k]
    q = piece_at(edges, t)[k, k]
    mid = piece_at(edges, 0.5 * (s + t))[k, k]
    err = np.abs(curve.halfway(p, q) - mid).max()
    # a piece's start (also the previous piece's end) with a point inside the piece
    start = curve.halfway(edges[:, 0], q)
    err_start = np.abs(start - piece_at(edges, 0.5 * t)[k, k]).max()
    print(f"halfway vs the parameter midpoint: {err:.1e}; from a shared vertex {err_start:.1e}")
    assert err <= 1e-14 and err_start <= 1e-14


def test_quadratic_boundary_normal_is_the_outward_unit_normal_of_the_pieces():
    edges = wavy_pieces()
    curve = QuadraticBoundary(edges)
    t = np.linspace(0.05, 0.95, 7)
    x = piece_at(edges, t).reshape(-1, 2)
    n = curve.normal(x)
    h = 1e-6
    tangent = (piece_at(edges, t + h) - piece_at(edges, t - h)).reshape(-1, 2)
    assert np.abs(np.hypot(*n.T) - 1).max() <= 1e-14
    assert np.abs((n * tangent).sum(1)).max() <= 1e-9 * np.abs(tangent).max()
    assert np.all((n * x).sum(1) > 0)  # out of the star-shaped domain the pieces bound
    np.testing.assert_allclose(curve.tangent(x), tangent / np.hypot(*tangent.T)[:, None], atol=1e-8)


def test_quadratic_boundary_normal_where_pieces_meet_is_the_mean_of_theirs():
    # pieces through points of a circle at equal spacing: at a joint the two pieces' normals
    # lean by ±θ³/32 (θ the angle per piece); their mean is the circle's normal
    theta = np.pi / 16
    phi = theta * np.arange(9)
    v = 2.0 * np.column_stack([np.cos(phi), np.sin(phi)])
    mid = 2.0 * np.column_stack([np.cos(phi[:-1] + theta / 2), np.sin(phi[:-1] + theta / 2)])
    curve = QuadraticBoundary(np.stack([v[:-1], v[1:], mid], axis=1))
    error = np.hypot(*(curve.normal(v) - v / 2.0).T)
    print(f"normal error at the vertices {error}, theta^3 / 32 = {theta**3 / 32:.3e}")
    assert error[1:-1].max() <= 1e-14  # joints
    assert error[[0, -1]] == pytest.approx(theta**3 / 32, rel=0.02)  # the part's two ends


@pytest.mark.parametrize(
    ("edges", "message"),
    [
        (np.zeros((2, 2, 2)), r"finite \(k, 3, 2\) array .* got shape \(2, 2, 2\)"),
        (np.zeros((0, 3, 2)), "k >= 1"),
        ([[[0, 0], [1, 0], [np.nan, 0]]], "finite"),
        ([[[1, 2], [1, 2], [1, 2]]], r"piece 0 starts and ends at \[1.0, 2.0\]"),
        ([[[0, 0], [1, 0], [0.8, 0.1]]], r"piece 0 .* folds back on itself: .* at 0.8 of"),
        ([[[0, 0], [1, 0], [0.5, 0]], [[1, 0], [2, 0], [1.2, 0]]], r"piece 1 .*\(1 such"),
    ],
)
def test_quadratic_boundary_arguments_are_checked(edges, message):
    with pytest.raises(MeshError, match=message):
        QuadraticBoundary(edges)
