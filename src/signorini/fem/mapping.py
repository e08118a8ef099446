"""The geometry of a mesh: the maps from the reference triangle to its cells and from the
reference facet (in 2D the interval [0, 1]) to its facets (docs/method.md, *Curved
boundaries*).

Every integral of the package (stiffness, loads, error norms, the estimator's terms) is
written once against these objects; the geometry decides what is constant:

- :class:`AffineCells`: ``x(ξ) = v0 + J ξ``. ``J``, ``det J`` and ``J⁻¹`` are constant on
  each cell, so their arrays carry a point axis of length 1 that broadcasts against the
  points of any rule; derivatives of a P2 field are taken in closed form (its gradient is
  linear, its Hessian constant). The bulk of every mesh.
- :class:`IsoparametricCells`: ``x(ξ) = Σ_a x_a φ_a(ξ)`` through the six P2 node points
  (:mod:`signorini.fem.iso`): everything per point. The thin layer of cells with an edge on a
  curved boundary part.
- :class:`AffineSimplices`, :class:`IsoparametricSimplices`: what these two share with the
  tetrahedra (:mod:`signorini.fem.mapping3d`), by reference cell and P2 basis module.
- :class:`CellMap`: a mesh's cells as such groups (affine first), each knowing its rows in
  the mesh (``cells``, a slice for all cells). :meth:`CellMap.per_cell` evaluates an integrand
  group by group and returns one array in mesh order: each row is computed once, by its own
  geometry.
- :class:`StraightFacets`, :class:`QuadraticFacets`: the geometry of 2D facets (line
  segments, straight or quadratic through their midpoint node): points, unit normals and the
  line element ``|x'(t)|``, constant along straight ones (arrays with a point axis of length
  1). A 3D face geometry (a triangle's map and area element) will come beside them with
  the same methods.

Adding a geometry (a cubic map, a cell of another shape) means one more group class with the
same methods; the integrands do not change. Points are ``(..., d)`` arrays; the Jacobian
determinants and normals here are those of plane (d = 2) cells and edges.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from types import ModuleType

import numpy as np

from ..mesh.geometry import facet_normals, spanned_normals
from ..mesh.jacobians import affine_jacobian, determinant, inverse_transpose
from ..mesh.reference import TRIANGLE, ReferenceCell
from . import iso, p2

__all__ = [
    "AffineCells",
    "AffineSimplices",
    "CellMap",
    "IsoparametricCells",
    "IsoparametricSimplices",
    "QuadraticFacets",
    "StraightFacets",
    "facet_groups",
]

#: local nodes ``[start, end, midpoint]`` of local edge k = 0, 1, 2 of a P2 cell
EDGE_NODES = TRIANGLE.edge_nodes

_ALL = slice(None)


# --------------------------------------------------------------------------- facets (2D: segments)


class StraightFacets:
    """Straight 2D facets (segments) ``x(t) = a + t (b − a)``: constant unit normal and line
    element ``|b − a|``.

    Parameters
    ----------
    ends : (k, 2, d) float array
        ``(start, end)`` of each edge, counter-clockwise around its cell (so the normal
        ``(dy, −dx) / |e|`` points out of the cell).
    """

    order = 1

    def __init__(self, ends: np.ndarray) -> None:
        self.ends = np.asarray(ends, dtype=np.float64)
        self.length, self._normal = facet_normals(self.ends)

    def __len__(self) -> int:
        return len(self.ends)

    def points(self, t: np.ndarray) -> np.ndarray:
        """``(k, q, d)`` the points ``x(t)``."""
        a, b = self.ends[:, 0], self.ends[:, 1]
        return a[:, None, :] + np.asarray(t)[None, :, None] * (b - a)[:, None, :]

    def normals(self, t: np.ndarray | None = None) -> np.ndarray:
        """``(k, 1, d)`` outward unit normals (constant along each edge)."""
        return self._normal[:, None, :]

    def speeds(self, t: np.ndarray | None = None) -> np.ndarray:
        """``(k, 1)`` the line element ``|x'(t)|`` = the length (constant)."""
        return self.length[:, None]

    def speed_at(self, t: np.ndarray) -> np.ndarray:
        """``|x'(t)|`` at per-edge parameters ``t (k, q)``: ``(k, 1)``, constant."""
        return self.length[:, None]


class QuadraticFacets:
    """Quadratic 2D facets ``x(t) = x_s ψ_0 + x_e ψ_1 + x_m ψ_2`` through ``[start, end,
    midpoint]`` (the midpoint node on the curve): normal and line element vary along the
    facet.

    Parameters
    ----------
    nodes : (k, 3, d) float array
        ``[start, end, midpoint]``, start to end counter-clockwise around the cell.
    """

    order = 2

    def __init__(self, nodes: np.ndarray) -> None:
        self.nodes = np.asarray(nodes, dtype=np.float64)

    def __len__(self) -> int:
        return len(self.nodes)

    @property
    def length(self) -> np.ndarray:
        """``(k,)`` chord lengths."""
        d = self.nodes[:, 1] - self.nodes[:, 0]
        return np.hypot(d[:, 0], d[:, 1])

    def _geometry(self, t):
        return iso.edge_geometry(self.nodes[:, :2], self.nodes[:, 2], np.asarray(t))

    def points(self, t: np.ndarray) -> np.ndarray:
        """``(k, q, d)`` the points ``x(t)``."""
        return np.einsum("qa,kai->kqi", p2.edge_basis(t), self.nodes)

    def normals(self, t: np.ndarray) -> np.ndarray:
        """``(k, q, d)`` outward unit normals at ``t`` (the tangent turned clockwise)."""
        return self._geometry(t)[2]

    def speeds(self, t: np.ndarray) -> np.ndarray:
        """``(k, q)`` the line element ``|x'(t)|``."""
        return self._geometry(t)[1]

    def speed_at(self, t: np.ndarray) -> np.ndarray:
        """``|x'(t)|`` ``(k, q)`` at per-edge parameters ``t (k, q)``."""
        t = t[..., None]
        nodes = self.nodes
        dx = (4 * t - 3) * nodes[:, None, 0] + (4 * t - 1) * nodes[:, None, 1]
        dx = dx + (4 - 8 * t) * nodes[:, None, 2]
        return spanned_normals(dx[..., None, :])[0]


Facets = StraightFacets | QuadraticFacets


def facet_groups(
    nodes: np.ndarray, quadratic: np.ndarray
) -> Iterator[tuple[slice | np.ndarray, Facets]]:
    """The 2D facets with node points ``nodes (k, 3, d)`` ``[start, end, midpoint]`` as
    groups of one kind: ``(rows, facets)`` for the straight ones, then the ``quadratic (k,)
    bool`` ones (``rows`` a slice when one kind holds every facet)."""
    quadratic = np.asarray(quadratic, dtype=bool)
    if not quadratic.any():
        yield _ALL, StraightFacets(nodes[:, :2])
        return
    if quadratic.all():
        yield _ALL, QuadraticFacets(nodes)
        return
    straight = np.flatnonzero(~quadratic)
    rows = np.flatnonzero(quadratic)
    yield straight, StraightFacets(nodes[straight, :2])
    yield rows, QuadraticFacets(nodes[rows])


# --------------------------------------------------------------------------- cells


class AffineSimplices:
    """Straight cells of any dimension ``x(ξ) = v0 + J ξ``, ``J = [v1 − v0, …, v_d − v0]``
    (constant): what the triangles (:class:`AffineCells`) and the tetrahedra
    (:class:`~signorini.fem.mapping3d.AffineTetrahedra`) share.

    Parameters
    ----------
    vertices : (m, d + 1, d) float array
        Positively oriented (``det J > 0``; counter-clockwise in 2D).
    cells : (m,) int array or slice
        Their rows in the mesh (``slice(None)``: all cells, in order).
    """

    order = 1

    def __init__(self, vertices: np.ndarray, cells: np.ndarray | slice = _ALL) -> None:
        self.vertices = np.asarray(vertices, dtype=np.float64)
        self.cells = cells

    def __len__(self) -> int:
        return len(self.vertices)

    def jacobians(self, xi: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``J (m, 1, d, d)`` and ``det J (m, 1)``: one per cell, for every point."""
        J, det = affine_jacobian(self.vertices)
        return J[:, None], det[:, None]

    def inverse_transpose(self, xi: np.ndarray | None = None) -> np.ndarray:
        """``J^{-T}`` ``(m, 1, d, d)`` (cofactors times ``1 / det J``): physical gradients
        are ``J^{-T} ∇̂``."""
        J, det = affine_jacobian(self.vertices)
        return inverse_transpose(J, det, reciprocal=True)[:, None]

    def measure(self, w: np.ndarray, xi: np.ndarray | None = None) -> np.ndarray:
        """``(m, q)`` the weights ``w_q det J`` of a rule on the reference cell."""
        return affine_jacobian(self.vertices)[1][:, None] * w

    def rows(self, slot: np.ndarray) -> AffineSimplices:
        """The cells at rows ``slot`` of this group, as a group of the same class."""
        cells = slot if isinstance(self.cells, slice) else self.cells[slot]
        return type(self)(self.vertices[slot], cells)


class IsoparametricSimplices:
    """Cells mapped by the quadratic ``x(ξ) = Σ_a x_a φ_a(ξ)`` through their P2 node points,
    what the triangles (:class:`IsoparametricCells`) and the tetrahedra
    (:class:`~signorini.fem.mapping3d.IsoparametricTetrahedra`) share: a subclass names its
    reference cell and P2 basis module, and adds the field derivatives.

    Parameters
    ----------
    nodes : (m, n_local, d) float array
        Node points in local node order (:attr:`shape_functions`).
    cells : (m,) int array or slice
        Their rows in the mesh.
    """

    order = 2
    #: the reference cell (its vertex count: the first nodes are the vertices)
    reference: ReferenceCell = TRIANGLE
    #: the module of the reference P2 basis (``basis``, ``grad_basis``)
    shape_functions: ModuleType = p2

    def __init__(self, nodes: np.ndarray, cells: np.ndarray | slice = _ALL) -> None:
        self.nodes = np.asarray(nodes, dtype=np.float64)
        self.cells = cells

    def __len__(self) -> int:
        return len(self.nodes)

    @property
    def vertices(self) -> np.ndarray:
        """``(m, d + 1, d)`` the vertices."""
        return self.nodes[:, : self.reference.n_vertices]

    def points(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, d)`` images of the reference points ``xi (q, d)``."""
        return np.einsum("qa,mai->mqi", self.shape_functions.basis(xi), self.nodes)

    def jacobians(self, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``J (m, q, d, d)`` and ``det J (m, q)`` at each point.

        ``J = Σ_a x_a ⊗ ∇φ_a(ξ)`` summed elementwise in the order a = 0 … n_local − 1: a
        cell's Jacobians depend on its own nodes alone, bit for bit
        (:mod:`signorini.fem.fixed_order`).
        """
        g = self.shape_functions.grad_basis(xi)[None, :, :, None, :]  # (1, q, n_local, 1, d)
        x = self.nodes[:, None, :, :, None]  # (m, 1, n_local, d, 1)
        J = x[:, :, 0] * g[:, :, 0]
        for a in range(1, g.shape[2]):  # a loop over the local basis functions
            J += x[:, :, a] * g[:, :, a]
        return J, determinant(J)

    def inverse_transpose(self, xi: np.ndarray) -> np.ndarray:
        """``J^{-T}`` ``(m, q, d, d)`` at each point (cofactors divided by ``det J``)."""
        J, det = self.jacobians(xi)
        return inverse_transpose(J, det)

    def measure(self, w: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q)`` the weights ``w_q det J(ξ_q)`` of a rule on the reference cell."""
        return self.jacobians(xi)[1] * w

    def gradient_field(self, u_cell: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """The physical gradient of a P2 field, ``xi ↦ field_gradients(u_cell, xi)``."""
        return lambda xi: self.field_gradients(u_cell, xi)

    def rows(self, slot: np.ndarray) -> IsoparametricSimplices:
        """The cells at rows ``slot`` of this group, as a group of the same class."""
        cells = slot if isinstance(self.cells, slice) else self.cells[slot]
        return type(self)(self.nodes[slot], cells)


class AffineCells(AffineSimplices):
    """Straight triangles ``x(ξ) = v0 + J ξ``, ``J = [v1 − v0, v2 − v0]`` (constant).

    Parameters
    ----------
    vertices : (m, 3, d) float array
        Counter-clockwise.
    cells : (m,) int array or slice
        Their rows in the mesh (``slice(None)``: all cells, in order).
    """

    def points(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, d)`` images of the reference points ``xi (q, 2)``."""
        return p2.physical_points(self.vertices, xi)

    def basis_gradients(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 6, d)`` physical gradients of the six P2 basis functions."""
        return p2.physical_gradients(self.vertices, xi)

    def gradient_field(self, u_cell: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
        """The physical gradient of the P2 field with interleaved coefficients ``u_cell
        (m, 12)``, as a function of reference points ``(q, 2)`` or ``(m, q, 2)`` returning
        ``(m, q, 2, d)``: linear on each cell, its coefficients computed once."""
        J, det = p2.jacobian(self.vertices)
        coef = p2.gradient_coefficients(u_cell, p2.inverse_transpose(J, det))

        def gradient(xi: np.ndarray) -> np.ndarray:
            xi = np.asarray(xi, dtype=np.float64)
            x = xi[None] if xi.ndim == 2 else xi
            return (
                coef[:, None, 0]
                + x[:, :, 0, None, None] * coef[:, None, 1]
                + x[:, :, 1, None, None] * coef[:, None, 2]
            )

        return gradient

    def field_gradients(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 2, d)`` ``∂u_i/∂x_j`` of a P2 field at reference points ``xi``."""
        return p2.field_gradients(self.vertices, u_cell, xi)

    def field_hessians(self, u_cell: np.ndarray, xi: np.ndarray | None = None) -> np.ndarray:
        """``(m, 1, 2, d, d)`` ``∂²u_i/∂x_j∂x_k`` of a P2 field (constant on each cell)."""
        return p2.field_hessian(self.vertices, u_cell)[:, None]

    def local_facets(self, slot: np.ndarray, k: np.ndarray) -> StraightFacets:
        """Local facet ``k`` (an edge in 2D) of the cells at rows ``slot`` of this group."""
        flat = self.vertices.reshape(-1, self.vertices.shape[-1])
        start, end = 3 * slot + TRIANGLE.edges[k, 0], 3 * slot + TRIANGLE.edges[k, 1]
        return StraightFacets(np.stack([flat[start], flat[end]], 1))


class IsoparametricCells(IsoparametricSimplices):
    """Triangles mapped by the quadratic ``x(ξ) = Σ_a x_a φ_a(ξ)`` through their six P2 node
    points (:mod:`signorini.fem.iso`): Jacobians vary from point to point.

    Parameters
    ----------
    nodes : (m, 6, d) float array
        Node points in local node order (:mod:`signorini.fem.p2`).
    cells : (m,) int array
        Their rows in the mesh.
    """

    def basis_gradients(self, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 6, d)`` physical gradients of the six P2 basis functions."""
        return np.matmul(p2.grad_basis(xi)[None], np.swapaxes(self.inverse_transpose(xi), -1, -2))

    def field_gradients(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 2, d)`` ``∂u_i/∂x_j`` of a P2 field at reference points ``xi``."""
        return iso.field_derivatives(self.nodes, u_cell, xi)[0]

    def field_hessians(self, u_cell: np.ndarray, xi: np.ndarray) -> np.ndarray:
        """``(m, q, 2, d, d)`` ``∂²u_i/∂x_j∂x_k`` of a P2 field, exact through the map."""
        return iso.field_derivatives(self.nodes, u_cell, xi)[1]

    def local_facets(self, slot: np.ndarray, k: np.ndarray) -> QuadraticFacets:
        """Local facet ``k`` (an edge in 2D) of the cells at rows ``slot``: the map
        restricted to it."""
        return QuadraticFacets(self.nodes[slot[:, None], EDGE_NODES[k]])


Cells = AffineCells | IsoparametricCells


class CellMap:
    """The cells of a mesh as groups of one geometry: affine, then isoparametric.

    Parameters
    ----------
    vertices : (n_cells, 3, d) float array
        Every cell's vertices, counter-clockwise.
    curved : (cells (k,), nodes (k, 6, d)), optional
        The isoparametric cells and their node points
        (:attr:`~signorini.fem.space.P2Space.curved`); ``None``: every cell is affine.

    The group classes are the class attributes :attr:`affine` and :attr:`isoparametric`
    (tetrahedra: :class:`signorini.fem.mapping3d.TetrahedronMap`).
    """

    affine: type = AffineCells
    isoparametric: type = IsoparametricCells

    def __init__(
        self, vertices: np.ndarray, curved: tuple[np.ndarray, np.ndarray] | None = None
    ) -> None:
        vertices = np.asarray(vertices, dtype=np.float64)
        self.n_cells = len(vertices)
        self.group = np.zeros(0, dtype=np.int8)  # which group each cell is in (if several)
        self.slot = np.zeros(0, dtype=np.int64)  # its row in that group
        if curved is None or len(curved[0]) == 0:
            self.groups: tuple[Cells, ...] = (self.affine(vertices),)
            return
        cells, nodes = curved
        self.group = np.zeros(self.n_cells, dtype=np.int8)
        self.group[cells] = 1
        affine = np.flatnonzero(self.group == 0)
        self.slot = np.empty(self.n_cells, dtype=np.int64)
        self.slot[affine] = np.arange(affine.size)
        self.slot[cells] = np.arange(len(cells))
        if affine.size == 0:  # every cell is isoparametric (a coarse mesh of a curved body)
            self.groups = (self.isoparametric(nodes),)
            self.group, self.slot = np.zeros(0, dtype=np.int8), np.zeros(0, dtype=np.int64)
            return
        self.groups = (self.affine(vertices[affine], affine), self.isoparametric(nodes, cells))

    def per_cell(self, func: Callable[[Cells], np.ndarray]) -> np.ndarray:
        """``func(group)`` of every group, in mesh order ``(n_cells, ...)``."""
        if len(self.groups) == 1:
            return func(self.groups[0])
        out = None
        for g in self.groups:
            if len(g) == 0:
                continue
            values = func(g)
            if out is None:
                out = np.empty((self.n_cells,) + values.shape[1:], dtype=values.dtype)
            out[g.cells] = values
        return out

    def points(self, xi: np.ndarray) -> np.ndarray:
        """``(n_cells, q, d)`` the images of the reference points ``xi (q, 2)``."""
        return self.per_cell(lambda g: g.points(xi))

    def split(self, cell: np.ndarray) -> Iterator[tuple[slice | np.ndarray, Cells, np.ndarray]]:
        """The given cells ``(e,)`` by group: ``(rows into cell, group, rows in the group)``."""
        if len(self.groups) == 1:
            yield _ALL, self.groups[0], cell
            return
        group = self.group[cell]
        for i, g in enumerate(self.groups):
            rows = np.flatnonzero(group == i)
            if rows.size:
                yield rows, g, self.slot[cell[rows]]

    def local_facets(
        self, cell: np.ndarray, k: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, Cells, np.ndarray, Facets]]:
        """Local facet ``k (e,)`` (an edge in 2D) of each ``cell (e,)`` by group: ``(rows,
        group, slots, facets)``, the facets being the group's map restricted to them."""
        for rows, g, slot in self.split(cell):
            yield rows, g, slot, g.local_facets(slot, k[rows])
