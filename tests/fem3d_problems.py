"""Shared 3D elasticity problems of the tests: distorted Kuhn boxes, the Dirichlet solve, a
manufactured smooth solution and quadratic fields with their body forces."""

from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

from signorini.fem.dofs import node_dofs
from signorini.fem.elasticity3d import assemble_body_force_3d
from signorini.fem.material import Material
from signorini.fem.space import space_of
from signorini.fem.stiffness3d import assemble_stiffness_3d
from signorini.mesh.builders3d import box
from signorini.mesh.mesh import Mesh

MATERIAL = Material(lam=1.7, mu=0.9)


def distorted_box(n: int, amount: float = 0.15, seed: int = 0) -> Mesh:
    """The Kuhn mesh of [0, 1]³ with ``n`` cubes a side, interior points moved at random by
    up to ``amount`` h in each coordinate (the cells stay positively oriented)."""
    mesh = box(n, n, n)
    rng = np.random.default_rng(seed)
    p = mesh.points.copy()
    inner = np.all((p > 1e-12) & (p < 1 - 1e-12), axis=1)
    p[inner] += amount / n * rng.uniform(-1, 1, (inner.sum(), 3))
    return Mesh(p, mesh.cells, mesh.boundary, mesh.boundary_part, mesh.part_names)


def divergence_of_stress(hessian: np.ndarray, material: Material) -> np.ndarray:
    """``div σ(u)`` from the Hessians ``H[..., i, j, k] = ∂_j ∂_k u_i``:
    ``μ Δu_i + (λ + μ) ∂_i div u``."""
    lam, mu = material.lam, material.mu
    laplace = np.einsum("...ijj->...i", hessian)
    grad_div = np.einsum("...jij->...i", hessian)
    return mu * laplace + (lam + mu) * grad_div


def solve_dirichlet(space, f, u_boundary, material: Material = MATERIAL) -> np.ndarray:
    """The P2 solution ``(n_nodes, 3)`` with body force ``f`` and ``u = u_boundary`` at the
    boundary nodes (the nodal interpolant there), by a direct sparse solve."""
    K = assemble_stiffness_3d(space.mapping, space.cell_dofs, space.n_dofs, material)
    F = assemble_body_force_3d(space, f)
    fixed = node_dofs(space.part_nodes(space.mesh.part_names), 3).ravel()
    u = np.zeros(space.n_dofs)
    u[fixed] = np.asarray(u_boundary(space.node_points)).ravel()[fixed]
    free = np.setdiff1d(np.arange(space.n_dofs), fixed)
    rhs = F[free] - K[free][:, fixed] @ u[fixed]
    u[free] = spla.spsolve(K[free][:, free].tocsc(), rhs)
    return u.reshape(-1, 3)


class Smooth:
    """``u = (sin πx sin πy sin πz, x y z e^{x}, cos(πx/2) y² z)`` and its derivatives."""

    @staticmethod
    def u(x):
        X, Y, Z = np.moveaxis(x, -1, 0)
        pi = np.pi
        return np.stack(
            [
                np.sin(pi * X) * np.sin(pi * Y) * np.sin(pi * Z),
                X * Y * Z * np.exp(X),
                np.cos(pi * X / 2) * Y**2 * Z,
            ],
            axis=-1,
        )

    @staticmethod
    def grad(x):
        X, Y, Z = np.moveaxis(x, -1, 0)
        pi = np.pi
        s, c = np.sin, np.cos
        g = np.empty(x.shape + (3,))
        g[..., 0, 0] = pi * c(pi * X) * s(pi * Y) * s(pi * Z)
        g[..., 0, 1] = pi * s(pi * X) * c(pi * Y) * s(pi * Z)
        g[..., 0, 2] = pi * s(pi * X) * s(pi * Y) * c(pi * Z)
        e = np.exp(X)
        g[..., 1, 0] = Y * Z * e * (1 + X)
        g[..., 1, 1] = X * Z * e
        g[..., 1, 2] = X * Y * e
        g[..., 2, 0] = -pi / 2 * s(pi * X / 2) * Y**2 * Z
        g[..., 2, 1] = 2 * c(pi * X / 2) * Y * Z
        g[..., 2, 2] = c(pi * X / 2) * Y**2
        return g

    @staticmethod
    def hessian(x):
        X, Y, Z = np.moveaxis(x, -1, 0)
        pi = np.pi
        s, c = np.sin, np.cos
        H = np.empty(x.shape + (3, 3))
        sx, sy, sz, cx, cy, cz = s(pi * X), s(pi * Y), s(pi * Z), c(pi * X), c(pi * Y), c(pi * Z)
        p2 = pi**2
        H[..., 0, 0, 0] = -p2 * sx * sy * sz
        H[..., 0, 1, 1] = -p2 * sx * sy * sz
        H[..., 0, 2, 2] = -p2 * sx * sy * sz
        H[..., 0, 0, 1] = H[..., 0, 1, 0] = p2 * cx * cy * sz
        H[..., 0, 0, 2] = H[..., 0, 2, 0] = p2 * cx * sy * cz
        H[..., 0, 1, 2] = H[..., 0, 2, 1] = p2 * sx * cy * cz
        e = np.exp(X)
        H[..., 1, 0, 0] = Y * Z * e * (2 + X)
        H[..., 1, 1, 1] = 0.0
        H[..., 1, 2, 2] = 0.0
        H[..., 1, 0, 1] = H[..., 1, 1, 0] = Z * e * (1 + X)
        H[..., 1, 0, 2] = H[..., 1, 2, 0] = Y * e * (1 + X)
        H[..., 1, 1, 2] = H[..., 1, 2, 1] = X * e
        h, ch = s(pi * X / 2), c(pi * X / 2)
        H[..., 2, 0, 0] = -(pi**2) / 4 * ch * Y**2 * Z
        H[..., 2, 1, 1] = 2 * ch * Z
        H[..., 2, 2, 2] = 0.0
        H[..., 2, 0, 1] = H[..., 2, 1, 0] = -pi * h * Y * Z
        H[..., 2, 0, 2] = H[..., 2, 2, 0] = -pi / 2 * h * Y**2
        H[..., 2, 1, 2] = H[..., 2, 2, 1] = 2 * ch * Y
        return H

    @classmethod
    def force(cls, material: Material = MATERIAL):
        return lambda x: -divergence_of_stress(cls.hessian(x), material)


def quadratic_field(seed: int = 1):
    """A random quadratic displacement ``u(x) = A[x ⊗ x] + B x + c``: ``(u, hessian)``, the
    Hessian constant."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3, 3, 3))
    A = 0.5 * (A + A.transpose(0, 2, 1))
    B, c = rng.normal(size=(3, 3)), rng.normal(size=3)

    def u(x):
        return np.einsum("ijk,...j,...k->...i", A, x, x) + x @ B.T + c

    def grad(x):
        return 2 * np.einsum("ijk,...k->...ij", A, x) + B

    return u, grad, 2 * A


def space_on(mesh: Mesh):
    return space_of(mesh, "P2")
