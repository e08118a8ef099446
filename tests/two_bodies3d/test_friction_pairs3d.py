"""Friction between two bodies in 3D (docs/method.md, *Two bodies in three dimensions:
friction*): the disc law on the dual mortar rows' relative slip. The sheared stacked cubes
(non-matching meshes, both stick and slip) against an independent dual solve of the Tresca
problem, both laws' KKT conditions, Coulomb with F = 0 as the frictionless pair, the
interface force against the supports' reactions, a turn about the normal, a load path."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
from contact3d.independent_tresca import solve_tresca_rows, tangent_basis
from contact3d_problems import without_contact

from signorini.algebra.friction.newton import SLIP, STICK
from signorini.contact import solve
from signorini.contact.mortar3d import mortar_coupling_3d
from signorini.fem.material import Material
from signorini.mesh.bodies import union
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann, Tresca

COUNTS = ((3, 3, 1), (4, 4, 1))


def turn(angle: float) -> np.ndarray:
    """The rotation by ``angle`` about z (the interface's normal)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def sheared_cubes(law, angle: float = 0.0, shift: float = 0.004) -> ContactProblem:
    """The upper box ``[0, 1]² × [1, 2]`` on the lower ``[0, 1]³`` (non-matching meshes),
    its top moved by ``(shift, 0, −0.01)``, the lower bottom clamped, the sides free, the
    upper bottom the slave with ``law``; all turned by ``angle`` about z."""
    R = turn(angle)

    def turned(mesh: Mesh) -> Mesh:
        parts = {p: mesh.facets[mesh.part_facets(p)] for p in mesh.part_names}
        return Mesh.from_arrays(mesh.points @ R.T, mesh.cells, parts)

    upper = turned(box(*COUNTS[0], lower=(0.0, 0.0, 1.0), upper=(1.0, 1.0, 2.0)))
    free = Neumann((0.0, 0.0, 0.0))
    conditions = {f"{b}.{p}": free for b in ("upper", "lower") for p in ("x0", "x1", "y0", "y1")}
    conditions.update({
        "upper.z1": Dirichlet(tuple((R @ [shift, 0.0, -0.01]).tolist())),
        "lower.z0": Dirichlet((0.0, 0.0, 0.0)),
        "upper.z0": Contact(master="lower.z1", friction=law),
    })  # fmt: skip
    return ContactProblem(
        mesh=union({"upper": upper, "lower": turned(box(*COUNTS[1]))}),
        material={"upper": Material.from_young(1.0, 0.3), "lower": Material.from_young(3.0, 0.2)},
        conditions=conditions,
    )


def independent_tresca(problem: ContactProblem, s: float):
    """The Tresca problem of the pair with the bound ``s`` per unit area, without the
    package's change of basis or solver: the rows ``[n; t_1; t_2] · (ũ_j − Σ_k T_jk u_k)``
    of every slave node (``ũ`` the slave's transformed coefficients written from its faces,
    ``T = D⁻¹ M``, tangents of its own), ``n · (…) ≤ g̃_j / D_jj`` and the nodal bound
    ``s D_jj``, solved by :func:`~contact3d.independent_tresca.solve_tresca_rows`."""
    plain = without_contact(problem)
    space = plain.space
    c = mortar_coupling_3d(space, "upper.z0", "lower.z1")
    rows = c.slave_nodes
    m, a = rows.size, c.alpha
    # ũ_j: u_j at a vertex, (u_e − α (u_a + u_b)) / (1 − 2α) at a side's midpoint e
    ends = np.full((space.n_nodes, 2), -1)
    for e, s0, s1 in ((3, 0, 1), (4, 1, 2), (5, 2, 0)):  # the three sides of a face
        ends[c.slave_faces[:, e]] = c.slave_faces[:, [s0, s1]]
    mid = ends[rows, 0] >= 0
    r = np.arange(m)
    node_rows = [r, r[mid], r[mid]]
    node_cols = [rows, ends[rows[mid], 0], ends[rows[mid], 1]]
    values = [np.where(mid, 1 / (1 - 2 * a), 1.0), np.full(mid.sum(), -a / (1 - 2 * a))]
    values.append(values[1])
    T = sp.coo_matrix(sp.diags(1.0 / c.D) @ c.M)
    node_rows.append(T.row)
    node_cols.append(T.col)
    values.append(-T.data)
    relative = sp.csr_matrix(
        (np.concatenate(values), (np.concatenate(node_rows), np.concatenate(node_cols))),
        shape=(m, space.n_nodes),
    ).toarray()  # (m, n_nodes): ũ_j − Σ_k T_jk u_k, per component
    t1, t2 = tangent_basis(c.normal)
    basis = np.stack([c.normal, t1, t2], axis=1)  # (m, 3, 3)
    B = np.einsum("mn,mkc->mknc", relative, basis).reshape(3 * m, 3 * space.n_nodes)
    offset = np.zeros((m, 3))
    offset[:, 0] = c.weighted_gap / c.D
    solution = solve_tresca_rows(
        plain.K, plain.F, plain.dirichlet, plain.dirichlet_values, B, offset.ravel(),
        s * c.D, basis,
    )  # fmt: skip
    return solution, rows, c.D


def interface_forces(result) -> np.ndarray:
    """``(k, 3)`` the Cartesian force of each row on the slave's ``φ̃_j``."""
    return result.contact.row_forces(result.contact_force, result.tangential_force)


def test_tresca_pair_equals_an_independent_dual_solve():
    """Stick and slip on the interface; u, the Cartesian row forces and the bounds s D_jj
    equal the independent solve's; KKT ≤ 1e-12."""
    s = 2e-3
    result = solve(sheared_cubes(Tresca(s)))
    assert result.report.kkt.max <= 1e-12
    assert {STICK, SLIP} <= set(result.state.tolist())
    other, rows, D = independent_tresca(result.problem, s)
    cs = result.contact
    np.testing.assert_array_equal(cs.node, rows)
    np.testing.assert_allclose(cs.friction.laws.weight, s * D, rtol=1e-12)
    u = result.u.ravel()
    assert np.abs(u - other.u).max() <= 1e-8 * np.abs(other.u).max()
    force = interface_forces(result)
    assert np.abs(force - other.force).max() <= 1e-8 * np.abs(other.force).max()


def test_coulomb_pair_meets_both_laws():
    """Coulomb F = 0.3: stick and slip; at slipping rows ‖Λ_t‖ = F Λ_n and the relative
    slip points along Λ_t; at sticking rows ‖Λ_t‖ < F Λ_n and no slip. The Newton steps'
    matrices share one pattern: one symbolic analysis for all their factorizations."""
    result = solve(sheared_cubes(Coulomb(0.3), shift=0.003))
    assert result.report.kkt.max <= 1e-12
    assert result.report.n_factorizations > 2 and result.report.n_analyses == 1
    slip, stick = result.state == SLIP, result.state == STICK
    assert slip.any() and stick.any()
    lam_n, lam_t = result.contact_force, result.tangential_force
    norm = np.linalg.norm(lam_t, axis=1)
    np.testing.assert_allclose(norm[slip], 0.3 * lam_n[slip], rtol=1e-10)
    assert np.all(norm[stick] < 0.3 * lam_n[stick])
    cs = result.contact
    y = cs.unknowns(result.u.ravel())[cs.friction.tangent]  # the relative slip, (k, 2)
    cosine = np.sum(y[slip] * lam_t[slip], 1) / (np.linalg.norm(y[slip], axis=1) * norm[slip])
    assert cosine.min() >= 1 - 1e-10
    assert np.abs(y[stick]).max() <= 1e-12 * np.abs(y).max()


def test_coulomb_zero_is_the_frictionless_pair():
    """F = 0: the same displacement and normal forces as the pair without friction, no
    tangential force."""
    plain = solve(sheared_cubes(None))
    zero = solve(sheared_cubes(Coulomb(0.0)))
    assert np.abs(zero.u - plain.u).max() <= 1e-12 * np.abs(plain.u).max()
    np.testing.assert_allclose(zero.contact_force, plain.contact_force, rtol=1e-10)
    assert np.abs(zero.tangential_force).max() == 0.0


@pytest.mark.parametrize("law", [Tresca(2e-3), Coulomb(0.3)])
def test_the_interface_force_is_what_the_supports_hold(law):
    """Newton's third law across the interface: the upper top's reaction is minus the
    slave's received force ``−Σ_j f_j``, the lower bottom's that of the master's ``Σ_k
    T_jk f_j``, both in all three components to 1e-10 (the tangential ones not small)."""
    result = solve(sheared_cubes(law))
    problem = result.problem
    plain = without_contact(problem)
    residual = (plain.K @ result.u.ravel() - plain.F).reshape(-1, 3)
    space = result.space
    top = np.unique(space.facet_nodes(result.mesh.part_facets("upper.z1")))
    bottom = np.unique(space.facet_nodes(result.mesh.part_facets("lower.z0")))
    f = interface_forces(result)
    master = result.contact.master_forces(result.contact_force, space.n_nodes,
                                          result.tangential_force)  # fmt: skip
    scale = np.abs(f.sum(axis=0)).max()
    assert abs(f.sum(axis=0)[0]) > 0.05 * scale  # a real shear along the shift
    assert np.abs(residual[top].sum(axis=0) - f.sum(axis=0)).max() <= 1e-10 * scale
    assert np.abs(residual[bottom].sum(axis=0) + master.sum(axis=0)).max() <= 1e-10 * scale


@pytest.mark.parametrize("law", [Tresca(2e-3), Coulomb(0.3)])
def test_a_turn_about_the_normal_turns_the_answer(law):
    """The problem turned by 0.7 rad about z: the node frames' tangents differ, the disc law
    is isotropic, so the answer is the turned one, the states the same."""
    answers = []
    for angle in (0.0, 0.7):
        result = solve(sheared_cubes(law, angle))
        answers.append((result.u @ turn(angle), result.state))
    (u0, s0), (u1, s1) = answers
    np.testing.assert_array_equal(s0, s1)
    assert np.abs(u1 - u0).max() <= 1e-10 * np.abs(u0).max()


def test_a_load_path_acts_on_the_slip_increment():
    """Tresca on a path: the press alone, then the shear; the second step's reference is
    the first's relative slip, its law met on the increment (KKT ≤ 1e-12), and a shear
    back to the start returns the relative slip the law allows."""
    press = solve(sheared_cubes(Tresca(2e-3), shift=0.0))
    shear = solve(sheared_cubes(Tresca(2e-3)), previous=press)
    cs = shear.contact
    y0 = cs.unknowns(press.u.ravel())[cs.friction.tangent]
    np.testing.assert_array_equal(shear.tangential_reference, y0)
    assert shear.report.kkt.max <= 1e-12
    y1 = cs.unknowns(shear.u.ravel())[cs.friction.tangent]
    stick = shear.state == STICK
    assert stick.any() and (shear.state == SLIP).any()
    assert np.abs(y1[stick] - y0[stick]).max() <= 1e-12 * np.abs(y1).max()


def sheared_patch(law, p: float = 0.01, tau: float = 0.004) -> tuple[ContactProblem, object]:
    """The 3D frictional contact patch test: the stacked boxes of :func:`sheared_cubes` in
    ``σ_zz = −p``, ``σ_xz = τ`` (the rest 0) in both, with ``ν / E`` the same in both so that
    their lateral strains ``ν p / E`` match and the interface sticks: the top and bottom
    held at the exact affine displacement, the x sides loaded by ``(0, 0, ±τ)``. Returns the
    problem and the exact displacement ``x (n, 3) → (n, 3)``."""
    materials = {"upper": Material.from_young(1.0, 0.1), "lower": Material.from_young(3.0, 0.3)}
    e = 0.1 * p  # the lateral strain of both
    gamma = {b: tau / m.mu for b, m in materials.items()}
    young = {b: m.young for b, m in materials.items()}

    def exact(x: np.ndarray, body: str) -> np.ndarray:
        z = x[:, 2]
        if body == "lower":
            return np.column_stack([e * x[:, 0] + gamma["lower"] * z, e * x[:, 1],
                                    -p * z / young["lower"]])  # fmt: skip
        return np.column_stack([
            e * x[:, 0] + gamma["upper"] * (z - 1) + gamma["lower"], e * x[:, 1],
            -p / young["lower"] - p * (z - 1) / young["upper"],
        ])  # fmt: skip

    base = sheared_cubes(law, shift=0.0)
    conditions = dict(base.conditions)
    conditions.update({
        "upper.z1": Dirichlet(lambda x: exact(x, "upper")),
        "lower.z0": Dirichlet(lambda x: exact(x, "lower")),
        "upper.x0": Neumann((0.0, 0.0, -tau)), "upper.x1": Neumann((0.0, 0.0, tau)),
        "lower.x0": Neumann((0.0, 0.0, -tau)), "lower.x1": Neumann((0.0, 0.0, tau)),
    })  # fmt: skip
    return replace(base, material=materials, conditions=conditions), exact


@pytest.mark.parametrize("law", [Tresca(0.005), Coulomb(0.5)])
def test_frictional_patch_test_and_its_estimate(law):
    """A uniform pressure and shear cross the non-matching interface exactly in stick: u is
    the exact affine field, every slave row's dual-basis tractions are ``p`` and ``τ`` to
    1e-10, and every estimator term (η3 on the master faces with the friction forces, η4
    with the friction stress) is round-off; η8² is a work, bound times slip, so its
    round-off is ``ε b U |Γ_C|`` (b the slip bound, U = max |u|), not a square of one."""
    from signorini.estimator import estimate
    from signorini.estimator.roundoff import roundoff_level
    from signorini.mesh.bodies import body_of_cells

    p, tau = 0.01, 0.004
    problem, exact = sheared_patch(law, p, tau)
    result = solve(problem)
    assert result.report.kkt.max <= 1e-12
    assert (result.state == STICK).all()
    space = result.space
    upper = np.zeros(space.n_nodes, dtype=bool)
    upper[space.cell_nodes[body_of_cells(result.mesh) == 0].ravel()] = True
    x = space.node_points
    u = np.where(upper[:, None], exact(x, "upper"), exact(x, "lower"))
    assert np.abs(result.u - u).max() < 1e-10 * np.abs(u).max()
    np.testing.assert_allclose(result.pressure, p, rtol=1e-10)
    traction = interface_forces(result) / result.contact.basis_integral[:, None]
    np.testing.assert_allclose(traction[:, 0], tau, rtol=1e-10)  # along x, on the slave
    est = estimate(result)
    *terms, eta8 = est.eta_terms
    assert max(terms) < min(roundoff_level(result), 1e-9 * p), est.eta_terms
    bound = law.bound if isinstance(law, Tresca) else law.coefficient * p
    assert eta8**2 < 100 * np.finfo(float).eps * bound * np.abs(u).max() * 1.0  # |Γ_C| = 1


def test_partial_slip_spheres_meet_the_law_and_newtons_third_law():
    """The built-in ``partial-slip-spheres`` on a coarse mesh (h = 0.15 at the poles): both
    steps meet the KKT conditions to 1e-12, the pull leaves stick and slip rows with
    0 < Q/(F P) < 1, rows on the mirror plane have their roller axis left out of the law, and
    the slave's force (normal and friction) is what the upper top and the lower bottom hold
    in x and z (the rollers' reactions are along y) to 1e-10."""
    from signorini.examples.partial_slip3d import partial_slip_3d_metrics
    from signorini.examples.partial_slip_spheres3d import partial_slip_spheres_path

    press, pull = partial_slip_spheres_path(h_contact=0.15)
    first = solve(press)
    result = solve(pull, previous=first)
    for r in (first, result):
        assert r.report.kkt.max <= 1e-12
    assert (result.state == STICK).any() and (result.state == SLIP).any()
    m = partial_slip_3d_metrics(result)
    assert 0.2 < m["q_over_fp"] < 1.0
    cs = result.contact
    on_plane = np.abs(result.space.node_points[cs.node, 1]) < 1e-12
    assert on_plane.any() and cs.friction.held[on_plane].any(axis=1).all()
    assert not cs.friction.held[~on_plane].any()
    plain = without_contact(pull)
    residual = (plain.K @ result.u.ravel() - plain.F).reshape(-1, 3)
    bottom = np.unique(result.space.facet_nodes(pull.mesh.part_facets("lower.z1")))
    f = interface_forces(result).sum(axis=0)
    master = cs.master_forces(result.contact_force, result.space.n_nodes,
                              result.tangential_force).sum(axis=0)  # fmt: skip
    top = np.unique(result.space.facet_nodes(pull.mesh.part_facets("upper.z1")))
    assert abs(f[0]) > 0.1 * abs(f[2])  # the pull
    assert np.abs(residual[top].sum(axis=0) - f)[[0, 2]].max() <= 1e-10 * abs(f[2])
    assert np.abs(residual[bottom].sum(axis=0) + master)[[0, 2]].max() <= 1e-10 * abs(f[2])


def test_a_frictional_pair_beside_a_frictionless_one():
    """Three stacked boxes, the middle one's bottom the slave of a Tresca pair and its top
    the master of a frictionless one, the top pressed, the middle held and sheared by its
    side x0 (each body held by its own parts): KKT ≤ 1e-12; the frictionless pair's
    rows carry no friction force and keep the slave's own tangential unknowns (their
    projection is ``n nᵀ``), the frictional pair's rows stick or slip; the lowest box's
    support holds the frictional interface's force to 1e-10."""
    free = Neumann((0.0, 0.0, 0.0))
    boxes = {
        "top": box(2, 2, 1, lower=(0.0, 0.0, 2.0), upper=(1.0, 1.0, 3.0)),
        "middle": box(3, 3, 1, lower=(0.0, 0.0, 1.0), upper=(1.0, 1.0, 2.0)),
        "bottom": box(4, 4, 1),
    }
    conditions = {f"{b}.{p}": free for b in boxes for p in ("x0", "x1", "y0", "y1")}
    conditions.update({
        "top.z1": Dirichlet((0.0, 0.0, -0.01)),
        "middle.x0": Dirichlet((0.003, 0.0, -0.005)),
        "bottom.z0": Dirichlet((0.0, 0.0, 0.0)),
        "middle.z0": Contact(master="bottom.z1", friction=Tresca(2e-3)),
        "top.z0": Contact(master="middle.z1"),
    })  # fmt: skip
    E = Material.from_young(1.0, 0.3)
    problem = ContactProblem(union(boxes), dict.fromkeys(boxes, E), conditions)
    result = solve(problem)
    assert result.report.kkt.max <= 1e-12
    cs = result.contact
    frictional = cs.part == cs.parts.index("middle.z0")
    n = cs.direction
    normal = n[:, :, None] * n[:, None, :]
    assert np.array_equal(cs.projection[~frictional], normal[~frictional])
    assert np.abs(cs.projection[frictional] - np.eye(3)).max() < 1e-14  # no held axis
    assert not result.tangential_force[~frictional].any()
    assert {STICK, SLIP} <= set(result.state[frictional].tolist())
    plain = without_contact(problem)
    residual = (plain.K @ result.u.ravel() - plain.F).reshape(-1, 3)
    bottom = np.unique(result.space.facet_nodes(problem.mesh.part_facets("bottom.z0")))
    f = interface_forces(result)[frictional].sum(axis=0)
    assert abs(f[0]) > 0.05 * abs(f[2])
    assert np.abs(residual[bottom].sum(axis=0) + f).max() <= 1e-10 * abs(f[2])
