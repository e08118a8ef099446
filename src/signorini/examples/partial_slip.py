"""Partial slip (Cattaneo–Mindlin): an elastic cylinder pressed on a rigid plane with Coulomb
friction, then pulled sideways by a force Q < F·P.

The body is the Hertz half-disc (:func:`~signorini.examples.hertz.hertz`: R = 1, centre
(0, R), its arc on the rigid half-plane y ≤ 0 as a shape, isoparametric cells along the arc)
with E = 1 and ν = 0.49, so that Dundurs' β = (1 − 2ν)/(2(1 − ν)) = 0.0196 against a rigid
plane is small and the normal and tangential problems nearly uncouple; Coulomb friction
F = 0.5 on the arc. Load path, two quasi-static steps on one mesh (docs/method.md, *Load
paths*): the flat top is moved by (0, −δ), δ = 0.01 R (press: a/R ≈ 0.082), then by
(ξ, −δ), ξ = 0.0075 R (pull, at constant push), which gives Q/(F P) ≈ 0.70. Coulomb friction
is path-dependent, so every level of the adaptive loop solves the whole path on its mesh and
estimates and marks on the last step (:func:`signorini.adaptive`, ``path=``).

Theory for a half-plane with β = 0 (Cattaneo 1938, Mindlin 1949): the contact zone |x| < a is
Hertz's; the pull leaves a central stick zone |x| < c with

    c/a = √(1 − Q/(F P)),

slip along Q on c < |x| < a. Measured per level (:data:`PARTIAL_SLIP_METRICS`): P = Σ Λ_n,
Q = Σ Λ_t, a = 2 √(Σ Λ_n (x − x̄)² / P) (for p ∝ √(1 − x²/a²) the second moment is a²/4), and
the stick zone's half-width c, its ends halfway between the outermost STICK nodes and their
neighbours outside.
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import SLIP, STICK, ContactResult
from ..fem.material import Material
from ..mesh.builders import half_disc
from ..mesh.curves import Circle
from ..problem import Contact, ContactProblem, Coulomb, Dirichlet
from ..problem.obstacles import HalfPlane
from .hertz import hertz_solution
from .metrics import Metrics, PressureComparison

__all__ = [
    "PARTIAL_SLIP_METRICS",
    "partial_slip",
    "partial_slip_metrics",
    "partial_slip_path",
]

#: ν of the cylinder: Dundurs β = (1 − 2ν)/(2(1 − ν)) = 0.0196 against the rigid plane
POISSON = 0.49
#: the Coulomb coefficient F on the arc
COEFFICIENT = 0.5
#: the press δ / R and the pull ξ / R of the flat top
PRESS, PULL = 0.01, 0.0075


def partial_slip_path(
    radius: float = 1.0,
    *,
    coefficient: float = COEFFICIENT,
    press: float = PRESS,
    pull: float = PULL,
    poisson: float = POISSON,
    h_bottom: float = 0.02,
) -> list[ContactProblem]:
    """The load path of the partial-slip problem: press, then pull at constant push.

    Parameters
    ----------
    radius : float
        R, the half-disc's radius (length units).
    coefficient : float
        Coulomb's F on the arc.
    press, pull : float
        δ / R and ξ / R: the flat top is moved by (0, −δ R), then by (ξ R, −δ R).
    poisson : float
        ν of the body (E = 1; the problem is linear in E).
    h_bottom : float
        Largest cell diameter at the first point of contact of the initial mesh, relative to
        R (:func:`~signorini.mesh.builders.half_disc`, ``rings=4``, ``grading=0.5``); the
        default 0.02 puts about 8 contact edges under a ≈ 0.082 R.

    Returns
    -------
    list of ContactProblem
        The two steps on one mesh, named ``"partial-slip"``: parts ``"top"`` (Dirichlet) and
        ``"arc"`` (contact with ``HalfPlane((0, 0), (0, 1))``, ``Coulomb(coefficient)``).
    """
    mesh = half_disc(radius, 4, h_bottom=h_bottom * radius, grading=0.5).with_curve(
        "arc", Circle((0.0, radius), radius)
    )
    material = Material.from_young(1.0, poisson)
    contact = Contact(obstacle=HalfPlane((0.0, 0.0), (0.0, 1.0)), friction=Coulomb(coefficient))
    return [
        ContactProblem(
            mesh=mesh,
            material=material,
            conditions={"top": Dirichlet((xi * radius, -press * radius)), "arc": contact},
            name="partial-slip",
        )
        for xi in (0.0, pull)
    ]


def partial_slip(**kwargs) -> ContactProblem:
    """The last step of :func:`partial_slip_path` (the pulled half-disc), with the same
    arguments. Solved alone it is the static (one-step) problem; the command line and the
    adaptive loop solve it after the press (``adaptive(partial_slip(), path=
    partial_slip_path()[:-1])``)."""
    return partial_slip_path(**kwargs)[-1]


def partial_slip_metrics(result: ContactResult) -> dict[str, float]:
    """A level's stick zone against Cattaneo–Mindlin.

    Returns
    -------
    dict
        ``a`` (length units), ``c_over_a`` (c/a with c the stick zone's half-width; 0 if no
        node sticks), ``c_over_a_theory`` = √(1 − Q/(F P)) and ``q_over_fp`` = Q/(F P);
        NaN without contact.
    """
    keys = ("a", "c_over_a", "c_over_a_theory", "q_over_fp")
    lam_n, lam_t = result.contact_force, result.tangential_force
    total = float(lam_n.sum())
    if not total > 0:
        return dict.fromkeys(keys, float("nan"))
    coefficient = next(
        c.friction.coefficient
        for c in result.problem.conditions.values()
        if isinstance(c, Contact) and c.friction is not None
    )
    x = result.space.node_points[result.contact.nodes, 0]
    centre = float(lam_n @ x) / total
    a = 2.0 * np.sqrt(float(lam_n @ (x - centre) ** 2) / total)
    order = np.argsort(x)
    xs = x[order]
    stick = np.flatnonzero(result.state[order] == STICK)
    c = 0.0
    if stick.size:
        first, last = stick[0], stick[-1]
        left = xs[first] if first == 0 else 0.5 * (xs[first] + xs[first - 1])
        right = xs[last] if last == xs.size - 1 else 0.5 * (xs[last] + xs[last + 1])
        c = 0.5 * (right - left)
    ratio = float(lam_t.sum()) / (coefficient * total)
    return {
        "a": float(a),
        "c_over_a": float(c / a),
        "c_over_a_theory": float(np.sqrt(max(1.0 - ratio, 0.0))),
        "q_over_fp": ratio,
    }


def partial_slip_pressure(result: ContactResult) -> PressureComparison:
    """The contact zone zoomed: the computed p_z and p_t,z, the stick and slip nodes, beside
    Hertz's pressure p0 √(1 − x²/a²) and Cattaneo–Mindlin's friction stress
    q(x) = F p0 (√(1 − x²/a²) − (c/a) √(1 − x²/c²) [|x| < c]) with the level's own forces
    (P = Σ Λ_n, Q = Σ Λ_t, c = a √(1 − Q/(F P))); x from the force-weighted centre."""
    lam_n = result.contact_force
    total = float(lam_n.sum())
    if not total > 0:
        raise ValueError("partial-slip: the half-disc does not touch the plane (no contact force)")
    problem = result.problem
    coefficient = problem.conditions["arc"].friction.coefficient
    radius = 0.5 * problem.mesh.part_measure("top")
    a, p0 = hertz_solution(total, radius, problem.material)
    ratio = float(result.tangential_force.sum()) / (coefficient * total)
    c = a * np.sqrt(max(1.0 - abs(ratio), 0.0))
    points = result.space.node_points[result.contact.nodes]
    x = points[:, 0] - float(lam_n @ points[:, 0]) / total
    x_ref = np.linspace(-a, a, 801)
    hertz_p = p0 * np.sqrt(np.maximum(1.0 - (x_ref / a) ** 2, 0.0))
    inner = (c / a) * np.sqrt(np.maximum(1.0 - (x_ref / max(c, 1e-300)) ** 2, 0.0))
    sign = np.sign(float(np.sum(result.tangential_pressure))) or 1.0
    state = np.where(
        result.state == STICK, "stick", np.where(result.state == SLIP, "slip", "inactive")
    )
    return PressureComparison(
        x=x,
        pressure=result.pressure,
        x_reference=x_ref,
        reference=hertz_p,
        label=rf"Hertz, $a$ = {a:.4g}",
        title=f"partial-slip: contact zone, {result.ndof} unknowns",
        tangential=result.tangential_pressure,
        tangential_reference=sign * coefficient * (hertz_p - p0 * inner),
        tangential_label=rf"Cattaneo–Mindlin, $c/a$ = {c / a:.3f}",
        state=state,
        window=(-1.5 * a, 1.5 * a),
    )


#: The partial-slip example's columns of ``history.csv``.
PARTIAL_SLIP_METRICS = Metrics(
    measure=partial_slip_metrics,
    columns={
        "a": "half-width of the contact zone from the nodal forces, 2 √(Σ Λ_n (x − x̄)² / P), "
        "length units",
        "c_over_a": "c/a, c the half-width of the stick zone (its ends halfway between the "
        "outermost stick nodes and their neighbours), no unit",
        "c_over_a_theory": "Cattaneo–Mindlin's c/a = √(1 − Q/(F P)) with the level's P = Σ Λ_n "
        "and Q = Σ Λ_t, no unit",
        "q_over_fp": "Q/(F P), the pull against the force that makes the whole contact slip, "
        "no unit",
    },
    pressure=partial_slip_pressure,
)
