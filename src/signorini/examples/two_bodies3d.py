"""Contact between two elastic bodies in three dimensions (docs/method.md, *Two bodies in
three dimensions*): two boxes with non-matching meshes under uniform compression, the 3D
contact patch test.

The upper box ``[0, 1]² × [1, 2]`` stands on the lower box ``[0, 1]³``; their meshes meet
non-matching at ``z = 1``. Rollers hold ``u_x = 0`` on both ``x0`` and ``u_y = 0`` on both
``y0`` (symmetry planes), ``u_z = 0`` on the lower bottom; the upper top is pressed down by δ
(``u_z = −δ``, its other components free); the other sides are traction-free. The exact
solution is uniaxial compression in each box, ``σ_zz = −p`` in both with

    δ = p (H_1 / E_1 + H_2 / E_2),

(heights H_i = 1, free lateral expansion), and the contact pressure is p everywhere on the
interface: the dual mortar coupling transmits it to round-off whichever side is the slave
(:data:`CUBES_METRICS`).
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..fem.material import Material
from ..mesh.bodies import union
from ..mesh.builders3d import box
from ..problem import Contact, ContactProblem, Dirichlet, Neumann
from .metrics import Metrics

__all__ = ["CUBES_METRICS", "cubes_metrics", "cubes_pressure", "stacked_cubes"]

_FREE = Neumann((0.0, 0.0, 0.0))


def stacked_cubes(
    counts: tuple[tuple[int, int, int], tuple[int, int, int]] = ((3, 3, 2), (4, 4, 2)),
    depth: float = 0.01,
    materials: tuple[Material, Material] | None = None,
    *,
    slave: str = "upper",
) -> ContactProblem:
    """The two boxes of the module docstring, ``counts = (upper, lower)`` the cuboids of
    :func:`~signorini.mesh.builders3d.box` (non-matching at ``z = 1``), the upper top moved
    by ``−δ`` along z, ``slave`` the body whose face at ``z = 1`` is the pair's slave
    (``"upper"`` or ``"lower"``). Default materials: ``E = 1, ν = 0.3`` above, ``E = 3,
    ν = 0.2`` below."""
    if slave not in ("upper", "lower"):
        raise ValueError(f"slave must be 'upper' or 'lower', got {slave!r}")
    upper = box(*counts[0], lower=(0.0, 0.0, 1.0), upper=(1.0, 1.0, 2.0))
    lower = box(*counts[1])
    if materials is None:
        materials = (Material.from_young(1.0, 0.3), Material.from_young(3.0, 0.2))
    pair = ("upper.z0", "lower.z1") if slave == "upper" else ("lower.z1", "upper.z0")
    return ContactProblem(
        mesh=union({"upper": upper, "lower": lower}),
        material={"upper": materials[0], "lower": materials[1]},
        conditions={
            "upper.z1": Dirichlet((None, None, -depth)),
            "upper.x0": Dirichlet((0.0, None, None)),
            "upper.y0": Dirichlet((None, 0.0, None)),
            "upper.x1": _FREE,
            "upper.y1": _FREE,
            "lower.z0": Dirichlet((None, None, 0.0)),
            "lower.x0": Dirichlet((0.0, None, None)),
            "lower.y0": Dirichlet((None, 0.0, None)),
            "lower.x1": _FREE,
            "lower.y1": _FREE,
            pair[0]: Contact(master=pair[1]),
        },
        name="stacked-cubes",
    )


def cubes_pressure(problem: ContactProblem, depth: float = 0.01) -> float:
    """The exact contact pressure ``p = δ / Σ H_i / E_i`` of :func:`stacked_cubes`."""
    m = problem.material
    return depth / sum(1.0 / m[b].young for b in ("upper", "lower"))


def cubes_metrics(result: ContactResult) -> dict[str, float]:
    """The 3D contact patch test on a level: the largest relative deviation of the slave's
    nodal pressures ``Λ̃_j / D_jj`` from their mean, and of the master's nodal forces
    ``Σ_j T_jk Λ̃_j n_j`` from the consistent forces of that mean pressure, ``p̄ ∫_Γm φ_k``
    along the normal, relative to the largest of them (round-off for the dual mortar
    coupling)."""
    cs = result.contact
    p = result.pressure
    mean = float(np.mean(p)) if p.size else 0.0
    if not mean > 0:
        return {"slave_pressure_deviation": np.nan, "master_force_deviation": np.nan}
    space = result.space
    facets = result.mesh.part_facets(cs.masters[0])
    faces = space.facet_nodes(facets)
    w = np.zeros(space.n_nodes)
    share = np.asarray(space.element.facet.basis_share)
    area = result.mesh.facet_measure[facets]
    np.add.at(w, faces, area[:, None] * share[None, :])
    on = np.unique(faces)
    normal = np.mean(cs.direction, axis=0)
    consistent = mean * w[on, None] * normal
    got = cs.master_forces(result.contact_force, space.n_nodes)[on]
    scale = np.abs(consistent).max()
    return {
        "slave_pressure_deviation": float(np.abs(p / mean - 1.0).max()),
        "master_force_deviation": float(np.abs(got - consistent).max() / scale),
    }


#: The stacked cubes' columns of ``history.csv``: the 3D patch test's deviations.
CUBES_METRICS = Metrics(
    measure=cubes_metrics,
    columns={
        "slave_pressure_deviation": "max |p_j / mean p − 1| over the slave's constrained "
        "nodes, p_j = Λ̃_j / D_jj, no unit (uniform pressure: round-off)",
        "master_force_deviation": "max |Σ_j T_jk Λ̃_j n_j − p̄ ∫ φ_k n| over the master's "
        "nodes, relative to the largest consistent force, no unit",
    },
)
