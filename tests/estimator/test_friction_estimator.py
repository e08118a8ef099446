"""The frictional extension of the residual estimator (docs/method.md, *Estimator*, "With
friction"): η4 = h_p‖σ_t(u_h) + p_t,h‖², η8 = ∫_{γ̃_p} (max(b_h, |p_t,h|)|u_t| − p_t,h u_t).

Measured: on a manufactured Tresca solution with a stick and a slip zone the estimator and the
energy error decay at the same rate under uniform refinement, with a bounded efficiency index;
the adaptive loop on a Coulomb problem converges at the optimal rate and refines at the ends of
the contact zone and at the stick–slip transitions; zero friction gives the frictionless
estimator.
"""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import SLIP, STICK, solve
from signorini.estimator.residual import NODE_TERMS, TERMS, estimate
from signorini.estimator.terms import friction_work
from signorini.fem.material import Material, stress
from signorini.loop import adaptive
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh
from signorini.mesh.refine import refine_uniform
from signorini.output.history import fitted_slope
from signorini.problem import (
    Contact,
    ContactProblem,
    Coulomb,
    Dirichlet,
    ExactSolution,
    Neumann,
    Tresca,
)
from signorini.problem.obstacles import Disc, HalfPlane

MATERIAL = Material.from_young(1.0, 0.3)
#: the stick–slip transition point of the manufactured solution (not a dyadic point: it
#: lies inside an edge on every mesh of the sequence)
C = 0.4
A, B, K, D = 0.05, 0.02, 0.5, 0.05


def _pieces(x: np.ndarray):
    """``P = (x − c)₊³``, ``Q = (c − x)₊³`` and their first two derivatives."""
    p, q = np.maximum(x - C, 0.0), np.maximum(C - x, 0.0)
    return p**3, 3 * p**2, 6 * p, q**3, -3 * q**2, 6 * q


def manufactured_tresca(nx: int = 4) -> ContactProblem:
    """A Tresca problem on the unit square with a known solution, a stick and a slip zone.

    Γ_C is the bottom y = 0 (outward normal n = (0, −1), tangent t = (−n_y, n_x) = (1, 0), so
    ``u_t = u_x``, ``u·n = −u_y``, ``σ_nn = σ_yy`` and ``σ_t = −σ_xy``); the top is clamped
    at the exact displacement, the sides carry its tractions ``σ(u) n``, and ``f = −div σ(u)``.
    With ``P = (x − c)₊³``, ``Q = (c − x)₊³`` (c = 0.4):

        u_x = A P(x) + y (B − K Q(x)),    u_y = −D y.

    So ``σ_xy = μ (B − K Q)``, ``σ_yy = λ (A P' − y K Q' − D) − 2μ D``, and on y = 0:

    - normal law: ``u·n = −u_y = 0 = ψ`` (gap 0, full contact) and ``σ_yy(x, 0) = λ(3A(x −
      c)₊² − D) − 2μD < 0`` since ``D(λ + 2μ) > 3λA(1 − c)²``;
    - tangential law with the Tresca bound ``s = μB`` (constant): the friction stress on the
      body is ``−λ_t t`` with ``λ_t = −σ_t = σ_xy = μ(B − K Q(x))``;
      on [c, 1] ``λ_t = μB = s`` and ``u_t = A (x − c)³ ≥ 0``: slip along λ_t, i.e. opposite
      to σ_t (``u_t = α λ_t``, ``α = A(x − c)³/s ≥ 0``);
      on [0, c) ``u_t = 0`` (stick) and ``|λ_t| < s`` since ``0 < K c³ < 2B``.

    u is C² (P, Q are piecewise cubics), so P2 converges at its optimal rate; f has the kink
    of P'' and Q'' at x = c.
    """
    material = MATERIAL
    lam, mu = material.lam, material.mu

    def displacement(x):
        P, _, _, Q, _, _ = _pieces(x[:, 0])
        y = x[:, 1]
        return np.column_stack([A * P + y * (B - K * Q), -D * y])

    def gradient(x):
        _, P1, _, Q, Q1, _ = _pieces(x[:, 0])
        y = x[:, 1]
        g = np.zeros((x.shape[0], 2, 2))
        g[:, 0, 0] = A * P1 - y * K * Q1
        g[:, 0, 1] = B - K * Q
        g[:, 1, 1] = -D
        return g

    def body_force(x):
        _, _, P2, _, Q1, Q2 = _pieces(x[:, 0])
        y = x[:, 1]
        return np.column_stack([-(lam + 2 * mu) * (A * P2 - y * K * Q2), (lam + mu) * K * Q1])

    def traction(x, normal):
        return np.einsum("...ij,...j->...i", stress(material, gradient(x)), normal)

    return ContactProblem(
        mesh=rectangle(nx=nx, ny=nx),
        material=material,
        conditions={
            "top": Dirichlet(displacement),
            "left": Neumann(traction),
            "right": Neumann(traction),
            "bottom": Contact(gap=0.0, friction=Tresca(mu * B)),
        },
        body_force=body_force,
        exact=ExactSolution(displacement, gradient),
        name="manufactured-tresca",
    )


def test_manufactured_solution_satisfies_the_tresca_law():
    """The docstring's claims, on a fine sample of Γ_C: full normal contact with σ_nn < 0,
    |λ_t| < s and u_t = 0 on [0, c), λ_t = s and u_t > 0 on (c, 1]."""
    pb = manufactured_tresca()
    x = np.column_stack([np.linspace(0.0, 1.0, 1001), np.zeros(1001)])
    u, sigma = pb.exact.displacement(x), stress(MATERIAL, pb.exact.gradient(x))
    s = MATERIAL.mu * B
    stick, slip = x[:, 0] < C, x[:, 0] > C
    lam_t = sigma[:, 0, 1]
    assert np.all(sigma[:, 1, 1] < 0) and np.all(u[:, 1] == 0)
    assert np.all(np.abs(lam_t[stick]) < s) and np.all(u[stick, 0] == 0)
    np.testing.assert_allclose(lam_t[slip], s, rtol=1e-14)
    assert np.all(u[slip, 0] > 0)


def _sweep(levels: int):
    pb = manufactured_tresca()
    mesh, rows = pb.mesh, []
    for _ in range(levels):
        r = solve(pb, mesh)
        est = estimate(r)
        rows.append((r.ndof, est.eta, r.errors()["error_energy"], est.eta_terms, r))
        mesh = refine_uniform(mesh).mesh
    return rows


@pytest.mark.slow
def test_manufactured_stick_slip_estimator_and_error_decay_alike():
    """Uniform refinement: η_h and the energy error both like Ndof⁻¹, efficiency bounded."""
    rows = _sweep(5)
    print("\n  Ndof        η_h      error   η/error   η4        η8        stick slip")
    for n, eta, err, terms, r in rows:
        states = np.bincount(r.state, minlength=3)
        print(
            f"{n:6d}  {eta:.3e}  {err:.3e}  {eta / err:6.2f}   {terms[3]:.2e}  {terms[7]:.2e}"
            f"  {states[STICK]:4d} {states[SLIP]:4d}"
        )
    ndof = np.array([row[0] for row in rows], float)
    eta = np.array([row[1] for row in rows])
    err = np.array([row[2] for row in rows])
    s_eta, s_err = fitted_slope(ndof, eta, last=3), fitted_slope(ndof, err, last=3)
    print(f"slopes (last 3 levels): eta {s_eta:.3f}, error {s_err:.3f}")
    assert -1.15 <= s_eta <= -0.85, f"η_h slope {s_eta:.3f} not ≈ −1"
    assert -1.15 <= s_err <= -0.85, f"error slope {s_err:.3f} not ≈ −1"
    index = eta / err
    assert index.max() / index.min() < 1.5, f"efficiency index not bounded: {index}"
    # η8 lives at the stick–slip transition: its largest node contribution within two edges
    # of c on every level after the first
    k8 = NODE_TERMS.index("eta_8")
    for _, _, _, _, r in rows[1:]:
        est = estimate(r)
        top = int(np.argmax(est.eta2_node[k8]))
        x_top, h = r.space.node_points[top, 0], r.mesh.edge_length[r.contact.facets].max()
        print(f"largest η8 node contribution at x = {x_top:.4f} (c = {C}, h = {h:.4f})")
        assert abs(x_top - C) < 2 * h, (x_top, h)
    # the discrete solution has both zones: stick nodes left of c, slip nodes right of it
    r = rows[-1][4]
    x = r.space.node_points[r.contact.nodes, 0]
    assert np.all(x[r.state == STICK] < C + 0.05) and np.all(x[r.state == SLIP] > C - 0.05)
    assert (r.state == STICK).sum() > 10 and (r.state == SLIP).sum() > 10


def test_friction_stress_balances_the_tangential_stress():
    """The sign of p_t,h: on the finest mesh ‖σ_t(u_h) + p_t,h‖ is far below ‖σ_t(u_h)‖
    (and ‖σ_t(u_h) − p_t,h‖), and η4 with friction decays like the error."""
    rows = _sweep(4)
    r = rows[-1][4]
    s = MATERIAL.mu * B
    # η4 with p_t,h against the frictionless η4 of the same solution: ‖σ_t‖ ≈ s |Γ_C|^{1/2}
    eta4 = np.array([row[3][3] for row in rows])
    print("η4:", " ".join(f"{v:.3e}" for v in eta4), f" (s = {s:.3e})")
    ndof = np.array([row[0] for row in rows], float)
    slope = fitted_slope(ndof, eta4, last=3)
    print(f"η4 slope {slope:.3f}")
    assert slope < -0.9, f"η4 slope {slope:.3f}"
    flipped = estimate(_with_tangential_force(r, -r.tangential_force)).eta_terms[3]
    print(f"η4 with p_t: {eta4[-1]:.3e}, with −p_t: {flipped:.3e}")
    assert eta4[-1] < 1e-2 * flipped


def _with_tangential_force(r, force):
    from dataclasses import replace

    return replace(r, tangential_force=force)


@pytest.mark.parametrize("friction", [Tresca(0.0), Coulomb(0.0)])
def test_zero_friction_gives_the_frictionless_estimator(friction):
    """F = 0 and s = 0: the same η_k and element indicators as without friction, η8 = 0."""
    free = _block(None)
    pb = _block(friction)
    a, b = estimate(solve(free)), estimate(solve(pb))
    print(
        type(friction).__name__,
        "max |Δη_k| / η_h:",
        np.abs(a.eta_terms - b.eta_terms).max() / a.eta,
    )
    np.testing.assert_allclose(b.eta_terms, a.eta_terms, rtol=1e-10, atol=1e-13 * a.eta)
    # cell by cell; η7 apart: the H^{1/2} norm of the round-off penetrations of two solutions
    # that agree to 1e-14 moves between cells (its total agrees as above)
    rows = [k for k, name in enumerate(TERMS) if name != "eta_7"]
    atol = 1e-14 * a.eta**2
    np.testing.assert_allclose(b.eta2_cell[rows], a.eta2_cell[rows], rtol=1e-9, atol=atol)
    assert b.eta_terms[TERMS.index("eta_8")] == 0.0


def test_indicators_sum_to_eta_and_dirichlet_nodes_carry_nothing():
    """With friction the cell indicators sum to η_h², the node rows to their terms, η8 ≥ 0;
    Dirichlet end points of Γ_C (a contact part meeting a clamped part) carry no η8."""
    pb = _block(Coulomb(0.4), clamp_ends=True)
    r = solve(pb)
    est = estimate(r)
    assert est.eta2_cell.shape == (len(TERMS), r.mesh.n_cells)
    assert est.eta2_node.shape == (len(NODE_TERMS), r.space.n_nodes)
    np.testing.assert_allclose(est.eta2.sum(), est.eta**2, rtol=1e-13)
    k8 = NODE_TERMS.index("eta_8")
    np.testing.assert_allclose(est.eta2_node[k8].sum(), est.eta2_terms[-1], rtol=1e-12)
    assert est.eta2_node.min() >= 0 and est.eta_terms[-1] > 0
    np.testing.assert_array_equal(est.eta2_node[:, r.dirichlet_nodes], 0.0)


@pytest.mark.parametrize("c", [1e100, 1e-100])
def test_frictional_terms_scale_with_young_modulus(c):
    """Coulomb friction, the material scaled by c (the clamped top drives the block, so u_h
    does not change): η4 → c η4 and η8 → c^{1/2} η8 (η8² is a stress times a displacement
    times a length), with no overflow when E is extreme."""
    import dataclasses

    pb = _block(Coulomb(0.3), nx=8)
    big = dataclasses.replace(pb, material=Material.from_lame(c * MATERIAL.lam, c * MATERIAL.mu))
    e0 = estimate(solve(pb))
    with np.errstate(over="raise", invalid="raise", divide="raise"):
        e = estimate(solve(big))
    k4, k8 = TERMS.index("eta_4"), TERMS.index("eta_8")
    assert e0.eta_terms[k8] > 0
    np.testing.assert_allclose(e.eta_terms[k4], c * e0.eta_terms[k4], rtol=1e-9)
    np.testing.assert_allclose(e.eta_terms[k8], np.sqrt(c) * e0.eta_terms[k8], rtol=1e-9)


def _block(friction, clamp_ends: bool = False, nx: int = 16) -> ContactProblem:
    """The block (0, 2) × (0, 1) pressed down and sideways by its clamped top onto a rigid
    cylinder below: contact in the middle, stick and slip zones (as in
    tests/contact/test_frictional.py)."""
    base = rectangle(0.0, 2.0, 0.0, 1.0, nx=nx, ny=nx // 2)
    parts = {
        "left": lambda x: np.abs(x[:, 0]) < 1e-12,
        "right": lambda x: np.abs(x[:, 0] - 2.0) < 1e-12,
        "top": lambda x: np.abs(x[:, 1] - 1.0) < 1e-12,
        "bottom": lambda x: np.abs(x[:, 1]) < 1e-12,
    }
    mesh = Mesh.from_arrays(base.points, base.cells, parts)
    side = Dirichlet((0.0, 0.0)) if clamp_ends else Neumann()
    return ContactProblem(
        mesh,
        MATERIAL,
        {
            "left": side,
            "right": side,
            "top": Dirichlet((0.012, -0.02)),
            "bottom": Contact(obstacle=Disc((1.0, -12.5), 12.5), friction=friction),
        },
    )


@pytest.mark.slow
def test_adaptive_coulomb_rate_and_where_it_refines():
    """Coulomb (F = 0.3) on the pressed block: η_h like Ndof⁻¹ over the last levels; the
    smallest contact edges sit at the ends of the contact zone and at the stick–slip
    transitions."""
    pb = _block(Coulomb(0.3), nx=8)
    levels = list(adaptive(pb, max_ndof=25_000, theta=0.4))
    print("\nlevel  Ndof    η_h       η4        η8        stick slip  kkt_t")
    for lv in levels:
        r = lv.record
        print(
            f"{r.level:3d} {r.ndof:6d}  {r.eta:.3e}  {r.eta_4:.2e}  {r.eta_8:.2e}  "
            f"{r.n_stick:4d} {r.n_slip:4d}  {r.kkt_tangential_complementarity:.1e}"
        )
    ndof = np.array([lv.record.ndof for lv in levels], float)
    eta = np.array([lv.record.eta for lv in levels])
    slope = fitted_slope(ndof, eta, last=5)
    print(f"η_h slope over the last 5 levels: {slope:.3f}")
    assert slope <= -0.9, f"η_h slope {slope:.3f} > −0.9"
    last = levels[-1].result
    x, points = _transitions(last)
    mesh, cs = last.mesh, last.contact
    length = mesh.edge_length[cs.facets]
    mid = 0.5 * (
        mesh.points[mesh.edges[cs.facets, 0], 0] + mesh.points[mesh.edges[cs.facets, 1], 0]
    )
    finest = mid[np.argsort(length)[:12]]
    print("contact ends and stick–slip transitions at x =", np.round(points, 4))
    print(
        "the 12 smallest contact edges (length",
        f"{np.sort(length)[:12].max():.1e}) at x =",
        np.round(np.sort(finest), 4),
    )
    near = np.abs(finest[:, None] - points[None, :]).min(axis=1)
    assert np.all(near < 0.02), f"small edges away from the transitions: {finest[near >= 0.02]}"
    # every transition point attracts refinement: an edge at most 4× the smallest within 0.01
    for p in points:
        close = np.abs(mid - p) < 0.01
        assert close.any() and length[close].min() <= 4 * length.min(), p
    assert x.size


def _transitions(r):
    """The contact nodes' abscissae in boundary order and the points where the state changes
    (midway between the two nodes): contact ends and stick–slip transitions."""
    x = r.space.node_points[r.contact.nodes, 0]
    order = np.argsort(x)
    x, state = x[order], r.state[order]
    change = np.flatnonzero(state[1:] != state[:-1])
    return x, 0.5 * (x[change] + x[change + 1])


def test_friction_work_along_straight_edges_given_as_quadratic_edges():
    """η8's integrals with the node points of straight edges (the quadratic-edge path, 5 Gauss
    points with |x'(t)|) equal the straight ones; a stick edge (u_t = 0) and a slip edge with
    the stress at its bound along the slip give 0; a slip against the stress gives 2 s ∫|u_t|."""
    rng = np.random.default_rng(3)
    a, b = rng.uniform(-1, 1, (20, 2)), rng.uniform(-1, 1, (20, 2))
    points = np.stack([a, b, 0.5 * (a + b)], axis=1)
    length = np.hypot(*(b - a).T)
    slip, force, bound = rng.normal(size=(3, 20, 3))
    bound = np.abs(bound)
    straight = friction_work(slip, force, bound, length)
    curved = friction_work(slip, force, bound, length, points)
    np.testing.assert_allclose(curved, straight, rtol=1e-10, atol=1e-14)
    assert straight.min() >= 0
    # against a dense midpoint rule over each third (independent of the cuts at the kinks)
    from signorini.fem.p2 import edge_basis

    n = 30_000
    for k, (lo, hi) in enumerate(((0, 1 / 3), (2 / 3, 1), (1 / 3, 2 / 3))):
        t = lo + (hi - lo) * (np.arange(n) + 0.5) / n
        u, p, s = (v @ edge_basis(t).T for v in (slip, force, bound))
        dense = length * (hi - lo) * (np.maximum(s, np.abs(p)) * np.abs(u) - p * u).mean(axis=1)
        np.testing.assert_allclose(straight[:, k], dense, rtol=1e-6, atol=1e-9)
    one = np.ones((1, 3))
    assert np.all(friction_work(0 * one, 0.5 * one, one, np.ones(1)) == 0)
    np.testing.assert_allclose(friction_work(2 * one, one, one, np.ones(1)), 0, atol=1e-15)
    # slip against the friction stress: max(1, 1)·2 − (−1)·2 = 4 per unit length
    np.testing.assert_allclose(friction_work(2 * one, -one, one, np.ones(1)).sum(), 4.0)


def test_coulomb_on_a_curved_contact_part():
    """A half-disc (R = 1) pressed down and sideways onto the rigid half-plane y ≤ 0 with
    Coulomb friction on its arc: η8 along the quadratic edges, indicators summing to η_h²."""
    from tests.estimator.test_curved import half_disc

    pb = ContactProblem(
        half_disc(n=8),
        MATERIAL,
        {
            "top": Dirichlet((0.002, -0.01)),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(0.3)),
        },
    )
    r = solve(pb)
    est = estimate(r)
    states = np.bincount(r.state, minlength=3)
    print("states", states, "terms", np.array2string(est.eta_terms, precision=2))
    assert states[STICK] > 0 and states[SLIP] > 0
    assert est.eta_terms[TERMS.index("eta_8")] > 0
    np.testing.assert_allclose(est.eta2.sum(), est.eta**2, rtol=1e-13)
