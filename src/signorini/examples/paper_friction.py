"""Example 6.2 with friction on its contact part: Tresca (a slip bound) and Coulomb.

The problem of :func:`~signorini.examples.paper.example_6_2` (the square pushed by u = (0.1, 0)
on its left side against the obstacle ψ(y) = −0.2 + 0.5|y − 1/2| on its right side, E = 500,
ν = 0.3) with a friction law on the part ``"right"`` (docs/method.md, *Friction in a
ContactProblem*). The data are chosen so that the contact zone (y ≈ 0.19 … 0.81, as without
friction) holds both stick and slip zones, with a transition inside it at each side:

- Coulomb, F = 0.3: the body slides along the obstacle's two slopes towards y = 1/2 less
  where the pressure is large; it sticks on y ≈ 0.32 … 0.68 around the kink and slips on
  both sides of it, out to the ends of the contact zone;
- Tresca, s = 30 (stress units, E = 500): about 5 % of the frictionless peak pressure (584)
  and 0.2 times the mean pressure over the contact zone (≈ 167); the friction stress the
  sticking body would need exceeds it on y ≈ 0.27 … 0.73 (but at the kink y = 1/2, where it
  vanishes by symmetry), which slips, while the ends of the contact zone stick. Tresca is the
  classical law, acting on the whole of Γ_C (docs/method.md, *Friction*).

Measured (docs/method.md, *The friction examples*): the transitions on the initial meshes'
uniform refinements, and the adaptive runs' rates and refinement.
"""

from __future__ import annotations

import dataclasses

from ..problem import ContactProblem, Coulomb, Tresca
from ..problem.friction_laws import Friction
from .paper import example_6_2

__all__ = [
    "COULOMB_COEFFICIENT",
    "TRESCA_BOUND",
    "example_6_2_coulomb",
    "example_6_2_friction",
    "example_6_2_tresca",
]

#: Example 6.2's Coulomb coefficient F (dimensionless): stick around y = 1/2, slip outside.
COULOMB_COEFFICIENT = 0.3
#: Example 6.2's Tresca slip bound s (stress units, E = 500): slip around y = 1/2 (but at the
#: kink), stick at the ends of the contact zone.
TRESCA_BOUND = 30.0


def example_6_2_friction(
    friction: Friction, nx: int = 4, name: str | None = None
) -> ContactProblem:
    """Example 6.2 with the friction law ``friction`` on its contact part ``"right"``.

    Parameters
    ----------
    friction : Tresca or Coulomb
        The law on Γ_C = {x = 1}.
    nx : int, default 4
        The initial mesh, as for :func:`~signorini.examples.paper.example_6_2`.
    name : str, optional
        The problem's name (default ``"example-6.2-tresca"`` or ``"example-6.2-coulomb"``).

    Returns
    -------
    ContactProblem
    """
    if not isinstance(friction, Tresca | Coulomb):
        raise ValueError(f"friction must be Tresca(...) or Coulomb(...), got {friction!r}")
    problem = example_6_2(nx)
    contact = dataclasses.replace(problem.conditions["right"], friction=friction)
    law = "tresca" if isinstance(friction, Tresca) else "coulomb"
    return dataclasses.replace(
        problem,
        conditions={**problem.conditions, "right": contact},
        name=name or f"example-6.2-{law}",
    )


def example_6_2_tresca(nx: int = 4, bound: float = TRESCA_BOUND) -> ContactProblem:
    """Example 6.2 with Tresca friction, slip bound ``bound`` (stress units; default
    :data:`TRESCA_BOUND` = 30) on its contact part; named ``"example-6.2-tresca"``."""
    return example_6_2_friction(Tresca(bound), nx)


def example_6_2_coulomb(nx: int = 4, coefficient: float = COULOMB_COEFFICIENT) -> ContactProblem:
    """Example 6.2 with Coulomb friction, coefficient ``coefficient`` (default
    :data:`COULOMB_COEFFICIENT` = 0.3) on its contact part; named ``"example-6.2-coulomb"``."""
    return example_6_2_friction(Coulomb(coefficient), nx)
