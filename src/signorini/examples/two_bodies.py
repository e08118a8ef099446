"""Contact between two elastic bodies (docs/method.md, *Two bodies*): two cylinders of
different radii and materials pressed together (Hertz), two mirror-image half-discs (the
one-body Hertz problem twice), and two blocks with non-matching meshes under uniform
compression (the contact patch test).

For two cylinders Hertz's theory (a ≪ R) gives, with the total contact force P per unit
thickness, the effective radius 1/R = 1/R1 + 1/R2 and the plane-strain modulus
1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2,

    a = √(4 P R / (π E*)),   p0 = 2 P / (π a).

Each level is compared with the Hertz solution of its own P (:func:`cylinders_metrics`), a
from the consistent nodal forces as in :mod:`.hertz`.
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..mesh.bodies import union
from ..mesh.builders import half_disc, rectangle
from ..mesh.curves import Circle
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from .hertz import beside_hertz
from .metrics import Metrics, PressureComparison

__all__ = [
    "BLOCKS_METRICS",
    "CYLINDERS_METRICS",
    "blocks_metrics",
    "cylinders_metrics",
    "hertz_pair",
    "mirrored",
    "split_arc",
    "stacked_blocks",
    "two_cylinders",
]


def mirrored(mesh: Mesh, curves: dict[str, Circle] | None = None) -> Mesh:
    """The mirror image of ``mesh`` in the line ``y = 0``: points ``(x, −y)``, cells
    reversed (counter-clockwise again, the refinement edge kept), the same parts; the parts
    named in ``curves`` carry the given (mirrored) circles."""
    mesh = Mesh(
        mesh.points * [1.0, -1.0],
        mesh.cells[:, [1, 0, 2]],
        mesh.boundary,
        mesh.boundary_part,
        mesh.part_names,
        validate=False,  # the mirror image of a valid mesh
        cell_region=mesh.cell_region,
        region_names=mesh.region_names,
    )
    for name, curve in (curves or {}).items():
        mesh = mesh.with_curve(name, curve)
    return mesh


def _rotated(mesh: Mesh, rotation: np.ndarray) -> Mesh:
    """``mesh`` (straight parts and circles) rotated by the matrix ``rotation``."""
    curves = [None if c is None else Circle(rotation @ c.center, c.radius) for c in mesh.curves]
    return Mesh(
        mesh.points @ rotation.T,
        mesh.cells,
        mesh.boundary,
        mesh.boundary_part,
        mesh.part_names,
        validate=False,  # a rotated copy of a valid mesh
        curves=curves,
        cell_region=mesh.cell_region,
        region_names=mesh.region_names,
    )


def split_arc(mesh: Mesh, center: tuple, radius: float, width: float) -> Mesh:
    """The half-disc ``mesh`` (parts top, arc) with its arc split into ``"contact"``
    (``|x| < width``) and ``"arc"`` (the rest), both on the circle of ``center`` and
    ``radius``."""
    on_arc = mesh.boundary_part == mesh.part_index("arc")
    mid = mesh.points[mesh.boundary].mean(axis=1)
    part = np.where(on_arc & (np.abs(mid[:, 0]) < width), len(mesh.part_names), mesh.boundary_part)
    circle = Circle(center, radius)
    return (
        Mesh(
            mesh.points,
            mesh.cells,
            mesh.boundary,
            part,
            (*mesh.part_names, "contact"),
            validate=False,
            cell_region=mesh.cell_region,
            region_names=mesh.region_names,
        )
        .with_curve("arc", circle)
        .with_curve("contact", circle)
    )


def hertz_pair(
    radius: float = 1.0,
    depth: float = 0.015,
    young: float = 1.0,
    poisson: float = 0.3,
    *,
    rings: int = 4,
    h_bottom: float | None = None,
) -> ContactProblem:
    """Two identical half-discs pressed together: the body of
    :func:`~signorini.examples.hertz.hertz` (``"upper"``, its top moved by ``(0, −δ/2)``) and
    its mirror image in ``y = 0`` (``"lower"``, its flat side moved by ``(0, δ/2)``), meshed
    as mirror images; the arcs' parts with ``|x| < R/2`` are the contact parts (the upper one
    the slave), the rest of the arcs traction-free. By symmetry the
    upper body's solution is that of ``hertz(depth=δ/2)`` on the same mesh (docs/method.md,
    *Two bodies*)."""
    body = half_disc(radius, rings, h_bottom=h_bottom)
    upper = split_arc(body, (0.0, radius), radius, radius / 2)
    lower = split_arc(mirrored(body), (0.0, -radius), radius, radius / 2)
    return ContactProblem(
        mesh=union({"upper": upper, "lower": lower}),
        material=Material.from_young(young, poisson),
        conditions={
            "upper.top": Dirichlet((0.0, -depth / 2)),
            "lower.top": Dirichlet((0.0, depth / 2)),
            "upper.arc": Neumann(),
            "lower.arc": Neumann(),
            "upper.contact": Contact(master="lower.contact"),
        },
        name="hertz-pair",
    )


def two_cylinders(
    radii: tuple[float, float] = (1.0, 2.0),
    young: tuple[float, float] = (1.0, 3.0),
    poisson: float = 0.3,
    depth: float = 0.012,
    *,
    rings: int = 4,
    h_bottom: float | None = None,
    friction: object = None,
    shear: float = 0.0,
    angle: float = 0.0,
) -> ContactProblem:
    """Two cylinders (half-discs) of radii R1 (``"upper"``, centre ``(0, R1)``) and R2
    (``"lower"``, centre ``(0, −R2)``) touching at the origin, of Young's moduli E1, E2 and
    Poisson's ratio ν, pressed together by moving their flat sides by ``(0, ∓δ/2)``.

    The part of each arc with ``|x| < R1 / 2`` is the contact part (``"upper.contact"`` the
    slave; ``"lower.contact"``, with ``|x| < min(R1, 0.9 R2)``, the master); the rest of the arcs
    is traction-free. Defaults: a / R ≈ 0.1 with the effective radius R = R1 R2 / (R1 + R2).
    ``friction`` is the law on the pair (``None``: frictionless); ``shear`` moves the flat
    sides apart along x as well, by ``±shear/2`` (the second step of a load path, after the
    press). ``angle`` rotates the whole problem about the origin (radians,
    counter-clockwise).
    """
    r1, r2 = radii
    upper = split_arc(half_disc(r1, rings, h_bottom=h_bottom), (0.0, r1), r1, r1 / 2)
    lower = half_disc(r2, rings, h_bottom=None if h_bottom is None else h_bottom * r2 / r1)
    lower = split_arc(mirrored(lower), (0.0, -r2), r2, min(r1, 0.9 * r2))
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.array([[c, -s], [s, c]])
    return ContactProblem(
        mesh=_rotated(union({"upper": upper, "lower": lower}), rotation),
        material={
            "upper": Material.from_young(young[0], poisson),
            "lower": Material.from_young(young[1], poisson),
        },
        conditions={
            "upper.top": Dirichlet(tuple(rotation @ [shear / 2, -depth / 2])),
            "lower.top": Dirichlet(tuple(rotation @ [-shear / 2, depth / 2])),
            "upper.arc": Neumann(),
            "lower.arc": Neumann(),
            "upper.contact": Contact(master="lower.contact", friction=friction),
        },
        name="two-cylinders",
    )


def stacked_blocks(
    edges: tuple[int, int] = (5, 7),
    depth: float = 0.01,
    materials: tuple[Material, Material] | None = None,
) -> ContactProblem:
    """Two blocks, ``"upper"`` on ``[0, 1] × [1, 2]`` and ``"lower"`` on ``[0, 1] × [0, 1]``,
    with ``edges = (n_upper, n_lower)`` edges along their common side (non-matching), the
    upper top moved by ``(·, −δ)`` (its x free), both left sides on rollers (``u_x = 0``),
    the lower bottom on a roller (``u_y = 0``), the other sides free. The exact solution is
    uniform compression in each block, ``σ_yy = −p`` in both; the contact pressure is ``p``
    everywhere along the interface (docs/method.md, *Two bodies*, the contact patch test;
    :data:`BLOCKS_METRICS` print its deviation per level). The estimator is at round-off on
    every mesh, so an adaptive run stops on its first mesh: η_h is below its round-off level
    (docs/method.md, *Round-off*), and a finer mesh would refine noise.
    """
    n_upper, n_lower = edges
    upper = rectangle(0.0, 1.0, 1.0, 2.0, n_upper, n_upper, pattern="right")
    lower = rectangle(0.0, 1.0, 0.0, 1.0, n_lower, n_lower, pattern="right")
    if materials is None:
        materials = (Material.from_young(1.0, 0.3), Material.from_young(3.0, 0.2))
    return ContactProblem(
        mesh=union({"upper": upper, "lower": lower}),
        material={"upper": materials[0], "lower": materials[1]},
        conditions={
            "upper.top": Dirichlet((None, -depth)),
            "upper.left": Dirichlet((0.0, None)),
            "upper.right": Neumann(),
            "upper.bottom": Contact(master="lower.top"),
            "lower.bottom": Dirichlet((None, 0.0)),
            "lower.left": Dirichlet((0.0, None)),
            "lower.right": Neumann(),
        },
        name="stacked-blocks",
    )


def _pair_materials(result: ContactResult) -> tuple[float, float]:
    """The effective radius and the plane-strain modulus E* of :func:`two_cylinders`."""
    mesh = result.problem.mesh
    r1 = 0.5 * mesh.part_measure("upper.top")
    r2 = 0.5 * mesh.part_measure("lower.top")
    m = result.problem.material
    compliance = sum((1.0 - m[b].poisson ** 2) / m[b].young for b in ("upper", "lower"))
    return r1 * r2 / (r1 + r2), 1.0 / compliance


def cylinders_metrics(result: ContactResult) -> dict[str, float]:
    """Half-width and peak pressure of a level of :func:`two_cylinders` and their errors
    against Hertz with the level's own total force P; NaN without contact."""
    names = ("a", "p0", "a_rel_error", "p0_rel_error")
    force = result.contact_force
    total = float(force.sum())
    if not total > 0:
        return dict.fromkeys(names, float("nan"))
    x = result.space.node_points[result.contact.nodes, 0]
    centre = force @ x / total
    a_h = float(2.0 * np.sqrt(force @ (x - centre) ** 2 / total))
    p0_h = float(np.max(result.pressure))
    radius, e_star = _pair_materials(result)
    a = float(np.sqrt(4.0 * total * radius / (np.pi * e_star)))
    p0 = 2.0 * total / (np.pi * a)
    return dict(zip(names, (a_h, p0_h, a_h / a - 1.0, p0_h / p0 - 1.0), strict=True))


def cylinders_pressure(result: ContactResult) -> PressureComparison:
    """The computed pressure along the slave beside Hertz's of the same total force."""
    force = result.contact_force
    total = float(force.sum())
    radius, e_star = _pair_materials(result)
    a = float(np.sqrt(4.0 * total * radius / (np.pi * e_star)))
    p0 = 2.0 * total / (np.pi * a)
    x = result.space.node_points[result.contact.nodes, 0]
    order = np.argsort(x)
    x = x[order] - force @ x / total
    title = f"two cylinders: contact pressure, {result.ndof} unknowns"
    return beside_hertz(x, result.pressure[order], (a, p0), title)


#: The two-cylinder example's columns of ``history.csv`` and its pressure figure.
CYLINDERS_METRICS = Metrics(
    measure=cylinders_metrics,
    columns={
        "a": "half-width of the contact zone from the slave's nodal forces, "
        "2 √(Σ Λ_z x_z² / Σ Λ_z), length units",
        "p0": "peak consistent contact pressure on the slave, max p_z, stress units",
        "a_rel_error": "a / a_Hertz − 1, a_Hertz = √(4 P R / (π E*)) with 1/R = 1/R1 + 1/R2, "
        "1/E* = Σ (1 − ν²)/E and P the level's total contact force, no unit",
        "p0_rel_error": "p0 / p0_Hertz − 1, p0_Hertz = 2 P / (π a_Hertz), no unit",
    },
    pressure=cylinders_pressure,
)


def blocks_metrics(result: ContactResult) -> dict[str, float]:
    """The contact patch test of :func:`stacked_blocks` on a level: the largest relative
    deviation of the slave's pressures and of the master's transferred pressures from their
    mean (round-off for the mortar coupling; 5 to 25 % for node-to-segment, docs/method.md,
    *Two bodies*)."""
    _, _, master = result.master_side
    out = {}
    for name, p in (
        ("slave_pressure_deviation", result.pressure),
        ("master_pressure_deviation", master),
    ):
        mean = float(np.mean(p)) if p.size else 0.0
        out[name] = float(np.abs(p / mean - 1.0).max()) if mean > 0 else float("nan")
    return out


#: The stacked blocks' columns of ``history.csv``: the patch test's pressure deviations.
BLOCKS_METRICS = Metrics(
    measure=blocks_metrics,
    columns={
        "slave_pressure_deviation": "max |p_z / mean p − 1| over the slave's constrained nodes, "
        "no unit (uniform pressure: round-off)",
        "master_pressure_deviation": "the same for the master's transferred pressures "
        "Σ_j T_jk Λ_j / w_k, no unit",
    },
)
