"""``hertz-3d``: an elastic ball pressed onto a rigid plane, its eighth with symmetry rollers,
beside Hertz's theory (docs/method.md, *Three dimensions: contact on faces*, "Hertz in 3D").

The body is the eighth of the ball of radius R about (0, 0, R) below its equator
(:func:`signorini.mesh.builders3d.eighth_ball`: ``x ≥ 0``, ``y ≥ 0``, ``z ≤ R``, the pole at
the origin, the part ``"sphere"`` carrying its sphere so that refinement puts new points on
it). Rollers hold ``u_x = 0`` on ``"x0"`` and ``u_y = 0`` on ``"y0"`` (the symmetry planes);
the flat top ``"z1"`` (``z = R``) is moved down by ``u_z = −δ`` and free to slide (a rigid
frictionless press: the rollers and ``u_z`` leave no rigid motion); the sphere meets the
rigid half-space ``z ≤ 0`` as a shape, so every constrained node gets ``n_z = −e_z``.

For a sphere on a rigid plane, Hertz's theory (a ≪ R), with the total contact force P of the
whole ball and ``E* = E / (1 − ν²)``, gives

    a = (3 P R / (4 E*))^{1/3},   p0 = 3 P / (2 π a²),   p(r) = p0 √(1 − r² / a²),

r the distance from the axis. The eighth carries a quarter of the contact disc, so the
measured total force is ``4 Σ_z Λ_z``. Each level is compared with the Hertz solution of the
prescribed P under force control, of its own measured P under displacement control
(:func:`hertz_3d_metrics`): the radius from the nodal forces,
``a_h = √(5/2 · Σ Λ_z r_z² / Σ Λ_z)`` (exact for the Hertz profile: ``∫ r² p dA / ∫ p dA =
2 a² / 5``, and ``r² = x² + y²`` is quadratic), and the peak pressure, the recovered
(P1-lumped) pressure at the pole node (:meth:`~signorini.contact.face_contact.FaceContactSet.
recovered_pressure`), for either discrete contact condition.

The initial mesh is graded toward the pole (:func:`graded_eighth_ball`): cells of
:func:`~signorini.mesh.builders3d.eighth_ball` are bisected (:func:`~signorini.mesh.refine.
refine_nvb`) until each is no longer than ``h_contact + grading · max(d − patch, 0)``, d its
distance from the pole, so that the contact disc of radius a ≈ 0.1 R is resolved before the
run refines (defaults: h_contact = 0.1 R, grading 0.5, patch = 0.15 R).
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.elasticity3d import assemble_face_load_3d
from ..fem.material import Material
from ..fem.space3d import P2TetSpace
from ..mesh.builders3d import eighth_ball
from ..mesh.mesh import Mesh
from ..mesh.refine import refine_nvb
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from ..problem.conditions import Roller
from ..problem.obstacles3d import HalfSpace
from .metrics import Metrics, PressureComparison

__all__ = [
    "CONTACT_RADIUS_3D",
    "DEPTH_3D",
    "FORCE_3D",
    "HERTZ_3D_METRICS",
    "QUARTERS",
    "graded_eighth_ball",
    "hertz_3d",
    "hertz_3d_contact",
    "hertz_3d_force",
    "hertz_3d_force_control",
    "hertz_3d_metrics",
    "hertz_3d_pressure",
    "hertz_3d_solution",
    "prescribed_force",
    "top_area",
]

#: the prescribed displacement of the top, δ / R: gives a / R ≈ 0.102 with ν = 0.3
DEPTH_3D = 0.01

#: Hertz's contact radius a / R of the built-in ``hertz-3d``'s force (:data:`FORCE_3D`)
CONTACT_RADIUS_3D = 0.1

#: the contact disc of the whole ball over the eighth's quarter disc: ``P = 4 Σ Λ_z``
QUARTERS = 4

#: a node within this distance (times R) of the plane y = 0 lies on the pressure's line
LINE_TOL = 1e-9

#: the bisections :func:`graded_eighth_ball` may take before it gives up
MAX_GRADING_STEPS = 60


def graded_eighth_ball(
    n: int = 2,
    radius: float = 1.0,
    h_contact: float = 0.1,
    grading: float = 0.5,
    patch: float = 0.0,
) -> Mesh:
    """The eighth ball of :func:`hertz_3d`, graded toward its pole.

    Starting from ``eighth_ball(n, radius=R, center=(0, 0, R))``, every cell whose longest
    edge exceeds ``h_contact + grading · max(d − patch, 0)`` (d the distance from the pole,
    the origin, to the cell's bounding box) is bisected once
    (:func:`~signorini.mesh.refine.refine_nvb` with its closure), until none does.

    Parameters
    ----------
    n : int
        Cubes per direction of the Kuhn grid (``6 n³`` cells before grading).
    radius : float
        R (length units).
    h_contact : float
        The longest edge wanted at the pole (length units).
    grading : float
        How fast the wanted edge grows with the distance from the pole (no unit).
    patch : float
        The distance from the pole within which the wanted edge is ``h_contact`` (length
        units): about the contact radius, so that the whole contact disc is resolved.

    Returns
    -------
    Mesh
        Parts ``x0 y0 z1 sphere``, the sphere carrying ``Sphere((0, 0, R), R)``.
    """
    mesh = eighth_ball(n, radius=radius, center=(0.0, 0.0, radius))
    for _ in range(MAX_GRADING_STEPS):
        p = mesh.points[mesh.cells]  # (n_cells, 4, 3)
        distance = np.linalg.norm(np.clip(0.0, p.min(axis=1), p.max(axis=1)), axis=1)
        longest = np.linalg.norm(p[:, :, None] - p[:, None], axis=-1).max(axis=(1, 2))
        marked = longest > h_contact + grading * np.maximum(distance - patch, 0.0)
        if not marked.any():
            return mesh
        mesh = refine_nvb(mesh, marked).mesh
    raise ValueError(f"graded_eighth_ball: h_contact = {h_contact} not reached")


def hertz_3d(
    radius: float = 1.0,
    depth: float | None = None,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    force: float | None = None,
    n: int = 2,
    h_contact: float | None = None,
    grading: float = 0.5,
    patch: float | None = None,
    face_alpha: float | None = None,
) -> ContactProblem:
    """The 3D Hertz problem: the eighth of an elastic ball pressed by its flat top onto a rigid
    plane, under a prescribed displacement of the top (the default) or a prescribed total
    force (``force``; the built-in ``hertz-3d``, :func:`hertz_3d_force_control`).

    Defaults: R = 1, δ = 0.01 R (:data:`DEPTH_3D`), E = 1, ν = 0.3 (consistent units; the
    problem is linear in E, and a / R depends on δ / R and ν only): a / R ≈ 0.102.

    Parameters
    ----------
    radius : float
        R, the radius of the ball (length units).
    depth : float, optional
        δ, the downward displacement ``u_z = −δ`` prescribed on the flat top (length units);
        default ``DEPTH_3D * radius`` when ``force`` is not given.
    young, poisson : float
        E (stress units) and ν of the body.
    force : float, optional
        P, the total force pressing the whole ball onto the plane (force units; the eighth
        carries P / 4): the top carries the uniform traction ``(0, 0, −P / (4 |z1|_h))``
        (:func:`top_area`) instead of ``u_z = −δ``, and the body is held along z by its
        contact alone (force control). A P < 0 pulls the ball off and is refused by the
        solve, naming the free translation along z. Not with ``depth``.
    n, h_contact, grading, patch : optional
        The initial mesh, :func:`graded_eighth_ball` ``(n, radius, h_contact, grading,
        patch)``; ``h_contact`` defaults to ``0.1 R``, ``patch`` to ``0.15 R`` (the
        default contact radius is about 0.102 R).
    face_alpha : float, optional
        The discrete contact condition (:class:`~signorini.problem.Contact`): None for (b),
        the transformed face basis with α = 1/5; 0 for (a), nodal constraints at all P2
        nodes.

    Returns
    -------
    ContactProblem
        Named ``"hertz-3d"``; parts ``"x0"``, ``"y0"`` (rollers), ``"z1"`` (``u_z = −δ``, or
        the traction of ``force``) and ``"sphere"`` (contact with ``HalfSpace((0, 0, 0),
        (0, 0, 1))``).

    Raises
    ------
    ValueError
        If ``force`` is not a finite non-zero number, or both ``depth`` and ``force`` are
        given.
    """
    if force is not None:
        if depth is not None:
            raise ValueError("hertz_3d: give depth (displacement control) or force, not both")
        if isinstance(force, bool) or not isinstance(force, int | float | np.floating):
            raise ValueError(f"hertz_3d: force must be a number (P), got {force!r}")
        if not np.isfinite(force) or force == 0:
            raise ValueError(f"hertz_3d: force must be finite and non-zero (P), got {force!r}")
    h_contact = 0.1 * radius if h_contact is None else h_contact
    patch = 0.15 * radius if patch is None else patch
    mesh = graded_eighth_ball(n, radius, h_contact, grading, patch)
    if force is None:
        top = Dirichlet((None, None, -(DEPTH_3D * radius if depth is None else depth)))
    else:
        top = Neumann((0.0, 0.0, -float(force) / (QUARTERS * top_area(mesh))))
    plane = HalfSpace([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    return ContactProblem(
        mesh=mesh,
        material=Material.from_young(young, poisson),
        conditions={
            "x0": Roller(),
            "y0": Roller(),
            "z1": top,
            "sphere": Contact(obstacle=plane, face_alpha=face_alpha),
        },
        name="hertz-3d",
    )


def top_area(mesh: Mesh) -> float:
    """``|z1|_h``, the area of the flat top ``"z1"`` of :func:`graded_eighth_ball`'s mesh as
    the Neumann load integrates it: ``Σ_z G[3 z + 2]`` of the load of the unit traction
    ``e_z`` (:func:`~signorini.fem.elasticity3d.assemble_face_load_3d`; the P2 basis sums to
    one). Its faces at the rim are curved in their plane (their midpoints on the sphere), so
    it is below the quarter disc's πR²/4 (−6.6·10⁻⁵ relative on the default mesh) and grows
    as the rim is refined."""
    unit = np.array([0.0, 0.0, 1.0])
    load = assemble_face_load_3d(
        P2TetSpace(mesh), mesh.part_facets("z1"), lambda x: np.broadcast_to(unit, x.shape)
    )
    return float(load[2::3].sum())


def prescribed_force(problem: ContactProblem) -> float | None:
    """P, the whole ball's total force a force-controlled :func:`hertz_3d` prescribes (its
    top's traction times ``4 |z1|_h`` on the problem's mesh, :func:`top_area`), or None under
    displacement control."""
    top = problem.conditions["z1"]
    if not isinstance(top, Neumann):
        return None
    return -QUARTERS * float(top.traction[2]) * top_area(problem.mesh)


def hertz_3d_force(contact_radius: float, radius: float, material: Material) -> float:
    """The total force P whose Hertz contact radius is ``contact_radius``: the inverse of
    :func:`hertz_3d_solution`, ``P = 4 E* a³ / (3 R)``."""
    e_star = material.young / (1.0 - material.poisson**2)
    return 4.0 * e_star * contact_radius**3 / (3.0 * radius)


#: the built-in ``hertz-3d``'s total force (R = 1, E = 1, ν = 0.3): Hertz's a = 0.1 R
#: (:data:`CONTACT_RADIUS_3D`), P = 4 E* (0.1 R)³ / (3 R) ≈ 1.4652·10⁻³ E R²
FORCE_3D = hertz_3d_force(CONTACT_RADIUS_3D, 1.0, Material.from_young(1.0, 0.3))


def hertz_3d_force_control() -> ContactProblem:
    """The built-in ``hertz-3d``: :func:`hertz_3d` under the total force :data:`FORCE_3D`
    (force control, Hertz's a = 0.1 R), on the default graded mesh and condition (b)."""
    return hertz_3d(force=FORCE_3D)


def hertz_3d_solution(force: float, radius: float, material: Material) -> tuple[float, float]:
    """Hertz's contact radius ``a = (3 P R / (4 E*))^{1/3}`` and peak pressure
    ``p0 = 3 P / (2 π a²)`` of a sphere on a rigid plane.

    Parameters
    ----------
    force : float
        P, the total contact force of the whole ball (force units).
    radius : float
        R, the sphere's radius (length units).
    material : Material
        Gives ``E* = E / (1 − ν²)``.
    """
    e_star = material.young / (1.0 - material.poisson**2)
    a = float(np.cbrt(3.0 * force * radius / (4.0 * e_star)))
    return a, 3.0 * force / (2.0 * np.pi * a**2)


def hertz_3d_contact(result: ContactResult) -> dict[str, object]:
    """The contact disc of a solution of :func:`hertz_3d`.

    Returns
    -------
    dict
        ``force`` P = 4 Σ Λ_z (:data:`QUARTERS`); ``r`` (k,) each row's distance from the
        axis; ``pressure`` (k,) the recovered pressure of the rows; ``a`` the radius
        √(5/2 · Σ Λ_z r_z² / Σ Λ_z); ``p0`` the recovered pressure at the pole node;
        ``radius`` R (the sphere's).

    Raises
    ------
    ValueError
        If the ball does not touch the plane (no contact force).
    """
    force = result.contact_force
    total = float(force.sum())
    if not total > 0:
        raise ValueError("hertz-3d: the ball does not touch the plane (no contact force)")
    cs, mesh = result.contact, result.problem.mesh
    r2 = np.sum(result.space.node_points[cs.node, :2] ** 2, axis=1)
    pressure = cs.recovered_pressure(force)
    return {
        "force": QUARTERS * total,
        "r": np.sqrt(r2),
        "pressure": pressure,
        "a": float(np.sqrt(2.5 * (force @ r2) / total)),
        "p0": float(pressure[np.argmin(r2)]),
        "radius": float(mesh.curves[mesh.part_names.index("sphere")].radius),
    }


def hertz_3d_metrics(result: ContactResult) -> dict[str, float]:
    """The level's total force, contact radius and peak pressure (:func:`hertz_3d_contact`),
    their errors against Hertz (:func:`hertz_3d_solution`) for the prescribed P under force
    control (:func:`prescribed_force`; ``force`` and ``force_rel_error``, the measured total
    force against it) or for the level's own measured P under displacement control (``force``
    NaN), and the discrete contact condition's α (NaN without contact)."""
    alpha = float(result.contact.edges.alpha)
    prescribed = prescribed_force(result.problem)
    force = float("nan") if prescribed is None else prescribed
    if not result.total_contact_force > 0:
        keys = ("total_force", "force_rel_error", "a", "p0", "a_rel_error", "p0_rel_error")
        return dict.fromkeys(keys, float("nan")) | {"force": force, "face_alpha": alpha}
    zone = hertz_3d_contact(result)
    a, p0 = _hertz(result, zone)
    return {
        "total_force": zone["force"],
        "force": force,
        "force_rel_error": zone["force"] / force - 1.0,
        "a": zone["a"],
        "p0": zone["p0"],
        "a_rel_error": zone["a"] / a - 1.0,
        "p0_rel_error": zone["p0"] / p0 - 1.0,
        "face_alpha": alpha,
    }


def _hertz(result: ContactResult, zone: dict[str, object]) -> tuple[float, float]:
    """Hertz's a and p0 for the prescribed force of ``result``'s problem, else for the
    measured one ``zone["force"]``."""
    prescribed = prescribed_force(result.problem)
    force = zone["force"] if prescribed is None else prescribed
    return hertz_3d_solution(force, zone["radius"], result.problem.material)


def hertz_3d_pressure(result: ContactResult) -> PressureComparison:
    """The recovered pressure along the line y = 0 through the contact disc (the rows on
    the symmetry plane ``"y0"``, whose nodes lie on the line: the pressure there is linear
    between them), against r = x up to 2a, beside Hertz's ``p0 √(1 − r² / a²)`` of the
    prescribed total force (force control) or of the measured one (:func:`_hertz`)."""
    zone = hertz_3d_contact(result)
    a, p0 = _hertz(result, zone)
    x = result.space.node_points[result.contact.node]
    on_line = np.abs(x[:, 1]) <= LINE_TOL * zone["radius"]
    near = on_line & (zone["r"] <= 2.0 * a)
    order = np.argsort(x[near, 0], kind="stable")
    r_ref = np.linspace(0.0, a, 201)
    return PressureComparison(
        x=x[near, 0][order],
        pressure=zone["pressure"][near][order],
        x_reference=r_ref,
        reference=p0 * np.sqrt(np.maximum(1.0 - (r_ref / a) ** 2, 0.0)),
        label=rf"Hertz, $a$ = {a:.4g}, $p_0$ = {p0:.4g}",
        title=f"hertz-3d: recovered contact pressure along y = 0, {result.ndof} unknowns",
        xlabel=r"$r = x$ (along $y = 0$)",
        joined=True,
    )


#: The 3D Hertz example's columns of ``history.csv`` and its pressure figure.
HERTZ_3D_METRICS = Metrics(
    measure=hertz_3d_metrics,
    columns={
        "total_force": "4 Σ Λ_z, the whole ball's measured contact force (the eighth carries a "
        "quarter of the contact disc; contact_force is Σ Λ_z), force units",
        "force": "P, the prescribed total force under force control (the built-in hertz-3d: "
        "the top's uniform traction times 4 |z1|_h on the initial mesh); NaN under "
        "displacement control, force units",
        "force_rel_error": "total_force / force − 1: round-off on the initial mesh; on a "
        "refined one the rim's new points on the sphere enlarge the loaded top by up to "
        "1e-4 relative; NaN under displacement control, no unit",
        "a": "contact radius from the nodal forces, √(5/2 · Σ Λ_z r_z² / Σ Λ_z), length units",
        "p0": "recovered (P1-lumped) contact pressure at the pole node, stress units",
        "a_rel_error": "a / a_Hertz − 1, a_Hertz = (3 P R / (4 E*))^(1/3) with P the "
        "prescribed force (force control) or the level's total_force (displacement control), "
        "no unit",
        "p0_rel_error": "p0 / p0_Hertz − 1, p0_Hertz = 3 P / (2 π a_Hertz²), no unit",
        "face_alpha": "the discrete contact condition: 0 for (a), nodal constraints at all P2 "
        "nodes; 0.2 for (b), the transformed face basis",
    },
    pressure=hertz_3d_pressure,
)
