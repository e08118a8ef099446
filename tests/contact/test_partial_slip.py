"""The partial-slip problem of Cattaneo and Mindlin, measured at the solve level.

An elastic half-disc (R = 1, E = 1, ν = 0.49) stands on its arc on the rigid plane y = 0
with Coulomb friction F = 0.5. Its flat top is pressed down by δ (step 1), then pulled
sideways by ξ at constant δ (steps 2, 3), then moved back to ξ/2 (step 4), a load path solved
by :func:`signorini.contact.load_path.solve_path`. The mesh is graded towards the contact,
``h = 2⁻⁸`` on it, isoparametric on the arc.

Measured from the discrete solution: the normal and tangential resultants ``P = Σ Λ_n`` and
``Q = Σ Λ_t``, the contact half-width ``a = 2 √(Σ Λ_n (x − x̄)² / P)`` (for Hertz's
``p ∝ √(1 − x²/a²)`` the second moment is a²/4), and the stick zone half-width c, half the
distance between its two ends, each end halfway between the last STICK node and the first
SLIP node. The theory for a half-plane with Dundurs β = 0 (nearly so here: β = (1 − 2ν) /
(2 (1 − ν)) = 0.0196 against a rigid plane, so that the normal and tangential problems nearly
uncouple; a/R ≈ 0.08):

- loading (Cattaneo–Mindlin): ``c/a = √(1 − Q/(F P))``, slip at both edges along Q;
- unloading from Q* to Q (Mindlin): stick where ``|x| < c'``, slip against the loading
  direction outside, ``c'/a = √(1 − (Q* − Q)/(2 F P))``.

Tolerance: the stick ends are located to a node spacing (h/2, the P2 nodes) at each end, so
c/a is asserted within h/a (0.048); observed 0.005 and less. The press alone leaves slip at
the edges, c/a = 0.954, 0.943, 0.937 for h = 2⁻⁷, 2⁻⁸, 2⁻⁹: not from β (it is 0.916 at
ν = 0.499, β = 0.002) but from the body, which is not the half-space of the theory (a/R =
0.08, clamped top); it is smaller with F = 1 (0.966) and is overtaken by the pull's slip.
"""

from __future__ import annotations

import numpy as np
import pytest
from contact_problems import graded_half_disc

from signorini.contact.load_path import solve_path
from signorini.contact.solution import SLIP, STICK, ContactResult, solve
from signorini.fem.material import Material
from signorini.problem import Contact, ContactProblem, Coulomb, Dirichlet
from signorini.problem.obstacles import HalfPlane

RADIUS, NU, COEFFICIENT = 1.0, 0.49, 0.5
H_CONTACT = 2.0**-8
DELTA = 0.01
PULL = (0.004, 0.0075)
BETA = (1 - 2 * NU) / (2 * (1 - NU))


@pytest.fixture(scope="module")
def mesh():
    return graded_half_disc(RADIUS, H_CONTACT, zone=0.1)


@pytest.fixture(scope="module")
def path(mesh):
    """The load path: press, pull to ``PULL[0]`` and ``PULL[1]``, move back to half of it."""
    steps = [0.0, *PULL, PULL[-1] / 2]
    return steps, solve_path([half_disc_problem(mesh, xi) for xi in steps])


def half_disc_problem(mesh, shift: float, push: float = DELTA, nu: float = NU) -> ContactProblem:
    """The half-disc with its top displaced by (shift, −push) on the rigid plane y ≤ 0."""
    return ContactProblem(
        mesh,
        Material.from_young(1.0, nu),
        {
            "top": Dirichlet((shift, -push)),
            "arc": Contact(
                obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(COEFFICIENT)
            ),
        },
    )


def measure(res: ContactResult) -> dict[str, float]:
    """P, Q, a, c (stick zone half-width) and the slip directions outside the stick zone."""
    x = res.space.node_points[res.contact.nodes, 0]
    lam_n, lam_t = res.contact_force, res.tangential_force
    P, Q = lam_n.sum(), lam_t.sum()
    centre = (lam_n * x).sum() / P
    a = 2 * np.sqrt((lam_n * (x - centre) ** 2).sum() / P)
    order = np.argsort(x)
    xs, state, direction = x[order], res.state[order], res.report.direction[order]
    stick = np.flatnonzero(state == STICK)
    first, last = stick[0], stick[-1]
    assert stick.size == last - first + 1, "the stick zone is not one interval"
    assert state[first - 1] == SLIP and state[last + 1] == SLIP
    c = 0.25 * (xs[last] + xs[last + 1] - xs[first] - xs[first - 1])
    slip = state == SLIP
    return {"P": P, "Q": Q, "a": a, "c": c, "directions": set(direction[slip].tolist())}


@pytest.mark.slow
def test_the_stick_zone_follows_cattaneo_mindlin_on_loading_and_unloading(path):
    """Press, pull twice, move back halfway: c/a on loading and c'/a on unloading against
    the theory, the slip directions, and KKT of both laws at every step."""
    h = H_CONTACT
    steps, results = path
    for res in results:
        assert res.report.kkt.max < 1e-10, res.report.kkt
    m = [measure(res) for res in results]
    a = m[0]["a"]
    print(
        f"\nβ = {BETA:.4f}, F = {COEFFICIENT}, a = {a:.4f} (a/R = {a / RADIUS:.3f}), "
        f"h/a = {h / a:.3f}"
    )
    print(f"press: P = {m[0]['P']:.5e}, c/a = {m[0]['c'] / a:.4f} (edge slip: the finite body)")
    assert 0.05 < a / RADIUS < 0.1
    for k, xi in enumerate(PULL, start=1):
        ratio = m[k]["Q"] / (COEFFICIENT * m[k]["P"])
        theory = np.sqrt(1 - ratio)
        measured = m[k]["c"] / m[k]["a"]
        print(
            f"pull ξ = {xi}: Q/(F P) = {ratio:.4f}, c/a measured {measured:.4f}, "
            f"Cattaneo–Mindlin {theory:.4f}, difference {measured - theory:+.4f}"
        )
        assert abs(measured - theory) <= h / a, (measured, theory, h / a)
        assert m[k]["directions"] == {1}, m[k]["directions"]  # both edges slip along Q > 0
    top, back = m[len(PULL)], m[-1]
    theory = np.sqrt(1 - (top["Q"] - back["Q"]) / (2 * COEFFICIENT * back["P"]))
    measured = back["c"] / back["a"]
    print(
        f"back to ξ = {steps[-1]}: Q* = {top['Q']:.5e}, Q = {back['Q']:.5e}, c'/a measured "
        f"{measured:.4f}, Mindlin {theory:.4f}, difference {measured - theory:+.4f}"
    )
    assert abs(measured - theory) <= h / a, (measured, theory, h / a)
    assert back["directions"] == {-1}, back["directions"]  # reversed slip at both edges


@pytest.mark.slow
def test_coulomb_friction_is_path_dependent(mesh, path):
    """The static (one-step) solve of a load against the end of a load path.

    - Press then pull (twice): the static solution of the pulled state is the path's end
      state (the press step leaves its stick nodes at u_t = 0, the pulls only shrink the
      stick zone, and at the end every slipping node has moved along its friction force from
      where it started, so the path's end state satisfies the static law).
    - Press, pull, move back halfway: the path ends with reversed slip at the edges and a
      larger stick zone than the static solve of the same final load, and a smaller Q.
    - Proportional loading (push and pull grow together in 6 steps): the contact grows and
      its new nodes stick about where they touch, so almost all of it sticks
      (Mindlin–Deresiewicz) where the static solve of the same load slips at c/a ≈ 0.55.
    """
    xi = PULL[-1]
    pulled, back = path[1][-2:]
    static_pulled = solve(half_disc_problem(mesh, xi))
    du = np.abs(static_pulled.u - pulled.u).max() / np.abs(pulled.u).max()
    print(f"\npress, pull: static against path max|Δu|/max|u| = {du:.1e}")
    assert du < 1e-10, du

    static = solve(half_disc_problem(mesh, xi / 2))
    mb, ms = measure(back), measure(static)
    print(
        f"press, pull, back: Q path {mb['Q']:.5e}, static {ms['Q']:.5e} "
        f"({(ms['Q'] - mb['Q']) / mb['Q']:+.1%}); c/a path {mb['c'] / mb['a']:.4f} slip "
        f"{mb['directions']}, static {ms['c'] / ms['a']:.4f} slip {ms['directions']}"
    )
    assert mb["directions"] == {-1} and ms["directions"] == {1}
    assert mb["c"] - ms["c"] > H_CONTACT, (mb["c"], ms["c"])
    assert (ms["Q"] - mb["Q"]) / mb["Q"] > 0.02

    t = np.arange(1, 7) / 6
    proportional = solve_path([half_disc_problem(mesh, xi * s, DELTA * s) for s in t])[-1]
    mp, ms = measure(proportional), measure(static_pulled)
    print(
        f"proportional: Q/(F P) = {mp['Q'] / (COEFFICIENT * mp['P']):.4f}, c/a "
        f"{mp['c'] / mp['a']:.4f}; static of the same load: Q/(F P) = "
        f"{ms['Q'] / (COEFFICIENT * ms['P']):.4f}, c/a {ms['c'] / ms['a']:.4f}"
    )
    assert mp["c"] / mp["a"] > 0.9 and ms["c"] / ms["a"] < 0.6
    assert (ms["Q"] - mp["Q"]) / mp["Q"] > 0.02


@pytest.mark.slow
def test_with_coupling_the_stick_zone_departs_from_cattaneo_mindlin(mesh):
    """The same press and pull with ν = 0.3 (β = 0.286): the normal and tangential problems
    couple, and c/a departs from √(1 − Q/(F P)) by far more than h/a, so the agreement at
    ν = 0.49 is not built into the measurement."""
    nu = 0.3
    beta = (1 - 2 * nu) / (2 * (1 - nu))
    steps = solve_path([half_disc_problem(mesh, xi, nu=nu) for xi in (0.0, PULL[-1])])
    m, pressed = measure(steps[-1]), measure(steps[0])
    theory = np.sqrt(1 - m["Q"] / (COEFFICIENT * m["P"]))
    measured = m["c"] / m["a"]
    print(
        f"\nν = {nu}, β = {beta:.3f}: press c/a {pressed['c'] / pressed['a']:.3f}; pull "
        f"c/a measured {measured:.4f}, Cattaneo–Mindlin {theory:.4f}"
    )
    assert theory - measured > 2 * H_CONTACT / m["a"], (measured, theory)
