"""Friction laws on a contact part: Tresca (a given slip bound) and Coulomb (a coefficient).

On a contact part with normal n and tangent t (docs/method.md, *Friction*), beside the
Signorini conditions in the normal direction:

- Tresca with a slip bound ``s ≥ 0`` (stress units, a function on Γ_C):
  ``|σ_t| ≤ s``; ``|σ_t| < s ⇒ u_t = 0`` (stick); ``|σ_t| = s ⇒ u_t = −α σ_t, α ≥ 0`` (slip,
  opposite to the friction force);
- Coulomb with a coefficient ``F ≥ 0``: the same with ``s = F |σ_n|``.

Discretely the laws hold node-wise with the nodal contact forces (3.17): ``|Λ_t,z| ≤ s_z``
with ``s_z = ∫ s ψ_z ds`` (Tresca) or ``|Λ_t,z| ≤ F Λ_n,z`` (Coulomb).

Both implement the friction-law protocol
:class:`signorini.algebra.friction.laws.FrictionLaw` that the contact layer, the solver and
the estimator ask (its slip bound from a nodal weight and the normal force,
the bound's derivative, whether the systems stay symmetric): a new law is one
class with the same five members, given as ``Contact(friction=...)``.

The laws check their data when they are built (numbers must be finite and ``≥ 0``, a function
must accept points ``x (n, 2)``); a bound function's values are checked where it is evaluated
(:func:`signorini.problem.fields.evaluate_field`, then ``≥ 0``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .fields import ProblemError, check_function, check_numbers, constant_field

__all__ = ["LAW_MEMBERS", "Coulomb", "Friction", "Tresca"]

_BOUND = "a finite number >= 0 or a function s(x) of points x (n, 2) returning values >= 0"
_COEFFICIENT = "a finite number >= 0"


@dataclass(frozen=True)
class Tresca:
    """Tresca friction: the tangential stress is bounded by a given slip bound.

    Parameters
    ----------
    bound : float or callable
        The slip bound ``s ≥ 0`` in stress units (MPa if E is in MPa): a number, or a function
        ``s(x)`` of the points ``x (n, 2)`` returning ``(n,)`` values ``≥ 0``
        (docs/method.md, *User functions*).
    everywhere : bool
        The bound acts on every node of the part (the classical Tresca problem, a convex
        minimisation; the default), or only on the nodes in contact (a bound that models a
        known contact pressure).

    Raises
    ------
    ProblemError
        If ``bound`` is negative, NaN or infinite, or neither a number nor a function of
        ``x``.
    """

    bound: Callable[[np.ndarray], np.ndarray] | float
    everywhere: bool = True

    #: the bound does not depend on the normal force
    symmetric: ClassVar[bool] = True

    def __post_init__(self) -> None:
        if not isinstance(self.everywhere, bool):
            raise ProblemError(
                f"Tresca(everywhere=...) must be True or False; got {self.everywhere!r}"
            )
        if callable(self.bound):
            check_function(self.bound, "Tresca(bound=...)", _BOUND)
            return
        check_numbers(self.bound, 1, "Tresca(bound=...)", _BOUND)
        if float(np.asarray(self.bound, dtype=np.float64)) < 0:
            raise ProblemError(f"Tresca(bound=...) must be {_BOUND}; got {self.bound!r}")

    def bound_field(self) -> Callable[[np.ndarray], np.ndarray]:
        """``s`` as a scalar function of ``x (n, 2)``."""
        if callable(self.bound):
            return self.bound
        return constant_field(np.asarray(self.bound, dtype=np.float64).reshape(()), shape=())

    def nodal_weight(self, integrate, size: int) -> np.ndarray:
        """The nodal bounds ``s_z = ∫ s ψ_z ds`` (force units)."""
        return integrate(self.bound_field())

    def slip_bound(
        self, weight: np.ndarray, normal_force: np.ndarray, in_contact: np.ndarray
    ) -> np.ndarray:
        """``s_z`` (where the bound acts: everywhere, or in contact)."""
        return weight if self.everywhere else weight * in_contact

    def bound_derivative(self, weight: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
        """0: the bound is data."""
        return np.zeros(weight.shape)


@dataclass(frozen=True)
class Coulomb:
    """Coulomb friction: the tangential stress is bounded by ``F`` times the normal pressure.

    Parameters
    ----------
    coefficient : float
        The friction coefficient ``F ≥ 0`` (dimensionless).

    Raises
    ------
    ProblemError
        If ``coefficient`` is negative, NaN or infinite, or not a number.
    """

    coefficient: float

    #: the bound ``F Λ_n`` depends on the normal force: non-symmetric systems
    symmetric: ClassVar[bool] = False
    #: no normal force, no friction force
    everywhere: ClassVar[bool] = False

    def __post_init__(self) -> None:
        check_numbers(self.coefficient, 1, "Coulomb(coefficient=...)", _COEFFICIENT)
        if float(np.asarray(self.coefficient, dtype=np.float64)) < 0:
            raise ProblemError(
                f"Coulomb(coefficient=...) must be {_COEFFICIENT}; got {self.coefficient!r}"
            )

    def nodal_weight(self, integrate, size: int) -> np.ndarray:
        """The coefficient ``F`` at every node."""
        return np.full(size, float(self.coefficient))

    def slip_bound(
        self, weight: np.ndarray, normal_force: np.ndarray, in_contact: np.ndarray
    ) -> np.ndarray:
        """``F max(Λ_n, 0)``."""
        return weight * np.maximum(normal_force, 0.0)

    def bound_derivative(self, weight: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
        """``F``."""
        return weight


Friction = Tresca | Coulomb
"""The built-in friction laws; ``Contact(friction=...)`` takes any object with their five
members (:class:`signorini.algebra.friction.laws.FrictionLaw`)."""

#: what a friction law has (:class:`signorini.algebra.friction.laws.FrictionLaw`)
LAW_MEMBERS = ("symmetric", "everywhere", "nodal_weight", "slip_bound", "bound_derivative")
