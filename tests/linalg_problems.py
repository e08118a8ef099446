"""Test matrices for the linear solver, PDAS and frame tests (no dependence on the package).

- ``block_spd``: a 2D grid graph with a random SPD 2x2 coupling per edge (node-block pattern).
- ``random_spd_dense``: a dense random SPD matrix.
- ``p2_elasticity``: P2 plane-strain stiffness on a structured triangulation of the unit
  square, assembled here independently of :mod:`signorini`, with interleaved DOFs.
"""

from __future__ import annotations

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
    nx: int, ny: int, lam: float = 1.0, mu: float = 1.0
) -> tuple[sp.csr_matrix, np.ndarray]:
    """P2 plane-strain stiffness on the unit square cut into ``2 nx ny`` right triangles.

    Returns
    -------
    K : csr_matrix, shape (2 n_nodes, 2 n_nodes)
        Interleaved DOFs (``2 * node + component``), singular (3 rigid motions).
    node_xy : (n_nodes, 2) float array
        Vertices first, then edge midpoints.
    """
    X, Y = np.meshgrid(np.linspace(0, 1, nx + 1), np.linspace(0, 1, ny + 1), indexing="ij")
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
