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

Measured (:data:`PARTIAL_SLIP_3D_METRICS`): P = 2 Σ Λ_n, Q = 2 Σ Λ_t·e_x (the half ball),
``a = √(5/2 · Σ Λ_z r_z² / Σ Λ_z)`` (as :func:`~.hertz3d.hertz_3d_metrics`), and c from the
area of the discrete stick set, ``π c² / 2 = Σ_{stick} w̃_z`` (``w̃_z = ∫ φ̃_z``: the
rows' shares of Γ_C).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..contact.solution import STICK, ContactResult
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


def partial_slip_3d_metrics(result: ContactResult) -> dict[str, float]:
    """The stick disc against Mindlin's: ``a``, ``c_over_a``, ``c_over_a_theory`` =
    (1 − Q/(F P))^{1/3}, ``q_over_fp``, and the counts ``stick_nodes``, ``slip_nodes``
    (NaN without contact)."""
    keys = ("a", "c_over_a", "c_over_a_theory", "q_over_fp", "stick_nodes", "slip_nodes")
    cs = result.contact
    lam_n = result.contact_force
    total = float(lam_n.sum())
    if not total > 0:
        return dict.fromkeys(keys, float("nan"))
    coefficient = result.problem.conditions["sphere"].friction.coefficient
    x = result.space.node_points[cs.node]
    a = float(np.sqrt(2.5 * float(lam_n @ (x[:, 0] ** 2 + x[:, 1] ** 2)) / total))
    frames = cs.frames[np.searchsorted(cs.frame_nodes, cs.node)]  # (k, 3, 3): [n t1 t2]
    pull = np.einsum("kc,kcj->k", result.tangential_force, frames[:, :, 1:].transpose(0, 2, 1))
    ratio = float(pull.sum()) / (coefficient * total)
    stick = result.state == STICK
    c = np.sqrt(2.0 * float(cs.transformed_integral[stick].sum()) / np.pi)
    return {
        "a": a,
        "c_over_a": float(c / a),
        "c_over_a_theory": float(np.cbrt(max(1.0 - ratio, 0.0))),
        "q_over_fp": ratio,
        "stick_nodes": float(stick.sum()),
        "slip_nodes": float((result.state == 2).sum()),
    }


#: The partial-slip-3d example's columns of ``history.csv``.
PARTIAL_SLIP_3D_METRICS = Metrics(
    measure=partial_slip_3d_metrics,
    columns={
        "a": "radius of the contact disc from the nodal forces, √(5/2 Σ Λ r² / Σ Λ), length units",
        "c_over_a": "c/a, c the radius of the discrete stick set's area (π c²/2 = Σ_stick w̃_z)"
        ", no unit",
        "c_over_a_theory": "Mindlin's c/a = (1 − Q/(F P))^(1/3) with the level's P and Q, no unit",
        "q_over_fp": "Q/(F P), no unit",
        "stick_nodes": "rows that stick",
        "slip_nodes": "rows that slip",
    },
)
