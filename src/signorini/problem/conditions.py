"""Boundary conditions on named boundary parts, and a known exact solution.

The strong form (paper, Section 2; docs/method.md, *The continuous problem*)::

    u = u_D on Γ_D   (Dirichlet),
    σ(u) n = g on Γ_N   (Neumann),
    u·n ≤ ψ,  σ_nn ≤ 0,  (u·n − ψ) σ_nn = 0,  σ_t = 0 on Γ_C   (Contact).

Each condition holds its data as given (a constant or a function of ``x``) and hands it out as
a function through ``field`` / ``gap_field``; the functions are called and checked by
:func:`signorini.problem.fields.evaluate_field`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .fields import VectorField, constant_field

__all__ = ["Condition", "Contact", "Dirichlet", "ExactSolution", "Neumann"]


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement ``u = u_D`` (a constant vector or a function of ``x (n, 2)``)."""

    value: VectorField | tuple[float, float] = (0.0, 0.0)

    def field(self) -> VectorField:
        """``u_D`` as a function of ``x (..., 2)``."""
        return self.value if callable(self.value) else constant_field(self.value)


@dataclass(frozen=True)
class Neumann:
    """Prescribed traction ``σ(u) n = g``: a constant vector or ``g(x (..., 2), n (..., 2))``."""

    traction: Callable[[np.ndarray, np.ndarray], np.ndarray] | tuple[float, float] = (0.0, 0.0)

    def field(self) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        """``g`` as a function of the points and the outward unit normals."""
        if callable(self.traction):
            return self.traction
        const = constant_field(self.traction)
        return lambda x, n: const(x)

    @property
    def is_zero(self) -> bool:
        """A zero constant traction (the part adds nothing to the load)."""
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
        with the geometry (checked by :class:`~signorini.problem.problem.ContactProblem`).
    """

    gap: Callable[[np.ndarray], np.ndarray] | float = 0.0
    normal: tuple[float, float] | None = None

    def gap_field(self) -> Callable[[np.ndarray], np.ndarray]:
        """``ψ`` as a scalar function of ``x (..., 2)``."""
        return self.gap if callable(self.gap) else constant_field(self.gap, shape=())


@dataclass(frozen=True)
class ExactSolution:
    """A known solution: displacement ``u(x) -> (..., 2)``, gradient ``grad(x) -> (..., 2, 2)``
    with ``grad[..., i, j] = ∂u_i/∂x_j``."""

    displacement: VectorField
    gradient: Callable[[np.ndarray], np.ndarray]


Condition = Dirichlet | Neumann | Contact
