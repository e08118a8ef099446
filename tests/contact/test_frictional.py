"""Frictional contact through ``solve`` (signorini.contact.frictional): Tresca against an
independent solve of its convex minimisation, Coulomb's laws node by node, zero friction
against the frictionless solve, rotation invariance, and what is refused.

The reference for Tresca works in Cartesian DOFs: with the constraint rows ``B_n u ≤ ψ`` and
the friction rows ``B_t u`` (n_z and t_z at the node's two DOFs), the minimiser of
``½ uᵀKu − fᵀu + Σ s_z |t_z·u_z|`` subject to ``B_n u ≤ ψ`` is ``u = K⁻¹(f − B_nᵀλ_n −
B_tᵀλ_t)`` with the dual ``min ½ λᵀ B K⁻¹ Bᵀ λ − λᵀ(B K⁻¹ f − [ψ; 0])`` over the box
``λ_n ≥ 0, |λ_t| ≤ s``, solved by bounded-variable least squares: no node frames, no
semismooth Newton.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg as la
from contact_problems import corner_problem, problem_contact_set
from scipy.optimize import lsq_linear

from signorini.algebra import FrictionResult
from signorini.contact.solution import INACTIVE, SLIP, STICK, solve
from signorini.estimator.friction_facets import friction_facets
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.loop import adaptive
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann, Tresca
from signorini.problem.fields import ProblemError
from signorini.problem.obstacles import Disc

MATERIAL = Material.from_young(1.0, 0.3)


def pressed_block(
    friction, angle: float = 0.0, nx: int = 8, right_friction: object = "same"
) -> ContactProblem:
    """The block (0, 2) × (0, 1) (rotated by ``angle``) pushed down and sideways by its top
    onto a rigid cylinder below its bottom: contact in the middle, stick and slip zones.
    With ``right_friction`` the bottom is two contact parts, ``bottom`` (x < 1) with
    ``friction`` and ``bottom_right`` (x > 1) with ``right_friction``."""
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    base = rectangle(0.0, 2.0, 0.0, 1.0, nx=nx, ny=nx // 2)

    def on(coord, value):
        return lambda x: np.abs((x @ R)[:, coord] - value) < 1e-12

    parts = {"left": on(0, 0.0), "right": on(0, 2.0), "top": on(1, 1.0)}
    if right_friction == "same":
        parts["bottom"] = on(1, 0.0)
    else:
        parts["bottom"] = lambda x: on(1, 0.0)(x) & ((x @ R)[:, 0] < 1.0)
        parts["bottom_right"] = lambda x: on(1, 0.0)(x) & ((x @ R)[:, 0] > 1.0)
    mesh = Mesh.from_arrays(base.points @ R.T, base.cells, parts)
    cylinder = Disc(R @ [1.0, -12.5], 12.5)  # touches the bottom at x = 1
    conditions = {
        "left": Neumann(),
        "right": Neumann(),
        "top": Dirichlet(R @ [0.012, -0.02]),
        "bottom": Contact(obstacle=cylinder, friction=friction),
    }
    if right_friction != "same":
        conditions["bottom_right"] = Contact(obstacle=cylinder, friction=right_friction)
    return ContactProblem(mesh, MATERIAL, conditions)


def law_residuals(res, bound: np.ndarray) -> dict[str, float]:
    """The tangential law of every constraint with the nodal slip bounds ``bound (k,)``, from
    the computed forces and displacements alone, relative to the largest contact force and
    displacement: the force within its bound, stick without tangential displacement, slip at
    the bound along the friction force."""
    lam_t, scale, disp = res.tangential_force, res.contact_force.max(), np.abs(res.u).max()
    n = res.contact.normal
    u_t = np.einsum("kc,kc->k", res.u[res.contact.nodes], np.column_stack([-n[:, 1], n[:, 0]]))
    stick, slip = res.state == STICK, res.state == SLIP
    return {
        "beyond bound": float(np.maximum(np.abs(lam_t) - bound, 0).max() / scale),
        "stick moves": float(np.abs(u_t[stick]).max(initial=0) / disp),
        "slip off bound": float(np.abs(np.abs(lam_t[slip]) - bound[slip]).max(initial=0) / scale),
        "slip against force": float(
            np.maximum(-u_t[slip] * lam_t[slip], 0).max(initial=0) / (scale * disp)
        ),
    }


def test_tresca_and_coulomb_parts_in_one_problem():
    """The bottom's left half with Tresca, its right half with Coulomb: both laws node by
    node; and with the Coulomb nodes' bound frozen at F Λ_n of the solution, the whole
    problem is a Tresca problem, whose minimiser (by its dual, no semismooth Newton) is the
    same solution."""
    F = 0.3
    bound = 0.25 * solve(pressed_block(None, nx=16)).pressure.max()
    pb = pressed_block(Tresca(bound), nx=16, right_friction=Coulomb(F))
    res = solve(pb)
    law = res.contact.friction
    tresca, coulomb = law.index == 0, law.index == 1
    assert law.laws == (Tresca(bound), Coulomb(F)) and not res.report.symmetric
    for nodes in (tresca, coulomb):  # both laws have stick and slip nodes in contact
        assert (res.state[nodes] == STICK).any() and (res.state[nodes] == SLIP).any()
    assert res.report.kkt.max < 1e-11, res.report.kkt
    s = np.where(tresca, law.weight, F * res.contact_force)
    worst = law_residuals(res, s)
    print(f"Tresca + Coulomb: law residuals {worst}")
    assert max(worst.values()) < 1e-11, worst
    u_ref, lam_n, lam_t = tresca_reference(pb, s)
    err_u = np.abs(res.u - u_ref).max() / np.abs(u_ref).max()
    err_n = np.abs(res.contact_force - lam_n).max() / lam_n.max()
    err_t = np.abs(res.tangential_force - lam_t).max() / lam_n.max()
    print(f"frozen Coulomb bound: |u − u_ref|/|u| = {err_u:.1e}, Λ_n {err_n:.1e}, Λ_t {err_t:.1e}")
    assert err_u < 1e-8 and err_n < 1e-8 and err_t < 1e-8


def tresca_reference(
    pb: ContactProblem, bound: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """u (n_nodes, 2), λ_n and λ_t of the Tresca problem by its dual over a box, with the
    nodal bounds ``bound (k,)`` (default the contact set's Tresca weights ∫ s ψ_z ds)."""
    space = P2Space(pb.mesh)
    cs = problem_contact_set(pb, space)
    n = space.n_dofs
    K = assemble_stiffness(space.vertices, space.cell_dofs, n, pb.material).toarray()
    u_d = np.zeros((space.n_nodes, 2))
    for name in pb.dirichlet_parts:
        nodes = space.part_nodes([name])
        u_d[nodes] = pb.conditions[name].field()(space.node_points[nodes])
    fixed = np.zeros(n, dtype=bool)
    d = pb.dirichlet_nodes(space)
    fixed[2 * d] = fixed[2 * d + 1] = True
    free = ~fixed
    k = cs.size
    s = cs.friction.weight if bound is None else bound
    rubs = np.flatnonzero(s > 0)  # a node without a bound has no tangential multiplier
    r = rubs.size
    t = np.column_stack([-cs.normal[:, 1], cs.normal[:, 0]])  # independently of cs.tangent
    B = np.zeros((k + r, n))
    B[np.arange(k), 2 * cs.nodes], B[np.arange(k), 2 * cs.nodes + 1] = cs.normal.T
    B[k + np.arange(r), 2 * cs.nodes[rubs]] = t[rubs, 0]
    B[k + np.arange(r), 2 * cs.nodes[rubs] + 1] = t[rubs, 1]
    chol = la.cho_factor(K[np.ix_(free, free)])
    rhs = -K[np.ix_(free, fixed)] @ u_d.ravel()[fixed]
    Bf = B[:, free]
    H = Bf @ la.cho_solve(chol, Bf.T)
    c = Bf @ la.cho_solve(chol, rhs) - np.concatenate([cs.gap, np.zeros(r)])
    L = np.linalg.cholesky(H)
    lower = np.concatenate([np.zeros(k), -s[rubs]])
    upper = np.concatenate([np.full(k, np.inf), s[rubs]])
    sol = lsq_linear(L.T, la.solve_triangular(L, c, lower=True), bounds=(lower, upper),
                     method="bvls", tol=1e-15)  # fmt: skip
    lam = sol.x
    u = u_d.ravel().copy()
    u[free] = la.cho_solve(chol, rhs - Bf.T @ lam)
    lam_t = np.zeros(k)
    lam_t[rubs] = lam[k:]
    return u.reshape(-1, 2), lam[:k], lam_t


def test_tresca_equals_the_minimiser_of_its_convex_energy():
    frictionless = solve(pressed_block(None))
    bound = 0.2 * frictionless.pressure.max()
    pb = pressed_block(Tresca(bound))
    res = solve(pb)
    u_ref, lam_n, lam_t = tresca_reference(pb)
    err_u = np.abs(res.u - u_ref).max() / np.abs(u_ref).max()
    err_n = np.abs(res.contact_force - lam_n).max() / lam_n.max()
    err_t = np.abs(res.tangential_force - lam_t).max() / lam_n.max()
    counts = {name: int((res.state == v).sum()) for name, v in (("inactive", INACTIVE),
              ("stick", STICK), ("slip", SLIP))}  # fmt: skip
    print(f"Tresca s = {bound:.3g}: |u − u_ref|/|u| = {err_u:.1e}, Λ_n {err_n:.1e}, "
          f"Λ_t {err_t:.1e}; states {counts}")  # fmt: skip
    assert err_u < 1e-7 and err_n < 1e-7 and err_t < 1e-7
    assert min(counts.values()) > 0  # no contact, stick and slip all occur
    assert res.report.kkt.max < 1e-10
    # friction pulls against the sideways push: the obstacle's force on the body points left
    assert res.contact_force_vector[0] < 0 < res.contact_force_vector[1]


@dataclass(frozen=True)
class Cohesive:
    """A toy law, written here and nowhere else: cohesion ``c`` (a stress) plus Coulomb
    friction, ``s_z = ∫ c ψ_z ds + F Λ_n`` on the nodes in contact."""

    cohesion: float
    coefficient: float
    symmetric = False
    everywhere = False

    def nodal_weight(self, integrate, size):
        return integrate(lambda x: np.full(len(x), self.cohesion))

    def slip_bound(self, weight, normal_force, in_contact):
        return (weight + self.coefficient * np.maximum(normal_force, 0.0)) * in_contact

    def bound_derivative(self, weight, in_contact):
        return np.full(weight.shape, self.coefficient)


def test_a_new_law_is_one_class():
    """The toy law through the public solve(): its law node by node, and with its bound
    frozen at the solution's ``∫ c ψ_z + F Λ_n`` the problem is a Tresca problem whose
    minimiser (by its dual) is the same solution."""
    c, F = 0.05 * solve(pressed_block(None, nx=16)).pressure.max(), 0.2
    res = solve(pressed_block(Cohesive(c, F), nx=16))
    assert isinstance(res.report, FrictionResult) and not res.report.symmetric
    assert (res.state == STICK).any() and (res.state == SLIP).any()
    w = res.contact.friction.weight
    assert np.allclose(w, c * res.contact.basis_integral, rtol=1e-13, atol=0)
    s = (w + F * res.contact_force) * res.active
    worst = law_residuals(res, s)
    print(f"cohesive law: KKT {res.report.kkt.max:.1e}, law residuals {worst}")
    assert res.report.kkt.max < 1e-11 and max(worst.values()) < 1e-11, worst
    u_ref, lam_n, lam_t = tresca_reference(res.problem, s)
    err_u = np.abs(res.u - u_ref).max() / np.abs(u_ref).max()
    err_n = np.abs(res.contact_force - lam_n).max() / lam_n.max()
    err_t = np.abs(res.tangential_force - lam_t).max() / lam_n.max()
    print(f"frozen cohesive bound: |u − u_ref|/|u| = {err_u:.1e}, Λ_n {err_n:.1e}, Λ_t {err_t:.1e}")
    assert err_u < 1e-8 and err_n < 1e-8 and err_t < 1e-8
    # the estimator asks the law too: its bound as a stress is s_z / w_z
    facets = friction_facets(res)
    loc = res.contact.facet_local
    inside = loc >= 0
    assert np.array_equal(facets.bound[inside], (s / res.contact.basis_integral)[loc[inside]])


def test_tresca_in_contact_only_is_tresca_with_the_bound_cut_to_the_contact_set():
    bound = 0.2 * solve(pressed_block(None)).pressure.max()
    res = solve(pressed_block(Tresca(bound, everywhere=False)))
    assert not np.any(res.tangential_force[~res.active]) and res.report.symmetric
    assert (res.state == STICK).any() and (res.state == SLIP).any()
    assert res.report.kkt.max < 1e-11
    u_ref, lam_n, lam_t = tresca_reference(res.problem, res.contact.friction.weight * res.active)
    assert np.abs(res.u - u_ref).max() < 1e-8 * np.abs(u_ref).max()
    assert np.abs(res.tangential_force - lam_t).max() < 1e-8 * lam_n.max()


@pytest.mark.parametrize("friction", [Tresca(0.0), Coulomb(0.0)])
def test_zero_friction_is_the_frictionless_solution(friction):
    ref = solve(pressed_block(None))
    res = solve(pressed_block(friction))
    assert np.abs(res.u - ref.u).max() < 1e-12 * np.abs(ref.u).max()
    assert np.abs(res.contact_force - ref.contact_force).max() < 1e-12 * ref.contact_force.max()
    assert np.array_equal(res.active, ref.active)
    assert np.abs(res.tangential_force).max() < 1e-14 * ref.contact_force.max()


def test_coulomb_laws_hold_node_by_node():
    F = 0.3
    res = solve(pressed_block(Coulomb(F)))
    lam_n, lam_t = res.contact_force, res.tangential_force
    scale = lam_n.max()
    stick, slip = res.state == STICK, res.state == SLIP
    print(f"Coulomb F = {F}: stick {stick.sum()}, slip {slip.sum()}, KKT {res.report.kkt.max:.1e}")
    assert stick.any() and slip.any()
    assert res.report.kkt.max < 1e-10
    assert (np.abs(lam_t) <= F * lam_n + 1e-10 * scale).all()
    assert np.abs(np.abs(lam_t[slip]) - F * lam_n[slip]).max() < 1e-10 * scale
    # the nodes that stick did not move tangentially; the ones that slip moved against Λ_t
    n = res.contact.normal
    t = np.column_stack([-n[:, 1], n[:, 0]])
    u_t = np.einsum("kc,kc->k", res.u[res.contact.nodes], t)
    assert np.abs(u_t[stick]).max() < 1e-12 * np.abs(res.u).max()
    assert (u_t[slip] * lam_t[slip] >= 0).all()


def test_frictional_solution_is_rotation_invariant():
    angle = 0.9
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    ref = solve(pressed_block(Coulomb(0.3)))
    rot = solve(pressed_block(Coulomb(0.3), angle))
    assert np.abs(rot.u - ref.u @ R.T).max() < 1e-10 * np.abs(ref.u).max()
    assert (
        np.abs(rot.tangential_force - ref.tangential_force).max() < 1e-10 * ref.contact_force.max()
    )
    assert np.array_equal(rot.state, ref.state)


def test_what_is_refused():
    with pytest.raises(ProblemError, match="is a corner of contact parts 'bottom'"):
        base = corner_problem()
        conditions = dict(base.conditions)
        conditions["bottom"] = Contact(friction=Coulomb(0.2))
        solve(ContactProblem(base.mesh, base.material, conditions))


def test_warm_start_reads_the_states_off_the_displacement():
    """From its own solution a frictional solve takes one linear solve: contact from the
    gap, stick where the tangential displacement is zero, slip along its sign."""
    from signorini.contact.frictional import states_from_displacement

    pb = pressed_block(Coulomb(0.3))
    res = solve(pb)
    active0 = (
        res.contact.normal_displacement(res.u) - res.contact.gap >= -1e-10 * np.abs(res.u).max()
    )
    state0, direction0 = states_from_displacement(
        res.u, res.contact, np.zeros(res.contact.size), active0, 1e-10
    )
    assert np.array_equal(state0, res.state)
    slip = res.state == SLIP
    assert np.array_equal(direction0[slip], res.report.direction[slip])
    again = solve(pb, u0=res.u)
    assert again.report.iterations == 1
    assert np.abs(again.u - res.u).max() < 1e-12 * np.abs(res.u).max()


@pytest.mark.slow
def test_adaptive_coulomb_levels_need_few_iterations():
    """Warm-started from the previous level, a level of Example 6.2 with Coulomb friction
    needs about two linear solves (from the update rule at the prolongated solution it
    needed 8–10 at 10⁵ unknowns)."""
    from signorini.examples import get_example

    iterations = [
        level.record.pdas_iterations
        for level in adaptive(get_example("example-6.2-coulomb"), max_ndof=30_000)
    ]
    print(f"friction iterations per level: {iterations}")
    assert np.mean(iterations[-8:]) <= 3 and max(iterations[-8:]) <= 5, iterations


def test_coulomb_systems_on_a_node_blocked_matrix_take_its_own_pattern(monkeypatch):
    """Coulomb's non-symmetric rows copy a node's normal row into its tangential row; in
    an assembled (node-blocked) K both rows store the same columns, so the system takes
    K's own arrays instead of building the widened pattern: the same iterations and the
    same solution, bit for bit, as with the widened pattern built."""
    import signorini.algebra.friction.system as friction_system
    from signorini.examples import example_6_2_coulomb

    problem = example_6_2_coulomb()
    levels = list(adaptive(problem, max_ndof=3000))
    mesh, u0 = levels[-2].next_mesh, levels[-2].next_u0
    seen = []
    same_columns = friction_system._same_columns

    def recorded(*args):
        seen.append(same_columns(*args))
        return seen[-1]

    monkeypatch.setattr(friction_system, "_same_columns", recorded)
    own = solve(problem, mesh, u0=u0)
    assert seen and seen[-1] is not None  # K's own pattern was taken
    monkeypatch.setattr(friction_system, "_same_columns", lambda *args: None)
    widened = solve(problem, mesh, u0=u0)
    assert own.report.iterations == widened.report.iterations >= 1
    assert np.array_equal(own.u, widened.u)
    assert np.array_equal(own.tangential_force, widened.tangential_force)


def test_a_tangential_row_without_the_normal_rows_columns_is_widened():
    import scipy.sparse as sp

    from signorini.algebra.friction.system import _same_columns

    K = sp.csr_matrix(np.array([[4.0, 1.0, 1.0], [1.0, 4.0, 0.0], [1.0, 0.0, 4.0]]))
    K.eliminate_zeros()  # row 1 lacks column 2, which row 0 stores
    assert _same_columns(K, np.array([0]), np.array([1])) is None
    blocked = sp.csr_matrix(np.ones((4, 4)) + 3 * np.eye(4))
    assert np.array_equal(_same_columns(blocked, np.array([0, 2]), np.array([1, 3])), [4, 4])
