"""The geometry of a tetrahedral mesh: the maps from the reference tetrahedron to its cells
and from the reference triangle to its faces (docs/method.md, *Three dimensions*).

The same objects as :mod:`signorini.fem.mapping`, one dimension up, with the same methods,
so an integrand is written once and the geometry decides what is constant:

- :class:`AffineTetrahedra`: ``x(ξ) = v0 + J ξ``, ``J = [v1 − v0, v2 − v0, v3 − v0]``
  (:mod:`signorini.mesh.jacobians`, d = 3): ``J``, ``det J``, ``J⁻ᵀ`` constant per cell
  (a point axis of length 1).
- :class:`IsoparametricTetrahedra`: ``x(ξ) = Σ_a x_a φ_a(ξ)`` through the ten P2 node points
  (:mod:`signorini.fem.p2_tet`): the cells with an edge node moved onto a curved surface.
- :class:`TetrahedronMap`: a mesh's tetrahedra as such groups (:class:`~signorini.fem.
  mapping.CellMap` with these group classes).
- :class:`FlatFaces`, :class:`QuadraticFaces`: points, unit normals and the area element
  ``|∂x/∂s₁ × ∂x/∂s₂|`` of triangular faces (reference triangle, area 1/2), their vertices
  in their cell's face order (outward normal).

Points are ``(..., 3)``; reference points of cells ``(q, 3)``, of faces ``(q, 2)``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

from ..mesh.geometry import facet_normals, spanned_normals
from ..mesh.jacobians import determinant
from ..mesh.reference import TETRAHEDRON
from . import p2, p2_tet
from .fixed_order import rows_times
from .mapping import AffineSimplices, CellMap, IsoparametricSimplices

__all__ = [
    "AffineTetrahedra",
    "FlatFaces",
    "IsoparametricTetrahedra",
    "QuadraticFaces",
    "TetrahedronMap",
    "face_groups",
]

_ALL = slice(None)


def _coefficients(u_cell: np.ndarray) -> np.ndarray:
    """Interleaved cell coefficients ``(m, 30)`` as ``(m, 10, 3)``."""
    return np.asarray(u_cell, dtype=np.float64).reshape(-1, 10, 3)


def _reference_gradients(u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """``(m, q, 3, 3)`` ``∂u_i/∂ξ_r = Σ_a u_{a,i} ∂φ_a/∂ξ_r`` of a P2 field at the reference
    points ``xi (q, 3)``: one product of the ``(3m, 10)`` coefficients by the ``(10, 3q)``
    reference gradients, each cell's rows rounded alike whatever cells stand beside them
    (:func:`~signorini.fem.fixed_order.rows_times`)."""
    g = p2_tet.grad_basis(xi)  # (q, 10, 3)
    q = g.shape[0]
    u = np.ascontiguousarray(_coefficients(u_cell).transpose(0, 2, 1)).reshape(-1, 10)
    flat = rows_times(u, np.ascontiguousarray(g.transpose(1, 0, 2)).reshape(10, 3 * q))
    return flat.reshape(-1, 3, q, 3).transpose(0, 2, 1, 3)


def _reference_hessians(u_cell: np.ndarray) -> np.ndarray:
    """``(m, 3, 3, 3)`` ``∂²u_i/∂ξ_r∂ξ_s`` of a P2 field (constant on the reference cell):
    one product of the ``(3m, 10)`` coefficients by the basis' ``(10, 9)`` reference Hessians,
    each cell's rows rounded alike whatever cells stand beside them."""
    u = np.ascontiguousarray(_coefficients(u_cell).transpose(0, 2, 1)).reshape(-1, 10)
    h = np.ascontiguousarray(p2_tet.hessian_basis().reshape(10, 9))
    return rows_times(u, h).reshape(-1, 3, 3, 3)


def _sandwich(jit: np.ndarray, h: np.ndarray) -> np.ndarray:
    """``(J⁻ᵀ h_i J⁻¹)_{jk} = Σ_{r,s} (J⁻ᵀ)_{jr} h_{irs} (J⁻ᵀ)_{ks}`` for ``jit (..., 3, 3)``
    and ``h (..., 3, 3, 3)`` (component i first): two stacked 3 × 3 products per component,
    each cell's from its own data alone (in place of a three-operand ``einsum``, 5 times
    slower)."""
    A = jit[..., None, :, :]
    return A @ h @ np.swapaxes(A, -1, -2)


def _times_inverse_transpose(ref: np.ndarray, jit: np.ndarray) -> np.ndarray:
    """``∂u_i/∂x_j = Σ_r ∂u_i/∂ξ_r (J⁻ᵀ)_{jr}`` for ``ref (m, q, 3, 3)`` and ``jit (m, q or 1,
    3, 3)``, the three products added in the order r = 0, 1, 2 (elementwise, so a cell's
    values depend on its own data alone)."""
    out = ref[..., :, None, 0] * jit[..., None, :, 0]
    out += ref[..., :, None, 1] * jit[..., None, :, 1]
    out += ref[..., :, None, 2] * jit[..., None, :, 2]
    return out


class AffineTetrahedra(AffineSimplices):
    """Straight tetrahedra ``x(ξ) = v0 + J ξ`` (constant ``J``; its ``J``, ``det J``, ``J⁻ᵀ``
    and measure those of :class:`~signorini.fem.mapping.AffineSimplices`).

    Parameters
    ----------
    vertices : (m, 4, 3) float array
        Positively oriented (``det J > 0``).
    cells : (m,) int array or slice
        Their rows in the mesh (``slice(None)``: all cells, in order).
    """

    def points(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3)`` images of the reference points ``xi (q, 3)``."""
        v = self.vertices
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        return v[:, None, 0] + xi @ (v[:, 1:] - v[:, :1])  # one (q, 3) × (3, 3) product a cell

    def basis_gradients(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 10, 3)`` physical gradients of the ten P2 basis functions."""
        jit = self.inverse_transpose()[:, 0]
        return np.einsum("mij,qaj->mqai", jit, p2_tet.grad_basis(xi))

    def field_values(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3)`` a P2 field with interleaved coefficients ``u_cell (m, 30)`` at the
        reference points ``xi (q, 3)``."""
        return np.einsum("qa,mai->mqi", p2_tet.basis(xi), _coefficients(u_cell))

    def field_gradients(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3, 3)`` ``∂u_i/∂x_j`` of a P2 field at reference points ``xi (q, 3)``:
        the reference gradients times the cell's constant ``J⁻ᵀ``, without the ``(m, q, 10,
        3)`` physical basis gradients."""
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        return _times_inverse_transpose(_reference_gradients(u_cell, xi), self.inverse_transpose())

    def gradient_field(self, u_cell: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """The physical gradient of a P2 field as a function of reference points."""
        return lambda xi: self.field_gradients(u_cell, xi)

    def field_hessians(self, u_cell: np.ndarray, xi: np.ndarray | None = None) -> np.ndarray:
        """``(m, 1, 3, 3, 3)`` ``∂²u_i/∂x_j∂x_k`` of a P2 field (constant on each cell)."""
        jit = self.inverse_transpose()[:, 0]
        return _sandwich(jit, _reference_hessians(u_cell))[:, None]


class IsoparametricTetrahedra(IsoparametricSimplices):
    """Tetrahedra mapped by the quadratic ``x(ξ) = Σ_a x_a φ_a(ξ)`` through their ten P2 node
    points: Jacobians vary from point to point (points, ``J``, ``det J``, ``J⁻ᵀ`` and
    measure those of :class:`~signorini.fem.mapping.IsoparametricSimplices`).

    Parameters
    ----------
    nodes : (m, 10, 3) float array
        Node points in local node order (:mod:`signorini.fem.p2_tet`).
    cells : (m,) int array or slice
        Their rows in the mesh.
    """

    reference = TETRAHEDRON
    shape_functions = p2_tet

    def jacobians(self, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``J (m, q, 3, 3)`` and ``det J (m, q)`` at each point: ``J_ir = ∂x_i/∂ξ_r``, the
        reference gradients of the node points as of a P2 field (each cell's from its own
        nodes alone, bit for bit, whatever cells stand beside it)."""
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        J = _reference_gradients(self.nodes.reshape(-1, 30), xi)
        return J, determinant(J)

    def basis_gradients(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 10, 3)`` physical gradients of the ten P2 basis functions."""
        jit = self.inverse_transpose(xi)
        return np.einsum("mqij,qaj->mqai", jit, p2_tet.grad_basis(xi))

    def field_values(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3)`` a P2 field at the reference points ``xi (q, 3)``."""
        return np.einsum("qa,mai->mqi", p2_tet.basis(xi), _coefficients(u_cell))

    def field_gradients(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3, 3)`` ``∂u_i/∂x_j`` of a P2 field at reference points ``xi``: the
        reference gradients times ``J⁻ᵀ`` at each point."""
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        ref = _reference_gradients(u_cell, xi)
        return _times_inverse_transpose(ref, self.inverse_transpose(xi))

    def field_hessians(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 3, 3, 3)`` ``∂²u_i/∂x_j∂x_k`` of a P2 field at ``xi (q, 3)``, exact through
        the quadratic map (the 3D form of :func:`signorini.fem.iso.field_derivatives`):
        ``∇²u_h = J⁻ᵀ (D²û − Σ_i (∂_i u_h) D²x_i) J⁻¹`` with the constant ``D²x_i``; the
        Jacobians once, the two products by ``J⁻ᵀ`` one after the other."""
        xi = np.atleast_2d(np.asarray(xi, dtype=np.float64))
        d2u = _reference_hessians(u_cell)  # (m, 3, 3, 3) [c, r, s]
        d2x = _reference_hessians(self.nodes.reshape(-1, 30))  # [i, r, s]
        jit = self.inverse_transpose(xi)  # [j, r] = ∂ξ_r / ∂x_j
        grad = _times_inverse_transpose(_reference_gradients(u_cell, xi), jit)  # [c, i]
        m, q = grad.shape[:2]
        bent = (grad @ d2x.reshape(m, 1, 3, 9)).reshape(m, q, 3, 3, 3)  # Σ_i ∂_i u_c D²x_i
        return _sandwich(jit, d2u[:, None] - bent)


class TetrahedronMap(CellMap):
    """The tetrahedra of a mesh as groups of one geometry: affine, then isoparametric.

    Parameters
    ----------
    vertices : (n_cells, 4, 3) float array
    curved : (cells (k,), nodes (k, 10, 3)), optional
        The isoparametric cells and their node points; ``None``: every cell is affine.
    """

    affine = AffineTetrahedra
    isoparametric = IsoparametricTetrahedra


# --------------------------------------------------------------------------- faces


class FlatFaces:
    """Flat triangular faces ``x(s) = a + s₁ (b − a) + s₂ (c − a)``: constant unit normal and
    area element ``2 |F|``.

    Parameters
    ----------
    corners : (k, 3, 3) float array
        ``(a, b, c)`` of each face in its cell's face order (outward normal).
    """

    order = 1

    def __init__(self, corners: np.ndarray) -> None:
        self.corners = np.asarray(corners, dtype=np.float64)
        self.area, self._normal = facet_normals(self.corners)

    def __len__(self) -> int:
        return len(self.corners)

    def points(self, s: np.ndarray) -> np.ndarray:
        """``(k, q, 3)`` the points ``x(s)`` of triangle reference points ``s (q, 2)``."""
        c = self.corners
        s = np.atleast_2d(np.asarray(s, dtype=np.float64))
        return c[:, None, 0] + s @ (c[:, 1:] - c[:, :1])  # one (q, 2) × (2, 3) product a face

    def normals(self, s: np.ndarray | None = None) -> np.ndarray:
        """``(k, 1, 3)`` outward unit normals (constant on each face)."""
        return self._normal[:, None, :]

    def speeds(self, s: np.ndarray | None = None) -> np.ndarray:
        """``(k, 1)`` the area element ``|∂x/∂s₁ × ∂x/∂s₂| = 2 |F|`` (constant)."""
        return 2.0 * self.area[:, None]


class QuadraticFaces:
    """Faces ``x(s) = Σ_a x_a ψ_a(s)`` through their six P2 node points (the P2 triangle's
    basis, :func:`signorini.fem.p2_tet.face_basis`): normal and area element vary.

    Parameters
    ----------
    nodes : (k, 6, 3) float array
        The face's vertices in its cell's face order, then its side midpoints.
    """

    order = 2

    def __init__(self, nodes: np.ndarray) -> None:
        self.nodes = np.asarray(nodes, dtype=np.float64)

    def __len__(self) -> int:
        return len(self.nodes)

    @property
    def area(self) -> np.ndarray:
        """``(k,)`` the areas of the flat triangles of the vertices."""
        return facet_normals(self.nodes[:, :3])[0]

    def points(self, s: np.ndarray) -> np.ndarray:
        """``(k, q, 3)`` the points ``x(s)`` (one ``(q, 6) × (6, 3)`` product per face)."""
        return p2_tet.face_basis(s) @ self.nodes

    def _tangents(self, s: np.ndarray) -> np.ndarray:
        """``(k, q, 2, 3)`` the tangents ``∂x/∂s₁``, ``∂x/∂s₂``: one ``(2q, 6) × (6, 3)``
        product per face (15 times the three-index ``einsum``'s speed)."""
        g = p2.grad_basis(s)  # (q, 6, 2)
        q = g.shape[0]
        rows = np.ascontiguousarray(g.transpose(0, 2, 1).reshape(2 * q, 6))
        return (rows @ self.nodes).reshape(len(self.nodes), q, 2, 3)

    def normals(self, s: np.ndarray) -> np.ndarray:
        """``(k, q, 3)`` unit normals at ``s``, outward as the cell's face order."""
        return spanned_normals(self._tangents(s))[1]

    def speeds(self, s: np.ndarray) -> np.ndarray:
        """``(k, q)`` the area element ``|∂x/∂s₁ × ∂x/∂s₂|``."""
        return spanned_normals(self._tangents(s))[0]


Faces = FlatFaces | QuadraticFaces


def face_groups(
    nodes: np.ndarray, quadratic: np.ndarray
) -> Iterator[tuple[slice | np.ndarray, FlatFaces | QuadraticFaces]]:
    """The faces with node points ``nodes (k, 6, 3)`` as groups of one kind: ``(rows,
    faces)`` for the flat ones, then the ``quadratic (k,) bool`` ones."""
    quadratic = np.asarray(quadratic, dtype=bool)
    if not quadratic.any():
        yield _ALL, FlatFaces(nodes[:, :3])
        return
    if quadratic.all():
        yield _ALL, QuadraticFaces(nodes)
        return
    flat, rows = np.flatnonzero(~quadratic), np.flatnonzero(quadratic)
    yield flat, FlatFaces(nodes[flat, :3])
    yield rows, QuadraticFaces(nodes[rows])
