"""``partial-slip-spheres`` (Cattaneo–Mindlin between two bodies): two elastic spheres of one
material pressed together, then pulled across each other by a force Q < F·P, with Coulomb
friction in their dual mortar pair (docs/method.md, *Two bodies in three dimensions:
friction*).

Both bodies are halves ``y ≥ 0`` of balls meeting at their poles at the origin, with a roller
``u_y = 0`` on the mirror plane y = 0 of both (pulling along x keeps it): the upper, radius
R1 about ``(0, 0, R1)``, is :func:`~.partial_slip3d.half_ball`; the lower, radius R2 about
``(0, 0, −R2)``, the same half ball of radius R2 turned half a turn about the y axis
(:data:`_ABOUT_Y`, a rotation: the cells keep their orientation and bisection order). The
slave is the upper sphere's cap within ``cap`` of the pole (:func:`~.two_spheres3d.with_cap`),
the master the lower's whole sphere. The lower's flat bottom holds ``u_x = u_z = 0``; the
upper's flat top is moved by ``(0, free, −δ)`` (press), then by ``(ξ, free, −δ)`` (pull at
constant approach): two quasi-static steps on one mesh, the friction law acting on the
relative slip from the press.

Theory: two bodies of one material have Dundurs' β = 0 whatever ν, so the normal and the
tangential problems uncouple exactly and Mindlin's result holds as for one ball on a rigid
plane with β = 0: the contact disc is Hertz's for ``1/R* = 1/R1 + 1/R2``, ``E* = E / (2 (1 −
ν²))``, and the pull leaves a central stick disc ``r < c`` with ``c/a = (1 − Q/(F P))^{1/3}``.
The measured columns are those of ``partial-slip-3d``
(:func:`~.partial_slip3d.partial_slip_3d_metrics` on the pair's rows: P, Q and a from the
slave's multipliers in the dual basis, c from the zero of the stick rows' traction deficit).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..fem.material import Material
from ..mesh.bodies import union
from ..mesh.mesh import Mesh
from ..problem import Contact, ContactProblem, Coulomb, Dirichlet, Neumann
from ..problem.conditions import Roller
from .partial_slip3d import COEFFICIENT_3D, half_ball
from .two_spheres3d import turned_ball, with_cap

__all__ = ["partial_slip_spheres", "partial_slip_spheres_path", "spheres_mesh"]

#: the rotation by π about the y axis, ``(x, y, z) → (−x, y, −z)``: keeps the half ``y ≥ 0``
_ABOUT_Y = np.diag([-1.0, 1.0, -1.0])

#: the built-in's radii (upper, lower), the press δ and the pull ξ of the upper top
RADII = (1.0, 2.0)
PRESS, PULL = 0.01, 0.002


def partial_slip_spheres_path(
    radii: tuple[float, float] = RADII,
    *,
    coefficient: float = COEFFICIENT_3D,
    press: float = PRESS,
    pull: float = PULL,
    n: int = 2,
    h_contact: float = 0.1,
    cap: float = 0.25,
) -> list[ContactProblem]:
    """The two load steps (press, pull) of the module docstring on one mesh of the two half
    balls (:func:`~.partial_slip3d.half_ball` ``(n, R_i, h_contact, 0.12)``, length units),
    E = 1 and ν = 0.3 for both, Coulomb ``coefficient`` on the pair, named
    ``"partial-slip-spheres"``.

    Raises
    ------
    ValueError
        Naming the argument: a radius, δ or ξ not positive and finite, ``cap`` not in (0,
        min(radii)).
    """
    radii = tuple(float(r) for r in radii)
    if len(radii) != 2 or not all(np.isfinite(r) and r > 0 for r in radii):
        raise ValueError(f"partial_slip_spheres: radii must be two positive numbers, got {radii!r}")
    for name, value in (("press", press), ("pull", pull)):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"partial_slip_spheres: {name} must be positive, got {value!r}")
    if not 0 < cap < min(radii):
        raise ValueError(f"partial_slip_spheres: cap must lie in (0, min(radii)), got {cap!r}")
    mesh = spheres_mesh(radii, n, h_contact, cap)
    material = Material.from_young(1.0, 0.3)
    steps = []
    for xi in (0.0, pull):
        conditions = {
            "upper.y0": Roller(), "lower.y0": Roller(),
            "upper.sphere": Neumann((0.0, 0.0, 0.0)),
            "upper.z1": Dirichlet((xi, None, -press)),
            "lower.z1": Dirichlet((0.0, None, 0.0)),
            "upper.cap": Contact(master="lower.sphere", friction=Coulomb(coefficient)),
        }  # fmt: skip
        steps.append(
            ContactProblem(
                mesh,
                {"upper": material, "lower": material},
                conditions,
                name="partial-slip-spheres",
            )  # fmt: skip
        )
    return steps


@lru_cache(maxsize=8)
def spheres_mesh(radii: tuple[float, float], n: int, h_contact: float, cap: float) -> Mesh:
    """The union of the two half balls of the module docstring, the upper's cap a part.
    Cached: the steps of a load path built twice (the problem and its path, as the command
    line asks them) share one mesh object."""
    upper = with_cap(half_ball(n, radii[0], h_contact, 0.12), cap)
    lower = turned_ball(half_ball(n, radii[1], h_contact, 0.12), _ABOUT_Y)
    return union({"upper": upper, "lower": lower})


def partial_slip_spheres(**kwargs) -> ContactProblem:
    """The last step of :func:`partial_slip_spheres_path` (the pulled spheres)."""
    return partial_slip_spheres_path(**kwargs)[-1]
