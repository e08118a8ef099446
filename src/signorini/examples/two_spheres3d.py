"""``two-spheres``: Hertz contact between two elastic spheres in three dimensions, through the
dual mortar coupling on non-matching curved faces (docs/method.md, *Two bodies in three
dimensions*, "Two spheres").

Both bodies are eighths of balls meeting at their poles at the origin, ``x ≥ 0``, ``y ≥ 0``
with symmetry rollers on both planes (``u_x = 0`` on ``x0``, ``u_y = 0`` on ``y0``): the
upper, radius R1 about ``(0, 0, R1)``, is :func:`~.hertz3d.graded_eighth_ball`; the lower,
radius R2 about ``(0, 0, −R2)``, is the same graded ball of radius R2 turned half a turn
about the line ``x = y`` of the plane z = 0 (:func:`turned_ball`: a rotation, so the cells
keep their orientation and bisection order and the sphere its curve). The lower's flat
bottom holds ``u_z = 0``; the upper's flat top is moved down by ``u_z = −δ`` and free to
slide (a prescribed approach: force control across a pair is built in 2D only), and the
total force P is read off the multiplier (the eighths carry a quarter of the contact disc,
``P = 4 Σ_j Λ̃_j |n_j,z|``): each level is compared with Hertz's solution of its own P. The
slave is the cap of the slave body's sphere within
``cap`` of the pole (it must lie wholly over the master, small sliding); the master the
other body's whole sphere.

Hertz's theory for two spheres (a ≪ R_i):

    1/R* = 1/R1 + 1/R2,   1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2,
    a = (3 P R* / (4 E*))^{1/3},   p0 = 3 P / (2 π a²).

The contact radius is measured from the multiplier as for ``hertz-3d``
(``∫ r² p dA / ∫ p dA = 2 a² / 5`` for Hertz's profile): ``λ_h = Σ_j p_j ψ_j`` with
``∫_Γs ψ_j φ̃_i = δ_ij D_jj`` gives ``∫ λ_h f_h = Σ_j Λ̃_j f̃_j`` for every P2 trace ``f_h``
(``f̃`` its coefficients in the transformed basis), so with ``f_h`` the interpolant of
``r² = x² + y²`` the radius ``a_h = √(5/2 · Σ Λ̃_j f̃_j / Σ Λ̃_j)`` is that of the discrete
multiplier itself; the peak pressure is ``p_j = Λ̃_j / D_jj`` at the pole node.
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..mesh.bodies import union
from ..mesh.mesh import Mesh
from ..mesh.surfaces import Sphere
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from .hertz3d import QUARTERS, graded_eighth_ball
from .metrics import Metrics

__all__ = [
    "SPHERES_METRICS",
    "two_spheres",
    "two_spheres_contact",
    "two_spheres_metrics",
    "two_spheres_solution",
    "turned_ball",
    "with_cap",
]

_FREE = Neumann((0.0, 0.0, 0.0))

#: the rotation by π about the line x = y of the plane z = 0: ``(x, y, z) → (y, x, −z)``
#: (determinant +1), which keeps the quadrant ``x, y ≥ 0`` and swaps its two planes
_TURN = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])

#: the built-in's radii, moduli and Poisson ratios (upper, lower)
RADII = (1.0, 2.0)
YOUNG = (1.0, 2.0)
POISSON = (0.3, 0.2)


def turned_ball(mesh: Mesh, rotation: np.ndarray = _TURN) -> Mesh:
    """A mesh of :func:`~.hertz3d.graded_eighth_ball` (radius R about ``(0, 0, R)``) turned
    by ``rotation`` (default :data:`_TURN`: the eighth of the ball of radius R about ``(0, 0,
    −R)`` above its equator, its pole at the origin); the parts ``"x0"`` and ``"y0"`` take the
    names of the planes they are turned onto (:data:`_TURN` swaps them), ``"z1"`` is the flat
    bottom ``z = −R`` and ``"sphere"`` carries the turned sphere."""
    axis = [int(np.argmax(np.abs(rotation[:, i]))) for i in range(2)]
    names = {f"{a}0": f"{'xyz'[j]}0" for a, j in zip("xy", axis, strict=True)}
    curves = []
    for curve in mesh.curves:
        if isinstance(curve, Sphere):
            curve = Sphere(rotation @ curve.center, curve.radius)
        curves.append(curve)
    return Mesh(
        mesh.points @ rotation.T,
        mesh.cells,
        mesh.boundary,
        mesh.boundary_part,
        [names.get(p, p) for p in mesh.part_names],
        curves=curves,
    )


def with_cap(mesh: Mesh, cap: float) -> Mesh:
    """``mesh`` with the faces of its ``"sphere"`` whose centroid lies within ``cap`` of the
    origin (the pole) as a new part ``"cap"``, carrying the same sphere."""
    index = mesh.part_index("sphere")
    centroid = mesh.points[mesh.boundary].mean(axis=1)
    near = (mesh.boundary_part == index) & (np.linalg.norm(centroid, axis=1) < cap)
    part = np.where(near, len(mesh.part_names), mesh.boundary_part)
    return Mesh(
        mesh.points,
        mesh.cells,
        mesh.boundary,
        part,
        [*mesh.part_names, "cap"],
        curves=[*mesh.curves, mesh.curves[index]],
        validate=False,
    )


def two_spheres_solution(
    force: float, radii: tuple[float, float], materials: tuple[Material, Material]
) -> tuple[float, float]:
    """Hertz's ``a = (3 P R* / (4 E*))^{1/3}`` and ``p0 = 3 P / (2 π a²)`` of two spheres
    (module docstring) pressed together by the total force P."""
    r_star = 1.0 / sum(1.0 / r for r in radii)
    e_star = 1.0 / sum((1.0 - m.poisson**2) / m.young for m in materials)
    a = float(np.cbrt(3.0 * force * r_star / (4.0 * e_star)))
    return a, 3.0 * force / (2.0 * np.pi * a**2)


def two_spheres(
    radii: tuple[float, float] = RADII,
    materials: tuple[Material, Material] | None = None,
    depth: float = 0.01,
    *,
    n: int = 2,
    h_contact: float | None = None,
    grading: float = 0.5,
    patch: float | None = None,
    cap: float | None = None,
    slave: str = "upper",
) -> ContactProblem:
    """The two spheres of the module docstring with the upper top moved down by δ.


    Parameters
    ----------
    radii : (R1, R2)
        The upper's and the lower's radius (length units), positive.
    materials : (Material, Material), optional
        Upper and lower; default ``E = 1, ν = 0.3`` and ``E = 2, ν = 0.2``.
    depth : float
        δ, the prescribed ``u_z = −δ`` of the upper's flat top (length units), positive;
        the default gives a ≈ 0.1 with the default radii and materials.
    n, h_contact, grading, patch : optional
        Each body's initial mesh, :func:`~.hertz3d.graded_eighth_ball` ``(n, R_i,
        h_contact, grading, patch)``; ``h_contact`` defaults to 0.1, ``patch`` to 0.15
        (length units, both bodies).
    cap : float, optional
        The slave part: the slave sphere's faces within ``cap`` of the pole (default 0.2,
        about twice the default contact radius); it must lie over the master.
    slave : str
        ``"upper"`` or ``"lower"``: whose cap is the slave.

    Raises
    ------
    ValueError
        Naming the argument: a radius or δ not positive and finite, ``slave`` not one of the
        two bodies, ``cap`` not positive or beyond a slave radius.
    """
    radii = tuple(float(r) for r in radii)
    if len(radii) != 2 or not all(np.isfinite(r) and r > 0 for r in radii):
        raise ValueError(f"two_spheres: radii must be two positive numbers, got {radii!r}")
    if slave not in ("upper", "lower"):
        raise ValueError(f"two_spheres: slave must be 'upper' or 'lower', got {slave!r}")
    if materials is None:
        materials = (Material.from_young(YOUNG[0], POISSON[0]),
                     Material.from_young(YOUNG[1], POISSON[1]))  # fmt: skip
    if isinstance(depth, bool) or not isinstance(depth, int | float | np.floating):
        raise ValueError(f"two_spheres: depth must be a number (δ), got {depth!r}")
    if not (np.isfinite(depth) and depth > 0):
        raise ValueError(f"two_spheres: depth must be positive and finite (δ), got {depth!r}")
    cap = 0.2 if cap is None else float(cap)
    if not 0 < cap < min(radii):
        raise ValueError(f"two_spheres: cap must lie in (0, min(radii)), got {cap!r}")
    h_contact = 0.1 if h_contact is None else h_contact
    patch = 0.15 if patch is None else patch
    upper = graded_eighth_ball(n, radii[0], h_contact, grading, patch)
    lower = turned_ball(graded_eighth_ball(n, radii[1], h_contact, grading, patch))
    bodies = {"upper": upper, "lower": lower}
    bodies[slave] = with_cap(bodies[slave], cap)
    master = "lower" if slave == "upper" else "upper"
    mesh = union(bodies)
    conditions = {}
    for body in ("upper", "lower"):
        conditions[f"{body}.x0"] = Dirichlet((0.0, None, None))
        conditions[f"{body}.y0"] = Dirichlet((None, 0.0, None))
        conditions[f"{body}.sphere"] = _FREE
    conditions["upper.z1"] = Dirichlet((None, None, -float(depth)))
    conditions["lower.z1"] = Dirichlet((None, None, 0.0))
    del conditions[f"{master}.sphere"]  # the pair gives the master its traction
    conditions[f"{slave}.cap"] = Contact(master=f"{master}.sphere")
    return ContactProblem(
        mesh=mesh,
        material={"upper": materials[0], "lower": materials[1]},
        conditions=conditions,
        name="two-spheres",
    )


def _radii(problem: ContactProblem) -> tuple[float, float]:
    mesh = problem.mesh
    return tuple(
        float(mesh.curves[mesh.part_names.index(f"{b}.sphere")].radius) for b in ("upper", "lower")
    )


def two_spheres_contact(result: ContactResult) -> dict[str, float]:
    """The contact disc of a solution of :func:`two_spheres`: ``force`` ``4 Σ Λ̃_j |n_j,z|``
    (the whole spheres' vertical contact force), ``a`` the multiplier's radius and ``p0``
    its pole coefficient (module docstring).

    Raises
    ------
    ValueError
        If the spheres do not touch (no contact force).
    """
    cs, force = result.contact, np.asarray(result.contact_force, dtype=np.float64)
    total = float(force.sum())
    if not total > 0:
        raise ValueError("two-spheres: the spheres do not touch (no contact force)")
    x = result.space.node_points
    r2 = cs.sides.coefficients(np.sum(x[:, :2] ** 2, axis=1))  # r²'s coefficients ũ
    pole = cs.node[np.argmin(np.sum(x[cs.node, :2] ** 2, axis=1))]
    hat = np.zeros(x.shape[0])  # the P2 interpolant of the pole's P1 hat, transformed
    e, start, end = cs.edges.T
    hat[e[(start == pole) | (end == pole)]] = 0.5
    hat[pole] = 1.0
    hat = hat[cs.node]
    return {
        "force": QUARTERS * float(force @ np.abs(cs.direction[:, 2])),
        "a": float(np.sqrt(2.5 * (force @ r2[cs.node]) / total)),
        "p0": float((hat @ force) / (hat @ cs.basis_integral)),
    }


def two_spheres_metrics(result: ContactResult) -> dict[str, float]:
    """The level's total force, contact radius and peak pressure (:func:`two_spheres_contact`)
    and their errors against Hertz (:func:`two_spheres_solution`) for the level's P."""
    problem = result.problem
    if not result.total_contact_force > 0:
        return dict.fromkeys(("total_force", "a", "p0", "a_rel_error", "p0_rel_error"), np.nan)
    zone = two_spheres_contact(result)
    materials = (problem.material["upper"], problem.material["lower"])
    a, p0 = two_spheres_solution(zone["force"], _radii(problem), materials)
    return {
        "total_force": zone["force"],
        "a": zone["a"],
        "p0": zone["p0"],
        "a_rel_error": zone["a"] / a - 1.0,
        "p0_rel_error": zone["p0"] / p0 - 1.0,
    }


#: The two spheres' columns of ``history.csv``.
SPHERES_METRICS = Metrics(
    measure=two_spheres_metrics,
    columns={
        "total_force": "4 Σ Λ̃_j |n_j,z|, the whole spheres' measured vertical contact force, "
        "force units",
        "a": "contact radius of the multiplier, √(5/2 · Σ Λ̃_j r̃²_j / Σ Λ̃_j), length units",
        "p0": "the multiplier's coefficient Λ̃_j / D_jj at the pole node, stress units",
        "a_rel_error": "a / a_Hertz − 1, a_Hertz = (3 P R* / (4 E*))^(1/3), no unit",
        "p0_rel_error": "p0 / p0_Hertz − 1, p0_Hertz = 3 P / (2 π a_Hertz²), no unit",
    },
)
