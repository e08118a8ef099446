"""The paper's numerical experiments as ready-made problems.

Paper, Section 6; the data and what the discrete solutions show: docs/method.md, *The paper's
examples*. Initial meshes (the paper does not give its own): the unit square cut into 4 × 4
squares, each split into two triangles with the diagonals of a "union jack" pattern (32
triangles), which is mirror-symmetric about both centre lines; Example 6.2 is symmetric about
y = 1/2 and so is its discrete solution on this mesh and on every mesh NVB makes from it with
symmetric marking.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..fem.material import Material, stress
from ..mesh.builders import rectangle
from ..problem import Contact, ContactProblem, Dirichlet, ExactSolution, Neumann

__all__ = ["example_6_1", "example_6_2"]


def _exact_6_1() -> tuple[Callable, Callable, Callable]:
    """u = (y²(y−1), (x−2) y (1−y) eʸ), its gradient and its Hessian-derived div σ."""

    def q(y):
        return (y - y**2) * np.exp(y)

    def dq(y):
        return (1 - y - y**2) * np.exp(y)

    def ddq(y):
        return (-(y**2) - 3 * y) * np.exp(y)

    def displacement(x):
        X, Y = x[..., 0], x[..., 1]
        return np.stack([Y**2 * (Y - 1), (X - 2) * q(Y)], axis=-1)

    def gradient(x):
        X, Y = x[..., 0], x[..., 1]
        g = np.zeros(x.shape[:-1] + (2, 2))
        g[..., 0, 1] = 3 * Y**2 - 2 * Y
        g[..., 1, 0] = q(Y)
        g[..., 1, 1] = (X - 2) * dq(Y)
        return g

    def div_stress(x, lam, mu):
        X, Y = x[..., 0], x[..., 1]
        # σ11 = lam (x−2) q', σ22 = (lam + 2 mu)(x−2) q', σ12 = mu (3y² − 2y + q)
        d1 = lam * dq(Y) + mu * (6 * Y - 2 + dq(Y))
        d2 = (lam + 2 * mu) * (X - 2) * ddq(Y)
        return np.stack([d1, d2], axis=-1)

    return displacement, gradient, div_stress


def example_6_1(nx: int = 4) -> ContactProblem:
    """Example 6.1: known solution, contact everywhere on the bottom (n = (0, −1), ψ = 0).

    Ω = (0,1)², Γ_D = top (u = 0), Γ_N = left and right with g = σ(u) n,
    Γ_C = bottom, μ = λ = 1, f = −div σ(u), u = (y²(y−1), (x−2) y (1−y) eʸ)
    (paper, Section 6; docs/method.md, *The paper's examples*). Every constrained node is in
    full contact, so η6 = η7 = 0, and the total contact force is ∫ 3(2 − x) dx = 4.5.

    Parameters
    ----------
    nx : int, default 4
        The initial mesh cuts Ω into ``nx × nx`` squares with "union jack" diagonals
        (``2 nx²`` triangles).

    Returns
    -------
    ContactProblem
        Named ``"example-6.1"``, with its :class:`ExactSolution`.
    """
    material = Material.from_lame(1.0, 1.0)
    displacement, gradient, div_stress = _exact_6_1()

    def body_force(x):
        return -div_stress(x, material.lam, material.mu)

    def traction(x, normal):
        sigma = stress(material, gradient(x))
        return np.einsum("...ij,...j->...i", sigma, normal)

    return ContactProblem(
        mesh=rectangle(nx=nx, ny=nx, pattern="unionjack"),
        material=material,
        conditions={
            "top": Dirichlet((0.0, 0.0)),
            "left": Neumann(traction),
            "right": Neumann(traction),
            "bottom": Contact(gap=0.0, normal=(0.0, -1.0)),
        },
        body_force=body_force,
        exact=ExactSolution(displacement, gradient),
        name="example-6.1",
    )


def example_6_2(nx: int = 4) -> ContactProblem:
    """Example 6.2: a square pushed against the obstacle ψ(y) = −0.2 + 0.5|y − 0.5|.

    Ω = (0,1)², Γ_D = {x = 0} with u = (0.1, 0), Γ_N = top and bottom with g = 0,
    Γ_C = {x = 1}, n = e1, f = 0, E = 500, ν = 0.3 (paper, Section 6; docs/method.md,
    *The paper's examples*). No exact solution is known; the contact zone is one interval
    around y = 1/2.

    Parameters
    ----------
    nx : int, default 4
        The initial mesh cuts Ω into ``nx × nx`` squares with "union jack" diagonals
        (``2 nx²`` triangles).

    Returns
    -------
    ContactProblem
        Named ``"example-6.2"``, without an exact solution.
    """
    return ContactProblem(
        mesh=rectangle(nx=nx, ny=nx, pattern="unionjack"),
        material=Material.from_young(500.0, 0.3),
        conditions={
            "left": Dirichlet((0.1, 0.0)),
            "top": Neumann((0.0, 0.0)),
            "bottom": Neumann((0.0, 0.0)),
            "right": Contact(gap=lambda x: -0.2 + 0.5 * np.abs(x[..., 1] - 0.5), normal=(1.0, 0.0)),
        },
        name="example-6.2",
    )
