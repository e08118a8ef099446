"""``elasticity-3d``: a manufactured smooth solution of 3D elasticity on the unit cube, no
contact (docs/method.md, *Three dimensions: solving elasticity*) — the first thing a 3D user
runs (``signorini run elasticity-3d --uniform``).

``u = (sin πx sin πy sin πz, x y z eˣ, cos(πx/2) y² z)`` with ``λ = 1.7``, ``μ = 0.9``, the
body force ``f = −div σ(u)`` and ``u`` itself on all six faces (Dirichlet). Under uniform
refinement of P2 tetrahedra the energy error falls like ``h² ~ N^{−2/3}`` and the L² error
like ``h³ ~ N^{−1}``. The measurements (:data:`ELASTICITY_3D_METRICS`) add the L² error and
the observed rates of the three errors against the free unknowns N to the history.
"""

from __future__ import annotations

import numpy as np

from ..fem.material import Material
from ..mesh.builders3d import box
from ..problem.conditions import Dirichlet, ExactSolution
from ..problem.problem import ContactProblem
from .metrics import error_rate_metrics

__all__ = ["ELASTICITY_3D_METRICS", "elasticity_3d"]

MATERIAL = Material(lam=1.7, mu=0.9)


def displacement(x: np.ndarray) -> np.ndarray:
    """``u(x (n, 3)) -> (n, 3)``."""
    X, Y, Z = x[:, 0], x[:, 1], x[:, 2]
    return np.stack(
        [
            np.sin(np.pi * X) * np.sin(np.pi * Y) * np.sin(np.pi * Z),
            X * Y * Z * np.exp(X),
            np.cos(np.pi * X / 2) * Y**2 * Z,
        ],
        axis=-1,
    )


def _derivatives(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``∇u (n, 3, 3)`` and the Hessians ``H[n, i, j, k] = ∂_j ∂_k u_i (n, 3, 3, 3)``."""
    X, Y, Z = x[:, 0], x[:, 1], x[:, 2]
    pi, s, c, e = np.pi, np.sin, np.cos, np.exp(X)
    sx, sy, sz, cx, cy, cz = s(pi * X), s(pi * Y), s(pi * Z), c(pi * X), c(pi * Y), c(pi * Z)
    h, ch = s(pi * X / 2), c(pi * X / 2)
    zero = np.zeros_like(X)
    g = np.stack(
        [
            [pi * cx * sy * sz, pi * sx * cy * sz, pi * sx * sy * cz],
            [Y * Z * e * (1 + X), X * Z * e, X * Y * e],
            [-pi / 2 * h * Y**2 * Z, 2 * ch * Y * Z, ch * Y**2],
        ]
    )  # (3, 3, n)
    p2 = pi**2
    H = np.stack(
        [
            [
                [-p2 * sx * sy * sz, p2 * cx * cy * sz, p2 * cx * sy * cz],
                [p2 * cx * cy * sz, -p2 * sx * sy * sz, p2 * sx * cy * cz],
                [p2 * cx * sy * cz, p2 * sx * cy * cz, -p2 * sx * sy * sz],
            ],
            [
                [Y * Z * e * (2 + X), Z * e * (1 + X), Y * e * (1 + X)],
                [Z * e * (1 + X), zero, X * e],
                [Y * e * (1 + X), X * e, zero],
            ],
            [
                [-p2 / 4 * ch * Y**2 * Z, -pi * h * Y * Z, -pi / 2 * h * Y**2],
                [-pi * h * Y * Z, 2 * ch * Z, 2 * ch * Y],
                [-pi / 2 * h * Y**2, 2 * ch * Y, zero],
            ],
        ]
    )  # (3, 3, 3, n)
    return np.moveaxis(g, -1, 0), np.moveaxis(H, -1, 0)


def gradient(x: np.ndarray) -> np.ndarray:
    """``∇u(x (n, 3)) -> (n, 3, 3)``, ``[:, i, j] = ∂u_i/∂x_j``."""
    return _derivatives(x)[0]


def body_force(x: np.ndarray) -> np.ndarray:
    """``f = −div σ(u) = −(μ Δu + (λ + μ) ∇ div u)`` at ``x (n, 3)``: the traces of
    :func:`_derivatives`' Hessians written out (``Δu_i = H_ijj``, ``(∇ div u)_i = H_jij``)."""
    X, Y, Z = x[:, 0], x[:, 1], x[:, 2]
    pi, e = np.pi, np.exp(X)
    sx, sy, sz = np.sin(pi * X), np.sin(pi * Y), np.sin(pi * Z)
    cx, cy, cz = np.cos(pi * X), np.cos(pi * Y), np.cos(pi * Z)
    h, ch = np.sin(pi * X / 2), np.cos(pi * X / 2)
    p2, sxyz = pi**2, sx * sy * sz
    laplace = np.stack([-3 * p2 * sxyz, Y * Z * e * (2 + X), ch * Z * (2 - p2 / 4 * Y**2)], axis=-1)
    grad_div = np.stack(
        [
            -p2 * sxyz + Z * e * (1 + X) - pi / 2 * h * Y**2,
            p2 * cx * cy * sz + 2 * ch * Y,
            p2 * cx * sy * cz + X * e,
        ],
        axis=-1,
    )
    return -(MATERIAL.mu * laplace + (MATERIAL.lam + MATERIAL.mu) * grad_div)


def elasticity_3d(n: int = 2) -> ContactProblem:
    """The manufactured problem on the Kuhn mesh of ``n³`` cubes."""
    mesh = box(n, n, n)
    return ContactProblem(
        mesh,
        MATERIAL,
        {name: Dirichlet(displacement) for name in mesh.part_names},
        body_force=body_force,
        exact=ExactSolution(displacement, gradient),
        name="elasticity-3d",
    )


#: the L² error and the observed rates of the three errors (columns of the history)
ELASTICITY_3D_METRICS = error_rate_metrics()
