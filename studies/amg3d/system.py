"""The clamped P2 elasticity system on the cube, uniform or graded, at up to 10⁶ unknowns.

The mesh is :func:`faces3d.mesh.cube_mesh` (n³ cubes, six Kuhn tetrahedra each, P2 nodes:
vertices first, then edge midpoints; DOFs interleaved, ``3 node + component``). The graded
mesh maps the vertices by ``x ↦ x r^(γ−1)``, ``r = max_k x_k`` (a radial grading towards the
corner 0 in the max norm, isotropic: the cells near the corner shrink like ``r^(γ−1)``, as
an adaptive mesh refined towards a point singularity), then puts the P2 nodes back at the
edge midpoints, so the cells stay affine tetrahedra. The Jacobian of the map is
``r^(3(γ−1)) γ > 0`` on each of the three pieces, so the tetrahedra stay valid (checked).

The stiffness matrix is a(u, v) = ∫ 2μ ε(u):ε(v) + λ div u div v (the paper's (2.1) in
3D), assembled by 3 × 3 node blocks into a BSR matrix; the face ``x = 0`` is clamped (its
nodes removed: whole nodes, so the block structure stays), and the body force is
``f = (0, 0, −1)``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from faces3d.elasticity import p2_lambda_gradients  # noqa: E402
from faces3d.mesh import CubeMesh, cube_mesh  # noqa: E402

#: Keast's 4-point rule on the reference tetrahedron, exact to degree 2 (the integrand of
#: the P2 stiffness has degree 2): barycentrics (4, 4), weights summing to 1/6.
_A, _B = 0.5854101966249685, 0.1381966011250105
RULE_BARY = np.full((4, 4), _B) + np.eye(4) * (_A - _B)
RULE_WEIGHTS = np.full(4, 1 / 24)

#: Cells per chunk of the element matrices (bounds the memory of one chunk to ~0.3 GB).
CHUNK = 40_000


@dataclass(frozen=True)
class ClampedSystem:
    """``K u = F`` on the free DOFs of the clamped cube.

    Attributes
    ----------
    K : scipy.sparse.bsr_matrix, shape (3 m, 3 m), blocksize (3, 3)
        Stiffness on the m free nodes.
    F : ndarray, shape (3 m,)
    points : ndarray, shape (m, 3)
        The free nodes' coordinates.
    h_ratio : float
        Longest over shortest cell edge (1 + … on the uniform mesh, large when graded).
    """

    K: sp.bsr_matrix
    F: np.ndarray
    points: np.ndarray
    h_ratio: float


def graded_mesh(n: int, gamma: float) -> CubeMesh:
    """:func:`cube_mesh` with its vertices mapped by ``x ↦ x r^(γ−1)``, ``r = max_k x_k``,
    and the P2 nodes at the new edge midpoints (module docstring); ``gamma = 1``: uniform."""
    mesh = cube_mesh(n)
    if gamma == 1:
        return mesh
    vertices = mesh.points[: mesh.n_vertices]
    r = vertices.max(axis=1, keepdims=True)
    mapped = vertices * r ** (gamma - 1)
    points = np.vstack([mapped, mapped[mesh.edges].mean(axis=1)])
    graded = CubeMesh(n, points, mesh.tets, mesh.n_vertices, mesh.edges)
    turned = np.sign(_volumes(graded)) != np.sign(_volumes(mesh))
    if turned.any():
        raise ValueError(f"the grading γ = {gamma} inverts {int(turned.sum())} tetrahedra")
    return graded


def _volumes(mesh: CubeMesh) -> np.ndarray:
    """Signed 6 |T| of every tetrahedron, shape (n_tets,)."""
    x = mesh.points[mesh.tets[:, :4]]
    return np.linalg.det(x[:, 1:] - x[:, :1])


def _gradients(mesh: CubeMesh, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """∇φ_a at the rule's points of ``cells``, (c, 4, 10, 3), and det J, (c,)."""
    x = mesh.points[mesh.tets[cells, :4]]
    jac = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], x[:, 3] - x[:, 0]], axis=2)
    inv = np.linalg.inv(jac)
    grad_bary = np.concatenate([-inv.sum(axis=1, keepdims=True), inv], axis=1)  # (c, 4, 3)
    return np.einsum("qak,ckj->cqaj", p2_lambda_gradients(RULE_BARY), grad_bary), np.linalg.det(jac)


def element_blocks(mesh: CubeMesh, cells: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """The element matrices of ``cells`` as node blocks, shape (c, 10, 10, 3, 3):
    ``[t, a, b, i, j] = ∫ λ ∂_i φ_a ∂_j φ_b + μ (δ_ij ∇φ_a·∇φ_b + ∂_j φ_a ∂_i φ_b)``.

    One batched product ``L[t, (a, i), (b, j)] = Σ_q w_q ∂_i φ_a ∂_j φ_b`` gives all three
    terms: λ L, μ L with i and j swapped, μ δ_ij tr_k L[a, k, b, k].
    """
    G, det = _gradients(mesh, cells)
    g = G.reshape(cells.size, 4, 30) * np.sqrt(
        np.abs(det)[:, None, None] * RULE_WEIGHTS[None, :, None]
    )
    L = (np.swapaxes(g, 1, 2) @ g).reshape(-1, 10, 3, 10, 3).transpose(0, 1, 3, 2, 4)
    blocks = lam * L + mu * np.swapaxes(L, 3, 4)
    blocks += mu * np.einsum("tabkk,ij->tabij", L, np.eye(3))
    return blocks


def stiffness_blocks(mesh: CubeMesh, lam: float, mu: float) -> sp.bsr_matrix:
    """The P2 stiffness of the whole mesh, BSR with 3 × 3 node blocks, canonical."""
    n_nodes = mesh.n_nodes
    pairs = (mesh.tets[:, :, None].astype(np.int64) * n_nodes + mesh.tets[:, None, :]).ravel()
    keys, where = np.unique(pairs, return_inverse=True)
    del pairs
    data = np.zeros((keys.size, 3, 3))
    for start in range(0, mesh.tets.shape[0], CHUNK):  # chunks of cells, for the memory
        cells = np.arange(start, min(start + CHUNK, mesh.tets.shape[0]))
        blocks = element_blocks(mesh, cells, lam, mu).reshape(-1, 9)
        at = where[100 * start : 100 * (start + cells.size)]
        for k in range(9):  # the nine entries of a node block
            data[:, k // 3, k % 3] += np.bincount(at, blocks[:, k], keys.size)
    rows, cols = np.divmod(keys, n_nodes)
    indptr = np.searchsorted(rows, np.arange(n_nodes + 1))
    return sp.bsr_matrix((data, cols.astype(np.int32), indptr), shape=(3 * n_nodes,) * 2)


def body_load(mesh: CubeMesh, force: np.ndarray) -> np.ndarray:
    """∫ f·φ_a for a constant ``force`` (3,): exactly |T|/20 · (−1) at a P2 vertex function
    and |T|/5 at an edge one; shape (3 n_nodes,)."""
    volume = np.abs(_volumes(mesh)) / 6
    share = np.r_[np.full(4, -1 / 20), np.full(6, 1 / 5)]
    nodal = np.bincount(mesh.tets.ravel(), (volume[:, None] * share).ravel(), mesh.n_nodes)
    return (nodal[:, None] * force).ravel()


def clamped_system(n: int, gamma: float = 1.0, nu: float = 0.3, E: float = 1.0) -> ClampedSystem:
    """The system on the n³ cube (graded by ``gamma``), clamped on ``x = 0``."""
    mesh = graded_mesh(n, gamma)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    K = stiffness_blocks(mesh, lam, mu)
    F = body_load(mesh, np.array([0.0, 0.0, -1.0]))
    free = np.flatnonzero(mesh.points[:, 0] > 0)
    dofs = (3 * free[:, None] + np.arange(3)).ravel()
    K = K.tocsr()[dofs][:, dofs].tobsr(blocksize=(3, 3))
    K.sort_indices()
    length = np.linalg.norm(np.diff(mesh.points[mesh.edges], axis=1)[:, 0], axis=1)
    return ClampedSystem(K, F[dofs], mesh.points[free], float(length.max() / length.min()))


def rigid_modes(points: np.ndarray) -> np.ndarray:
    """The six rigid motions at ``points`` (m, 3), interleaved DOFs, shape (3 m, 6): three
    translations, then the rotations ``e_k × (x − c)`` about the centroid c."""
    m = points.shape[0]
    x = points - points.mean(axis=0)
    modes = np.zeros((m, 3, 6))
    modes[:, [0, 1, 2], [0, 1, 2]] = 1.0
    for k in range(3):  # the three axes
        modes[:, :, 3 + k] = np.cross(np.eye(3)[k], x)
    return modes.reshape(3 * m, 6)
