"""The estimator on curved boundaries (docs/method.md, *Estimator*, "On curved boundaries"):
second derivatives through the quadratic map, normals of the quadratic edges, the rate and
efficiency on a manufactured solution with a Dirichlet arc, what the straight-cell estimator
does there, and the adaptive loop on a half-disc pressed onto a rigid plane."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from signorini.contact.solution import solve
from signorini.estimator import residual
from signorini.estimator.residual import contact_stress, estimate
from signorini.estimator.terms import (
    FacetSet,
    direction_field,
    facet_traction,
    tangential_stress,
    third_integrals,
)
from signorini.estimator.traction import CellStress
from signorini.fem import iso, p2
from signorini.fem.mapping import CellMap, IsoparametricCells
from signorini.fem.material import Material, stress
from signorini.fem.norms import energy_error2
from signorini.fem.postprocess import div_stress as affine_div_stress
from signorini.fem.postprocess import stress_divergence
from signorini.fem.quadrature import line_rule
from signorini.fem.space import P2Space
from signorini.loop import adaptive
from signorini.mesh import Circle, Line, Mesh, rectangle
from signorini.mesh.refine import refine_uniform
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann
from signorini.problem.obstacles import Disc, HalfPlane

from ..fem.test_iso import (
    MATERIAL,
    annulus_sector,
    body_force,
    curved_sector,
    exact_grad,
    exact_u,
    problem,
)


def straight_estimator(monkeypatch) -> None:
    """Make ``estimate`` treat every cell as the straight triangle of its vertices (the
    estimator before curved boundaries)."""
    monkeypatch.setattr(
        residual, "geometry", lambda space: (CellMap(space.vertices), np.zeros(0, np.int64))
    )


def slope(ndof, values) -> float:
    return float(np.polyfit(np.log(ndof), np.log(values), 1)[0])


def curved_cell() -> np.ndarray:
    """One curved cell ``(1, 6, 2)``: a straight triangle whose first edge bulges out."""
    nodes = 0.3 * p2.REFERENCE_NODES + [1.0, 0.2]
    nodes[3] += [0.01, -0.04]
    nodes[4] += [0.02, 0.01]
    return nodes[None]


# ---------------------------------------------------------------------------- derivatives
def test_hessian_through_the_quadratic_map_matches_finite_differences():
    """u_h = û ∘ x⁻¹ with û a random quadratic: its gradient and Hessian at a point, against
    central differences of u_h evaluated by inverting the map with Newton's method."""
    rng = np.random.default_rng(3)
    nodes, u = curved_cell(), rng.standard_normal((1, 12))
    xi0 = np.array([[0.2, 0.3]])
    grad, hess = iso.field_derivatives(nodes, u, xi0)
    x0 = iso.geometry(nodes, xi0)[0][0, 0]

    def u_h(x):
        xi = xi0[0].copy()
        for _ in range(30):
            X, J, _ = iso.geometry(nodes, xi[None])
            xi = xi - np.linalg.solve(J[0, 0], X[0, 0] - x)
        return (p2.basis(xi[None]) @ u.reshape(6, 2))[0]

    e, E = 1e-4, np.eye(2) * 1e-4
    fd_grad = np.column_stack([(u_h(x0 + E[j]) - u_h(x0 - E[j])) / (2 * e) for j in range(2)])
    fd_hess = np.empty((2, 2, 2))
    for j in range(2):
        for k in range(2):
            s = u_h(x0 + E[j] + E[k]) - u_h(x0 + E[j] - E[k])
            s = s - u_h(x0 - E[j] + E[k]) + u_h(x0 - E[j] - E[k])
            fd_hess[:, j, k] = s / (4 * e * e)
    err_g = np.abs(grad[0, 0] - fd_grad).max() / np.abs(grad).max()
    err_h = np.abs(hess[0, 0] - fd_hess).max() / np.abs(hess).max()
    # the affine Hessian of the same coefficients (the straight-cell reading) is far off
    affine = p2.field_hessian(nodes[:, :3], u)[0]
    err_affine = np.abs(affine - fd_hess).max() / np.abs(hess).max()
    print(f"gradient {err_g:.1e}, Hessian {err_h:.1e}, affine Hessian {err_affine:.1e}")
    assert err_g < 1e-7 and err_h < 1e-5, (err_g, err_h)
    assert err_affine > 0.1, err_affine


def test_derivatives_on_a_straight_cell_are_the_affine_ones_and_linear_fields_are_exact():
    rng = np.random.default_rng(5)
    vertices = np.array([[[0.1, 0.0], [1.3, 0.4], [0.2, 0.9]]])
    nodes = np.concatenate([vertices, 0.5 * (vertices + np.roll(vertices, -1, axis=1))], axis=1)
    u = rng.standard_normal((1, 12))
    xi = np.array([[0.1, 0.2], [0.6, 0.3], [0.0, 1.0]])
    grad, hess = iso.field_derivatives(nodes, u, xi)
    scale = np.abs(hess).max()
    assert np.abs(grad - p2.field_gradients(vertices, u, xi)).max() < 1e-13 * np.abs(grad).max()
    assert np.abs(hess - p2.field_hessian(vertices, u)[:, None]).max() < 1e-13 * scale
    # a linear field on a curved cell: its Hessian vanishes, its gradient is exact
    B, c = np.array([[0.3, -0.7], [0.2, 0.5]]), np.array([0.1, -0.4])
    lin = (curved_cell()[0] @ B.T + c).reshape(1, 12)
    grad, hess = iso.field_derivatives(curved_cell(), lin, xi)
    assert np.abs(grad - B).max() < 1e-14 and np.abs(hess).max() < 1e-12


def test_div_stress_of_the_interpolant_converges_on_curved_cells_only_through_the_map():
    """On the isoparametric cells of the annulus sector, div σ(I_h u) at the cell rule's
    points converges to div σ(u) at rate h through the map; read on the straight triangle
    (the affine Hessian of the same coefficients) it does not converge."""
    mesh = curved_sector()
    iso_err, affine_err = [], []
    for _ in range(4):
        mesh = refine_uniform(mesh).mesh
        space = P2Space(mesh)
        cells, nodes = space.curved
        u = space.cell_values(space.interpolate(exact_u))[cells]
        xi = np.array([[1 / 3, 1 / 3], [0.6, 0.2], [0.2, 0.6], [0.2, 0.2]])
        x = iso.geometry(nodes, xi)[0]
        exact = -body_force(x.reshape(-1, 2)).reshape(x.shape)  # div σ(u) = −f
        _, hess = iso.field_derivatives(nodes, u, xi)
        iso_err.append(np.abs(stress_divergence(hess, MATERIAL) - exact).max())
        affine = affine_div_stress(space.vertices[cells], u, MATERIAL)
        affine_err.append(np.abs(affine[:, None] - exact).max())
    rate = np.log2(np.array(iso_err[:-1]) / iso_err[1:])
    print(f"max |div σ(I_h u) − div σ(u)| through the map {np.round(iso_err, 4)}")
    print(f"  rates {rate.round(3)}; read on the straight cells {np.round(affine_err, 4)}")
    assert np.all(rate > 0.9), rate
    assert affine_err[-1] > 0.5 * affine_err[0] and affine_err[-1] > 5 * iso_err[-1]


# ---------------------------------------------------------------------------- edges
def lame_mesh(n: int) -> Mesh:
    """The quarter annulus 1 ≤ r ≤ 2 (a mapped rectangle) with its outer arc on a circle."""
    base = rectangle(1.0, 2.0, 0.0, np.pi / 2, nx=n, ny=2 * n)
    r, t = base.points[:, 0], base.points[:, 1]
    points = np.column_stack([r * np.cos(t), r * np.sin(t)])
    outer = base.facets[base.part_facets("right")]
    mesh = Mesh.from_arrays(points, base.cells, {"outer": outer, "rest": lambda x: x[:, 0] > -1})
    return mesh.with_curve("outer", Circle((0, 0), 2.0))


def test_tangential_stress_of_a_radial_field_vanishes_with_the_local_normal():
    """The Lamé field u = (r + 1/r) e_r has σ_rθ = 0: on the outer arc its traction is
    normal. η4's integrand ‖σ_t(I_h u)‖² along the arc with the normal n(t) of the quadratic
    edges decays like h⁴; with the chord normal (the straight estimator) like h²."""
    material = Material.from_young(1.0, 0.3)

    def lame(x):
        r2 = (x**2).sum(axis=1, keepdims=True)
        return x * (1 + 1 / r2)

    t, w = line_rule(7)
    local, chord = [], []
    for n in (2, 4, 8, 16):
        mesh = lame_mesh(n)
        space = P2Space(mesh)
        u = space.interpolate(lame)
        e = mesh.part_facets("outer")
        edges = FacetSet(e, space.facet_nodes(e), mesh.facet2cell[e], mesh.facet_measure[e])
        x = space.node_points[edges.nodes]
        direction = x / np.hypot(x[..., 0], x[..., 1])[..., None]  # the arc's normal n_z
        ab = mesh.points[mesh.oriented_boundary(e)]
        d = ab[:, 1] - ab[:, 0]
        normal = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
        stresses = CellStress.of(space, u, material)
        J4, _ = contact_stress(stresses, mesh, edges, normal, direction, t, w)
        kinds = [type(g) for _, g, _ in space.mapping.split(edges.cells[:, 0])]
        assert kinds == [IsoparametricCells]  # every arc edge's cell is isoparametric
        local.append(np.sqrt(J4.sum()))
        u_cell = space.cell_values(u)
        sigma = stress(material, p2.field_gradients(space.vertices, u_cell, p2.REFERENCE_NODES[:3]))
        sn = facet_traction(
            sigma, mesh.points, mesh.cells, edges.cells[:, 0], mesh.facet_local[e, 0], t
        )
        chord.append(np.sqrt(tangential_stress(sn, normal, w, edges.measure).sum()))
    r_local = np.log2(np.array(local[:-1]) / local[1:])
    r_chord = np.log2(np.array(chord[:-1]) / chord[1:])
    print(f"‖σ_t(I_h u)‖ on the arc: local normal {np.array(local)} (rates {r_local.round(2)})")
    print(f"                         chord normal {np.array(chord)} (rates {r_chord.round(2)})")
    assert r_local[-1] > 1.8 and r_chord[-1] < 1.2, (r_local, r_chord)


def test_third_integrals_along_a_quadratic_edge():
    """With ``points``, η6's integrals carry |x'(t)|: on a straight edge they are the
    length-scaled ones; on an arc they agree with adaptive quadrature split at the roots."""
    rng = np.random.default_rng(2)
    v = rng.standard_normal((50, 3))
    a, b = rng.standard_normal((50, 2)), rng.standard_normal((50, 2))
    pts = np.stack([a, b, 0.5 * (a + b)], axis=1)
    length = np.hypot(*(b - a).T)
    ref = third_integrals(v, length)
    assert np.abs(third_integrals(v, length, pts) - ref).max() < 1e-14 * np.abs(ref).max()
    # an arc of the unit circle [start, end, halfway]
    phi = np.array([0.1, 0.7, 0.4])
    arc = np.column_stack([np.cos(phi), np.sin(phi)])[None]
    v = np.array([[0.3, -0.2, 0.5]])  # changes sign twice on the edge
    got = third_integrals(v, np.zeros(1), arc)[0]
    expected = np.zeros(3)
    for lo, hi, col, (p0, p1) in [
        (0, 1 / 3, 0, (1, -2)),
        (2 / 3, 1, 1, (-1, 2)),
        (1 / 3, 0.5, 2, (0, 2)),
        (0.5, 2 / 3, 2, (2, -2)),
    ]:

        def integrand(t, p0=p0, p1=p1):
            _, speed, _ = iso.edge_geometry(arc[:, :2], arc[:, 2], np.array([t]))
            vq = (p2.edge_basis(np.array([t])) @ v[0])[0]
            return max(vq, 0.0) * (p0 + p1 * t) * speed[0, 0]

        expected[col] += quad(integrand, lo, hi, epsabs=1e-14, epsrel=1e-13, limit=200)[0]
    print(f"η6 thirds along an arc {got}, reference {expected}")
    assert np.abs(got - expected).max() < 1e-10 * np.abs(expected).max(), (got, expected)


# ---------------------------------------------------------------------------- rates
def level_row(res, exact_gradient):
    """``(Ndof, η, energy error, estimate)`` of a solve against a known displacement
    gradient, on the isoparametric cells where there are any."""
    est = estimate(res)
    sp = res.space
    e2 = energy_error2(sp.mapping, sp.cell_values(res.u), exact_gradient, MATERIAL)
    return res.ndof, est.eta, float(np.sqrt(e2.sum())), est


def manufactured_levels(levels: int = 5):
    """η_h, its terms, the energy error and Ndof under uniform refinement of the annulus
    sector with a Dirichlet condition on the outer arc (tests/fem/test_iso.py)."""
    mesh = curved_sector()
    out = []
    for level in range(levels):
        if level:
            mesh = refine_uniform(mesh).mesh
        out.append(level_row(solve(problem(mesh)), exact_grad))
    return out


def test_estimator_and_error_decay_alike_with_a_dirichlet_arc(monkeypatch):
    levels = manufactured_levels()
    ndof = [lv[0] for lv in levels]
    eta, err = np.array([lv[1] for lv in levels]), np.array([lv[2] for lv in levels])
    eff = eta / err
    for n, e, r, est in levels:
        print(
            f"Ndof {n:6d}  η {e:.4e}  error {r:.4e}  η/error {e / r:.2f}  terms {est.eta_terms[:3]}"
        )
        assert abs(est.eta2.sum() - e**2) <= 1e-13 * e**2
    s_eta, s_err = slope(ndof[1:], eta[1:]), slope(ndof[1:], err[1:])
    print(f"slopes in Ndof: η {s_eta:.3f}, error {s_err:.3f}; efficiency {eff.round(2)}")
    assert -1.1 <= s_eta <= -0.9, s_eta
    assert -1.1 <= s_err <= -0.9, s_err
    assert eff.max() / eff.min() < 1.25, eff
    change = np.abs(np.diff(eff))
    assert np.all(change[1:] < 0.7 * change[:-1]) and change[-1] < 0.02 * eff[-1], eff  # settles

    straight_estimator(monkeypatch)
    old = manufactured_levels()
    eta_old = np.array([lv[1] for lv in old])
    eff_old = eta_old / err
    s_old = slope(ndof[1:], eta_old[1:])
    for n, e, r, est in old:
        print(f"straight cells: Ndof {n:6d}  η {e:.4e}  η/error {e / r:.2f}  {est.eta_terms[:3]}")
    print(f"straight cells: slope {s_old:.3f}; efficiency {eff_old.round(2)}")
    # the straight reading of the curved layer (wrong Hessians, chord normals) decays like
    # h^{3/2}: η's slope drifts towards −3/4 and the efficiency index grows without bound
    assert s_old > -0.95, s_old
    assert eff_old[-1] > 1.4 * eff_old[0] and np.all(np.diff(eff_old) > 0), eff_old
    assert np.all(eff_old > eff)


def test_the_estimator_is_invariant_under_rotation_on_a_curved_mesh():
    angle = 0.9
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    base = refine_uniform(curved_sector()).mesh
    ref = estimate(solve(problem(base)))

    def rotated(f):
        return lambda x, *n: f(x @ R) @ R.T

    parts = {name: base.facets[base.part_facets(name)] for name in base.part_names}
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    mesh = mesh.with_curve("inner", Circle((0, 0), 1)).with_curve("outer", Circle((0, 0), 2))
    pb = problem(mesh, rotated(exact_u), lambda x: R @ exact_grad(x @ R) @ R.T, rotated(body_force))
    rot = estimate(solve(pb))
    err = np.abs(rot.eta2_cell - ref.eta2_cell).max() / ref.eta2_cell.max()
    print(f"rotation by {angle}: max |Δη_T²| / max η_T² = {err:.1e}")
    assert err < 1e-10, err


def test_a_part_carrying_a_line_gives_the_straight_estimator():
    mesh = rectangle(nx=4, ny=2)
    pb = lambda m: ContactProblem(  # noqa: E731
        m,
        MATERIAL,
        {
            "left": Dirichlet(),
            "top": Dirichlet((0.0, -0.02)),
            "right": Contact(gap=0.0),
            "bottom": Contact(gap=0.001),
        },
    )
    plain = estimate(solve(pb(mesh)))
    lined = estimate(solve(pb(mesh.with_curve("bottom", Line((0, 0), (1, 0))))))
    assert np.array_equal(plain.eta2_cell, lined.eta2_cell)


# ---------------------------------------------------------------------------- contact
def half_disc(n: int = 4, radius: float = 1.0) -> Mesh:
    """The lower half of the disc of ``radius`` centred at (0, radius): flat side ``top``
    (y = radius), arc ``arc`` on its circle, touching y = 0 at the origin. The union-jack
    rectangle [−1, 1] × [−1, 0] mapped by p ↦ p |p|_∞ / |p|_2 (squares to circles), so no
    cell has two edges on the arc."""
    base = rectangle(-1.0, 1.0, -1.0, 0.0, nx=2 * n, ny=n)
    p = base.points
    norm2 = np.hypot(p[:, 0], p[:, 1])
    scale = np.abs(p).max(axis=1) / np.where(norm2 > 0, norm2, 1.0)
    points = radius * p * scale[:, None] + [0.0, radius]
    mesh = Mesh.from_arrays(
        points,
        base.cells,
        {
            "top": lambda x: x[:, 1] > radius * (1 - 1e-12),
            "arc": lambda x: x[:, 1] < radius * (1 - 1e-12),
        },
    )
    return mesh.with_curve("arc", Circle((0.0, radius), radius))


@pytest.mark.slow
def test_adaptive_loop_on_a_half_disc_pressed_onto_a_rigid_plane():
    """A half-disc (E = 1, ν = 0.3, R = 1) pushed 0.01 down by its flat side onto the
    half-plane y ≤ 0: contact half-width a ≈ 0.078 R on the arc. The adaptive loop with the
    curved estimator: η_h ∝ Ndof^{-1} over its last levels, indicators summing to η_h²."""
    pb = ContactProblem(
        half_disc(),
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((0.0, -0.01)),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0))),
        },
    )
    ndof, eta = [], []
    for level in adaptive(pb, theta=0.4, max_ndof=16_000):
        est, res = level.estimate, level.result
        total = est.eta2.sum()
        assert abs(total - est.eta**2) <= 1e-13 * est.eta**2, (total, est.eta**2)
        assert res.report.kkt.max < 1e-10
        ndof.append(level.record.ndof)
        eta.append(est.eta)
    x = res.space.node_points[res.contact.nodes[res.active]]
    a = np.abs(x[:, 0]).max()
    s = slope(ndof[-6:], eta[-6:])
    print(f"levels {len(ndof)}, Ndof {ndof[-6:]}, η {np.round(eta[-6:], 6)}")
    print(f"η_h slope over the last 6 levels {s:.3f}; contact half-width a = {a:.4f}")
    # where the last mesh is fine: at the contact ends and the clamped corners
    h = res.mesh.h
    mid = res.mesh.points[res.mesh.cells].mean(axis=1)
    near_end = np.abs(np.abs(mid[:, 0]) - a) + np.abs(mid[:, 1]) < 0.05
    near_corner = np.hypot(np.abs(mid[:, 0]) - 1.0, mid[:, 1] - 1.0) < 0.05
    print(
        f"smallest h near the contact ends {h[near_end].min():.2e} ({near_end.sum()} cells), "
        f"near the clamped corners {h[near_corner].min():.2e} ({near_corner.sum()} cells), "
        f"largest {h.max():.2e}"
    )
    assert 0.05 < a < 0.1
    assert s <= -0.9, s
    assert h[near_end].min() < 0.1 * h.max()
    # η4 splits the traction along the obstacle's direction n_z (the discrete contact force
    # acts along it), not along the body's normal, which is a/R off at the contact ends
    stresses = CellStress.of(res.space, res.u, res.problem.material, est.unit)
    cs, mesh = res.contact, res.mesh
    edges = FacetSet(
        cs.facets, cs.facet_nodes, mesh.facet2cell[cs.facets], mesh.facet_measure[cs.facets]
    )
    t, w = line_rule(7)
    body = res.space.node_points[cs.facet_nodes] - [0.0, 1.0]
    eta4 = {
        name: np.sqrt(contact_stress(stresses, mesh, edges, cs.facet_normal, d, t, w)[0].sum())
        for name, d in (("n_z", cs.facet_direction), ("body normal", body))
    }
    print(f"‖σ_t(u_h)‖ on Γ_C at Ndof {ndof[-1]}: {eta4}")
    assert eta4["n_z"] < 0.5 * eta4["body normal"], eta4


@pytest.mark.slow
def test_straight_contact_part_against_a_disc_splits_along_the_obstacle_direction():
    """A block [−1, 1] × [0, 1] pushed 0.01 down onto the cylinder of radius 1 below it: the
    contact part is straight but n_z is radial (the obstacle's). η4 splits the traction along
    the direction field of n_z; the edge normal would leave a tangential stress of order
    p a/R that no refinement removes."""
    pb = ContactProblem(
        rectangle(-1.0, 1.0, 0.0, 1.0, nx=4, ny=2),
        Material.from_young(1.0, 0.3),
        {
            "top": Dirichlet((0.0, -0.01)),
            "left": Neumann(),
            "right": Neumann(),
            "bottom": Contact(obstacle=Disc((0.0, -1.0), 1.0)),
        },
    )
    ndof, eta = [], []
    for level in adaptive(pb, theta=0.4, max_ndof=16_000):
        est, res = level.estimate, level.result
        assert abs(est.eta2.sum() - est.eta**2) <= 1e-13 * est.eta**2
        ndof.append(level.record.ndof)
        eta.append(est.eta)
    s = slope(ndof[-6:], eta[-6:])
    mesh, cs = res.mesh, res.contact
    t, w = line_rule(7)
    sigma = stress(
        res.problem.material,
        p2.field_gradients(
            res.space.vertices, res.space.cell_values(res.u), p2.REFERENCE_NODES[:3]
        ),
    )
    sn = facet_traction(
        sigma,
        mesh.points,
        mesh.cells,
        mesh.facet2cell[cs.facets, 0],
        mesh.facet_local[cs.facets, 0],
        t,
    )
    length = mesh.edge_length[cs.facets]
    eta4 = {
        "n_z": np.sqrt(
            tangential_stress(sn, direction_field(cs.facet_direction, t), w, length).sum()
        ),
        "edge normal": np.sqrt(tangential_stress(sn, cs.facet_normal, w, length).sum()),
    }
    print(f"η_h slope over the last 6 levels {s:.3f} (Ndof {ndof[-6:]})")
    print(f"‖σ_t(u_h)‖ on Γ_C at Ndof {ndof[-1]}: {eta4}")
    assert s <= -0.9, s
    assert eta4["n_z"] < 0.5 * eta4["edge normal"], eta4


def _r(x):
    return np.hypot(x[:, 0], x[:, 1])[:, None]


def test_a_gap_along_the_curve_normal_splits_along_the_body_normal():
    """A gap function on a curved part: n_z is the curve's normal at the nodes, and the
    direction field is the quadratic edges' normal n(t) up to O(h²), so η4 and η5 are the
    paper's (split along the body's normal) up to that. The quarter annulus pushed outwards
    from its inner arc onto an obstacle at a gap along the outer arc."""
    diffs = []
    for n in (2, 4, 8):
        mesh = lame_mesh(n)
        pb = ContactProblem(
            mesh,
            Material.from_young(10.0, 0.3),
            {
                # radial, 0.02 on the inner arc and 0 where the sides meet the outer arc (a
                # uniform 0.02 would push those two nodes into the obstacle: no solution)
                "rest": Dirichlet(lambda x: 0.02 * (2.0 - _r(x)) * x / _r(x)),
                "outer": Contact(gap=lambda x: 0.002 + 0.01 * x[:, 0]),
            },
        )
        res = solve(pb)
        est = estimate(res)
        assert abs(est.eta2.sum() - est.eta**2) <= 1e-13 * est.eta**2
        assert 0 < res.active.sum() < res.contact.size
        cs = res.contact
        edges = FacetSet(
            cs.facets, cs.facet_nodes, mesh.facet2cell[cs.facets], mesh.facet_measure[cs.facets]
        )
        t, w = line_rule(7)
        stresses = CellStress.of(res.space, res.u, res.problem.material, est.unit)
        J4, _ = contact_stress(stresses, mesh, edges, cs.facet_normal, cs.facet_direction, t, w)
        # the paper's split: along the normal n(t) of the quadratic edges at each point
        e = cs.facets
        ((_, sn, arc),) = stresses.on_facets(mesh.facet2cell[e, 0], mesh.facet_local[e, 0], t)
        speed, normal = arc.speeds(t), arc.normals(t)
        J4n = tangential_stress(sn, normal, w, speed)
        diffs.append(abs(np.sqrt(J4.sum()) - np.sqrt(J4n.sum())) / np.sqrt(J4n.sum()))
        print(f"n = {n}: η4 along d {np.sqrt(J4.sum()):.4e}, along n(t) {np.sqrt(J4n.sum()):.4e}")
    print(f"relative differences {np.round(diffs, 6)}")
    assert diffs[-1] < 1e-4 and diffs[-1] < 0.1 * diffs[0], diffs


# ---------------------------------------------------------------------------- exact contact
LAME_B = 0.01  # u = LAME_B x / |x|²: the Lamé field (LAME_B / r) e_r, div σ(u) = 0


def lame_u(x):
    return LAME_B * x / (x**2).sum(axis=1, keepdims=True)


def lame_grad(x):
    r2 = (x**2).sum(axis=1)[:, None, None]
    return LAME_B * (np.eye(2) / r2 - 2 * np.einsum("ni,nj->nij", x, x) / r2**2)


def lame_traction(x, normal):
    g = lame_grad(x.reshape(-1, 2))
    eps = 0.5 * (g + np.swapaxes(g, -1, -2))
    tr = eps[:, 0, 0] + eps[:, 1, 1]
    sig = MATERIAL.lam * tr[:, None, None] * np.eye(2) + 2 * MATERIAL.mu * eps
    n = np.broadcast_to(normal, x.shape).reshape(-1, 2)
    return np.einsum("nij,nj->ni", sig, n).reshape(x.shape)


def press_fit_levels(levels: int = 5):
    """A press fit with an exact solution: the annulus sector around a rigid shaft whose
    surface lies at ψ = u·n = −LAME_B along the inner arc's normal (a gap function on a
    curved contact part). u = (LAME_B / r) e_r has σ_rθ = 0 and σ_rr = −2μ LAME_B / r² < 0:
    full contact, no tangential stress, so it solves the Signorini problem with u on the
    outer arc and its tractions on the straight sides."""
    mesh = (
        annulus_sector()
        .with_curve("inner", Circle((0, 0), 1))
        .with_curve("outer", Circle((0, 0), 2))
    )
    out = []
    for level in range(levels):
        if level:
            mesh = refine_uniform(mesh).mesh
        conditions = {
            "outer": Dirichlet(lame_u),
            "inner": Contact(gap=lambda x: -np.einsum("nc,nc->n", lame_u(x), x) / np.hypot(*x.T)),
            "bottom": Neumann(lame_traction),
            "left": Neumann(lame_traction),
        }
        res = solve(ContactProblem(mesh, MATERIAL, conditions))
        assert res.active.all() and res.report.kkt.max < 1e-10
        out.append(level_row(res, lame_grad))
    return out


def test_estimator_is_efficient_on_an_exact_contact_solution_on_a_curved_part(monkeypatch):
    levels = press_fit_levels()
    ndof = [lv[0] for lv in levels]
    eta, err = np.array([lv[1] for lv in levels]), np.array([lv[2] for lv in levels])
    eff = eta / err
    for n, e, r, est in levels:
        terms = " ".join(f"{v:.2e}" for v in est.eta_terms)
        print(f"Ndof {n:6d}  η {e:.4e}  error {r:.4e}  η/error {e / r:.2f}  η1…η7 {terms}")
        assert abs(est.eta2.sum() - e**2) <= 1e-13 * e**2
    s_eta, s_err = slope(ndof[1:], eta[1:]), slope(ndof[1:], err[1:])
    print(f"slopes in Ndof: η {s_eta:.3f}, error {s_err:.3f}; efficiency {eff.round(2)}")
    assert -1.1 <= s_eta <= -0.9, s_eta
    assert -1.1 <= s_err <= -0.9, s_err
    assert eff[1:].max() / eff[1:].min() < 1.05, eff

    straight_estimator(monkeypatch)
    eta_old = np.array([lv[1] for lv in press_fit_levels()])
    eff_old = eta_old / err
    s_old = slope(ndof[1:], eta_old[1:])
    print(f"straight cells: slope {s_old:.3f}; efficiency {eff_old.round(2)}")
    assert s_old > -0.85, s_old
    assert eff_old[-1] > 2 * eff_old[1], eff_old


def test_direction_field_interpolates_unit_directions():
    t = np.array([0.0, 0.3, 0.5, 1.0, (1 + np.sqrt(5)) / 4])
    a, b = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    m = (a + b) / np.sqrt(2)
    d = direction_field(np.array([[a, b, m], [a, -a, b]]), t)
    assert np.allclose(np.hypot(d[..., 0], d[..., 1]), 1.0, rtol=0, atol=1e-15)
    assert np.allclose(d[0, [0, 2, 3]], [a, m, b], rtol=0, atol=1e-15)
    # nodal directions [a, −a, a]: the interpolant (1 + 2t − 4t²) a vanishes at the last t,
    # where the midpoint's direction is used
    d = direction_field(np.array([[a, -a, a]]), t)
    assert np.allclose(d[0], [a, a, a, -a, a], rtol=0, atol=1e-12), d
