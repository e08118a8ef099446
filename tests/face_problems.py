"""Manufactured frictionless contact on the unit cube, contact face z = 0 against a rigid plane
(the closed forms of studies/faces3d/manufactured.py, copied): the package's blocks assemble
and solve them in the 3D contact tests.

The outward normal of Γ_C = {z = 0} is n = (0, 0, −1), u·n = −u_z, the constraint u·n ≤ ψ.
Given on Γ_C a gap g ≥ 0 and a pressure p ≥ 0 with g p = 0, tangential fields a and the
obstacle ψ,

    u_1 = a_1 + z² q_1,  u_2 = a_2 + z² q_2,  u_3 = g − ψ + z (−p − λ div a)/(λ + 2μ) + z² c,

so that ψ − u·n = g and σ_nn = −p on z = 0; f = −div σ(u), σ(u) n on the side faces, σ_t(u)
on Γ_C, u held at z = 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as s

X = s.symbols("x y z")
x, y, z = X


@dataclass(frozen=True)
class Manufactured:
    """NumPy callables on points ``(..., 3)``: u, f ``(..., 3)``, stress ``(..., 3, 3)``, psi
    and pressure ``(...)``; the Lamé parameters."""

    u: object
    stress: object
    f: object
    psi: object
    pressure: object
    lam: float
    mu: float


def _vector(exprs, shape):
    fn = s.lambdify(X, exprs, "numpy")

    def field(p):
        out = fn(p[..., 0], p[..., 1], p[..., 2])
        flat = [np.broadcast_to(np.asarray(v, float), p.shape[:-1]) for v in out]
        return np.stack(flat, axis=-1).reshape(*p.shape[:-1], *shape)

    return field


def manufactured(g, p, a, q, c, psi, E=1.0, nu=0.3) -> Manufactured:
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
        _vector(u, (3,)),
        _vector(list(sigma), (3, 3)),
        _vector(f, (3,)),
        _vector([psi], ()),
        _vector([p], ()),
        lam,
        mu,
    )


_A = (s.sin(s.pi * y) * s.cos(x) / 50, s.cos(s.pi * x) * s.sin(y) / 50)
_Q = (3 * s.cos(x + y) / 100, 3 * s.sin(x - y) / 100)
_PSI = (1 + s.sin(2 * x + y)) / 50


def full_contact() -> Manufactured:
    """g = 0, p = 0.1 (1 + ½ sin πx cos πy)."""
    p = s.Rational(1, 10) * (1 + s.sin(s.pi * x) * s.cos(s.pi * y) / 2)
    return manufactured(s.Integer(0), p, _A, _Q, s.sin(x + y) / 20, _PSI)


def transition(radius: float = 0.3) -> Manufactured:
    """Contact inside r = radius about (½, ½): p = 300 (φ⁻)³, g = (φ⁺)³."""
    phi = (x - s.Rational(1, 2)) ** 2 + (y - s.Rational(1, 2)) ** 2 - s.nsimplify(radius) ** 2
    g = s.Piecewise((phi**3, phi > 0), (0, True))
    p = s.Piecewise((-300 * phi**3, phi < 0), (0, True))
    return manufactured(g, p, _A, _Q, s.sin(x + y) / 20, _PSI)


def patch() -> Manufactured:
    """u affine, σ constant, p = 0.1, ψ affine."""
    a = (x / 100 + y / 50, -x / 100 + y / 200)
    zero = (s.Integer(0), s.Integer(0))
    psi = s.Rational(1, 100) + x / 50 - y / 100
    return manufactured(s.Integer(0), s.Rational(1, 10), a, zero, s.Integer(0), psi)
