"""The Signorini problem a user states: a mesh, a material, one condition per boundary part,
the body force and (optionally) an exact solution.

The strong form (paper, Section 2; docs/method.md, *The continuous problem*)::

    −div σ(u) = f in Ω,   u = u_D on Γ_D,   σ(u) n = g on Γ_N,
    u·n ≤ ψ,  σ_nn ≤ 0,  (u·n − ψ) σ_nn = 0,  σ_t = 0 on Γ_C.

:class:`ContactProblem` is a public boundary: it checks that every part has exactly one
condition, that there is a Dirichlet part, and that each contact part is straight with the
given normal. Everything below it trusts the problem.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..fem.material import Material
from ..fem.space import P2Space
from ..mesh.geometry import segment_normals
from ..mesh.mesh import Mesh
from .conditions import Condition, Contact, Dirichlet, ExactSolution, Neumann
from .fields import ProblemError, VectorField

__all__ = ["ContactProblem"]


@dataclass(frozen=True)
class ContactProblem:
    """A Signorini problem on an initial mesh.

    Parameters
    ----------
    mesh : Mesh
        The initial mesh; its boundary parts carry the conditions.
    material : Material
    conditions : mapping part name -> Dirichlet | Neumann | Contact
        Every boundary part of the mesh must get exactly one condition.
    body_force : callable ``f(x (..., 2)) -> (..., 2)`` or None (zero)
    exact : ExactSolution or None
    name : str
    """

    mesh: Mesh
    material: Material
    conditions: Mapping[str, Condition]
    body_force: VectorField | None = None
    exact: ExactSolution | None = None
    name: str = "problem"
    contact_normals: dict[str, np.ndarray] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        mesh = self.mesh
        if not isinstance(mesh, Mesh):
            raise ProblemError(f"mesh must be a signorini Mesh, got {type(mesh).__name__}")
        if not isinstance(self.material, Material):
            raise ProblemError(
                "material must be a signorini Material (Material.from_young or Material.from_lame)"
            )
        unknown = sorted(set(self.conditions) - set(mesh.part_names))
        if unknown:
            raise ProblemError(
                f"conditions name boundary parts the mesh does not have: "
                f"{unknown}; its parts are {list(mesh.part_names)}"
            )
        missing = [p for p in mesh.part_names if p not in self.conditions]
        if missing:
            raise ProblemError(
                f"boundary part(s) {missing} have no condition; give each part "
                "Dirichlet(...), Neumann(...) or Contact(...)"
            )
        for name, cond in self.conditions.items():
            if not isinstance(cond, Dirichlet | Neumann | Contact):
                raise ProblemError(
                    f"the condition of part {name!r} must be Dirichlet, Neumann or "
                    f"Contact, got {type(cond).__name__}"
                )
            _check_data(name, cond)
        if self.body_force is not None and not callable(self.body_force):
            raise ProblemError("body_force must be a function of x (..., 2), or None")
        if self.exact is not None and not isinstance(self.exact, ExactSolution):
            raise ProblemError(f"exact must be an ExactSolution, got {type(self.exact).__name__}")
        if not self.dirichlet_parts:
            raise ProblemError(
                "the problem needs a Dirichlet part (meas Γ_D > 0) to rule out rigid body motions"
            )
        normals = {name: self._segment_normal(name) for name in self.contact_parts}
        object.__setattr__(self, "contact_normals", normals)

    @property
    def dirichlet_parts(self) -> list[str]:
        return [n for n, c in self.conditions.items() if isinstance(c, Dirichlet)]

    @property
    def neumann_parts(self) -> list[str]:
        return [n for n, c in self.conditions.items() if isinstance(c, Neumann)]

    @property
    def contact_parts(self) -> list[str]:
        return [n for n, c in self.conditions.items() if isinstance(c, Contact)]

    def dirichlet_nodes(self, space: P2Space) -> np.ndarray:
        """Sorted P2 nodes of ``space`` on the closure of Γ_D: both their DOFs are prescribed."""
        return space.part_nodes(self.dirichlet_parts)

    def free_ndof(self, mesh: Mesh) -> int:
        """Free scalar unknowns on ``mesh``, the paper's Ndof: all P2 DOFs minus the Dirichlet
        DOFs (docs/method.md, *Data conventions*)."""
        space = P2Space(mesh)
        return space.n_dofs - 2 * self.dirichlet_nodes(space).size

    def _segment_normal(self, name: str) -> np.ndarray:
        """Outward unit normal of a straight contact part, checked against a given one."""
        mesh = self.mesh
        ab = mesh.oriented_boundary(mesh.part_edges(name))
        _, n = segment_normals(mesh.points[ab[:, 0]], mesh.points[ab[:, 1]])
        mean = n.mean(axis=0)
        mean /= np.linalg.norm(mean)
        if np.abs(n - mean).max() > 1e-8:
            raise ProblemError(
                f"contact part {name!r} is not straight: its edges' outward "
                "normals differ; split it into straight parts"
            )
        given = self.conditions[name].normal
        if given is not None:
            g = np.asarray(given, dtype=np.float64).reshape(2)
            if not np.isfinite(g).all() or np.linalg.norm(g) == 0:
                raise ProblemError(
                    f"the normal of contact part {name!r} must be a non-zero finite vector"
                )
            g = g / np.linalg.norm(g)
            if np.abs(g - mean).max() > 1e-6:
                raise ProblemError(
                    f"the normal {tuple(given)} given for contact part {name!r} "
                    f"is not its outward normal {tuple(np.round(mean, 12))}"
                )
        return mean


def _check_data(name: str, cond: Condition) -> None:
    """A condition's data given as numbers must be finite, of the right size: two numbers for a
    displacement or traction, one for a gap (functions are checked where they are called)."""
    if isinstance(cond, Dirichlet):
        data, size, what = cond.value, 2, "Dirichlet value"
    elif isinstance(cond, Neumann):
        data, size, what = cond.traction, 2, "traction"
    else:
        data, size, what = cond.gap, 1, "gap"
    if callable(data):
        return
    try:
        values = np.asarray(data, dtype=np.float64)
    except (TypeError, ValueError):
        values = np.full(0, np.nan)
    if values.size != size or not np.isfinite(values).all():
        raise ProblemError(
            f"the {what} of part {name!r} must be a function of x or {size} finite "
            f"number(s), got {data!r}"
        )
