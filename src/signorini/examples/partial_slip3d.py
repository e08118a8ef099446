"""``partial-slip-3d`` (Cattaneo–Mindlin): an elastic ball pressed on a rigid plane with
Coulomb friction, then pulled along x by a force Q < F·P (docs/method.md, *Friction in three
dimensions: the disc law*).

The body is the half of the Hertz ball of :mod:`.hertz3d` on the side y ≥ 0 (the graded
eighth ball mirrored in the plane x = 0): pulling along x keeps the mirror plane y = 0, where a
roller holds ``u_y = 0``. E = 1 and ν = 0.49, so that Dundurs' β = (1 − 2ν)/(2(1 − ν)) =
0.0196 is small and the normal and tangential problems nearly uncouple; Coulomb F = 0.5 on
the sphere. Load path, two quasi-static steps on one mesh: the flat top is moved by
(0, free, −δ), δ = 0.01 R (press), then by (ξ, free, −δ) (pull at constant push).

Theory (Mindlin 1949, β = 0): the contact disc r < a is Hertz's; the pull leaves a central
stick disc r < c with

    c/a = (1 − Q/(F P))^{1/3}.

Measured (:data:`PARTIAL_SLIP_3D_METRICS`, docs/method.md, *Friction in three dimensions:
the disc law*, "Measured on partial-slip-3d"): P = 2 Σ Λ_n, Q = 2 Σ Λ̃_t·e (e the pull
direction, Λ̃_t carried to space by each row's own tangents, its held components left out),
``a = √(5/2 · Σ Λ_z r_z² / Σ Λ_z)`` (as :func:`~.hertz3d.hertz_3d_metrics`), and c from the
zero of the stick rows' traction deficit: in Mindlin's stick disc
``d = 1 − ‖q‖/(F p) = √((c² − r²)/(a² − r²))``, so ``d² (a² − r²) = c² − r²`` is linear in
r² and vanishes at r = c; the line fitted by least squares (weights ``w̃_z = ∫ φ̃_z``, the
rows' shares of Γ_C) through ``d_z² (a² − r_z²)`` against ``r_z²`` over the stick rows, with
``d_z = 1 − ‖Λ̃_t‖/(F Λ̃_n)``, crosses zero at c². The area of the discrete stick set,
``π c² / 2 = Σ_{stick} w̃_z``, is kept beside it (``c_over_a_area``).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..contact.face_friction import row_tangents
from ..contact.mortar3d_set import MortarFaceSet
from ..contact.solution import SLIP, STICK, ContactResult
from ..fem.material import Material
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
from ..problem.conditions import Roller
from ..problem.obstacles3d import HalfSpace
from .hertz3d import graded_eighth_ball
from .metrics import Metrics

__all__ = [
    "PARTIAL_SLIP_3D_METRICS",
    "half_ball",
    "partial_slip_3d",
    "partial_slip_3d_metrics",
    "partial_slip_3d_path",
]

#: ν of the ball: Dundurs β = 0.0196 against the rigid plane
POISSON_3D = 0.49
#: the Coulomb coefficient F on the sphere
COEFFICIENT_3D = 0.5
#: the press δ / R and the pull ξ / R of the flat top
PRESS_3D, PULL_3D = 0.01, 0.002


@lru_cache(maxsize=8)
def half_ball(n: int = 2, radius: float = 1.0, h_contact: float = 0.05, patch: float = 0.12):
    """The half ball y ≥ 0 about (0, 0, R) below its equator: :func:`~.hertz3d.graded_eighth_ball`
    mirrored in x = 0 (the image's cells reoriented, the part ``x0`` now inside). Parts
    ``y0 z1 sphere``. Cached: the steps of a load path built twice (the problem and its path,
    as the command line asks them) share one mesh object."""
    eighth = graded_eighth_ball(n, radius, h_contact, 0.5, patch)
    p = eighth.points
    off = p[:, 0] != 0.0
    image = np.arange(eighth.n_points)
    image[off] = eighth.n_points + np.arange(off.sum())
    flipped = p[off].copy()
    flipped[:, 0] *= -1.0
    parts = {}
    for name in eighth.part_names:  # a loop over parts
        faces = eighth.facets[eighth.part_facets(name)]
        if off[faces].any() and name != "x0":
            parts[name] = np.vstack([faces, image[faces]])
    cells = np.vstack([eighth.cells, image[eighth.cells][:, [0, 2, 1, 3]]])
    whole = Mesh.from_arrays(np.vstack([p, flipped]), cells, parts)
    for name, curve in zip(eighth.part_names, eighth.curves, strict=True):
        if curve is not None and name in parts:
            whole = whole.with_curve(name, curve)
    return whole


def partial_slip_3d_path(
    radius: float = 1.0,
    *,
    coefficient: float = COEFFICIENT_3D,
    press: float = PRESS_3D,
    pull: float = PULL_3D,
    n: int = 2,
    h_contact: float = 0.1,
) -> list[ContactProblem]:
    """The two load steps (press, pull) on one half-ball mesh (:func:`half_ball` with
    ``h_contact`` relative to R), named ``"partial-slip-3d"``."""
    mesh = half_ball(n, radius, h_contact * radius, 0.12 * radius)
    material = Material.from_young(1.0, POISSON_3D)
    contact = Contact(
        obstacle=HalfSpace((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)), friction=Coulomb(coefficient)
    )
    steps = []
    for xi in (0.0, pull):
        conditions = {name: Neumann((0.0, 0.0, 0.0)) for name in mesh.part_names}
        conditions.update(
            y0=Roller(), z1=Dirichlet((xi * radius, None, -press * radius)), sphere=contact
        )
        steps.append(ContactProblem(mesh, material, conditions, name="partial-slip-3d"))
    return steps


def partial_slip_3d(**kwargs) -> ContactProblem:
    """The last step of :func:`partial_slip_3d_path` (the pulled half ball)."""
    return partial_slip_3d_path(**kwargs)[-1]


def partial_slip_3d_metrics(
    result: ContactResult, direction: tuple[float, float] = (1.0, 0.0)
) -> dict[str, float]:
    """The stick disc against Mindlin's (module docstring): ``a``, ``c_over_a`` (the zero of
    the stick rows' deficit), ``c_over_a_area`` (the stick set's area), ``c_over_a_theory``
    = (1 − Q/(F P))^{1/3}, ``q_over_fp``, the fitted line's ``deficit_slope`` (−1 in
    Mindlin's disc) and the counts ``stick_nodes``, ``slip_nodes`` (NaN without contact).
    ``direction``: the pull's horizontal direction (x for the example)."""
    keys = ("a", "c_over_a", "c_over_a_area", "c_over_a_theory", "q_over_fp", "deficit_slope")
    counts = {
        "stick_nodes": float((result.state == STICK).sum()),
        "slip_nodes": float((result.state == SLIP).sum()),
    }
    cs = result.contact
    total = float(result.contact_force.sum())
    if not total > 0:
        return dict.fromkeys(keys, float("nan")) | counts
    coefficient = result.problem.conditions[cs.parts[0]].friction.coefficient
    x = result.space.node_points[cs.node]
    r2 = x[:, 0] ** 2 + x[:, 1] ** 2
    normal, w, moment = _normal_rows(result, r2)
    a2 = 2.5 * moment / total
    pull = float(_friction_forces(result).sum(0)[:2] @ np.asarray(direction, dtype=float))
    ratio = pull / (coefficient * total)
    stick = result.state == STICK
    c2_area = 2.0 * float(w[stick].sum()) / np.pi
    c2, slope = _deficit_zero(result, coefficient, (r2, a2), (normal, w), stick)
    return {
        "a": float(np.sqrt(a2)),
        "c_over_a": float(np.sqrt(max(c2, 0.0) / a2)) if np.isfinite(c2) else float("nan"),
        "c_over_a_area": float(np.sqrt(c2_area / a2)),
        "c_over_a_theory": float(np.cbrt(max(1.0 - ratio, 0.0))),
        "q_over_fp": ratio,
        "deficit_slope": slope,
    } | counts


def _friction_forces(result: ContactResult) -> np.ndarray:
    """``(k, 3)`` the rows' friction forces ``Σ_j Λ̃_t,j t_j`` in space, each row's tangents
    ``t_j`` its own frame's columns (``friction.tangent``), held components (a roller's
    reaction) left out."""
    return np.einsum("kj,kjc->kc", _unheld_force(result), row_tangents(result.contact))


def _unheld_force(result: ContactResult) -> np.ndarray:
    """``(k, 2)`` the rows' tangential forces ``Λ̃_t`` in their frames, the components a
    roller holds (its reaction, not friction) set to zero."""
    return np.where(result.contact.friction.held, 0.0, result.tangential_force)


def _normal_rows(result: ContactResult, r2: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The rows' normal forces on the transformed functions ``Λ̃_n``, their weights ``w̃_z =
    ∫ φ̃_z`` and ``∫ λ_h r²`` (``r2 (k,)`` at the rows' nodes): of one body ``T Λ``,
    ``T w`` and ``Σ Λ_z r_z²`` (``Λ`` on the P2 functions); of pairs (docs/method.md, *Two
    bodies in three dimensions: friction*) the multipliers themselves, ``D_jj`` and
    ``Σ Λ̃_j r̃²_j`` with ``r̃²`` the coefficients of r²'s interpolant in the transformed basis
    (:func:`~.two_spheres3d.two_spheres_contact`)."""
    cs, force = result.contact, result.contact_force
    if isinstance(cs, MortarFaceSet):
        x = result.space.node_points
        r2_coefficients = cs.sides.coefficients(np.sum(x[:, :2] ** 2, axis=1))
        return force, cs.basis_integral, float(force @ r2_coefficients[cs.node])
    return cs.edges.transformed(force), cs.transformed_integral, float(force @ r2)


def _deficit_zero(
    result: ContactResult, coefficient: float, radii, rows, stick: np.ndarray
) -> tuple[float, float]:
    """``(c², slope)``: the zero and slope of the least-squares line (weights ``w̃_z``) of
    ``d_z² (a² − r_z²)`` against ``r_z²`` over the stick rows inside the disc, ``d_z = 1 −
    ‖Λ̃_t‖/(F Λ̃_n)`` clipped to [0, 1] (module docstring); ``radii = (r², a²)``, ``rows =
    (Λ̃_n, w̃)`` (:func:`_normal_rows`); NaN with fewer than three rows."""
    (r2, a2), (normal, weight) = radii, rows
    use = stick & (normal > 0) & (r2 < a2)
    if use.sum() < 3:
        return float("nan"), float("nan")
    force_t = _unheld_force(result)[use]
    d = np.clip(1.0 - np.linalg.norm(force_t, axis=1) / (coefficient * normal[use]), 0.0, 1.0)
    root = np.sqrt(weight[use])
    design = np.stack([np.ones(use.sum()), r2[use]], 1) * root[:, None]
    (c2, slope), *_ = np.linalg.lstsq(design, d**2 * (a2 - r2[use]) * root, rcond=None)
    return float(-c2 / slope), float(slope)


#: The partial-slip-3d example's columns of ``history.csv``.
PARTIAL_SLIP_3D_METRICS = Metrics(
    measure=partial_slip_3d_metrics,
    columns={
        "a": "radius of the contact disc from the nodal forces, √(5/2 Σ Λ r² / Σ Λ), length units",
        "c_over_a": "c/a, c² the zero of the stick rows' deficit: the weighted least-squares "
        "line of d² (a² − r²) against r², d = 1 − ‖Λ̃_t‖/(F Λ̃_n), no unit",
        "c_over_a_area": "c/a, c the radius of the discrete stick set's area "
        "(π c²/2 = Σ_stick w̃_z), no unit",
        "c_over_a_theory": "Mindlin's c/a = (1 − Q/(F P))^(1/3) with the level's P and Q, no unit",
        "q_over_fp": "Q/(F P), Q the friction force along the pull, no unit",
        "deficit_slope": "slope of that line against r² (−1 in Mindlin's stick disc), no unit",
        "stick_nodes": "rows that stick",
        "slip_nodes": "rows that slip",
    },
)
