"""Contact between two elastic bodies (docs/method.md, *Two bodies*): the contact patch test,
an independent dual solve of the mortar-constrained QP, the symmetric pair against the
one-body Hertz problem, equal and opposite resultants, rotation invariance, the estimator,
and bad input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.optimize import nnls
from scipy.spatial import cKDTree

from signorini.contact import solve
from signorini.contact.mortar import mortar_coupling
from signorini.estimator import estimate
from signorini.examples.hertz import hertz
from signorini.examples.two_bodies import hertz_pair, stacked_blocks, two_cylinders
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.bodies import body_of_cells, union
from signorini.mesh.builders import rectangle
from signorini.mesh.refine import refine_nvb, refine_uniform
from signorini.mesh.validation import MeshError
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError


def exact_pressure(problem: ContactProblem, depth: float = 0.01) -> float:
    """σ_yy = −p in both blocks of :func:`stacked_blocks`: δ = p Σ (1 − ν²) / E (height 1
    each, plane strain, free lateral expansion)."""
    m = problem.material
    return depth / sum((1 - m[b].poisson ** 2) / m[b].young for b in ("upper", "lower"))


@pytest.mark.parametrize("edges", [(5, 7), (7, 5), (4, 4), (3, 8)])
def test_contact_patch_test(edges):
    """Uniform compression through a non-matching interface is reproduced: uniform pressure
    on both sides equal to the exact p, the affine displacement at every node, η at
    round-off."""
    problem = stacked_blocks(edges)
    r = solve(problem)
    p = exact_pressure(problem)
    nodes, traction, master_pressure = r.master_side
    print(f"{edges}: slave p in [{r.pressure.min():.15g}, {r.pressure.max():.15g}], exact {p:.15g}")
    assert np.abs(r.pressure / p - 1).max() < 1e-11
    assert np.abs(master_pressure / p - 1).max() < 1e-11
    assert np.abs(traction - [0.0, -p]).max() < 1e-11 * p
    assert r.active.all()
    # the exact displacement, block by block: u_y = −ε (y-top) and u_x = ν' ε x style
    body = np.zeros(r.space.n_nodes, dtype=np.int64)
    body[r.space.cell_nodes.ravel()] = np.repeat(body_of_cells(r.mesh), 6)
    m = problem.material
    x = r.space.node_points
    for b, name in enumerate(("upper", "lower")):
        E, nu = m[name].young, m[name].poisson
        eyy = -p * (1 - nu**2) / E
        exx = p * nu * (1 + nu) / E
        on = body == b
        uy_exact = np.where(b == 0, eyy * (x[on, 1] - 2.0) - 0.01, eyy * x[on, 1])
        assert np.abs(r.u[on, 1] - uy_exact).max() < 1e-12
        assert np.abs(r.u[on, 0] - exx * x[on, 0]).max() < 1e-12
    assert estimate(r).eta < 1e-11 * p


def test_resultants_equal_and_opposite():
    """The forces the slave receives and the master receives sum to zero, component by
    component, and the slave's resultant is the load the Dirichlet parts carry."""
    r = solve(two_cylinders(rings=4))
    cs = r.contact
    slave = -(r.contact_force[:, None] * cs.normal).sum(axis=0)
    nodes, traction, _ = r.master_side
    from signorini.contact.two_body import master_forces

    master = master_forces(cs.transfer.dofs, cs.nodes, -r.contact_force[:, None] * cs.normal,
                           r.space.n_nodes).sum(axis=0)  # fmt: skip
    print(f"slave {slave}, master {master}")
    assert slave[1] > 0
    assert np.abs(slave + master).max() < 1e-13 * np.abs(slave).max()


def _cartesian_qp(problem: ContactProblem, tangential: bool = False):
    """The two-body QP assembled here from the fem layer and the mortar coupling alone:
    ``min ½ uᵀ K u`` with the held DOFs, subject to ``n_j·(D_jj u_j − Σ_k M_jk u_k) ≤ g̃_j``."""
    mesh = problem.mesh
    space = P2Space(mesh)
    K = assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, problem.material_on(mesh))
    held = problem.held_components(space).ravel()
    values = np.zeros(space.n_dofs)
    for name, cond in problem.held.items():
        nodes = space.part_nodes([name])
        for c in range(2):
            if cond.components[c]:
                values[2 * nodes + c] = cond.field()(space.node_points[nodes])[:, c]
    rows, gaps = [], []
    dirichlet_nodes = problem.dirichlet_nodes(space)
    for slave, master in problem.pairs.items():
        c = mortar_coupling(space, slave, master)
        keep = ~np.isin(c.slave_nodes, dirichlet_nodes)
        M = sp.lil_matrix((keep.sum(), space.n_nodes))
        M[:, :] = c.M[keep]
        j = c.slave_nodes[keep]
        n = c.normal[keep]
        B = sp.lil_matrix((j.size, space.n_dofs))
        for comp in range(2):  # B_j = n_j ⊗ (D_jj e_j − M_j)
            block = -sp.csr_matrix(M).multiply(n[:, [comp]])
            B[:, comp::2] = block
        B = sp.csr_matrix(B)
        B = B + sp.csr_matrix(
            (np.concatenate([c.D[keep] * n[:, 0], c.D[keep] * n[:, 1]]),
             (np.tile(np.arange(j.size), 2), np.concatenate([2 * j, 2 * j + 1]))),
            shape=B.shape,
        )  # fmt: skip
        rows.append(B)
        gaps.append(c.weighted_gap[keep])
        if tangential:  # t_j ⊗ (D_jj e_j − M_j), t = (−n_y, n_x)
            t = np.column_stack([-n[:, 1], n[:, 0]])
            Bt = sp.lil_matrix((j.size, space.n_dofs))
            for comp in range(2):
                Bt[:, comp::2] = -sp.csr_matrix(M).multiply(t[:, [comp]])
            Bt = sp.csr_matrix(Bt) + sp.csr_matrix(
                (np.concatenate([c.D[keep] * t[:, 0], c.D[keep] * t[:, 1]]),
                 (np.tile(np.arange(j.size), 2), np.concatenate([2 * j, 2 * j + 1]))),
                shape=(j.size, space.n_dofs),
            )  # fmt: skip
            rows.append(Bt)
            gaps.append(np.zeros(j.size))
    return space, K.tocsc(), held, values, sp.vstack(rows).tocsr(), np.concatenate(gaps)


@pytest.mark.parametrize("make", [lambda: stacked_blocks((3, 4)), lambda: two_cylinders(rings=4)])
def test_agrees_with_dual_nnls(make):
    """The mortar-constrained QP solved independently (Cartesian, no change of basis, dual
    NNLS) gives the same displacement, the same contact forces and active set."""
    problem = make()
    r = solve(problem)
    space, K, held, values, B, g = _cartesian_qp(problem)
    free = np.flatnonzero(~held)
    Kff = K[free][:, free].tocsc()
    b = -(K[free][:, np.flatnonzero(held)] @ values[held])
    Bf = B[:, free]
    g = g - B[:, np.flatnonzero(held)] @ values[held]
    lu = spla.splu(Kff)
    KiBt = lu.solve(Bf.T.toarray())
    Kib = lu.solve(b)
    L = np.linalg.cholesky(Bf @ KiBt)
    lam, _ = nnls(L.T, sl.solve_triangular(L, Bf @ Kib - g, lower=True), maxiter=50 * g.size)
    u = values.copy()
    u[free] = Kib - KiBt @ lam
    du = np.abs(u - r.u.ravel()).max() / np.abs(r.u).max()
    # the multiplier λ_j of the weighted constraint is the pressure: Λ_j = D_jj λ_j = w_j p_j
    dl = np.abs(lam - r.pressure).max() / np.abs(lam).max()
    print(f"{problem.name}: {free.size} unknowns, {g.size} constraints: du {du:.1e}, dΛ {dl:.1e}")
    assert du < 1e-10 and dl < 1e-9
    assert np.array_equal(lam > 1e-12 * lam.max(), r.active)


def _upper_nodes(result) -> np.ndarray:
    body = np.zeros(result.space.n_nodes, dtype=bool)
    cells = body_of_cells(result.mesh) == 0
    body[result.space.cell_nodes[cells].ravel()] = True
    return np.flatnonzero(body)


@pytest.mark.parametrize("h_bottom", [None, 0.05])
def test_symmetric_pair_equals_one_body_hertz(h_bottom):
    """Two mirror-image half-discs pressed together by δ equal, node by node, the one-body
    Hertz problem pressed by δ/2 against the plane: displacements, contact forces and active
    sets to round-off (the averaged normal is the symmetry plane's)."""
    pair = solve(hertz_pair(depth=0.015, h_bottom=h_bottom))
    one = solve(hertz(depth=0.0075, h_bottom=h_bottom))
    upper = _upper_nodes(pair)
    dist, idx = cKDTree(pair.space.node_points[upper]).query(one.space.node_points)
    assert dist.max() < 1e-14
    du = np.abs(pair.u[upper][idx] - one.u).max() / np.abs(one.u).max()
    # constraints: the one-body problem constrains the whole arc, the pair |x| < R/2
    z1 = one.space.node_points[one.contact.nodes]
    z2 = pair.space.node_points[pair.contact.nodes]
    d, j = cKDTree(z1).query(z2)
    assert d.max() < 1e-14
    dl = np.abs(pair.contact_force - one.contact_force[j]).max() / one.contact_force.max()
    print(f"h_bottom {h_bottom}: max |Δu|/max|u| = {du:.1e}, max |ΔΛ|/max Λ = {dl:.1e}")
    assert du < 1e-12 and dl < 1e-11
    assert np.array_equal(pair.active, one.active[j])
    assert one.active.sum() == pair.active.sum()


def test_rotation_invariance():
    """The two-cylinder problem rotated by 0.7 rad gives the rotated solution."""
    angle = 0.7
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    a = solve(two_cylinders(rings=4))
    b = solve(two_cylinders(rings=4, angle=angle))
    assert np.abs(b.space.node_points - a.space.node_points @ R.T).max() < 1e-13
    du = np.abs(b.u - a.u @ R.T).max() / np.abs(a.u).max()
    dl = np.abs(b.contact_force - a.contact_force).max() / a.contact_force.max()
    print(f"rotated by {angle} rad: |Δu| {du:.1e}, |ΔΛ| {dl:.1e}")
    assert du < 1e-11 and dl < 1e-10
    assert np.array_equal(a.active, b.active)


# ------------------------------------------------------------------------------- bad input
def two_blocks(conditions: dict) -> ContactProblem:
    mesh = union({"a": rectangle(0, 1, 1, 2, 2, 2), "b": rectangle(0, 1, 0, 1, 3, 3)})
    base = {p: Neumann() for p in mesh.part_names}
    base.update({"a.top": Dirichlet((0.0, -0.01)), "b.bottom": Dirichlet((0.0, 0.0))})
    base.update(conditions)
    base = {k: v for k, v in base.items() if v is not None}
    return ContactProblem(mesh=mesh, material=_material(), conditions=base)


def _material():
    from signorini.fem.material import Material

    return Material.from_young(1.0, 0.3)


def test_pair_refusals():
    with pytest.raises(ProblemError, match="'b.nowhere' is not a boundary part"):
        two_blocks({"a.bottom": Contact(master="b.nowhere")})
    with pytest.raises(ProblemError, match="names itself as its master"):
        two_blocks({"a.bottom": Contact(master="a.bottom")})
    with pytest.raises(ProblemError, match="takes no condition of its own"):
        two_blocks({"a.bottom": Contact(master="b.top")})  # b.top keeps its Neumann
    with pytest.raises(ProblemError, match="do not give gap"):
        Contact(master="b.top", gap=0.1)
    with pytest.raises(ProblemError, match="do not give obstacle"):
        from signorini.problem.obstacles import HalfPlane

        Contact(master="b.top", obstacle=HalfPlane((0, 0), (0, 1)))


def test_union_refusals():
    a = rectangle(0, 1, 0, 1, 2, 2)
    with pytest.raises(MeshError, match="overlaps body"):
        union({"a": a, "b": rectangle(0.5, 1.5, 0.5, 1.5, 2, 2)})
    with pytest.raises(MeshError, match="two or more"):
        union({"a": a})
    with pytest.raises(MeshError, match="without '.'"):
        union({"a.b": a, "c": rectangle(0, 1, 1, 2, 2, 2)})


def test_union_names_and_bodies():
    m = union({"upper": rectangle(0, 1, 1, 2, 2, 2), "lower": rectangle(0, 1, 0, 1, 3, 3)})
    assert m.part_names[:4] == ("upper.bottom", "upper.right", "upper.top", "upper.left")
    assert m.region_names == ("upper", "lower")
    body = body_of_cells(m)
    assert np.array_equal(np.bincount(body), [8, 18])
    assert np.array_equal(body, m.cell_region)


def union_body(mesh) -> np.ndarray:
    """The union's body of each cell, from its region ("body" or "body.region")."""
    names = [r.split(".")[0] for r in mesh.region_names]
    bodies = list(dict.fromkeys(names))
    return np.array([bodies.index(n) for n in names])[mesh.cell_region]


@pytest.mark.parametrize("example", [two_cylinders, hertz_pair])
def test_body_labels_are_the_unions_order_on_every_level(example):
    """Refining all of the upper body puts lower cells ahead of upper ones (refinement keeps
    the unrefined cells first), refining a few cells brings upper ones back to the front:
    the labels follow the union on every level, not the cells' order."""
    mesh = example().mesh
    swapped = 0
    for level in range(6):
        expected = union_body(mesh)
        swapped += int(expected[0] != 0)
        np.testing.assert_array_equal(body_of_cells(mesh), expected, err_msg=f"level {level}")
        marked = expected == 0 if level % 2 == 0 else np.flatnonzero(expected == 1)[:3]
        mesh = refine_nvb(mesh, marked).mesh if level < 4 else refine_uniform(mesh).mesh
    assert swapped >= 2  # the cells' order did change (a lower cell first)


def test_body_held_only_by_its_pair_is_under_force_control():
    """The upper block on a roller only (its vertical motion held by nothing but the pair)
    is under force control: the pair carries the load on its top
    (tests/two_bodies/test_force_control_pair.py checks it further)."""
    problem = two_blocks({"a.top": Neumann((0.0, -1.0)), "a.left": Dirichlet((0.0, None)),
                          "a.bottom": Contact(master="b.top"), "b.top": None})  # fmt: skip
    assert problem.rigid_motions.shape == (1, 3)
    result = solve(problem)
    assert result.total_contact_force == pytest.approx(1.0, rel=1e-12)
    assert result.report.kkt.max < 1e-10


def sheared_blocks(friction) -> ContactProblem:
    """Two blocks (3 and 4 edges along the interface), the upper top moved by (0.004, −0.01),
    the lower bottom held, the other sides free: pressed and sheared."""
    mesh = union({"a": rectangle(0, 1, 1, 2, 3, 3), "b": rectangle(0, 1, 0, 1, 4, 4)})
    conditions = {p: Neumann() for p in mesh.part_names}
    del conditions["b.top"]
    conditions.update({
        "a.top": Dirichlet((0.004, -0.01)),
        "b.bottom": Dirichlet((0.0, 0.0)),
        "a.bottom": Contact(master="b.top", friction=friction),
    })  # fmt: skip
    return ContactProblem(mesh=mesh, material=_material(), conditions=conditions)


def test_tresca_pair_equals_the_minimiser_of_its_convex_energy():
    """Tresca friction on a pair: the solution is the minimiser of the convex energy with
    the weighted relative slip, computed here by its dual over a box (BVLS), with stick and
    slip nodes both present."""
    from scipy.optimize import lsq_linear

    from signorini.contact.solution import SLIP, STICK
    from signorini.problem import Tresca

    bound = 0.07 * solve(sheared_blocks(None)).pressure.max()
    problem = sheared_blocks(Tresca(bound))
    r = solve(problem)
    assert (r.state == STICK).any() and (r.state == SLIP).any()
    space, K, held, values, B, g = _cartesian_qp(problem, tangential=True)
    k = r.contact.size
    free = np.flatnonzero(~held)
    Kff = K[free][:, free].toarray()
    rhs = -(K[free][:, np.flatnonzero(held)] @ values[held])
    Bf = B[:, free].toarray()
    chol = sl.cho_factor(Kff)
    H = Bf @ sl.cho_solve(chol, Bf.T)
    c = Bf @ sl.cho_solve(chol, rhs) - (g - B[:, np.flatnonzero(held)] @ values[held])
    L = np.linalg.cholesky(H)
    s_t = r.contact.friction.weight / r.contact.basis_integral  # |Λ_t| ≤ s_z, Λ = D λ
    lower = np.concatenate([np.zeros(k), -s_t])
    upper = np.concatenate([np.full(k, np.inf), s_t])
    lam = lsq_linear(L.T, sl.solve_triangular(L, c, lower=True), bounds=(lower, upper),
                     method="bvls", tol=1e-15).x  # fmt: skip
    u = values.copy()
    u[free] = sl.cho_solve(chol, rhs - Bf.T @ lam)
    du = np.abs(u - r.u.ravel()).max() / np.abs(r.u).max()
    dn = np.abs(lam[:k] - r.pressure).max() / r.pressure.max()
    dt = np.abs(lam[k:] - r.tangential_pressure).max() / r.pressure.max()
    print(f"Tresca pair: |Δu| {du:.1e}, Δp {dn:.1e}, Δp_t {dt:.1e}")
    assert du < 1e-8 and dn < 1e-8 and dt < 1e-8
    assert r.report.kkt.max < 1e-11


@pytest.mark.slow
def test_partial_slip_of_identical_cylinders_against_cattaneo_mindlin():
    """Two identical cylinders (elastically similar: the normal and tangential problems
    uncouple exactly) pressed, then sheared at constant press with Coulomb friction F = 0.5:
    the stick zone's half-width c against Cattaneo–Mindlin, c/a = √(1 − Q/(F P)), within
    0.005 on a mesh refined along the contact zone (h ≤ 0.004, a ≈ 0.078)."""
    from signorini.contact import solve_path
    from signorini.examples.partial_slip import partial_slip_metrics
    from signorini.mesh.refine import refine_nvb
    from signorini.problem import Coulomb

    path = [
        two_cylinders(
            (1.0, 1.0), (1.0, 1.0), depth=0.02, friction=Coulomb(0.5), shear=s, h_bottom=0.02
        )  # fmt: skip
        for s in (0.0, 0.012)
    ]
    mesh = path[0].mesh
    for _ in range(12):  # a loop over refinement rounds
        x = mesh.points[mesh.cells].mean(axis=1)
        near = (np.abs(x[:, 0]) < 0.085) & (np.abs(x[:, 1]) < 0.01) & (mesh.h > 0.004)
        if not near.any():
            break
        mesh = refine_nvb(mesh, np.flatnonzero(near)).mesh
    r = solve_path(path, mesh=mesh)[-1]
    m = partial_slip_metrics(r)
    print(
        f"{r.ndof} unknowns: c/a = {m['c_over_a']:.4f}, Cattaneo–Mindlin "
        f"{m['c_over_a_theory']:.4f} (Q/(F P) = {m['q_over_fp']:.4f}), a = {m['a']:.5f}"
    )
    assert 0.6 < m["q_over_fp"] < 0.8
    assert abs(m["c_over_a"] - m["c_over_a_theory"]) < 0.005
    assert r.report.kkt.max < 1e-10


@pytest.mark.slow
def test_two_cylinders_adaptive_against_hertz():
    """Dissimilar cylinders (R1 = 1, R2 = 2, E1 = 1, E2 = 3): adaptively to 20 000 unknowns
    a and p0 are within 1 % of Hertz at the computed load (a/R ≈ 0.1), η decreases at a
    slope ≤ −0.9 in Ndof, the KKT residuals stay at round-off, the warm starts need one
    factorization per level and give a cold solve's solution, and each body's finest cells
    sit at the ends of the contact zone."""
    from signorini.examples.two_bodies import cylinders_metrics
    from signorini.loop import adaptive

    levels = list(adaptive(two_cylinders(), max_ndof=20_000))
    ndof = np.array([level.result.ndof for level in levels])
    eta = np.array([level.estimate.eta for level in levels])
    last = levels[-1].result
    m = cylinders_metrics(last)
    late = ndof >= 1000
    slope = np.polyfit(np.log(ndof[late]), np.log(eta[late]), 1)[0]
    print(f"{ndof[-1]} unknowns: a = {m['a']:.5f} ({m['a_rel_error']:+.2e}), "
          f"p0 {m['p0_rel_error']:+.2e}, η slope {slope:.3f}")  # fmt: skip
    assert abs(m["a_rel_error"]) < 0.01 and abs(m["p0_rel_error"]) < 0.01
    assert 0.09 < m["a"] / (2 / 3) < 0.11
    assert slope <= -0.9
    assert max(level.result.report.kkt.max for level in levels) < 1e-10
    # the warm start takes the new slave nodes in contact (nested.PAIR_WARM_START_RTOL): one
    # factorization per level after the first five, 1.24 solves per level (with the
    # frictionless rule's 1e-10: 1.65 solves and up to two factorizations)
    warm = [level.result.report for level in levels[5:]]
    assert max(r.n_factorizations for r in warm) == 1
    assert np.mean([r.n_solves for r in warm]) <= 1.3
    cold = solve(two_cylinders(), last.mesh)
    assert np.abs(cold.u - last.u).max() <= 1e-10 * np.abs(cold.u).max()
    mesh = last.mesh
    body = body_of_cells(mesh)
    x = mesh.points[mesh.cells].mean(axis=1)
    for b in (0, 1):
        cells = np.flatnonzero(body == b)
        finest = cells[np.argsort(mesh.h[cells])[:10]]
        ends = np.abs(np.abs(x[finest, 0]) - m["a"])
        print(f"body {b}: the 10 finest cells (h ≤ {mesh.h[finest].max():.2e}) at |x| − a "
              f"within {ends.max():.2e}")  # fmt: skip
        assert ends.max() < 0.25 * m["a"]


def manufactured_blocks(edges: tuple[int, int]) -> ContactProblem:
    """Two blocks of one material in contact all along y = 1 with the smooth solution
    ``u = (A sin(πx) (y − 1)², −B y + C cos(πx) (y − 1)²)``: its shear stress vanishes on
    y = 1 (frictionless), its normal displacement and σ_yy = −(λ + 2μ) B are continuous
    there (contact everywhere, pressure (λ + 2μ) B > 0); body force −div σ(u), the exact
    displacement on the top and bottom, the exact traction on the sides (so that the contact
    zone's ends are constrained nodes, not Dirichlet ones)."""
    from signorini.fem.material import Material
    from signorini.problem import ExactSolution

    A, B, C = 0.02, 0.01, 0.015
    material = Material.from_young(1.0, 0.3)
    lam, mu = material.lam, material.mu

    def u(x):
        s, c, d = np.sin(np.pi * x[:, 0]), np.cos(np.pi * x[:, 0]), x[:, 1] - 1.0
        return np.column_stack([A * s * d**2, -B * x[:, 1] + C * c * d**2])

    def grad(x):
        s, c, d = np.sin(np.pi * x[:, 0]), np.cos(np.pi * x[:, 0]), x[:, 1] - 1.0
        g = np.empty((len(x), 2, 2))
        g[:, 0, 0], g[:, 0, 1] = A * np.pi * c * d**2, 2 * A * s * d
        g[:, 1, 0], g[:, 1, 1] = -C * np.pi * s * d**2, -B + 2 * C * c * d
        return g

    def force(x):
        s, c, d = np.sin(np.pi * x[:, 0]), np.cos(np.pi * x[:, 0]), x[:, 1] - 1.0
        pi2 = np.pi**2
        # second derivatives of u
        uxx, uxy, uyy = -A * pi2 * s * d**2, 2 * A * np.pi * c * d, 2 * A * s
        vxx, vxy, vyy = -C * pi2 * c * d**2, -2 * C * np.pi * s * d, 2 * C * c
        div_x = (lam + 2 * mu) * uxx + mu * uyy + (lam + mu) * vxy
        div_y = (lam + 2 * mu) * vyy + mu * vxx + (lam + mu) * uxy
        return -np.column_stack([div_x, div_y])

    mesh = union({"a": rectangle(0, 1, 1, 2, edges[0], edges[0]),
                  "b": rectangle(0, 1, 0, 1, edges[1], edges[1])})  # fmt: skip

    def traction(x, normal):
        g = grad(x)
        eps = 0.5 * (g + g.transpose(0, 2, 1))
        sigma = lam * np.trace(eps, axis1=1, axis2=2)[:, None, None] * np.eye(2) + 2 * mu * eps
        return np.einsum("nij,nj->ni", sigma, normal)

    conditions = {p: Neumann(traction) for p in mesh.part_names}
    conditions.update({"a.top": Dirichlet(u), "b.bottom": Dirichlet(u)})
    conditions["a.bottom"] = Contact(master="b.top")
    del conditions["b.top"]
    return ContactProblem(mesh=mesh, material=material, conditions=conditions,
                          body_force=force, exact=ExactSolution(u, grad))  # fmt: skip


@pytest.mark.parametrize("edges", [(4, 3), (3, 4)])
def test_efficiency_on_a_manufactured_two_body_solution(edges):
    """Uniform refinement of the manufactured two-block problem (the slave finer, then
    coarser): the energy error decreases at the P2 rate (slope −1 in Ndof), every interface
    node is in contact, and the efficiency index η / ‖e‖ stays bounded (printed: 21 to 27)."""
    from signorini.mesh.refine import refine_uniform

    problem = manufactured_blocks(edges)
    mesh, rows = problem.mesh, []
    for _ in range(4):  # a loop over uniform refinements
        r = solve(problem, mesh)
        error = r.errors()["error_energy"]
        rows.append((r.ndof, error, estimate(r).eta))
        assert r.active.all()
        mesh = refine_uniform(mesh).mesh
    ndof, error, eta = (np.array(c) for c in zip(*rows, strict=True))
    slope = np.polyfit(np.log(ndof[1:]), np.log(error[1:]), 1)[0]
    efficiency = eta / error
    print(f"{edges}: energy error slope {slope:.3f}; efficiency η/‖e‖ {np.round(efficiency, 2)}")
    assert -1.05 < slope < -0.95
    assert 10.0 < efficiency.min() and efficiency.max() < 40.0
    assert efficiency.max() / efficiency.min() < 1.3


def test_stacked_blocks_print_the_patch_tests_deviation(tmp_path):
    """``signorini run stacked-blocks`` writes the slave's and the master's pressure
    deviations per level: round-off."""
    import csv

    from signorini.cli import main

    assert main(["run", "stacked-blocks", "--tol", "1e-10", "--out", str(tmp_path),
                 "--quiet", "--no-figures"]) == 0  # fmt: skip
    rows = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert len(rows) == 1  # η at round-off on the initial mesh
    for column in ("slave_pressure_deviation", "master_pressure_deviation"):
        assert float(rows[0][column]) < 1e-10
