"""Rollers on oblique straight and on curved parts (docs/method.md, *Rollers and
components*): ``u(z)·n_z`` held in a node frame. A model rotated as a whole gives the rotated
solution; an affine solution with an oblique roller and the Lamé solution with rollers on a
sector's radial sides and inner arc are reproduced."""

import numpy as np
import pytest

from signorini import adaptive
from signorini.contact.solution import solve
from signorini.contact.system import assemble
from signorini.examples.hertz_half import hertz_quarter
from signorini.fem.material import Material
from signorini.mesh.builders import rectangle
from signorini.mesh.curves import Circle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.output import fitted_slope
from signorini.problem import (
    Contact,
    ContactProblem,
    Coulomb,
    Dirichlet,
    ExactSolution,
    HalfPlane,
    Neumann,
    ProblemError,
    Roller,
)

ANGLE = 0.7
ROT = np.array([[np.cos(ANGLE), -np.sin(ANGLE)], [np.sin(ANGLE), np.cos(ANGLE)]])


def _rotated_mesh(mesh: Mesh) -> Mesh:
    """``mesh`` rotated by :data:`ANGLE` about the origin, its circles with it."""
    out = Mesh(mesh.points @ ROT.T, mesh.cells, mesh.boundary, mesh.boundary_part, mesh.part_names)
    for name, curve in zip(mesh.part_names, mesh.curves, strict=True):
        if curve is not None:
            out = out.with_curve(name, Circle(ROT @ curve.center, curve.radius))
    return out


def _rotated(problem: ContactProblem) -> ContactProblem:
    """``problem`` rotated as a whole: mesh, Dirichlet values, tractions and obstacles."""
    conditions = {}
    for name, cond in problem.conditions.items():
        if isinstance(cond, Dirichlet):
            cond = Dirichlet(tuple(ROT @ np.asarray(cond.value, dtype=float)))
        elif isinstance(cond, Neumann):
            cond = Neumann(tuple(ROT @ np.asarray(cond.traction, dtype=float)))
        elif isinstance(cond, Contact):
            plane = cond.obstacle
            cond = Contact(
                obstacle=HalfPlane(ROT @ plane.point, ROT @ plane.normal), friction=cond.friction
            )
        conditions[name] = cond
    return ContactProblem(_rotated_mesh(problem.mesh), problem.material, conditions)


def _assert_rotated(plain, turned):
    """The solution ``turned`` of the rotated problem is ``plain`` rotated, to round-off."""
    scale = np.abs(plain.u).max()
    assert np.abs(turned.space.node_points - plain.space.node_points @ ROT.T).max() < 1e-14
    assert np.abs(turned.u - plain.u @ ROT.T).max() <= 1e-12 * scale
    # the rollers' forces: along an axis (a Cartesian DOF) and oblique (a frame DOF)
    assert np.array_equal(turned.roller_nodes, plain.roller_nodes)
    force = np.abs(plain.roller_force).max()
    assert np.abs(turned.roller_force - plain.roller_force).max() <= 1e-11 * max(force, 1e-300)
    if plain.contact.size:
        assert np.array_equal(turned.contact.nodes, plain.contact.nodes)
        assert np.array_equal(turned.active, plain.active)
        total = plain.total_contact_force
        assert np.abs(turned.contact_force - plain.contact_force).max() <= 1e-11 * total
    return scale


@pytest.mark.parametrize("loading", ["depth", "force"])
def test_rotated_hertz_quarter_gives_the_rotated_solution(loading):
    # the roller on the axis becomes oblique; under force control the free rigid motion is
    # the translation along the rotated vertical, held by the contact alone
    kwargs = {"force": 0.0084} if loading == "force" else {}
    plain = hertz_quarter(rings=4, h_bottom=0.05, **kwargs)
    turned = _rotated(plain)
    assert turned.rollers.keys() == {"axis"} and "axis" not in turned.held
    assert plain.rigid_motions.shape == turned.rigid_motions.shape
    a, b = solve(plain), solve(turned)
    _assert_rotated(a, b)
    assert a.active.sum() >= 4
    # the roller's nodes off the contact hold u·n = 0 exactly in their frames
    axis = b.space.part_nodes(["axis"])
    n = ROT @ np.array([-1.0, 0.0])
    assert np.abs(b.u[axis] @ n).max() <= 1e-15 * np.abs(b.u).max()
    assert a.ndof == b.ndof


def test_rotated_hertz_quarter_adapts_the_same_meshes():
    plain = hertz_quarter(rings=3)
    turned = _rotated(plain)
    la = list(adaptive(plain, max_ndof=900))
    lb = list(adaptive(turned, max_ndof=900))
    assert len(la) == len(lb) >= 3
    for x, y in zip(la, lb, strict=True):
        assert np.array_equal(x.result.mesh.cells, y.result.mesh.cells)
        assert x.record.eta == pytest.approx(y.record.eta, rel=1e-9)
        _assert_rotated(x.result, y.result)


def test_rotated_block_on_rollers():
    # the block of test_roller.py on a roller and a moved roller, rotated
    mesh = rectangle(0.0, 1.0, 0.0, 1.0, 4, 4)
    conditions = {
        "top": Neumann((0.3, -0.2)),
        "right": Neumann((0.0, 0.0)),
        "left": Roller(),
        "bottom": Roller(0.01),
    }
    plain = ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions)
    turned = _rotated(plain)
    assert set(turned.rollers) == {"left", "bottom"} and not turned.held
    a, b = solve(plain), solve(turned)
    _assert_rotated(a, b)
    # the corner (0, 0) on both rollers is held in both components
    corner = np.flatnonzero(np.abs(b.space.node_points).max(axis=1) < 1e-15)
    assert np.isin(corner, b.dirichlet_nodes).all()
    assert a.ndof == b.ndof == plain.free_ndof(mesh)


def test_rotated_block_on_a_frictional_foundation_with_a_roller():
    # Coulomb friction at the foundation, a roller on the upper part of the left side (off
    # the contact), pushed down and sideways on the top: semismooth Newton in the frames
    unit = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4)
    mesh = Mesh.from_arrays(
        unit.points,
        unit.cells,
        {
            "bottom": lambda x: x[:, 1] < 1e-12,
            "top": lambda x: x[:, 1] > 1.0 - 1e-12,
            "roller": lambda x: (x[:, 0] < 1e-12) & (x[:, 1] > 0.5),
            "free": lambda x: (
                (x[:, 1] >= 1e-12)
                & (x[:, 1] <= 1.0 - 1e-12)
                & ((x[:, 0] > 1e-12) | (x[:, 1] < 0.5))
            ),
        },
    )
    conditions = {
        "bottom": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(0.3)),
        "top": Neumann((-0.03, -0.1)),
        "roller": Roller(),
        "free": Neumann(),
    }
    plain = ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions)
    turned = _rotated(plain)
    a, b = solve(plain), solve(turned)
    _assert_rotated(a, b)
    assert np.array_equal(a.state, b.state) and len(set(a.state.tolist())) >= 2
    scale = np.abs(a.tangential_force).max()
    assert scale > 0
    assert np.abs(b.tangential_force - a.tangential_force).max() <= 1e-10 * scale
    # equilibrium along x: the roller and the friction carry the push on the top
    # (the roller acts with −Λ n = Λ e_x, the foundation with −Λ_t t, t = e_x)
    assert a.roller_force.sum() - a.tangential_force.sum() == pytest.approx(0.06, rel=1e-9)


def _trapezoid(n: int) -> Mesh:
    """The trapezoid with the oblique left side from (1, 0) to (1.4, 1), the right side from
    (2.5, 0) to (2.2, 1): a mapped structured mesh, parts named as the rectangle's."""
    unit = rectangle(0.0, 1.0, 0.0, 1.0, n, n)
    xi, eta = unit.points.T
    left, right = 1.0 + 0.4 * eta, 2.5 - 0.3 * eta
    points = np.column_stack([left + xi * (right - left), eta])
    return Mesh(points, unit.cells, unit.boundary, unit.boundary_part, unit.part_names)


@pytest.mark.parametrize("bottom", ["dirichlet", "roller"])
def test_oblique_roller_reproduces_an_affine_solution(bottom):
    # a uniform stress with principal axes along the oblique side's normal n has no shear
    # traction there, and u·n is constant along it: a roller holds it
    material = Material.from_young(1.0, 0.3)
    lam, mu = material.lam, material.mu
    mesh = _trapezoid(3)
    t = np.array([0.4, 1.0]) / np.hypot(0.4, 1.0)  # the left side, upwards
    n = np.array([-t[1], t[0]])  # its outward normal
    if bottom == "dirichlet":
        s1, s2 = -0.3, 0.2  # principal stresses along n and t
    else:  # a roller on the bottom too: zero shear on two directions, hydrostatic
        s1 = s2 = -0.25
    sigma = s1 * np.outer(n, n) + s2 * np.outer(t, t)
    eps = (sigma - lam / (2 * (lam + mu)) * np.trace(sigma) * np.eye(2)) / (2 * mu)
    c = np.array([0.01, 0.0])  # a translation along the bottom (held only where Dirichlet)

    def u(x):
        return x @ eps.T + (c if bottom == "dirichlet" else 0.0)

    value = float(u(np.array([[1.0, 0.0]]))[0] @ n)
    assert abs(value) > 1e-3

    def traction(x, normal):
        return normal @ sigma.T

    conditions = {
        "left": Roller(value),
        "right": Neumann(traction),
        "top": Neumann(traction),
        "bottom": Dirichlet(u) if bottom == "dirichlet" else Roller(0.0),
    }
    exact = ExactSolution(u, lambda x: np.broadcast_to(eps, (len(x), 2, 2)))
    problem = ContactProblem(mesh, material, conditions, exact=exact)
    assert problem.rollers.keys() == {"left"}  # a roller along an axis holds u_y
    result = solve(problem)
    scale = np.abs(result.u).max()
    assert np.abs(result.u - u(result.space.node_points)).max() <= 1e-12 * scale
    # the rollers' nodal forces are the uniform stress's: Λ_z = −σ_nn ∫ ψ_z ds over the part
    space = result.space
    expected = np.zeros(space.n_nodes)
    for name in [p for p, c in conditions.items() if isinstance(c, Roller)]:
        edges = mesh.part_facets(name)
        nodes = space.facet_nodes(edges)
        length = mesh.edge_length[edges]
        ab = mesh.points[nodes[0, :2]]
        normal = np.array([ab[1, 1] - ab[0, 1], ab[0, 0] - ab[1, 0]]) / length[0]
        weights = np.column_stack([length / 6, length / 6, 2 * length / 3])
        np.add.at(expected, nodes.ravel(), -(normal @ sigma @ normal) * weights.ravel())
    assert result.roller_nodes.size == (6 if bottom == "dirichlet" else 12)
    assert not np.isin(result.roller_nodes, result.dirichlet_nodes).any()
    lam_z = result.roller_force
    assert np.abs(lam_z - expected[result.roller_nodes]).max() <= 1e-12 * np.abs(lam_z).max()
    assert result.errors()["error_energy"] <= 1e-12 * np.sqrt(np.abs(sigma).max() * scale)
    # the roller edges' free traction (η3) vanishes with the rest of η on the exact solution
    from signorini.estimator import estimate

    assert estimate(result).eta <= 1e-11 * np.abs(sigma).max()


def _sector(n: int, a: float = 1.0, b: float = 2.0, angles=(0.3, 1.4)) -> Mesh:
    """The annular sector ``a ≤ r ≤ b``, ``θ0 ≤ θ ≤ θ1`` (structured, ``n × 2n``): parts
    ``"inner"``, ``"outer"`` (circles) and the radial ``"start"``, ``"end"`` (oblique)."""
    unit = rectangle(a, b, *angles, n, 2 * n)
    r, theta = unit.points.T
    points = np.column_stack([r * np.cos(theta), r * np.sin(theta)])
    names = {"left": "inner", "right": "outer", "bottom": "start", "top": "end"}
    mesh = Mesh(
        points,
        unit.cells,
        unit.boundary,
        unit.boundary_part,
        [names[p] for p in unit.part_names],
    )
    return mesh.with_curve("inner", Circle((0, 0), a)).with_curve("outer", Circle((0, 0), b))


def _lame(material: Material, a: float, b: float, p: float) -> ExactSolution:
    """Plane-strain Lamé: ``u = f(r) x / r`` with ``f = A r + B / r``, ``f(a) = 0``,
    ``σ_rr(b) = −p``."""
    lam, mu = material.lam, material.mu
    A = -p / (2 * (lam + mu) + 2 * mu * a**2 / b**2)
    B = -A * a**2

    def u(x):
        r2 = (x**2).sum(axis=1)
        return x * (A + B / r2)[:, None]

    def grad(x):
        r2 = (x**2).sum(axis=1)
        # ∂/∂x_j (g(r) x_i) with g = A + B / r²: g δ_ij + g'(r) x_i x_j / r, g' = −2B / r³
        g = A + B / r2
        return (
            g[:, None, None] * np.eye(2)
            - 2 * B * np.einsum("ni,nj->nij", x, x) / (r2**2)[:, None, None]
        )

    return ExactSolution(u, grad)


def _sector_conditions(p: float) -> dict:
    """Rollers on the sector's inner arc and radial sides, the pressure ``p`` on its outer
    arc."""
    return {
        "inner": Roller(),
        "outer": Neumann(lambda x, normal: -p * normal),
        "start": Roller(),
        "end": Roller(),
    }


def test_rollers_on_a_sector_converge_to_lame_at_the_p2_rate():
    # rollers on the radial sides (oblique) and on the inner arc (the circle's normal), the
    # outer arc under pressure: the Lamé solution u_r = A r + B / r, u_θ = 0
    material = Material.from_young(1.0, 0.3)
    p = 0.1
    exact = _lame(material, 1.0, 2.0, p)
    conditions = _sector_conditions(p)
    mesh = _sector(2)
    ndof, errors = [], []
    for _ in range(4):
        problem = ContactProblem(mesh, material, conditions, exact=exact)
        result = solve(problem)
        ndof.append(result.ndof)
        errors.append(result.errors()["error_energy"])
        mesh = refine_uniform(mesh).mesh
    assert set(problem.rollers) == {"inner", "start", "end"}
    assert problem.rigid_motions.shape == (0, 3)
    slope = fitted_slope(ndof, errors, last=3)
    print("\nndof", ndof, "energy errors", [f"{e:.3e}" for e in errors], f"slope {slope:.3f}")
    assert -1.05 < slope < -0.95, f"energy error slope {slope:.3f} against Ndof, expected −1"
    # relative to the energy norm of u, ‖u‖² = the pressure's work p |u_r(b)| b (θ1 − θ0)
    norm = np.sqrt(p * np.abs(exact.displacement(np.array([[2.0, 0.0]]))[0, 0]) * 2.0 * 1.1)
    assert errors[-1] < 1e-3 * norm, f"relative energy error {errors[-1] / norm:.2e}"
    # the inner arc's nodes hold u·n_z = 0 with the circle's exact normal
    inner = result.space.part_nodes(["inner"])
    x = result.space.node_points[inner]
    un = np.einsum("nc,nc->n", result.u[inner], x / np.hypot(*x.T)[:, None])
    assert np.abs(un).max() <= 1e-14 * np.abs(result.u).max()


def test_a_roller_on_an_arc_leaves_the_rotation_about_its_centre_free():
    conditions = {
        "inner": Roller(),
        "outer": Neumann(lambda x, normal: -0.1 * normal),
        "start": Neumann(),
        "end": Neumann(),
    }
    with pytest.raises(ProblemError, match=r"rotation about \(0\.0, 0\.0\).*'inner'"):
        ContactProblem(_sector(2), Material.from_young(1.0, 0.3), conditions)
    # rollers on the radial sides hold it (and everything else)
    conditions = {**conditions, "inner": Neumann(), "start": Roller(), "end": Roller()}
    assert ContactProblem(
        _sector(2), Material.from_young(1.0, 0.3), conditions
    ).rigid_motions.shape == (0, 3)
    # two oblique straight rollers on parallel sides hold the translations along their
    # normal only
    mesh = _rotated_mesh(rectangle(0.0, 1.0, 0.0, 1.0, 2, 2))
    conditions = {"left": Roller(), "right": Roller(), "top": Neumann(), "bottom": Neumann()}
    with pytest.raises(
        ProblemError, match=r"translation along \(-0\.644218, 0\.764842\).*no contact part"
    ):
        ContactProblem(mesh, Material.from_young(1.0, 0.3), conditions)


def test_roller_refusals_on_oblique_and_curved_parts():
    material = Material.from_young(1.0, 0.3)
    # a roller part with a corner: its normal is not defined at the corner vertex
    unit = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2)
    corner = Mesh.from_arrays(
        unit.points,
        unit.cells,
        {
            "corner": lambda x: (x[:, 0] < 1e-12) | (x[:, 1] < 1e-12),
            "free": lambda x: (x[:, 0] >= 1e-12) & (x[:, 1] >= 1e-12),
        },
    )
    with pytest.raises(ProblemError, match=r"'corner'.*turns by 90°.*\(0, 0\).*Split the part"):
        ContactProblem(corner, material, {"corner": Roller(), "free": Neumann((0.1, 0.1))})
    # a polygonal arc (no curve) turning by 1.1 / 4 rad per vertex is accepted: its vertices
    # hold u·n with the mean of their two edges' normals
    sector = _sector(2)
    polygon = Mesh(sector.points, sector.cells, sector.boundary, sector.boundary_part,
                   sector.part_names)  # fmt: skip
    conditions = {"inner": Roller(), "outer": Neumann(lambda x, normal: -0.1 * normal)}
    pushed = {**conditions, "start": Roller(), "end": Neumann(lambda x, normal: -0.1 * normal)}
    result = solve(ContactProblem(polygon, material, pushed))  # slides along the arc
    x = polygon.points
    arc = np.flatnonzero(np.abs(np.hypot(*x.T) - 1.0) < 1e-12)
    arc = arc[np.argsort(np.arctan2(x[arc, 1], x[arc, 0]))]
    inner = arc[1:-1]  # the ends are corners held both ways
    assert inner.size == 3 and np.isin(inner, result.roller_nodes).all()
    prev, after = x[inner] - x[arc[:-2]], x[arc[2:]] - x[inner]
    tangent = prev / np.hypot(*prev.T)[:, None] + after / np.hypot(*after.T)[:, None]
    n = tangent @ np.array([[0.0, 1.0], [-1.0, 0.0]])  # (−τ_y, τ_x): the mean normal's line
    assert np.abs(np.einsum("kc,kc->k", result.u[inner], n)).max() <= 1e-15
    assert np.abs(result.u[inner]).max() > 1e-2
    # the roller on the rotated axis meets the unrotated plane's contact at an angle
    turned = _rotated(hertz_quarter(rings=3))
    conditions = {**turned.conditions, "arc": Contact(obstacle=HalfPlane((0, 0), (0, 1)))}
    problem = ContactProblem(turned.mesh, turned.material, conditions)
    with pytest.raises(ProblemError, match=r"held in u·n along n = .*'arc'.*conflict"):
        assemble(problem, problem.mesh)
    # two rollers along one line with different values: the later part's stands at the
    # shared node, as for two Dirichlet parts (and the rotated model agrees)
    mesh = rectangle(0.0, 2.0, 0.0, 1.0, 4, 2)
    split = Mesh.from_arrays(
        mesh.points,
        mesh.cells,
        {
            "a": lambda x: (x[:, 1] < 1e-12) & (x[:, 0] < 1.0),
            "b": lambda x: (x[:, 1] < 1e-12) & (x[:, 0] > 1.0),
            "top": lambda x: x[:, 1] > 1.0 - 1e-12,
            "sides": lambda x: (x[:, 1] >= 1e-12) & (x[:, 1] <= 1.0 - 1e-12),
        },
    )
    conditions = {"a": Roller(0.0), "b": Roller(0.01), "top": Dirichlet(), "sides": Neumann()}
    plain = ContactProblem(split, material, conditions)
    turned = ContactProblem(_rotated_mesh(split), material, conditions)
    assert not plain.rollers and set(turned.rollers) == {"a", "b"}
    ra, rb = solve(plain), solve(turned)
    _assert_rotated(ra, rb)
    shared = np.flatnonzero(np.abs(ra.space.node_points - [1.0, 0.0]).max(axis=1) < 1e-14)
    assert ra.u[shared, 1] == pytest.approx(-0.01, abs=1e-15)


def test_the_estimator_measures_the_free_traction_on_rollers():
    """Roller edges enter η3 with their tangential traction (which must vanish; zero on the
    exact affine trapezoid solution, test above): on the Lamé sector, where it is not exact,
    it falls at the P2 rate, and η with it keeps a bounded efficiency index."""
    from signorini.estimator import estimate
    from signorini.estimator.held import held_part_integrals
    from signorini.estimator.residual import geometry
    from signorini.estimator.traction import CellStress, vertex_stress
    from signorini.fem.quadrature import line_rule

    material = Material.from_young(1.0, 0.3)
    p = 0.1
    exact = _lame(material, 1.0, 2.0, p)
    conditions = _sector_conditions(p)
    mesh, rows = _sector(2), []
    for _ in range(4):  # a loop over uniform refinements
        r = solve(ContactProblem(mesh, material, conditions, exact=exact))
        cells, _ = geometry(r.space)
        u_cell = r.space.field_coefficients(r.u)
        sigma = vertex_stress(cells, u_cell, material)
        stresses = CellStress(cells, mesh.points, mesh.cells, u_cell, material, sigma, 1.0)
        t, w = line_rule(7)
        edges, J = held_part_integrals(r, stresses, t, w)
        rows.append((r.ndof, r.errors()["error_energy"], estimate(r).eta, np.sqrt(J.sum())))
        mesh = refine_uniform(mesh).mesh
    ndof, error, eta, roller = (np.array(c) for c in zip(*rows, strict=True))
    assert edges.size == sum(mesh.part_facets(n).size for n in ("inner", "start", "end")) // 2
    efficiency = eta / error
    print(f"\nroller traction residual {roller}; η/‖e‖ {np.round(efficiency, 2)}")
    assert (roller > 0).all() and fitted_slope(ndof, roller, last=3) < -0.9
    assert fitted_slope(ndof, eta, last=3) < -0.9
    assert efficiency.max() / efficiency.min() < 1.3
