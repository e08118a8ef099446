"""Hertz contact: an elastic half-disc pressed onto a rigid plane (plane strain).

The body is the half-disc of radius R below its flat side (:func:`signorini.mesh.builders.
half_disc`: centre (0, R), the arc touching the plane y = 0 at the origin, the arc carrying
its circle so that its cells are isoparametric). The flat top is moved down by (0, −δ); the
arc meets the rigid half-plane y ≤ 0, given as a shape, so every constrained node z gets the
plane's normal and its distance to the plane (docs/method.md, *Obstacles as shapes*).

For a cylinder on a rigid plane, Hertz's theory (small contact, a ≪ R) gives, with the total
contact force P per unit thickness and the plane-strain modulus E* = E / (1 − ν²),

    a = √(4 P R / (π E*)),   p0 = 2 P / (π a),   p(x) = p0 √(1 − x² / a²)   (|x| ≤ a),

x measured along the plane from the centre of the contact zone. Each level is compared with
the Hertz solution of its own total force P (:func:`hertz_metrics`): the half-width from the
consistent nodal forces, a_h = 2 √(Σ Λ_z x_z² / Σ Λ_z) (exact for the Hertz profile, since
∫ x² p dx / ∫ p dx = a² / 4 and x² is a P2 function), and the peak pressure max_z p_z. The
finite body makes both differ from Hertz by about 0.37 (a/R)² (measured at a/R = 0.099:
−0.377 % in a, +0.301 % in p0; docs/method.md, *The Hertz and punch examples*).
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..mesh.builders import half_disc
from ..mesh.curves import Circle
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Dirichlet
from ..problem.obstacles import HalfPlane
from .metrics import Metrics, PressureComparison

__all__ = [
    "DEPTH",
    "HERTZ_METRICS",
    "beside_hertz",
    "hertz",
    "hertz_contact",
    "hertz_metrics",
    "hertz_pressure",
    "hertz_solution",
]

#: the prescribed displacement of the top, δ / R: gives a / R ≈ 0.099 with ν = 0.3
DEPTH = 0.015


def hertz(
    radius: float = 1.0,
    depth: float | None = None,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    rings: int = 4,
    h_bottom: float | None = None,
    grading: float = 0.5,
    curved: bool = True,
    angle: float = 0.0,
) -> ContactProblem:
    """The Hertz problem: an elastic half-disc pressed by its flat top onto a rigid plane.

    Defaults: R = 1, δ = 0.015 R (:data:`DEPTH`), E = 1, ν = 0.3 (consistent units; the
    problem is linear in E, and a / R depends on δ / R and ν only): a / R ≈ 0.1.

    Parameters
    ----------
    radius : float
        R, the radius of the half-disc (length units).
    depth : float, optional
        δ, the downward displacement prescribed on the flat top (length units); default
        ``DEPTH * radius``.
    young, poisson : float
        E (stress units) and ν of the body.
    rings, h_bottom, grading : optional
        The initial mesh, :func:`~signorini.mesh.builders.half_disc` ``(radius, rings,
        h_bottom=h_bottom, grading=grading)``: ``h_bottom`` grades it towards the first point
        of contact.
    curved : bool
        Whether the arc carries its circle (isoparametric cells, new points on the circle);
        ``False`` keeps the same vertices with straight chords between them.
    angle : float
        The whole problem (mesh, circle, plane, prescribed displacement) rotated by this
        angle (radians, counter-clockwise) about the origin, the first point of contact.

    Returns
    -------
    ContactProblem
        Named ``"hertz"``; parts ``"top"`` (Dirichlet (0, −δ)) and ``"arc"`` (contact with
        ``HalfPlane((0, 0), (0, 1))``, rotated with the problem).
    """
    depth = DEPTH * radius if depth is None else depth
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s], [s, c]])
    mesh = half_disc(radius, rings, h_bottom=h_bottom, grading=grading)
    mesh = Mesh(
        mesh.points @ rotation.T,
        mesh.cells,
        mesh.boundary,
        mesh.boundary_part,
        mesh.part_names,
    )
    if curved:
        mesh = mesh.with_curve("arc", Circle(rotation @ [0.0, radius], radius))
    return ContactProblem(
        mesh=mesh,
        material=Material.from_young(young, poisson),
        conditions={
            "top": Dirichlet(tuple(rotation @ [0.0, -depth])),
            "arc": Contact(obstacle=HalfPlane((0.0, 0.0), rotation @ [0.0, 1.0])),
        },
        name="hertz",
    )


def hertz_solution(force: float, radius: float, material: Material) -> tuple[float, float]:
    """Hertz's half-width ``a = √(4 P R / (π E*))`` and peak pressure ``p0 = 2 P / (π a)``.

    Parameters
    ----------
    force : float
        P, the total contact force per unit thickness (force / length).
    radius : float
        R, the cylinder's radius (length units).
    material : Material
        Gives the plane-strain modulus ``E* = E / (1 − ν²)``.
    """
    e_star = material.young / (1.0 - material.poisson**2)
    a = float(np.sqrt(4.0 * force * radius / (np.pi * e_star)))
    return a, 2.0 * force / (np.pi * a)


def hertz_contact(result: ContactResult) -> dict[str, object]:
    """The contact zone of a solution of :func:`hertz`, measured along the plane.

    Returns
    -------
    dict
        ``force`` P = Σ Λ_z; ``centre`` (2,) the force-weighted mean of the constrained nodes;
        ``tangent`` (2,) the plane's direction; ``x`` (k,) each constrained node's coordinate
        along the plane from ``centre``; ``a`` the half-width 2 √(Σ Λ_z x_z² / Σ Λ_z);
        ``p0`` the peak consistent pressure max p_z; ``radius`` R (half the flat top).

    Raises
    ------
    ValueError
        If the body does not touch the plane (no contact force).
    """
    if not result.total_contact_force > 0:
        raise ValueError("hertz: the half-disc does not touch the plane (no contact force)")
    problem = result.problem
    normal = problem.conditions["arc"].obstacle.normal
    tangent = np.array([normal[1], -normal[0]])
    force = result.contact_force
    total = float(force.sum())
    z = result.space.node_points[result.contact.nodes]
    centre = force @ z / total
    x = (z - centre) @ tangent
    return {
        "force": total,
        "centre": centre,
        "tangent": tangent,
        "x": x,
        "a": float(2.0 * np.sqrt(force @ x**2 / total)),
        "p0": float(np.max(result.pressure)),
        "radius": 0.5 * problem.mesh.part_measure("top"),
    }


def hertz_metrics(result: ContactResult) -> dict[str, float]:
    """Half-width and peak pressure of a level, and their errors against Hertz with the
    level's own total force P (:func:`hertz_contact`, :func:`hertz_solution`); NaN without
    contact."""
    if not result.total_contact_force > 0:
        return dict.fromkeys(("a", "p0", "a_rel_error", "p0_rel_error"), float("nan"))
    zone = hertz_contact(result)
    a, p0 = hertz_solution(zone["force"], zone["radius"], result.problem.material)
    return {
        "a": zone["a"],
        "p0": zone["p0"],
        "a_rel_error": zone["a"] / a - 1.0,
        "p0_rel_error": zone["p0"] / p0 - 1.0,
    }


def hertz_pressure(result: ContactResult) -> PressureComparison:
    """The computed pressure p_z along the arc beside Hertz's p0 √(1 − x² / a²) of the same
    total force, x along the plane from the contact zone's centre."""
    zone = hertz_contact(result)
    a, p0 = hertz_solution(zone["force"], zone["radius"], result.problem.material)
    profile = result.contact_profile("arc")
    x = (profile.points - zone["centre"]) @ zone["tangent"]
    return beside_hertz(
        x, profile.pressure, (a, p0), f"hertz: contact pressure, {result.ndof} unknowns"
    )


def beside_hertz(
    x: np.ndarray, pressure: np.ndarray, hertz: tuple[float, float], title: str
) -> PressureComparison:
    """The pressures ``pressure`` at ``x`` (along the contact, from its centre) within 2a of
    the centre, beside Hertz's ``p0 √(1 − x² / a²)`` of ``hertz = (a, p0)``."""
    a, p0 = hertz
    near = np.abs(x) <= 2.0 * a
    x_ref = np.linspace(-a, a, 401)
    return PressureComparison(
        x=x[near],
        pressure=pressure[near],
        x_reference=x_ref,
        reference=p0 * np.sqrt(np.maximum(1.0 - (x_ref / a) ** 2, 0.0)),
        label=rf"Hertz, $a$ = {a:.4g}, $p_0$ = {p0:.4g}",
        title=title,
    )


#: The Hertz example's columns of ``history.csv`` and its pressure figure.
HERTZ_METRICS = Metrics(
    measure=hertz_metrics,
    columns={
        "a": "half-width of the contact zone from the nodal forces, 2 √(Σ Λ_z x_z² / Σ Λ_z), "
        "length units",
        "p0": "peak consistent contact pressure max p_z, stress units",
        "a_rel_error": "a / a_Hertz − 1, a_Hertz = √(4 P R / (π E*)) with P the level's total "
        "contact force, no unit",
        "p0_rel_error": "p0 / p0_Hertz − 1, p0_Hertz = 2 P / (π a_Hertz), no unit",
    },
    pressure=hertz_pressure,
)
