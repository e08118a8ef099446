"""Manufactured contact solutions on the cube, contact face z = 0 against a rigid plane.

The outward normal of Γ_C = {z = 0} is n = (0, 0, −1), so u·n = −u_z and the constraint is
u·n ≤ ψ. Given on Γ_C a gap g ≥ 0 and a pressure p ≥ 0 with g p = 0, tangential surface
fields a = (a_1, a_2) and the obstacle ψ, the exact solution is

    u_1 = a_1 + z² q_1,    u_2 = a_2 + z² q_2,
    u_3 = g − ψ + z (−p − λ div a)/(λ + 2μ) + z² c,

so that on z = 0: ψ − u·n = g and σ_nn = σ_zz = (λ + 2μ) ∂_z u_3 + λ div a = −p: the
Signorini conditions hold by construction. The body force is f = −div σ(u), the Neumann
data σ(u) n on the four side faces and the tangential traction σ_t(u) on Γ_C; u is held at
z = 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as s

from .elasticity import Field

X = s.symbols("x y z")
x, y, z = X


@dataclass(frozen=True)
class Manufactured:
    """An exact contact solution and its data, as NumPy callables on (..., 3) points.

    Attributes
    ----------
    u, f : callable, (..., 3) → (..., 3)
        Displacement and body force.
    grad_u, stress : callable, (..., 3) → (..., 3, 3)
    psi, gap, pressure : callable, (..., 3) → (...)
        Obstacle ψ, exact gap ψ − u·n and pressure −σ_nn on Γ_C (read at z = 0).
    lam, mu : float
    """

    name: str
    u: Field
    grad_u: Field
    stress: Field
    f: Field
    psi: Field
    gap: Field
    pressure: Field
    lam: float
    mu: float


def _vector(exprs: list, shape: tuple[int, ...]) -> Field:
    fn = s.lambdify(X, exprs, "numpy")

    def field(p: np.ndarray) -> np.ndarray:
        cols = [p[..., 0], p[..., 1], p[..., 2]]
        out = fn(*cols)
        flat = [np.broadcast_to(np.asarray(v, float), p.shape[:-1]) for v in out]
        return np.stack(flat, axis=-1).reshape(*p.shape[:-1], *shape)

    return field


def manufactured(name: str, g, p, a, q, c, psi, E: float = 1.0, nu: float = 0.3) -> Manufactured:
    """Build the solution of the module docstring from sympy expressions in x, y (and z)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    div_a = s.diff(a[0], x) + s.diff(a[1], y)
    u = [
        a[0] + z**2 * q[0],
        a[1] + z**2 * q[1],
        g - psi + z * (-p - lam * div_a) / (lam + 2 * mu) + z**2 * c,
    ]
    grad = s.Matrix(3, 3, lambda i, j: s.diff(u[i], X[j]))
    eps = (grad + grad.T) / 2
    sigma = 2 * mu * eps + lam * eps.trace() * s.eye(3)
    f = [-sum(s.diff(sigma[i, j], X[j]) for j in range(3)) for i in range(3)]
    return Manufactured(
        name,
        _vector(u, (3,)),
        _vector(list(grad), (3, 3)),
        _vector(list(sigma), (3, 3)),
        _vector(f, (3,)),
        _vector([psi], ()),
        _vector([g], ()),
        _vector([p], ()),
        lam,
        mu,
    )


def full_contact() -> Manufactured:
    """Full contact on Γ_C: g = 0, p = 0.1 (1 + ½ sin πx cos πy) ∈ [0.05, 0.15], smooth ψ."""
    return manufactured(
        "full contact",
        g=s.Integer(0),
        p=s.Rational(1, 10) * (1 + s.sin(s.pi * x) * s.cos(s.pi * y) / 2),
        a=(s.sin(s.pi * y) * s.cos(x) / 50, s.cos(s.pi * x) * s.sin(y) / 50),
        q=(3 * s.cos(x + y) / 100, 3 * s.sin(x - y) / 100),
        c=s.sin(x + y) / 20,
        psi=(1 + s.sin(2 * x + y)) / 50,
    )


def transition(radius: float = 0.3) -> Manufactured:
    """Contact inside the circle r = ``radius`` about (½, ½), a gap outside (a free boundary).

    With φ = (x − ½)² + (y − ½)² − R²: p = 300 (φ⁻)³ (≤ 0.22), g = (φ⁺)³ (≤ 0.07): C² data,
    so f is continuous.
    """
    phi = (x - s.Rational(1, 2)) ** 2 + (y - s.Rational(1, 2)) ** 2 - s.nsimplify(radius) ** 2
    return manufactured(
        "transition",
        g=s.Piecewise((phi**3, phi > 0), (0, True)),
        p=s.Piecewise((-300 * phi**3, phi < 0), (0, True)),
        a=(s.sin(s.pi * y) * s.cos(x) / 50, s.cos(s.pi * x) * s.sin(y) / 50),
        q=(3 * s.cos(x + y) / 100, 3 * s.sin(x - y) / 100),
        c=s.sin(x + y) / 20,
        psi=(1 + s.sin(2 * x + y)) / 50,
    )


def patch() -> Manufactured:
    """The constant-pressure patch test: u affine, σ constant, p = 0.1, f = 0, ψ affine."""
    return manufactured(
        "patch",
        g=s.Integer(0),
        p=s.Rational(1, 10),
        a=(x / 100 + y / 50, -x / 100 + y / 200),
        q=(s.Integer(0), s.Integer(0)),
        c=s.Integer(0),
        psi=s.Rational(1, 100) + x / 50 - y / 100,
    )
