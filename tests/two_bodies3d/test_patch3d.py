"""Two bodies in 3D through the dual mortar coupling (docs/method.md, *Two bodies in three
dimensions*): the contact patch test on the stacked cubes to round-off, either side as
slave; the coupled solution against a QP solved independently; bad input refused."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
from contact3d_problems import without_contact
from scipy.optimize import nnls

from signorini import adaptive
from signorini.contact import solve
from signorini.contact.mortar3d import mortar_coupling_3d
from signorini.contact.system import assemble
from signorini.examples.two_bodies3d import cubes_metrics, cubes_pressure, stacked_cubes
from signorini.fem.material import Material
from signorini.mesh.bodies import body_of_cells, union
from signorini.mesh.builders3d import box
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann, ProblemError
from signorini.problem.obstacles3d import HalfSpace


def exact_displacement(result, depth: float = 0.01) -> np.ndarray:
    """Uniaxial compression ``σ_zz = −p`` in both boxes of :func:`stacked_cubes`, at the
    P2 nodes of each body (at the interface the two bodies' nodes share z = 1, not u)."""
    problem, space = result.problem, result.space
    p = cubes_pressure(problem, depth)
    m = problem.material
    e1, n1, e2, n2 = m["upper"].young, m["upper"].poisson, m["lower"].young, m["lower"].poisson
    upper = np.zeros(space.n_nodes, dtype=bool)
    cells = space.cell_nodes
    upper[cells[body_of_cells(result.mesh) == 0].ravel()] = True  # the union's first body
    x = space.node_points
    u = np.empty_like(x)
    lateral = np.where(upper, n1 * p / e1, n2 * p / e2)
    u[:, 0], u[:, 1] = lateral * x[:, 0], lateral * x[:, 1]
    u[:, 2] = np.where(upper, -p / e2 - p * (x[:, 2] - 1.0) / e1, -p * x[:, 2] / e2)
    return u


@pytest.mark.parametrize("slave", ["upper", "lower"])
@pytest.mark.parametrize("counts", [((3, 3, 2), (4, 4, 2)), ((4, 3, 1), (2, 5, 1))])
def test_contact_patch_test_3d(slave, counts):
    """A uniform pressure crosses the non-matching interface exactly, either side as slave:
    every slave pressure Λ̃_j / D_jj equals p = δ / Σ H/E to 1e-10, the master's nodal forces
    are the consistent ones of p, the displacement the exact piecewise affine one; the
    resultant is p times the interface's area."""
    problem = stacked_cubes(counts, slave=slave)
    result = solve(problem)
    p = cubes_pressure(problem)
    assert result.active.all()
    assert np.abs(result.pressure / p - 1).max() < 1e-10
    metrics = cubes_metrics(result)
    assert metrics["slave_pressure_deviation"] < 1e-10
    assert metrics["master_force_deviation"] < 1e-10
    u = exact_displacement(result)
    assert np.abs(result.u - u).max() < 1e-10 * np.abs(u).max()
    assert result.contact_force.sum() == pytest.approx(p, rel=1e-12)
    assert result.report.kkt.columns()["kkt_stationarity"] < 1e-12


def tilted_press(gap: float = 0.005) -> ContactProblem:
    """The upper box 0.005 above the lower one, its top pressed down by a tilted rigid
    plate, ``u = (0, 0, −0.006 (1/4 + x))``: contact only where x is large."""
    free = Neumann((0.0, 0.0, 0.0))
    upper = box(2, 2, 1, lower=(0.0, 0.0, 1.0 + gap), upper=(1.0, 1.0, 2.0))
    return ContactProblem(
        mesh=union({"upper": upper, "lower": box(3, 3, 1)}),
        material={"upper": Material.from_young(1.0, 0.3), "lower": Material.from_young(2.0, 0.25)},
        conditions={
            "upper.z1": Dirichlet(lambda x: np.column_stack(
                [0 * x[:, 0], 0 * x[:, 0], -0.006 * (0.25 + x[:, 0])])),
            "upper.x0": Dirichlet((0.0, None, None)), "upper.y0": Dirichlet((None, 0.0, None)),
            "upper.x1": free, "upper.y1": free,
            "lower.z0": Dirichlet((None, None, 0.0)),
            "lower.x0": Dirichlet((0.0, None, None)), "lower.y0": Dirichlet((None, 0.0, None)),
            "lower.x1": free, "lower.y1": free,
            "upper.z0": Contact(master="lower.z1"),
        },
    )  # fmt: skip


def independent_solve(problem: ContactProblem):
    """The mortar-constrained QP in Cartesian DOFs, without the package's change of basis or
    solver: ``min ½ uᵀ K u − Fᵀ u`` with ``n_j·(ũ_j − Σ_k M_jk u_k / D_jj) ≤ g̃_j / D_jj``
    (``ũ`` the slave's transformed coefficients, written here from the slave faces), u_D
    held; its dual by NNLS on ``S = C_f K_ff⁻¹ C_fᵀ`` (dense Cholesky), then the positive
    multipliers solved once more for round-off accuracy."""
    plain = without_contact(problem)
    space = plain.space
    c = mortar_coupling_3d(space, "upper.z0", "lower.z1")
    n = plain.K.shape[0]
    held = plain.dirichlet
    rows = c.slave_nodes[~np.isin(3 * c.slave_nodes + 2, held)]  # normal (z) not held
    j = np.searchsorted(c.slave_nodes, rows)
    # ũ at the slave nodes: u_z at a vertex, (u_e − α (u_a + u_b)) / (1 − 2α) at a midpoint
    a = c.alpha
    mid = np.zeros((space.n_nodes, 3), dtype=np.int64) - 1
    for e, s, t in ((3, 0, 1), (4, 1, 2), (5, 2, 0)):  # the three sides of a face
        mid[c.slave_faces[:, e]] = np.column_stack(
            [c.slave_faces[:, e], c.slave_faces[:, s], c.slave_faces[:, t]]
        )
    is_mid = mid[rows, 0] >= 0
    r = np.arange(rows.size)
    entries = [(r, 3 * rows + 2, np.where(is_mid, 1 / (1 - 2 * a), 1.0))]
    for col in (1, 2):
        entries.append((r[is_mid], 3 * mid[rows[is_mid], col] + 2,
                        np.full(is_mid.sum(), -a / (1 - 2 * a))))  # fmt: skip
    nz = c.normal[j, 2]
    T = sp.diags(1.0 / c.D[j]) @ c.M[j]
    Tc = sp.coo_matrix(T)
    entries.append((Tc.row, 3 * Tc.col + 2, -Tc.data))
    ri, ci, vi = (np.concatenate(v) for v in zip(*entries, strict=True))
    C = sp.diags(nz) @ sp.csr_matrix((vi, (ri, ci)), shape=(rows.size, n))
    g = c.weighted_gap[j] / c.D[j]
    free = np.setdiff1d(np.arange(n), held)
    u0 = np.zeros(n)
    u0[held] = plain.dirichlet_values
    Kff = plain.K[free][:, free].toarray()
    b = plain.F[free] - plain.K[free] @ u0
    Cf = C[:, free].toarray()
    factor = la.cho_factor(Kff, lower=True)
    S = Cf @ la.cho_solve(factor, Cf.T)
    S = 0.5 * (S + S.T)
    cc = (g - C @ u0) - Cf @ la.cho_solve(factor, b)
    L = la.cholesky(S, lower=True)
    lam, _ = nnls(L.T, -la.solve_triangular(L, cc, lower=True), maxiter=50 * S.shape[0])
    active = lam > 0
    lam = np.zeros_like(lam)
    lam[active] = la.solve(S[np.ix_(active, active)], -cc[active], assume_a="pos")
    u = u0.copy()
    u[free] = la.cho_solve(factor, b - Cf.T @ lam)
    return u.reshape(-1, 3), rows, lam, active


def test_coupled_solution_against_an_independent_qp():
    """The tilted press (contact on part of the interface): the package's displacement,
    multipliers Λ̃ and active set equal the independent QP's (u to 1e-10 of its largest,
    Λ̃ to 1e-9 of the largest), both contact and separation present."""
    problem = tilted_press()
    result = solve(problem)
    u, rows, lam, active = independent_solve(problem)
    assert np.array_equal(result.contact.node, rows)
    assert 0 < active.sum() < active.size
    assert np.array_equal(result.active, active)
    assert np.abs(result.u - u).max() < 1e-10 * np.abs(u).max()
    assert np.abs(result.contact_force - lam).max() < 1e-9 * lam.max()


def pair_problem(drop: tuple[str, ...] = (), **changes) -> ContactProblem:
    base = stacked_cubes(((2, 2, 1), (2, 2, 1)))
    conditions = {k: v for k, v in base.conditions.items() if k not in drop}
    conditions.update(changes)
    return ContactProblem(mesh=base.mesh, material=base.material, conditions=conditions)


def test_bad_pairs_refused():
    """A pair beside an obstacle part, condition (a), self contact, a
    slave wider than its master (large sliding), a body held only by the other: refused
    naming what."""
    with pytest.raises(ProblemError, match="no contact parts against obstacles"):
        pair_problem(**{"upper.x1": Contact(obstacle=HalfSpace((2.0, 0, 0), (1.0, 0, 0)))})
    with pytest.raises(ProblemError, match="face_alpha=0"):
        pair_problem(**{"upper.z0": Contact(master="lower.z1", face_alpha=0.0)})
    with pytest.raises(ProblemError, match="self contact"):
        pair_problem(drop=("upper.x0",), **{"upper.x1": Contact(master="upper.x0"),
                                            "upper.z0": Neumann((0.0, 0.0, 0.0)),
                                            "lower.z1": Neumann((0.0, 0.0, 0.0))})  # fmt: skip
    wide = union({"upper": box(2, 2, 1, lower=(-0.5, 0, 1), upper=(1.5, 1, 2)),
                  "lower": box(2, 2, 1)})  # fmt: skip
    base = stacked_cubes(((2, 2, 1), (2, 2, 1)))
    with pytest.raises(ProblemError, match="large sliding"):
        solve(ContactProblem(mesh=wide, material=base.material, conditions=base.conditions))
    with pytest.raises(ProblemError, match="held in all its rigid motions"):
        pair_problem(**{"upper.z1": Neumann((0.0, 0.0, -0.01))})


def test_pairs_in_3d_refused_where_not_built():
    """A 3D pair system on several MPI ranks is refused before any work, naming the pairs."""
    from signorini.algebra.ranks import Ranks

    problem = stacked_cubes(((2, 2, 1), (2, 2, 1)))

    two = Ranks()  # a rank count only: the refusal comes before any communication
    two.size = 2
    with pytest.raises(ValueError, match="not split over MPI ranks"):
        assemble(problem, problem.mesh, ranks=two)


@pytest.mark.parametrize("slave", ["upper", "lower"])
def test_patch_test_on_a_uniformly_refined_level_with_a_warm_start(slave):
    """Issue 41's patch test through the loop, either side as slave: with tol 1e-10 the loop
    stops on the first level, whose η is at round-off (the estimator's mortar terms vanish
    there); the uniformly refined level, started warm from it (its active set read in the
    mortar set's variables), still transmits the uniform pressure to round-off,
    ``slave_pressure_deviation`` ≤ 1e-9."""
    from signorini.mesh.refine import refine_uniform

    problem = stacked_cubes(slave=slave)
    first = list(adaptive(problem, uniform=True, tol=1e-10, metrics=cubes_metrics))
    assert len(first) == 1 and first[0].record.stop in ("tol", "round-off")
    refinement = refine_uniform(problem.mesh)
    u0 = first[0].result.space.prolongate(first[0].result.u, refinement)
    second = list(
        adaptive(problem, mesh=refinement.mesh, u0=u0, uniform=True, max_levels=1,
                 metrics=cubes_metrics)
    )  # fmt: skip
    assert second[0].record.ndof > first[0].record.ndof
    for level in (*first, *second):
        assert level.record.extra["slave_pressure_deviation"] <= 1e-9
        assert level.record.extra["master_force_deviation"] <= 1e-9
