"""Test matrices for the linear solver, PDAS and frame tests (no dependence on the package).

- ``block_spd``: a 2D grid graph with a random SPD 2x2 coupling per edge (node-block pattern).
- ``random_spd_dense``: a dense random SPD matrix.
- ``p2_elasticity``: P2 plane-strain stiffness on a structured triangulation of the unit
  square, assembled here independently of :mod:`signorini`, with interleaved DOFs.
- ``random_problem``, ``brute_force_qp``, ``CYCLING_*``: bound-constrained QPs and their exact
  solution by enumeration of the active sets.
"""

from __future__ import annotations

import itertools

import numpy as np
import scipy.sparse as sp


def grid_edges(nx: int, ny: int) -> np.ndarray:
    """Edges ``(n_edges, 2)`` of the 4-neighbour graph on an ``nx x ny`` grid of nodes."""
    idx = np.arange(nx * ny).reshape(nx, ny)
    return np.vstack(
        [
            np.column_stack([idx[:-1, :].ravel(), idx[1:, :].ravel()]),
            np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()]),
        ]
    )


def block_spd(nx: int, ny: int, rng: np.random.Generator, shift: float = 1e-2) -> sp.csr_matrix:
    """``sum_e (e_a - e_b)(e_a - e_b)^T kron C_e + shift I`` with random SPD ``C_e`` (2x2).

    The node graph is the grid Laplacian's, so the matrix is a "2D Laplacian with a random SPD
    2x2 block per edge"; it is SPD, with a 2x2 node-block pattern and 2 * nx * ny rows.
    """
    edges = grid_edges(nx, ny)
    M = rng.standard_normal((len(edges), 2, 2))
    C = M @ M.transpose(0, 2, 1) + 0.1 * np.eye(2)
    C = 0.5 * (C + C.transpose(0, 2, 1))  # exactly symmetric
    a, b = edges[:, 0], edges[:, 1]
    # an explicit zero 2x2 block per node keeps the pattern node-blocked even for a single
    # node (no edge); the shift is then added to the stored diagonal
    nodes = np.arange(nx * ny)
    blocks = np.concatenate([C, C, -C, -C, np.zeros((nodes.size, 2, 2))])
    brow = np.concatenate([a, b, a, b, nodes])
    bcol = np.concatenate([a, b, b, a, nodes])
    comp = np.arange(2)
    rows = (2 * brow[:, None, None] + comp[None, :, None]).repeat(2, axis=2)
    cols = (2 * bcol[:, None, None] + comp[None, None, :]).repeat(2, axis=1)
    n = 2 * nx * ny
    K = sp.coo_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())), shape=(n, n)).tocsr()
    K.sum_duplicates()
    K.setdiag(K.diagonal() + shift)
    # duplicates are summed in an unspecified order: average with the transpose (same
    # pattern, explicit zeros kept) so that K is symmetric to the last bit
    Kt = sp.csr_matrix(K.T)
    Kt.sort_indices()
    K.data = 0.5 * (K.data + Kt.data)
    return sp.csr_matrix(K)


def random_spd_dense(n: int, rng: np.random.Generator, shift: float = 0.1) -> np.ndarray:
    """``B B^T / n + shift I`` with a standard normal ``B`` (n x n)."""
    B = rng.standard_normal((n, n))
    return B @ B.T / n + shift * np.eye(n)


def p2_elasticity(
    nx: int, ny: int, lam: float = 1.0, mu: float = 1.0, height: float = 1.0
) -> tuple[sp.csr_matrix, np.ndarray]:
    """P2 plane-strain stiffness on ``(0, 1) × (0, height)`` cut into ``2 nx ny`` right
    triangles.

    Returns
    -------
    K : csr_matrix, shape (2 n_nodes, 2 n_nodes)
        Interleaved DOFs (``2 * node + component``), singular (3 rigid motions).
    node_xy : (n_nodes, 2) float array
        Vertices first, then edge midpoints.
    """
    X, Y = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, height, ny + 1), indexing="ij")
    points = np.column_stack([X.ravel(), Y.ravel()])
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    cells = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    pairs = np.sort(cells[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 3, 2), axis=2).reshape(-1, 2)
    edges, cell2edge = np.unique(pairs, axis=0, return_inverse=True)
    nodes = np.hstack([cells, len(points) + cell2edge.reshape(-1, 3)])
    dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(len(cells), 12)

    v = points[cells]
    J = np.stack([v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]], axis=2)  # columns: edge vectors
    det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
    jit = np.linalg.inv(J).transpose(0, 2, 1)
    D = np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    dl = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])  # reference gradients of l0, l1, l2
    Ke = np.zeros((len(cells), 12, 12))
    for l0, l1, l2 in ((2 / 3, 1 / 6, 1 / 6), (1 / 6, 2 / 3, 1 / 6), (1 / 6, 1 / 6, 2 / 3)):
        g = np.array(
            [
                (4 * l0 - 1) * dl[0],
                (4 * l1 - 1) * dl[1],
                (4 * l2 - 1) * dl[2],
                4 * (l1 * dl[0] + l0 * dl[1]),
                4 * (l2 * dl[1] + l1 * dl[2]),
                4 * (l0 * dl[2] + l2 * dl[0]),
            ]
        )
        G = np.einsum("cij,kj->cki", jit, g)  # physical gradients (n_cells, 6, 2)
        B = np.zeros((len(cells), 3, 12))
        B[:, 0, 0::2] = G[:, :, 0]
        B[:, 1, 1::2] = G[:, :, 1]
        B[:, 2, 0::2] = G[:, :, 1]
        B[:, 2, 1::2] = G[:, :, 0]
        Ke += np.einsum("c,cai,ab,cbj->cij", np.abs(det) / 6, B, D, B)
    n = 2 * (len(points) + len(edges))
    rows = np.repeat(dofs, 12, axis=1).ravel()
    cols = np.tile(dofs, (1, 12)).ravel()
    K = sp.coo_matrix((Ke.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    K.sum_duplicates()
    node_xy = np.vstack([points, points[edges].mean(axis=1)])
    return sp.csr_matrix(K), node_xy


def rigid_motions(node_xy: np.ndarray) -> np.ndarray:
    """``(2 n_nodes, 3)`` interleaved rigid motions: x-translation, y-translation, rotation."""
    n = len(node_xy)
    R = np.zeros((2 * n, 3))
    R[0::2, 0] = 1.0
    R[1::2, 1] = 1.0
    R[0::2, 2] = -node_xy[:, 1]
    R[1::2, 2] = node_xy[:, 0]
    return R


# A 4 x 4 SPD problem on which plain PDAS (c = mean diagonal) cycles: found by a random search
# over matrices with one decimal; the bounds are on all four DOFs.
CYCLING_K = np.array(
    [
        [2.4, -1.2, -2.4, 1.8],
        [-1.2, 4.6, 4.2, -3.8],
        [-2.4, 4.2, 5.2, -2.8],
        [1.8, -3.8, -2.8, 7.0],
    ]
)
CYCLING_F = np.array([0.0, 0.8, -0.1, -0.5])
CYCLING_G = np.array([0.3, 0.4, -0.1, 1.4])


def brute_force_qp(K, F, c, g, d=(), xd=()):
    """Exact minimizer by enumerating all 2^m active sets (dense, independent of the package).

    For each candidate set S the bounds on S are equalities, the rest is dropped; the unique
    KKT point (strict convexity) is the candidate that is feasible with non-negative
    multipliers. Returns (x, multiplier, active).
    """
    K = np.asarray(K.toarray() if sp.issparse(K) else K, dtype=float)
    n = K.shape[0]
    c = np.asarray(c)
    d = np.asarray(d, dtype=int)
    best = None
    for bits in itertools.product([False, True], repeat=c.size):
        S = np.array(bits, dtype=bool)
        fixed = np.zeros(n, dtype=bool)
        fixed[d] = True
        fixed[c[S]] = True
        x = np.zeros(n)
        x[d] = xd
        x[c[S]] = g[S]
        free = ~fixed
        rhs = F[free] - K[np.ix_(free, fixed)] @ x[fixed]
        x[free] = np.linalg.solve(K[np.ix_(free, free)], rhs)
        multiplier = F[c] - K[c] @ x
        scale = np.abs(F).max() + np.abs(K).max() * np.abs(x).max() + 1e-300
        if (x[c] - g <= 1e-10 * (np.abs(g).max() + np.abs(x).max() + 1e-300)).all() and (
            multiplier[S] >= -1e-10 * scale
        ).all():
            assert best is None or np.allclose(best[0], x, atol=1e-8), "two KKT points"
            best = (x, np.where(S, multiplier, 0.0), S)
    assert best is not None
    return best


def random_problem(rng, n, m, n_dirichlet=0, dense=True):
    if dense:
        K = sp.csr_matrix(random_spd_dense(n, rng))
    else:
        K = block_spd(n // 2, 1, rng, shift=0.05)
        n = K.shape[0]
    perm = rng.permutation(n)
    c = perm[:m]
    d = perm[m : m + n_dirichlet]
    F = rng.standard_normal(n)
    g = 0.3 * rng.standard_normal(m)
    xd = 0.2 * rng.standard_normal(n_dirichlet)
    return K, F, c, g, d, xd


def just_touching_square(
    n: int, lam: float = 288.46153846153845, mu: float = 192.30769230769232
) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The unit square pushed by exactly its gap: every constraint is degenerate.

    ``u = (0.1, 0)`` on the left side, free top and bottom, ``u_x <= 0.1`` on the right side
    (E = 500, ν = 0.3 by default). The solution is the rigid shift ``(0.1, 0)``: every right
    node touches the bound with zero multiplier.

    Returns
    -------
    K, F, constrained, dirichlet, dirichlet_values
        ``F = 0``; the gap is 0.1 on every constrained DOF.
    """
    K, xy = p2_elasticity(n, n, lam, mu)
    left = np.flatnonzero(xy[:, 0] < 1e-12)
    right = np.flatnonzero(xy[:, 0] > 1 - 1e-12)
    dirichlet = np.column_stack([2 * left, 2 * left + 1]).ravel()
    values = np.tile([0.1, 0.0], left.size)
    return K, np.zeros(K.shape[0]), 2 * right, dirichlet, values
