"""Frictionless manufactured contact on the unit cube as a ``ContactProblem`` (the 3D estimator's
test problems): Γ_C = {z = 0} against a rigid plane, u held at z = 1, the exact tractions on
the four sides, the body force f = −div σ(u).

The closed forms of ``tests/face_problems.py`` (``studies/faces3d/manufactured.py``) with one
change: the tangential traction on Γ_C vanishes, so that the exact solution solves the
frictionless Signorini problem with no load on Γ_C. With the outward normal n = (0, 0, −1) of
Γ_C, a gap g ≥ 0 and a pressure p ≥ 0 with g p = 0, tangential fields a, q and the obstacle ψ,

    u_1 = a_1 + z ∂_x(ψ − g) + z² q_1,   u_2 = a_2 + z ∂_y(ψ − g) + z² q_2,
    u_3 = g − ψ + z (−p − λ div a)/(λ + 2μ) + z² c,

so that on z = 0: ψ − u·n = g, σ_nn = −p and σ_13 = μ(∂_z u_1 + ∂_x u_3) = 0 = σ_23.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as s

from signorini.fem.material import Material
from signorini.mesh.builders3d import box
from signorini.problem import Contact, ContactProblem, Dirichlet, Neumann
from signorini.problem.conditions import ExactSolution

X = s.symbols("x y z")
x, y, z = X
E, NU = 1.0, 0.3


def _vector(exprs, shape):
    fn = s.lambdify(X, exprs, "numpy")

    def field(p):
        p = np.asarray(p, dtype=np.float64)
        out = fn(p[..., 0], p[..., 1], p[..., 2])
        flat = [np.broadcast_to(np.asarray(v, float), p.shape[:-1]) for v in out]
        return np.stack(flat, axis=-1).reshape(*p.shape[:-1], *shape)

    return field


def _fields(g, p, a, q, c, psi):
    """u, ∇u, σ(u), f, ψ as NumPy functions of points ``(..., 3)`` (built once per process:
    sympy differentiates and compiles them in about a second)."""
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))
    mu = E / (2 * (1 + NU))
    div_a = s.diff(a[0], x) + s.diff(a[1], y)
    u = [
        a[0] + z * s.diff(psi - g, x) + z**2 * q[0],
        a[1] + z * s.diff(psi - g, y) + z**2 * q[1],
        g - psi + z * (-p - lam * div_a) / (lam + 2 * mu) + z**2 * c,
    ]
    grad = s.Matrix(3, 3, lambda i, j: s.diff(u[i], X[j]))
    eps = (grad + grad.T) / 2
    sigma = 2 * mu * eps + lam * eps.trace() * s.eye(3)
    f = [-sum(s.diff(sigma[i, j], X[j]) for j in range(3)) for i in range(3)]
    return {
        "u": _vector(u, (3,)),
        "grad": _vector(list(grad), (3, 3)),
        "stress": _vector(list(sigma), (3, 3)),
        "f": _vector(f, (3,)),
        "psi": _vector([psi], ()),
        "pressure": _vector([p], ()),
    }


_A = (s.sin(s.pi * y) * s.cos(x) / 50, s.cos(s.pi * x) * s.sin(y) / 50)
_Q = (3 * s.cos(x + y) / 100, 3 * s.sin(x - y) / 100)
_PSI = (1 + s.sin(2 * x + y)) / 50


@cache
def full_contact_fields():
    """g = 0, p = 0.1 (1 + ½ sin πx cos πy): every point of Γ_C in contact."""
    p = s.Rational(1, 10) * (1 + s.sin(s.pi * x) * s.cos(s.pi * y) / 2)
    return _fields(s.Integer(0), p, _A, _Q, s.sin(x + y) / 20, _PSI)


@cache
def transition_fields(radius: float = 0.3):
    """Contact inside the circle of ``radius`` about (½, ½): p = 300 (φ⁻)³, g = (φ⁺)³."""
    phi = (x - s.Rational(1, 2)) ** 2 + (y - s.Rational(1, 2)) ** 2 - s.nsimplify(radius) ** 2
    g = s.Piecewise((phi**3, phi > 0), (0, True))
    p = s.Piecewise((-300 * phi**3, phi < 0), (0, True))
    return _fields(g, p, _A, _Q, s.sin(x + y) / 20, _PSI)


@cache
def patch_fields():
    """u affine, σ constant, p = 0.1, ψ affine: reproduced by P2 exactly."""
    a = (x / 100 + y / 50, -x / 100 + y / 200)
    zero = (s.Integer(0), s.Integer(0))
    psi = s.Rational(1, 100) + x / 50 - y / 100
    return _fields(s.Integer(0), s.Rational(1, 10), a, zero, s.Integer(0), psi)


def cube_problem(fields, n: int, face_alpha: float | None = None) -> ContactProblem:
    """The manufactured ``fields`` on ``box(n, n, n)`` as a problem: Dirichlet on z1, the
    exact tractions on x0 x1 y0 y1, contact with the gap ψ on z0 (condition (b) for
    ``face_alpha`` None, (a) for 0)."""
    stress = fields["stress"]

    def traction(p, normal):
        return np.einsum("...ij,...j->...i", stress(p), normal)

    sides = {name: Neumann(traction) for name in ("x0", "x1", "y0", "y1")}
    return ContactProblem(
        mesh=box(n, n, n),
        material=Material.from_young(E, NU),
        conditions={
            **sides,
            "z1": Dirichlet(fields["u"]),
            "z0": Contact(gap=fields["psi"], face_alpha=face_alpha),
        },
        body_force=fields["f"],
        exact=ExactSolution(fields["u"], fields["grad"]),
        name="cube-3d",
    )
