"""Second-order Gmsh meshes (:func:`signorini.mesh.read_mesh`): an annulus sector whose arc
edges have their midpoints on the circles, as Gmsh writes ``triangle6`` / ``line3`` elements
of a curved geometry. The arc parts carry the file's piecewise-quadratic boundary; the same
mesh written first-order has only the chords."""

from __future__ import annotations

import meshio
import numpy as np
import pytest
import scipy.sparse.linalg as spla
from fem_problems import GradientField

from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.fem import iso
from signorini.fem.material import Material
from signorini.fem.norms import energy_error2
from signorini.fem.quadrature import triangle_rule
from signorini.fem.space import P2Space
from signorini.mesh import Circle, Mesh, MeshError, read_mesh
from signorini.mesh.curves import QuadraticBoundary
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann

MATERIAL = Material.from_young(1.0, 0.3)
A = 1.0  # u = grad(-cos(A x) cos(A y) / A), as in tests/fem/test_iso.py
ARCS = {"inner": 1.0, "outer": 2.0}


FIELD = GradientField(A, MATERIAL)
exact_u, exact_grad, traction, body_force = FIELD.u, FIELD.grad, FIELD.traction, FIELD.body_force


def sector(n_t: int, *, curved: bool = True) -> Mesh:
    """1 <= r <= 2, 0 <= φ <= π/2 with ``n_t`` cells' layers around and ``n_t / 2`` across;
    parts inner, outer (arcs, carrying their circles if ``curved``), bottom, left."""
    n_r = n_t // 2
    r, t = np.meshgrid(np.linspace(1, 2, n_r + 1), np.linspace(0, np.pi / 2, n_t + 1))
    p = np.column_stack([(r * np.cos(t)).ravel(), (r * np.sin(t)).ravel()])
    p[-(n_r + 1) :, 0] = 0.0
    i, j = (g.ravel() for g in np.meshgrid(np.arange(n_t), np.arange(n_r), indexing="ij"))
    k = lambda i, j: i * (n_r + 1) + j  # noqa: E731
    cells = np.vstack(
        [
            np.column_stack([k(i, j), k(i, j + 1), k(i + 1, j + 1)]),
            np.column_stack([k(i, j), k(i + 1, j + 1), k(i + 1, j)]),
        ]
    )
    radius = lambda x: np.hypot(x[:, 0], x[:, 1])  # noqa: E731
    mesh = Mesh.from_arrays(
        p,
        cells,
        {
            "inner": lambda x: radius(x) < 1 + 1e-9,  # chord midpoints lie inside the circles
            "outer": lambda x: radius(x) > 2 - 0.25 / n_r,
            "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
            "left": lambda x: np.abs(x[:, 0]) < 1e-12,
        },
    )
    for name, rho in ARCS.items() if curved else ():
        mesh = mesh.with_curve(name, Circle((0, 0), rho))
    return mesh


def gmsh_file(mesh: Mesh, order: int) -> meshio.Mesh:
    """``mesh`` as Gmsh writes it: order 2 gives each edge its P2 midpoint node (on the arc
    for the arc parts of a curved mesh, on the chord elsewhere), numbered after the
    vertices; physical line groups name the parts."""
    space = P2Space(mesh)
    tags = {name: i + 1 for i, name in enumerate(mesh.part_names)}
    edges = [mesh.part_facets(name) for name in mesh.part_names]
    lines = np.vstack([space.facet_nodes(e)[:, : order + 1] for e in edges])
    line_tags = np.concatenate([np.full(e.size, tags[n]) for n, e in zip(tags, edges, strict=True)])
    if order == 1:
        points, cells, kinds = mesh.points, mesh.cells, ("triangle", "line")
    else:
        points, cells, kinds = space.node_points, space.cell_nodes, ("triangle6", "line3")
    physical = [np.full(len(cells), 10), line_tags]
    field_data = {name: np.array([tag, 1]) for name, tag in tags.items()}
    field_data["domain"] = np.array([10, 2])
    return meshio.Mesh(
        np.column_stack([points, np.zeros(len(points))]),
        [(kinds[0], cells), (kinds[1], lines)],
        cell_data={"gmsh:physical": physical, "gmsh:geometrical": [t.copy() for t in physical]},
        field_data=field_data,
    )


def write(tmp_path, m: meshio.Mesh, name: str = "sector.msh"):
    path = tmp_path / name
    meshio.write(path, m, file_format="gmsh22", binary=False)
    return path


def radial_error(mesh: Mesh) -> float:
    """Largest distance of a vertex of the arc parts from its circle."""
    errors = []
    for name, rho in ARCS.items():
        v = np.unique(mesh.facets[mesh.part_facets(name)])
        errors.append(np.abs(np.hypot(*mesh.points[v].T) - rho).max())
    return float(max(errors))


def isoparametric_area(mesh: Mesh) -> float:
    """The area of the discrete domain: straight cells plus ∫ det J over curved ones."""
    space = P2Space(mesh)
    area = mesh.area.copy()
    if space.curved is not None:
        cells, nodes = space.curved
        xi, w = triangle_rule(2)  # det J has degree 2
        area[cells] = iso.geometry(nodes, xi)[2] @ w
    return float(area.sum())


def test_the_arc_parts_carry_the_files_quadratics_and_the_p2_nodes_are_the_files(tmp_path):
    written = gmsh_file(sector(8), order=2)
    mesh = read_mesh(write(tmp_path, written))
    curves = dict(zip(mesh.part_names, mesh.curves, strict=True))
    assert isinstance(curves["inner"], QuadraticBoundary)
    assert isinstance(curves["outer"], QuadraticBoundary)
    assert curves["bottom"] is None and curves["left"] is None
    space = P2Space(mesh)
    # every P2 node is the file's node: vertices, chord midpoints and the arc midpoints
    np.testing.assert_array_equal(space.node_points, written.points[:, :2])
    # the cells along the arcs are isoparametric, the others affine
    arcs = np.concatenate([mesh.part_facets("inner"), mesh.part_facets("outer")])
    np.testing.assert_array_equal(iso.curved_cells(mesh), np.unique(mesh.facet2cell[arcs, 0]))
    assert space.curved is not None and space.curved[0].size == arcs.size
    # the outward normal of the file's quadratics: towards the centre on the inner arc
    x = space.node_points[mesh.n_points + mesh.part_facets("inner")]
    np.testing.assert_allclose(curves["inner"].normal(x), -x, atol=1e-15)


def test_refinement_stays_on_the_files_quadratics_and_keeps_every_cell_valid(tmp_path):
    second = read_mesh(write(tmp_path, gmsh_file(sector(8), order=2), "second.msh"))
    first = read_mesh(write(tmp_path, gmsh_file(sector(8), order=1), "first.msh"))
    area0 = isoparametric_area(second)
    errors, chords = [radial_error(second)], [radial_error(first)]
    for _ in range(3):
        second, first = refine_uniform(second).mesh, refine_uniform(first).mesh
        assert second.area.min() > 0
        _, nodes = P2Space(second).curved  # raises if a quadratic map folds over
        assert iso.folded(nodes).size == 0
        # the new arc vertices lie on the file's quadratics, and the refined isoparametric
        # boundary is those quadratics: the discrete domain keeps its area to round-off
        for name in ARCS:
            curve = second.curves[second.part_index(name)]
            v = np.unique(second.facets[second.part_facets(name)])
            assert np.abs(curve.project(second.points[v]) - second.points[v]).max() <= 1e-15
        assert abs(isoparametric_area(second) - area0) <= 1e-14 * area0
        errors.append(radial_error(second))
        chords.append(radial_error(first))
    print(f"max radial error of the arc vertices per level, second-order file: {errors}")
    print(f"max radial error of the arc vertices per level, first-order file: {chords}")
    # the file's quadratics are within O(H^4) of the circles, the chords O(H^2): after the
    # first level (new vertices at the file's midpoints, on the circles) both stay put
    sagitta = 2 * (1 - np.cos(np.pi / 32))  # the outer chords' sagitta
    assert chords[0] == 0 and all(e == pytest.approx(sagitta, rel=1e-12) for e in chords[1:])
    assert errors[0] == 0 and errors[1] <= 1e-15 and max(errors) < 1e-3 * sagitta


def test_adaptive_refinement_stays_on_the_files_quadratics(tmp_path):
    mesh = read_mesh(write(tmp_path, gmsh_file(sector(4), order=2)))
    area0 = isoparametric_area(mesh)
    rng = np.random.default_rng(11)
    for _ in range(6):
        centroid = mesh.points[mesh.cells].mean(1)
        near = np.hypot(*(centroid - [2.0, 0.0]).T) < 0.6  # grade towards the corner (2, 0)
        mesh = refine_nvb(mesh, near | (rng.random(mesh.n_cells) < 0.1)).mesh
        assert mesh.area.min() > 0 and iso.folded(P2Space(mesh).curved[1]).size == 0
    for name in ARCS:
        curve = mesh.curves[mesh.part_index(name)]
        v = np.unique(mesh.facets[mesh.part_facets(name)])
        assert np.abs(curve.project(mesh.points[v]) - mesh.points[v]).max() <= 1e-15
    change = abs(isoparametric_area(mesh) - area0) / area0
    lengths = mesh.edge_length[mesh.part_facets("outer")]
    print(
        f"outer arc edges from {lengths.min():.2e} to {lengths.max():.2e}; area change {change:.1e}"
    )
    assert change <= 1e-14 and lengths.max() > 4 * lengths.min()


def test_the_files_geometry_converges_like_h4_and_the_chords_like_h2(tmp_path):
    # one file per mesh size, each refined three times: the arc vertices then sample the
    # file's boundary; their distance from the circles is the file's geometric error
    second, first = [], []
    for n_t in (4, 8, 16, 32):
        mesh = sector(n_t)
        for order, errors in ((2, second), (1, first)):
            refined = read_mesh(write(tmp_path, gmsh_file(mesh, order), f"s{n_t}_{order}.msh"))
            for _ in range(3):
                refined = refine_uniform(refined).mesh
            errors.append(radial_error(refined))
    ratio2, ratio1 = np.array(second[:-1]) / second[1:], np.array(first[:-1]) / first[1:]
    print(f"max radial error after 3 refinements, second order: {second}, ratios {ratio2}")
    print(f"max radial error after 3 refinements, first order: {first}, ratios {ratio1}")
    assert np.all(ratio2 >= 8), f"second-order ratios {ratio2}"
    assert np.all((ratio1 > 3.5) & (ratio1 < 4.5)), f"first-order ratios {ratio1}"


def solve_annulus(mesh: Mesh, data_on_circles: bool) -> tuple[int, float]:
    """Ndof and energy error of the manufactured solution, Dirichlet on both arcs.

    ``data_on_circles``: u_D is known on the circles only (as in an application, e.g. a
    prescribed rim displacement as a function of the angle), so a boundary node takes the
    value at the nearest point of its circle; otherwise u_D = u at the node (the smooth
    extension of the data, which hides where the boundary is)."""

    def on(rho):
        if not data_on_circles:
            return exact_u
        return lambda x: exact_u(rho * x / np.hypot(x[:, 0], x[:, 1])[:, None])

    conditions = {name: Dirichlet(on(rho)) for name, rho in ARCS.items()}
    conditions |= {"bottom": Neumann(traction), "left": Neumann(traction)}
    a = assemble(ContactProblem(mesh, MATERIAL, conditions, body_force=body_force), mesh)
    u = np.zeros(a.space.n_dofs)
    u[a.dirichlet] = a.dirichlet_values
    free = np.setdiff1d(np.arange(a.space.n_dofs), a.dirichlet)
    rhs = a.F[free] - a.K[free][:, a.dirichlet] @ a.dirichlet_values
    u[free] = spla.spsolve(a.K[free][:, free].tocsc(), rhs)
    space = a.space
    e2 = energy_error2(space.mapping, space.cell_values(u), exact_grad, MATERIAL)
    return space.n_dofs, float(np.sqrt(e2.sum()))


@pytest.mark.slow
def test_energy_error_converges_like_1_over_ndof_on_second_order_files_only(tmp_path):
    # one file per mesh size (a mesh generator's sequence); the Dirichlet data of the annulus
    # are given on its circles. On the chords of a first-order file they are imposed O(H^2)
    # away from where they hold: an O(H^{3/2}) error, Ndof^{-3/4} asymptotically
    results = {}
    for data_on_circles in (True, False):
        for order in (2, 1):
            ndof, error = [], []
            for n_t in (8, 16, 32, 64):
                path = write(tmp_path, gmsh_file(sector(n_t), order), f"a{n_t}_{order}.msh")
                n, e = solve_annulus(read_mesh(path), data_on_circles)
                ndof.append(n)
                error.append(e)
            slope = float(np.polyfit(np.log(ndof), np.log(error), 1)[0])
            results[data_on_circles, order] = slope
            print(
                f"data on the circles {data_on_circles}, order {order}: Ndof {ndof}, "
                f"energy error {error}, slope {slope:.3f}"
            )
    assert -1.1 <= results[True, 2] <= -0.9, f"second-order slope {results[True, 2]:.3f}"
    assert results[True, 1] > -0.9, f"first-order slope {results[True, 1]:.3f}"
    # with u_D = u at the nodes the chords' domain is as good a domain as any: both optimal
    assert -1.1 <= results[False, 1] <= -0.9, f"first order, u_D = u: {results[False, 1]:.3f}"
    assert -1.1 <= results[False, 2] <= -0.9, f"second order, u_D = u: {results[False, 2]:.3f}"


def test_refining_a_second_order_file_converges_like_1_over_ndof_and_a_first_order_file_stalls(
    tmp_path,
):
    # the adaptive loop's situation: one file, refined. The first-order file's domain stays
    # its polygon, whose boundary lies O(H^2) inside the circles where the data hold; the
    # second-order file's domain stays its quadratics, O(H^4) off, which is far below the
    # discretisation error on these levels
    slopes = {}
    for order in (2, 1):
        mesh = read_mesh(write(tmp_path, gmsh_file(sector(8), order), f"r{order}.msh"))
        ndof, error = [], []
        for level in range(4):
            if level:
                mesh = refine_uniform(mesh).mesh
            n, e = solve_annulus(mesh, data_on_circles=True)
            ndof.append(n)
            error.append(e)
        slopes[order] = float(np.polyfit(np.log(ndof), np.log(error), 1)[0])
        print(f"order {order}: Ndof {ndof}, energy error {error}, slope {slopes[order]:.3f}")
    assert -1.1 <= slopes[2] <= -0.9, f"second-order slope {slopes[2]:.3f}"
    assert slopes[1] > -0.5, f"first-order slope {slopes[1]:.3f}"


def test_a_straight_second_order_file_reads_as_the_first_order_one(tmp_path):
    straight = sector(8, curved=False)  # all midpoints on the chords
    a = read_mesh(write(tmp_path, gmsh_file(straight, order=1), "first.msh"))
    b = read_mesh(write(tmp_path, gmsh_file(straight, order=2), "second.msh"))
    assert a.curves == b.curves == (None,) * 4 and a.part_names == b.part_names
    for name in ("points", "cells", "boundary", "boundary_part", "reoriented"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
        assert getattr(a, name).dtype == getattr(b, name).dtype


def test_with_curve_replaces_the_files_curve(tmp_path):
    mesh = read_mesh(write(tmp_path, gmsh_file(sector(8), order=2)))
    exact = mesh.with_curve("outer", Circle((0, 0), 2.0))
    assert isinstance(exact.curves[exact.part_index("outer")], Circle)
    assert isinstance(exact.curves[exact.part_index("inner")], QuadraticBoundary)
    # the circle's halfway points are the file's midpoints up to round-off
    e = mesh.part_facets("outer")
    assert np.abs(exact.curved_midpoints[e] - mesh.curved_midpoints[e]).max() <= 1e-15
    for _ in range(3):
        exact = refine_uniform(exact).mesh
    v = np.unique(exact.facets[exact.part_facets("outer")])
    off = np.abs(np.hypot(*exact.points[v].T) - 2).max()
    print(f"outer arc with the exact circle after 3 refinements: radial error {off:.1e}")
    assert off <= 1e-14


def test_contact_on_a_files_arc_is_the_contact_on_the_exact_circle(tmp_path):
    # the same P2 nodes and isoparametric cells; the contact directions are the quadratics'
    # normals, which equal the circle's at the midpoints and (as the mean of two pieces') at
    # the joints; only the arc's two end vertices differ, by θ³/32 (both are off contact)
    exact = sector(8)
    read = read_mesh(write(tmp_path, gmsh_file(exact, order=2)))

    def solved(mesh):
        conditions = {
            "inner": Dirichlet(lambda x: 0.02 * x / np.hypot(x[:, 0], x[:, 1])[:, None]),
            "outer": Contact(gap=lambda x: 0.002 + 0.01 * (x[:, 0] - x[:, 1]) ** 2),
            "bottom": Neumann(),
            "left": Neumann(),
        }
        return solve(ContactProblem(mesh, MATERIAL, conditions))

    a, b = solved(read), solved(exact)
    np.testing.assert_array_equal(a.contact.nodes, b.contact.nodes)
    turn = np.hypot(*(a.contact.normal - b.contact.normal).T)
    print(f"contact directions: max difference {turn.max():.2e}, at nodes {np.argsort(turn)[-2:]}")
    assert np.sort(turn)[-3] <= 1e-14 and turn.max() <= 1.02 * (np.pi / 16) ** 3 / 32
    assert not a.active[np.argsort(turn)[-2:]].any()
    diff = np.abs(a.u - b.u).max() / np.abs(b.u).max()
    print(f"|u_file - u_circle| / |u| = {diff:.2e}, active {a.active.sum()} of {a.active.size}")
    assert np.array_equal(a.active, b.active) and 0 < a.active.sum() < a.active.size
    assert diff <= 1e-10 and a.report.kkt.max <= 1e-10


def moved_midpoint(edge_of: str, shift) -> meshio.Mesh:
    """The order-2 file of the coarse sector with one midpoint node moved by ``shift(a, b)``
    (``a``, ``b`` the ends of the first edge of part ``edge_of``, or of the first interior
    edge for ``edge_of="interior"``)."""
    mesh = sector(4)
    m = gmsh_file(mesh, order=2)
    if edge_of == "interior":
        e = int(np.flatnonzero(mesh.facet2cell[:, 1] >= 0)[0])
    else:
        e = int(mesh.part_facets(edge_of)[0])
    a, b = mesh.points[mesh.edges[e]]
    m.points[mesh.n_points + e, :2] += shift(a, b)
    return m


def normal_of(a, b):
    d = b - a
    return np.array([d[1], -d[0]])


def inward_of_outer(a, b):  # towards the centre, by the edge's length
    return -(a + b) / np.hypot(*(a + b)) * np.hypot(*(b - a))


@pytest.mark.parametrize(
    ("edge_of", "shift", "message"),
    [
        # along the chord to 0.9 of it: the quadratic runs backwards near its end
        ("outer", lambda a, b: 0.4 * (b - a), r"part 'outer': .* folds back on itself"),
        # a whole edge length into the domain: the cell turns over at a vertex
        ("outer", inward_of_outer, r"1 cell\(s\) turn over at a vertex"),
        ("bottom", lambda a, b: [0.0, np.hypot(*(b - a))], r"1 cell\(s\) turn over at a vertex"),
        ("interior", lambda a, b: 0.01 * normal_of(a, b), r"only boundary edges may be curved"),
    ],
)
def test_bad_midpoints_are_refused(tmp_path, edge_of, shift, message):
    with pytest.raises(MeshError, match=r"sector\.msh: .*" + message):
        read_mesh(write(tmp_path, moved_midpoint(edge_of, shift)))


def test_two_elements_giving_an_edge_different_midpoints_are_refused(tmp_path):
    mesh = sector(4)
    m = gmsh_file(mesh, order=2)
    lines = m.cells[1].data
    m.points = np.vstack([m.points, m.points[lines[0, 2]] + [0.0, 1e-3, 0.0]])
    lines[0, 2] = len(m.points) - 1  # the line's own midpoint node, off the triangle's
    with pytest.raises(MeshError, match=r"has two midpoints 0.001 apart"):
        read_mesh(write(tmp_path, m))


def test_a_first_order_file_of_a_curved_part_says_it_stays_polygonal(tmp_path, caplog):
    # before: read without a word, its arcs polygonal on every refined mesh
    with caplog.at_level("WARNING", logger="signorini.mesh.gmsh"):
        read_mesh(write(tmp_path, gmsh_file(sector(8), order=1)))
    (record,) = caplog.records
    message = record.getMessage()
    for text in (
        "sector.msh is a first-order mesh",
        "part(s) ['inner', 'outer'] look curved",
        "stay polygonal",
        "save the mesh second order",
        "triangle6",
        "Mesh.with_curve",
    ):
        assert text in message, message
    caplog.clear()
    with caplog.at_level("WARNING", logger="signorini.mesh.gmsh"):
        read_mesh(write(tmp_path, gmsh_file(sector(8), order=2), "curved.msh"))
        read_mesh(write(tmp_path, gmsh_file(sector(8, curved=False), order=2), "chords.msh"))
    assert not caplog.records  # second order: the file says what the boundary is
