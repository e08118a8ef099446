"""Friction laws on a contact part: Tresca (a given slip bound) and Coulomb (a coefficient).

On a contact part with normal n and tangent t (docs/method.md, *Friction*), beside the
Signorini conditions in the normal direction:

- Tresca with a slip bound ``s ≥ 0`` (stress units, a function on Γ_C):
  ``|σ_t| ≤ s``; ``|σ_t| < s ⇒ u_t = 0`` (stick); ``|σ_t| = s ⇒ u_t = −α σ_t, α ≥ 0`` (slip,
  opposite to the friction force);
- Coulomb with a coefficient ``F ≥ 0``: the same with ``s = F |σ_n|``.

Discretely the laws hold node-wise with the nodal contact forces (3.17): ``|Λ_t,z| ≤ s_z``
with ``s_z = ∫ s ψ_z ds`` (Tresca) or ``|Λ_t,z| ≤ F Λ_n,z`` (Coulomb).

The laws check their data when they are built (numbers must be finite and ``≥ 0``, a function
must accept points ``x (n, 2)``); a bound function's values are checked where it is evaluated
(:func:`signorini.problem.fields.evaluate_field`, then ``≥ 0``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .fields import ProblemError, check_function, check_numbers, constant_field

__all__ = ["Coulomb", "Friction", "Tresca"]

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

    Raises
    ------
    ProblemError
        If ``bound`` is negative, NaN or infinite, or neither a number nor a function of
        ``x``.
    """

    bound: Callable[[np.ndarray], np.ndarray] | float

    def __post_init__(self) -> None:
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

    def __post_init__(self) -> None:
        check_numbers(self.coefficient, 1, "Coulomb(coefficient=...)", _COEFFICIENT)
        if float(np.asarray(self.coefficient, dtype=np.float64)) < 0:
            raise ProblemError(
                f"Coulomb(coefficient=...) must be {_COEFFICIENT}; got {self.coefficient!r}"
            )


Friction = Tresca | Coulomb
