"""Problem definitions: material, data and boundary conditions of a Signorini problem.

The strong form (paper, Section 2; docs/method.md, *The continuous problem*)::

    −div σ(u) = f in Ω,   u = u_D on Γ_D,   σ(u) n = g on Γ_N,
    u·n ≤ ψ,  σ_nn ≤ 0,  (u·n − ψ) σ_nn = 0,  σ_t = 0 on Γ_C.

A :class:`ContactProblem` assigns one condition to every boundary part of its mesh.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from ..fem.elasticity import Material
from ..fem.space import P2Space
from ..mesh.geometry import segment_normals
from ..mesh.mesh import Mesh

__all__ = ["Dirichlet", "Neumann", "Contact", "ExactSolution", "ContactProblem", "ProblemError"]

VectorField = Callable[[np.ndarray], np.ndarray]


class ProblemError(ValueError):
    """Raised for an ill-posed or inconsistent problem definition."""


def _constant_field(value: np.ndarray) -> VectorField:
    v = np.asarray(value, dtype=np.float64).reshape(2)
    return lambda x: np.broadcast_to(v, np.shape(x)[:-1] + (2,)).copy()


def evaluate_field(func: VectorField, x: np.ndarray, what: str) -> np.ndarray:
    """Evaluate a vector field at points ``x (..., 2)``, checking shape and finiteness."""
    values = np.asarray(func(x), dtype=np.float64)
    expected = np.shape(x)[:-1] + (2,)
    if values.shape != expected:
        try:
            values = np.broadcast_to(values, expected).copy()
        except ValueError:
            raise ProblemError(
                f"{what} must return shape {expected} for points of shape "
                f"{np.shape(x)}, got {values.shape}"
            ) from None
    if not np.isfinite(values).all():
        raise ProblemError(f"{what} returned NaN or inf")
    return values


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement ``u = u_D`` (a constant vector or a function of ``x (n, 2)``)."""

    value: VectorField | tuple[float, float] = (0.0, 0.0)

    def field(self) -> VectorField:
        return self.value if callable(self.value) else _constant_field(self.value)


@dataclass(frozen=True)
class Neumann:
    """Prescribed traction ``σ(u) n = g``: a constant vector or ``g(x (..., 2), n (..., 2))``."""

    traction: Callable[[np.ndarray, np.ndarray], np.ndarray] | tuple[float, float] = (0.0, 0.0)

    def field(self) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        if callable(self.traction):
            return self.traction
        const = _constant_field(self.traction)
        return lambda x, n: const(x)

    @property
    def is_zero(self) -> bool:
        return not callable(self.traction) and not np.any(np.asarray(self.traction))


@dataclass(frozen=True)
class Contact:
    """Frictionless unilateral contact ``u·n ≤ ψ`` on a straight boundary part.

    Parameters
    ----------
    gap : float or callable
        The gap (obstacle) function ``ψ(x (n, 2)) -> (n,)``, or a constant.
    normal : (2,) array or None
        The outward unit normal; ``None`` takes it from the geometry. A given normal must agree
        with the geometry.
    """

    gap: Callable[[np.ndarray], np.ndarray] | float = 0.0
    normal: tuple[float, float] | None = None

    def gap_values(self, x: np.ndarray, part: str) -> np.ndarray:
        if callable(self.gap):
            values = np.asarray(self.gap(x), dtype=np.float64)
            if values.shape != x.shape[:-1]:
                try:
                    values = np.broadcast_to(values, x.shape[:-1]).copy()
                except ValueError:
                    raise ProblemError(
                        f"the gap function of contact part {part!r} must return "
                        f"shape {x.shape[:-1]}, got {values.shape}"
                    ) from None
        else:
            values = np.full(x.shape[:-1], float(self.gap))
        if not np.isfinite(values).all():
            raise ProblemError(f"the gap function of contact part {part!r} returned NaN or inf")
        return values


@dataclass(frozen=True)
class ExactSolution:
    """A known solution: displacement ``u(x) -> (..., 2)``, gradient ``grad(x) -> (..., 2, 2)``
    with ``grad[..., i, j] = ∂u_i/∂x_j``."""

    displacement: VectorField
    gradient: Callable[[np.ndarray], np.ndarray]


Condition = Dirichlet | Neumann | Contact


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
