"""Cells, meshes and quadrature built from plain arrays, for the tests of :mod:`signorini.fem`.

- :func:`random_reference_points`, :func:`random_triangles`: points of the reference triangle
  and counter-clockwise triangles of bounded shape;
- :class:`SquareMesh`: a structured triangulation of the unit square with its P2 numbering,
  built with ``np.unique`` (independent of :class:`signorini.mesh.Mesh`);
- :func:`gauss_square`: a tensor Gauss rule on the unit square (independent of
  :mod:`signorini.fem.quadrature`);
- :func:`rigid_modes`: the three rigid motions on one P2 cell.

Quadratic displacement fields are :class:`contact_problems.Quadratic`.
"""

from __future__ import annotations

import numpy as np

from signorini.fem import p2


def random_reference_points(n: int, rng: np.random.Generator) -> np.ndarray:
    """Uniform random points in the reference triangle, shape (n, 2)."""
    xy = rng.random((n, 2))
    flip = xy.sum(axis=1) > 1
    xy[flip] = 1 - xy[flip]
    return xy


def random_triangles(
    m: int, rng: np.random.Generator, min_angle_deg: float = 15.0, span: float = 2.0
) -> np.ndarray:
    """``m`` counter-clockwise triangles in ``[-span, span]²`` whose angles all exceed
    ``min_angle_deg``, shape (m, 3, 2)."""
    out = []
    while len(out) < m:
        v = rng.uniform(-span, span, size=(3, 2))
        e = np.roll(v, -1, axis=0) - v
        if e[0, 0] * e[1, 1] - e[0, 1] * e[1, 0] < 0:
            v = v[[0, 2, 1]]
            e = np.roll(v, -1, axis=0) - v
        lens = np.linalg.norm(e, axis=1)
        cosines = [(-e[k - 1]) @ e[k] / (lens[k - 1] * lens[k]) for k in range(3)]
        if np.degrees(np.arccos(np.max(cosines))) > min_angle_deg:
            out.append(v)
    return np.array(out)


class SquareMesh:
    """Structured n x n triangulation of [0, 1]^2, optionally with perturbed interior points.

    P2 nodes: vertices, then edge midpoints (edges numbered by np.unique). Boundary edges are
    listed in the counter-clockwise order of their cell, with their nodes (start, end, mid).
    """

    def __init__(self, n: int, rng: np.random.Generator | None = None, perturb: float = 0.0):
        x = np.linspace(0.0, 1.0, n + 1)
        X, Y = np.meshgrid(x, x, indexing="xy")
        pts = np.column_stack([X.ravel(), Y.ravel()])
        if perturb:
            inner = (pts > 0).all(axis=1) & (pts < 1).all(axis=1)
            pts[inner] += perturb / n * rng.uniform(-1, 1, size=(inner.sum(), 2))
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
        c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
        cells = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
        local = np.stack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]], axis=1)
        edges, inv, count = np.unique(
            np.sort(local.reshape(-1, 2), axis=1), axis=0, return_inverse=True, return_counts=True
        )
        inv = inv.reshape(-1, 3)
        self.points, self.cells = pts, cells.astype(np.int64)
        self.n_points = len(pts)
        self.n_nodes = len(pts) + len(edges)
        self.n_dofs = 2 * self.n_nodes
        self.cell_nodes = np.concatenate([cells, self.n_points + inv], axis=1)
        self.cell_dofs = interleaved(self.cell_nodes)
        self.vertices = pts[cells]
        mid = 0.5 * (pts[edges[:, 0]] + pts[edges[:, 1]])
        self.node_xy = np.concatenate([pts, mid])
        bnd = count[inv] == 1  # (m, 3)
        cell_id, k = np.nonzero(bnd)
        start = cells[cell_id, k]
        end = cells[cell_id, (k + 1) % 3]
        self.bedge_vertices = np.stack([pts[start], pts[end]], axis=1)
        self.bedge_nodes = np.column_stack([start, end, self.n_points + inv[cell_id, k]])
        self.bedge_dofs = interleaved(self.bedge_nodes)

    def interpolate(self, field) -> np.ndarray:
        """Interleaved nodal values ``(n_dofs,)`` of a vector field ``x (n, 2) -> (n, 2)``."""
        return field(self.node_xy).ravel()


def interleaved(nodes: np.ndarray) -> np.ndarray:
    """DOFs ``2 * node + component`` of node lists ``(m, k)``, shape ``(m, 2 k)``."""
    return (2 * nodes[:, :, None] + np.arange(2)).reshape(len(nodes), -1)


def gauss_square(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss-Legendre rule on [0, 1]^2: points (n*n, 2), weights (n*n,)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x, w = 0.5 * (x + 1), 0.5 * w
    X, Y = np.meshgrid(x, x, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()]), np.outer(w, w).ravel()


def rigid_modes(vertices: np.ndarray) -> np.ndarray:
    """(3, 12) interleaved nodal values of x- and y-translation and rotation (-y, x) on the P2
    cell with ``vertices (3, 2)``."""
    nodes = p2.physical_points(vertices[None], p2.REFERENCE_NODES)[0]  # (6, 2)
    modes = np.zeros((3, 6, 2))
    modes[0, :, 0] = 1
    modes[1, :, 1] = 1
    modes[2, :, 0] = -nodes[:, 1]
    modes[2, :, 1] = nodes[:, 0]
    return modes.reshape(3, 12)


def cell_values(field, vertices: np.ndarray) -> np.ndarray:
    """Interleaved nodal values (m, 12) of a vector field on the P2 cells ``vertices``."""
    nodes = p2.physical_points(vertices, p2.REFERENCE_NODES)  # (m, 6, 2)
    return field(nodes).reshape(len(vertices), 12)


def stress_of(grad: np.ndarray, material) -> np.ndarray:
    """Plane-strain stress ``λ tr(ε) I + 2μ ε`` of displacement gradients ``(..., 2, 2)``."""
    eps = 0.5 * (grad + np.swapaxes(grad, -1, -2))
    tr = eps[..., 0, 0] + eps[..., 1, 1]
    return material.lam * tr[..., None, None] * np.eye(2) + 2 * material.mu * eps


class GradientField:
    """The smooth displacement ``u = ∇(−cos(a x) cos(a y) / a)`` = ``(sin(ax) cos(ay),
    cos(ax) sin(ay))`` with its gradient, stress, traction and the body force
    ``f = −div σ = 2 a² (λ + 2μ) u`` of a material: a manufactured solution for curved
    domains (its divergence-free part vanishes, so ``−div σ = −(λ + 2μ) ∇ div u``)."""

    def __init__(self, a: float, material) -> None:
        self.a, self.material = a, material

    def u(self, x: np.ndarray) -> np.ndarray:
        a = self.a
        return np.column_stack(
            [np.sin(a * x[:, 0]) * np.cos(a * x[:, 1]), np.cos(a * x[:, 0]) * np.sin(a * x[:, 1])]
        )

    def grad(self, x: np.ndarray) -> np.ndarray:
        a = self.a
        cc = a * np.cos(a * x[:, 0]) * np.cos(a * x[:, 1])
        ss = -a * np.sin(a * x[:, 0]) * np.sin(a * x[:, 1])
        return np.stack([np.stack([cc, ss], -1), np.stack([ss, cc], -1)], -2)

    def stress(self, x: np.ndarray) -> np.ndarray:
        return stress_of(self.grad(x), self.material)

    def traction(self, x: np.ndarray, normal: np.ndarray) -> np.ndarray:
        return np.einsum("nij,nj->ni", self.stress(x), normal)

    def body_force(self, x: np.ndarray) -> np.ndarray:
        m = self.material
        return 2 * self.a**2 * (m.lam + 2 * m.mu) * self.u(x)
