"""Plane-strain linear elasticity with P2 elements: material, stiffness, loads, errors.

Everything here works on plain arrays, vectorized over cells:

* ``vertices (m, 3, 2)`` -- ``points[cells]``, counter-clockwise;
* ``cell_dofs (m, 12)`` -- interleaved global DOFs, ``cell_dofs[:, 2 a + c] = 2 * node_a + c``
  with the local node order of :mod:`signorini.p2`;
* ``u_cell (m, 12)`` -- ``u[cell_dofs]``.

The bilinear form and the load functional are those of the paper (Section 2),

.. math::

    a(w, v) = \\int_\\Omega \\sigma(w) : \\varepsilon(v)\\,dx, \\qquad
    L(v) = \\int_\\Omega f \\cdot v\\,dx + \\int_{\\Gamma_N} g \\cdot v\\,ds,

with Hooke's law (2.1) ``sigma(v) = lam tr(eps(v)) I + 2 mu eps(v)`` (the paper's
``chi`` is ``lam`` here).

Assembly
--------
The stiffness matrix is assembled at the level of nodes: every pair of nodes
that share a cell gets one full 2x2 block.  The two entries of each block row
are packed into one complex number, SciPy's COO -> CSR conversion sums the
duplicates of the resulting (scalar row, node column) matrix, and its data,
viewed as float64, are the scalar CSR data.  The result has sorted indices and
a node-block pattern: rows ``2 z`` and ``2 z + 1`` have identical column
patterns, and columns ``2 w``, ``2 w + 1`` are adjacent (explicit zeros kept).
At 1.6 M unknowns this takes less memory and time than converting the 144
scalar entries per cell directly, or sorting node pairs with ``np.unique``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ..mesh.geometry import segment_normals
from . import p2
from .quadrature import line_rule, triangle_rule

__all__ = [
    "Material",
    "assemble_body_force",
    "assemble_edge_load",
    "assemble_stiffness",
    "cell_stress",
    "div_stress",
    "edge_normals",
    "edge_traction",
    "element_stiffness",
    "energy_error2",
    "h1_seminorm_error2",
    "l2_error2",
    "strain",
    "stress",
    "traction",
]


# ---------------------------------------------------------------------------
# material
# ---------------------------------------------------------------------------


def _finite_float(value: float, name: str) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    return x


@dataclass(frozen=True)
class Material:
    """Isotropic, homogeneous linear elastic material in plane strain.

    Parameters
    ----------
    lam : float
        First Lamé parameter (the paper's ``chi`` in (2.1)).
    mu : float
        Shear modulus, ``> 0``.

    Raises
    ------
    ValueError
        If a parameter is not finite, ``mu <= 0``, or the plane-strain bulk
        modulus ``lam + mu <= 0`` (the elasticity tensor would not be
        positive definite).
    """

    lam: float
    mu: float

    def __post_init__(self) -> None:
        lam = _finite_float(self.lam, "lam")
        mu = _finite_float(self.mu, "mu")
        if mu <= 0.0:
            raise ValueError(f"shear modulus mu must be positive, got {mu}")
        if lam + mu <= 0.0:
            raise ValueError(
                f"plane-strain bulk modulus lam + mu must be positive, got lam + mu = {lam + mu}"
            )
        object.__setattr__(self, "lam", lam)
        object.__setattr__(self, "mu", mu)

    @classmethod
    def from_lame(cls, lam: float, mu: float) -> Material:
        """Material from the Lamé parameters ``lam``, ``mu``."""
        return cls(lam, mu)

    @classmethod
    def from_young(cls, E: float, nu: float) -> Material:  # noqa: N803 (the usual symbol)
        """Material from Young's modulus and Poisson's ratio (plane strain).

        ``mu = E / (2 (1 + nu))``, ``lam = E nu / ((1 + nu)(1 - 2 nu))``.

        Parameters
        ----------
        E : float
            Young's modulus, ``> 0``.
        nu : float
            Poisson's ratio, ``-1 < nu < 0.5``.

        Raises
        ------
        ValueError
            If ``E <= 0``, ``nu >= 0.5`` (incompressible limit not supported),
            ``nu <= -1``, or a value is not finite.
        """
        E = _finite_float(E, "Young's modulus E")
        nu = _finite_float(nu, "Poisson's ratio nu")
        if E <= 0.0:
            raise ValueError(f"Young's modulus E must be positive, got {E}")
        if nu >= 0.5:
            raise ValueError(
                f"Poisson's ratio nu must be < 0.5 (incompressible limit not supported), got {nu}"
            )
        if nu <= -1.0:
            raise ValueError(f"Poisson's ratio nu must be > -1, got {nu}")
        mu = E / (2.0 * (1.0 + nu))
        lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        return cls(lam, mu)

    @property
    def young(self) -> float:
        """Young's modulus ``E = mu (3 lam + 2 mu) / (lam + mu)``."""
        return self.mu * (3.0 * self.lam + 2.0 * self.mu) / (self.lam + self.mu)

    @property
    def poisson(self) -> float:
        """Poisson's ratio ``nu = lam / (2 (lam + mu))``."""
        return self.lam / (2.0 * (self.lam + self.mu))


def _check_material(material: Material) -> Material:
    if not isinstance(material, Material):
        raise ValueError(f"material must be a Material, got {type(material).__name__}")
    return material


def strain(grad_u: np.ndarray) -> np.ndarray:
    """Symmetric gradient ``eps = (grad u + grad u^T) / 2``.

    Parameters
    ----------
    grad_u : array_like of float, shape (..., 2, 2)
        ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., 2, 2)
    """
    g = np.asarray(grad_u, dtype=np.float64)
    if g.ndim < 2 or g.shape[-2:] != (2, 2):
        raise ValueError(f"grad_u must have shape (..., 2, 2), got {g.shape}")
    return 0.5 * (g + np.swapaxes(g, -1, -2))


def stress(material: Material, grad_u: np.ndarray) -> np.ndarray:
    """Cauchy stress of Hooke's law (2.1), ``sigma = lam tr(eps) I + 2 mu eps``.

    Parameters
    ----------
    material : Material
    grad_u : array_like of float, shape (..., 2, 2)
        Displacement gradients, ``grad_u[..., i, j] = d u_i / d x_j``.

    Returns
    -------
    ndarray of float64, shape (..., 2, 2)
        Symmetric stress tensors.
    """
    _check_material(material)
    eps = strain(grad_u)
    sig = 2.0 * material.mu * eps
    tr = material.lam * (eps[..., 0, 0] + eps[..., 1, 1])
    sig[..., 0, 0] += tr
    sig[..., 1, 1] += tr
    return sig


# ---------------------------------------------------------------------------
# element stiffness
# ---------------------------------------------------------------------------

# On a straight triangle, grad phi_a = J^{-T} ghat_a with ghat_a linear, so
#   B_ab[i, j] = int d_i phi_a d_j phi_b = sum_{kl} P[ij, kl] R[kl, ab],
#   P[ij, kl] = det J * Jit[i, k] * Jit[j, l],  R[kl, ab] = int_ref ghat_a[k] ghat_b[l]
# (R exact with the degree-2 rule), and
#   K[(a, i), (b, j)] = lam B_ab[i, j] + mu B_ab[j, i] + mu delta_ij tr B_ab.
# K is linear in the 16 numbers P, which satisfy P[ij, kl] = P[ji, lk]; the 10
# independent ones are gathered per cell and K = P10 @ KREF (one GEMM).
_P_PAIRS = [
    ((i, j, k, l), (j, i, l, k))
    for i in range(2)
    for j in range(2)
    for k in range(2)
    for l in range(2)  # noqa: E741
    if (i, j, k, l) <= (j, i, l, k)
]


@lru_cache(maxsize=32)
def _stiffness_basis(lam: float, mu: float, dof_order: bool) -> np.ndarray:
    """Matrix (10, 144) mapping the 10 geometric factors to K.

    The 144 columns are in node-block layout (a, b, i, j), or in interleaved DOF
    layout (a, i, b, j) if ``dof_order``.
    """
    xi, w = triangle_rule(2)
    g = p2.grad_basis(xi)
    R = np.einsum("q,qak,qbl->klab", w, g, g)  # (2, 2, 6, 6)
    full = np.zeros((2, 2, 2, 2, 6, 6, 2, 2))
    for i in range(2):
        for j in range(2):
            for k in range(2):
                for l in range(2):  # noqa: E741
                    r = R[k, l]
                    full[i, j, k, l, :, :, i, j] += lam * r
                    full[i, j, k, l, :, :, j, i] += mu * r
                    if i == j:
                        full[i, j, k, l, :, :, 0, 0] += mu * r
                        full[i, j, k, l, :, :, 1, 1] += mu * r
    out = np.empty((len(_P_PAIRS), 144))
    for s, (p, q) in enumerate(_P_PAIRS):
        blk = full[p] if p == q else full[p] + full[q]
        out[s] = (blk.transpose(0, 2, 1, 3) if dof_order else blk).ravel()
    out.setflags(write=False)
    return out


def _geometric_factors(vertices: np.ndarray) -> np.ndarray:
    """The 10 independent ``det J * Jit[i, k] * Jit[j, l]``, shape (m, 10)."""
    J, det = p2.jacobian(vertices)
    jit = p2.inverse_transpose(J, det)
    out = np.empty((J.shape[0], len(_P_PAIRS)))
    for s, ((i, j, k, el), _) in enumerate(_P_PAIRS):
        np.multiply(jit[:, i, k], jit[:, j, el], out=out[:, s])
    out *= det[:, None]
    return out


def _element_matrices(vertices: np.ndarray, material: Material, dof_order: bool) -> np.ndarray:
    """Element stiffness, shape (m, 144): (a, b, i, j) layout, or (a, i, b, j) if ``dof_order``."""
    _check_material(material)
    fac = _geometric_factors(vertices)
    return fac @ _stiffness_basis(material.lam, material.mu, dof_order)


def element_stiffness(vertices: np.ndarray, material: Material) -> np.ndarray:
    """P2 element stiffness matrices of plane-strain elasticity.

    ``K[c, 2 a + i, 2 b + j] = a(phi_b e_j, phi_a e_i)`` on cell ``c``, i.e. the
    local matrix of ``a(u, v) = int sigma(u) : eps(v)`` (Section 2 of the paper).
    The integrand is a polynomial of degree 2 on a straight triangle; the
    degree-2 rule makes the result exact.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    material : Material

    Returns
    -------
    ndarray of float64, shape (m, 12, 12)
        Symmetric positive semidefinite matrices, interleaved local DOF order
        ``2 * local_node + component``.

    Raises
    ------
    ValueError
        On a wrong shape, non-finite coordinates or non-positive orientation.
    """
    return _element_matrices(vertices, material, dof_order=True).reshape(-1, 12, 12)


# ---------------------------------------------------------------------------
# assembly
# ---------------------------------------------------------------------------


def _check_cell_dofs(
    cell_dofs: np.ndarray, n_cells: int, n_dofs: int, width: int = 12, name: str = "cell_dofs"
) -> np.ndarray:
    d = np.asarray(cell_dofs)
    if d.ndim != 2 or d.shape[1] != width:
        raise ValueError(f"{name} must have shape (n, {width}), got {d.shape}")
    if d.shape[0] != n_cells:
        raise ValueError(f"{name} has {d.shape[0]} rows but there are {n_cells} cells/edges")
    if d.size and not np.issubdtype(d.dtype, np.integer):
        raise ValueError(f"{name} must be an integer array, got dtype {d.dtype}")
    if d.size and (d.min() < 0 or d.max() >= n_dofs):
        raise ValueError(
            f"{name} out of range: values in [{d.min()}, {d.max()}] but n_dofs = {n_dofs}"
        )
    return d.astype(np.int64, copy=False)


def _check_n_dofs(n_dofs: int) -> int:
    try:
        n = int(n_dofs)
    except (TypeError, ValueError):
        raise ValueError(f"n_dofs must be a non-negative integer, got {n_dofs!r}") from None
    if n < 0 or n != n_dofs:
        raise ValueError(f"n_dofs must be a non-negative integer, got {n_dofs!r}")
    return n


def _cell_nodes(cell_dofs: np.ndarray) -> np.ndarray:
    """Node numbers (m, 6) from interleaved DOFs, checking the interleaving."""
    ev = cell_dofs[:, 0::2]
    od = cell_dofs[:, 1::2]
    if np.any(ev % 2) or np.any(od != ev + 1):
        raise ValueError(
            "cell_dofs must be interleaved: cell_dofs[:, 2a] = 2 * node_a and "
            "cell_dofs[:, 2a + 1] = 2 * node_a + 1"
        )
    return ev // 2


def _assemble_node_blocks(
    cell_nodes: np.ndarray, n_nodes: int, blocks: np.ndarray
) -> sp.csr_matrix:
    """Assemble per-cell 2x2 node blocks into a scalar CSR with node-block pattern.

    Each row ``(b_i0, b_i1)`` of a 2x2 block is packed into one complex number
    ``b_i0 + 1j b_i1``, and the complex matrix with rows ``2 z + i`` (scalar rows)
    and columns ``w`` (nodes) is built by SciPy's COO -> CSR conversion, which
    sums duplicates.  Viewed as float64, its data are exactly the scalar CSR data
    with columns ``2 w, 2 w + 1``; so every coupled node pair gets its full 2x2
    block, with no further copy of the values.

    Parameters
    ----------
    cell_nodes : ndarray of int, shape (m, k)
        Global node numbers of the ``k`` local nodes of each cell.
    n_nodes : int
    blocks : ndarray of float64, shape (m, k, k, 2, 2), C-contiguous
        ``blocks[c, a, b, i, j]`` is added to entry ``(2 z_a + i, 2 z_b + j)``.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (2 n_nodes, 2 n_nodes)
        Sorted indices; full 2x2 block for every coupled node pair.
    """
    m, k = cell_nodes.shape
    n_dofs = 2 * n_nodes
    n_entries = 2 * m * k * k
    idx = np.int32 if max(n_entries, n_dofs) < np.iinfo(np.int32).max // 2 else np.int64
    nodes = cell_nodes.astype(idx, copy=False)
    packed = np.ascontiguousarray(blocks, dtype=np.float64).reshape(-1, 2)
    packed = packed.view(np.complex128).reshape(-1)  # (c, a, b, i): b_i0 + 1j b_i1
    rows = np.empty((m, k, k, 2), dtype=idx)
    rows[..., 0] = 2 * nodes[:, :, None]
    rows[..., 1] = rows[..., 0] + 1
    cols = np.broadcast_to(nodes[:, None, :, None], (m, k, k, 2)).reshape(-1)
    half = sp.csr_matrix((packed, (rows.reshape(-1), cols)), shape=(n_dofs, n_nodes))
    del rows, cols
    half.sum_duplicates()  # canonical: summed duplicates, sorted indices
    if not half.has_sorted_indices:
        half.sort_indices()
    indices = np.empty((half.nnz, 2), dtype=half.indices.dtype)
    np.multiply(half.indices, 2, out=indices[:, 0])
    np.add(indices[:, 0], 1, out=indices[:, 1])
    data = np.ascontiguousarray(half.data[: half.nnz]).view(np.float64)
    out = sp.csr_matrix(
        (data, indices.reshape(-1), 2 * half.indptr), shape=(n_dofs, n_dofs), copy=False
    )
    out.has_sorted_indices = True
    return out


def assemble_stiffness(
    vertices: np.ndarray, cell_dofs: np.ndarray, n_dofs: int, material: Material
) -> sp.csr_matrix:
    """Global stiffness matrix of ``a(u, v) = int sigma(u) : eps(v)``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    cell_dofs : array_like of int, shape (m, 12)
        Interleaved global DOFs (``2 * node + component``).
    n_dofs : int
        Number of global DOFs (even: two per node).
    material : Material

    Returns
    -------
    scipy.sparse.csr_matrix of float64, shape (n_dofs, n_dofs)
        Symmetric, both triangles stored, sorted indices, node-block pattern:
        each pair of nodes sharing a cell has its full 2x2 block stored
        (explicit zeros kept), so rows ``2 z`` and ``2 z + 1`` have identical
        column patterns and columns ``2 w``, ``2 w + 1`` are adjacent.

    Raises
    ------
    ValueError
        On inconsistent shapes, out-of-range or non-interleaved DOFs, odd
        ``n_dofs``, or badly oriented cells.
    """
    n = _check_n_dofs(n_dofs)
    if n % 2:
        raise ValueError(f"n_dofs must be even (two components per node), got {n}")
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 3 or v.shape[1:] != (3, 2):
        raise ValueError(f"vertices must have shape (n_cells, 3, 2), got {v.shape}")
    dofs = _check_cell_dofs(cell_dofs, v.shape[0], n)
    nodes = _cell_nodes(dofs)
    blocks = _element_matrices(v, material, dof_order=False).reshape(-1, 6, 6, 2, 2)
    return _assemble_node_blocks(nodes, n // 2, blocks)


# ---------------------------------------------------------------------------
# loads
# ---------------------------------------------------------------------------


def _call_checked(fun: Callable, name: str, shape: tuple[int, ...], *args) -> np.ndarray:
    """Call a user function and check its result broadcasts to ``shape`` and is finite."""
    try:
        val = np.asarray(fun(*args), dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} did not return an array of numbers: {exc}") from exc
    try:
        val = np.broadcast_to(val, shape)
    except ValueError:
        raise ValueError(
            f"{name} returned an array of shape {val.shape}, expected {shape}"
        ) from None
    if not np.all(np.isfinite(val)):
        raise ValueError(f"{name} returned non-finite values (NaN or inf)")
    return val


def assemble_body_force(
    vertices: np.ndarray,
    cell_dofs: np.ndarray,
    n_dofs: int,
    f: Callable[[np.ndarray], np.ndarray],
    degree: int = 6,
) -> np.ndarray:
    """Load vector of a body force, ``F[2 z + c] = int_Omega f_c psi_z dx``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
        Cell vertices, counter-clockwise.
    cell_dofs : array_like of int, shape (m, 12)
        Interleaved global DOFs.
    n_dofs : int
    f : callable
        ``f(x)`` with ``x (m, q, 2)`` returns the force density, shape
        ``(m, q, 2)`` (or anything broadcastable to it, e.g. a constant ``(2,)``).
    degree : int, optional
        Quadrature degree on each cell (exact for ``f`` polynomial of degree
        ``degree - 2``).

    Returns
    -------
    ndarray of float64, shape (n_dofs,)

    Raises
    ------
    ValueError
        If ``f`` returns a wrong shape or non-finite values, or on bad mesh input.
    """
    n = _check_n_dofs(n_dofs)
    J, det = p2.jacobian(vertices)
    dofs = _check_cell_dofs(cell_dofs, J.shape[0], n)
    xi, w = triangle_rule(degree)
    x = p2.physical_points(vertices, xi)
    fx = _call_checked(f, "body force f", x.shape, x)
    phi = p2.basis(xi) * w[:, None]  # (q, 6)
    local = np.einsum("qa,mqc->mac", phi, fx) * det[:, None, None]
    return np.bincount(dofs.ravel(), weights=local.ravel(), minlength=n)


def edge_normals(edge_vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lengths and outward unit normals of straight edges.

    Parameters
    ----------
    edge_vertices : array_like of float, shape (k, 2, 2)
        (start, end) of each edge, taken in the counter-clockwise order of the
        cell it bounds.

    Returns
    -------
    length : ndarray of float64, shape (k,)
    normal : ndarray of float64, shape (k, 2)
        ``(dy, -dx) / |e|``, pointing out of the cell.
    """
    ev = np.asarray(edge_vertices, dtype=np.float64)
    if ev.ndim != 3 or ev.shape[1:] != (2, 2):
        raise ValueError(f"edge_vertices must have shape (k, 2, 2), got {ev.shape}")
    if not np.all(np.isfinite(ev)):
        raise ValueError("edge_vertices contain non-finite coordinates")
    with np.errstate(divide="ignore", invalid="ignore"):
        length, normal = segment_normals(ev[:, 0], ev[:, 1])
    if np.any(length <= 0.0):
        bad = np.flatnonzero(length <= 0.0)
        raise ValueError(f"{bad.size} edge(s) have zero length (first: edge {bad[0]})")
    return length, normal


def assemble_edge_load(
    edge_vertices: np.ndarray,
    edge_dofs: np.ndarray,
    n_dofs: int,
    g: Callable[[np.ndarray, np.ndarray], np.ndarray],
    degree: int = 6,
) -> np.ndarray:
    """Load vector of boundary tractions, ``G[2 z + c] = int_{Gamma_N} g_c psi_z ds``.

    Parameters
    ----------
    edge_vertices : array_like of float, shape (k, 2, 2)
        (start, end) of each straight boundary edge, in the counter-clockwise
        order of its cell (so the outward normal is ``(dy, -dx) / |e|``).
    edge_dofs : array_like of int, shape (k, 6)
        Interleaved DOFs of the edge's P2 nodes in the order (start, end, midpoint).
    n_dofs : int
    g : callable
        ``g(x, normal)`` with points ``x (k, q, 2)`` and outward unit normals
        ``normal (k, 1, 2)`` returns the traction, shape ``(k, q, 2)`` (or
        broadcastable to it).
    degree : int, optional
        Gauss-Legendre degree along each edge (exact for ``g`` polynomial of
        degree ``degree - 2``).

    Returns
    -------
    ndarray of float64, shape (n_dofs,)

    Raises
    ------
    ValueError
        If ``g`` returns a wrong shape or non-finite values, or on bad input.
    """
    n = _check_n_dofs(n_dofs)
    length, normal = edge_normals(edge_vertices)
    ev = np.asarray(edge_vertices, dtype=np.float64)
    dofs = _check_cell_dofs(edge_dofs, ev.shape[0], n, width=6, name="edge_dofs")
    t, w = line_rule(degree)
    x = ev[:, None, 0, :] + t[None, :, None] * (ev[:, 1] - ev[:, 0])[:, None, :]
    gx = _call_checked(g, "edge load g", x.shape, x, normal[:, None, :])
    psi = p2.edge_basis(t) * w[:, None]  # (q, 3)
    local = np.einsum("qa,kqc->kac", psi, gx) * length[:, None, None]
    return np.bincount(dofs.ravel(), weights=local.ravel(), minlength=n)


# ---------------------------------------------------------------------------
# stresses of a discrete field
# ---------------------------------------------------------------------------


def cell_stress(
    vertices: np.ndarray, u_cell: np.ndarray, material: Material, xi: np.ndarray
) -> np.ndarray:
    """Stress ``sigma(u_h)`` at reference points of each cell.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
        Interleaved local coefficients.
    material : Material
    xi : array_like of float, shape (q, 2) or (m, q, 2)
        Reference points, shared or per cell.

    Returns
    -------
    ndarray of float64, shape (m, q, 2, 2)
    """
    return stress(material, p2.field_gradients(vertices, u_cell, xi))


def traction(
    vertices: np.ndarray, u_cell: np.ndarray, material: Material, xi: np.ndarray, normal: np.ndarray
) -> np.ndarray:
    """Traction ``sigma(u_h) n`` at reference points of each cell.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
    material : Material
    xi : array_like of float, shape (q, 2) or (m, q, 2)
        Reference points, shared or per cell.
    normal : array_like of float, shape (m, 2), (m, q, 2) or (2,)
        Normal vectors (not normalised here).

    Returns
    -------
    ndarray of float64, shape (m, q, 2)
        ``(sigma n)_i = sum_j sigma_ij n_j``.
    """
    sig = cell_stress(vertices, u_cell, material, xi)
    nrm = np.asarray(normal, dtype=np.float64)
    if nrm.ndim == 2:
        nrm = nrm[:, None, :]
    try:
        nrm = np.broadcast_to(nrm, sig.shape[:-1])
    except ValueError:
        raise ValueError(
            f"normal of shape {np.shape(normal)} does not fit stresses of shape {sig.shape}"
        ) from None
    return np.einsum("mqij,mqj->mqi", sig, nrm)


def edge_traction(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    material: Material,
    local_edge: np.ndarray,
    t: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Traction ``sigma(u_h) n`` along one local edge of each cell, ``n`` outward.

    Local edge ``k`` runs from local vertex ``k`` to ``(k + 1) % 3``; ``t`` is the
    parameter along it (0 at the start).  The neighbour across an interior edge
    traverses it the other way: evaluate it at ``1 - t`` to get the same
    physical points (its normal is the opposite one), e.g. for the jump
    ``[[sigma n]] = sigma_1 n_1 + sigma_2 n_2``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
    material : Material
    local_edge : array_like of int, shape (m,)
        Which local edge of each cell, in {0, 1, 2}.
    t : array_like of float, shape (q,)
        Edge parameters in [0, 1].

    Returns
    -------
    traction : ndarray of float64, shape (m, q, 2)
    normal : ndarray of float64, shape (m, 2)
        Outward unit normals of those edges.
    """
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 3 or v.shape[1:] != (3, 2):
        raise ValueError(f"vertices must have shape (n_cells, 3, 2), got {v.shape}")
    le = np.asarray(local_edge)
    if le.shape != (v.shape[0],):
        raise ValueError(f"local_edge must have shape ({v.shape[0]},), got {le.shape}")
    xi = p2.edge_reference_points(le, t)
    rows = np.arange(v.shape[0])
    ends = np.stack([v[rows, le], v[rows, (le + 1) % 3]], axis=1)
    _, normal = edge_normals(ends)
    return traction(v, u_cell, material, xi, normal), normal


def div_stress(vertices: np.ndarray, u_cell: np.ndarray, material: Material) -> np.ndarray:
    """``div sigma(u_h)`` on each cell (constant for P2 on straight triangles).

    ``(div sigma)_i = mu Laplace u_i + (lam + mu) d_i div u``, from the constant
    Hessian of ``u_h``; this enters the interior residual ``f + div sigma(u_h)``
    of the estimator (term eta_1 of Section 5).

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
    material : Material

    Returns
    -------
    ndarray of float64, shape (m, 2)
    """
    _check_material(material)
    H = p2.field_hessian(vertices, u_cell)  # (m, i, j, k)
    lap = H[:, :, 0, 0] + H[:, :, 1, 1]
    grad_div = H[:, 0, 0, :] + H[:, 1, 1, :]
    return material.mu * lap + (material.lam + material.mu) * grad_div


# ---------------------------------------------------------------------------
# errors against exact solutions
# ---------------------------------------------------------------------------


def _error_setup(vertices, u_cell, degree):
    J, det = p2.jacobian(vertices)
    u = p2._check_u_cell(u_cell, J.shape[0])
    xi, w = triangle_rule(degree)
    v0 = np.asarray(vertices, dtype=np.float64)[:, 0]

    def point(p: int) -> np.ndarray:  # physical images of quadrature point p, (m, 2)
        return v0 + J[:, :, 0] * xi[p, 0] + J[:, :, 1] * xi[p, 1]

    return u, J, det, xi, w, point


def _grad_error_loop(vertices, u_cell, grad_exact, degree, density):
    """Sum over quadrature points of density(grad u - grad u_h) * w * det, per cell."""
    u, J, det, xi, w, point = _error_setup(vertices, u_cell, degree)
    coef = p2.gradient_coefficients(u, p2.inverse_transpose(J, det))  # (m, 3, 2, 2)
    out = np.zeros(det.shape[0])
    for p in range(w.size):
        ge = _call_checked(grad_exact, "grad_exact", coef.shape[:1] + (2, 2), point(p))
        diff = ge - coef[:, 0]
        diff -= xi[p, 0] * coef[:, 1]
        diff -= xi[p, 1] * coef[:, 2]
        out += w[p] * density(diff)
    return out * det


def energy_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    material: Material,
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared energy error ``a_T(e, e)``, ``e = u - u_h``.

    ``a_T(e, e) = int_T lam (div e)^2 + 2 mu eps(e) : eps(e)``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
        Interleaved coefficients of ``u_h`` on each cell.
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``grad u (m, 2, 2)``,
        ``[..., i, j] = d u_i / d x_j``.
    material : Material
    degree : int, optional
        Quadrature degree on each cell.

    Returns
    -------
    ndarray of float64, shape (m,)
        Non-negative; the energy error is ``sqrt(sum)``.
    """
    _check_material(material)
    lam, mu = material.lam, material.mu

    def density(ge: np.ndarray) -> np.ndarray:
        e00 = ge[:, 0, 0]
        e11 = ge[:, 1, 1]
        e01 = 0.5 * (ge[:, 0, 1] + ge[:, 1, 0])
        return lam * (e00 + e11) ** 2 + 2.0 * mu * (e00**2 + e11**2 + 2.0 * e01**2)

    return _grad_error_loop(vertices, u_cell, grad_exact, degree, density)


def h1_seminorm_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    grad_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared H^1 seminorm error ``int_T |grad(u - u_h)|^2``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
    grad_exact : callable
        ``grad_exact(x)`` with ``x (m, 2)`` returns ``(m, 2, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """
    return _grad_error_loop(
        vertices, u_cell, grad_exact, degree, lambda ge: np.einsum("mij,mij->m", ge, ge)
    )


def l2_error2(
    vertices: np.ndarray,
    u_cell: np.ndarray,
    u_exact: Callable[[np.ndarray], np.ndarray],
    degree: int = 10,
) -> np.ndarray:
    """Per-cell squared L^2 error ``int_T |u - u_h|^2``.

    Parameters
    ----------
    vertices : array_like of float, shape (m, 3, 2)
    u_cell : array_like of float, shape (m, 12)
    u_exact : callable
        ``u_exact(x)`` with ``x (m, 2)`` returns ``(m, 2)``.
    degree : int, optional

    Returns
    -------
    ndarray of float64, shape (m,)
    """
    u, _, det, xi, w, point = _error_setup(vertices, u_cell, degree)
    # u_h at all points: (m, 2, 6) @ (6, q) -> (m, 2, q)
    uh = np.matmul(np.swapaxes(u.reshape(-1, 6, 2), 1, 2), p2.basis(xi).T)
    out = np.zeros(det.shape[0])
    for p in range(w.size):
        ue = _call_checked(u_exact, "u_exact", uh.shape[:2], point(p))
        d = ue - uh[:, :, p]
        out += w[p] * np.einsum("mi,mi->m", d, d)
    return out * det
