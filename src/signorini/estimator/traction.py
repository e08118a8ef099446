"""``σ(u_h) n`` on the facets of the cells (edges in 2D), through each cell's map, and the direction
field the contact terms split it along (docs/method.md, *Estimator*, "On curved boundaries"); used
by the terms of :mod:`signorini.estimator.terms` (which re-exports ``facet_traction`` and
``direction_field``)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..fem.element import P2
from ..fem.mapping import AffineCells, CellMap, Cells, Facets
from ..fem.material import CellMaterials, Material, on_cells, stress
from ..fem.p2 import REFERENCE_NODES, edge_reference_points
from ..mesh.geometry import facet_normals
from ..mesh.reference import TRIANGLE
from .owned import per_cell_of

__all__ = ["CellStress", "direction_field", "facet_traction", "vertex_stress"]


def vertex_stress(
    cells: CellMap,
    u_cell: np.ndarray,
    material: Material | CellMaterials,
    subset: np.ndarray | None = None,
) -> np.ndarray:
    """σ(u_h) ``(n_cells, 3, 2, 2)`` of each cell at its vertices, through its map, from the
    interleaved coefficients ``u_cell (n_cells, 12)``; with ``subset (m,)`` (cell numbers) of
    those cells only, the other rows zero (a rank's cells and their neighbours, :mod:`.owned`)."""
    vertices = REFERENCE_NODES[:3]

    def of(g: Cells, rows=None) -> np.ndarray:
        return stress(on_cells(material, g.cells), g.field_gradients(u_cell[g.cells], vertices))

    if subset is None:
        return cells.per_cell(of)
    out = np.zeros((cells.n_cells, 3, 2, 2))
    out[subset] = per_cell_of(cells, subset, of, (3, 2, 2))
    return out


class CellStress:
    """σ(u_h) of a discrete solution in a stress unit, along the local facets of its cells.

    On cells with a constant Jacobian σ(u_h) is linear (P2 displacements), so it is
    interpolated from its vertex values (:func:`facet_traction`); on the isoparametric ones it
    is taken through the quadratic map at each point, with the normal of the quadratic facet
    (docs/method.md, *Estimator*, "On curved boundaries").

    Parameters
    ----------
    cells : CellMap
    points, cell_vertices : mesh arrays ``(n_points, 2)``, ``(n_cells, 3)``
    u_cell : (n_cells, 12) float array
    material : Material or CellMaterials
        One material, or each cell's (σ(u_h) of a cell with its own material).
    sigma_vertex : (n_cells, 3, 2, 2) float array
        :func:`vertex_stress`, already divided by ``unit``.
    unit : float
        The stress unit σ₀.
    owned : (n_cells,) bool array, optional
        A rank's cells (:mod:`.owned`): :meth:`on_facets` then gives the facets of these
        cells only. ``None`` (the default): every cell's.
    """

    def __init__(
        self, cells, points, cell_vertices, u_cell, material, sigma_vertex, unit=1.0, owned=None
    ):
        self.cells, self.points, self.cell_vertices = cells, points, cell_vertices
        self.u_cell, self.material = u_cell, material
        self.sigma_vertex, self.unit, self.owned = sigma_vertex, unit, owned

    @classmethod
    def of(
        cls, space, u: np.ndarray, material: Material | CellMaterials, unit: float = 1.0
    ) -> CellStress:
        """σ(u_h) of the nodal values ``u (n_nodes, 2)`` of a :class:`~signorini.fem.space.
        P2Space`, in the stress unit ``unit``."""
        u_cell = space.cell_values(u)
        sigma = vertex_stress(space.mapping, u_cell, material) / unit
        mesh = space.mesh
        return cls(space.mapping, mesh.points, mesh.cells, u_cell, material, sigma, unit)

    @property
    def everywhere(self) -> CellStress:
        """The same stresses, :meth:`on_facets` giving every facet (``owned`` dropped)."""
        if self.owned is None:
            return self
        return CellStress(
            self.cells, self.points, self.cell_vertices, self.u_cell, self.material,
            self.sigma_vertex, self.unit,
        )  # fmt: skip

    def _traction(self, group: Cells, slot, cell, k, t, facets: Facets | None) -> np.ndarray:
        """σ(u_h) n on local facets ``k`` of ``cell`` (rows ``slot`` of ``group``); ``facets``
        their geometry where already built."""
        if isinstance(group, AffineCells):
            return facet_traction(self.sigma_vertex, self.points, self.cell_vertices, cell, k, t)
        facets = group.local_facets(slot, k) if facets is None else facets
        grad = group.rows(slot).field_gradients(self.u_cell[cell], edge_reference_points(k, t))
        sig = stress(on_cells(self.material, cell), grad) / self.unit
        return np.einsum("eqij,eqj->eqi", sig, facets.normals(t))

    def on_facets(
        self, cell: np.ndarray, k: np.ndarray, t: np.ndarray
    ) -> Iterator[tuple[slice | np.ndarray, np.ndarray, Facets]]:
        """``σ(u_h) n`` along local facet ``k (e,)`` of each ``cell (e,)`` at parameters ``t
        (q,)`` (counter-clockwise around the cell), n the outward normal, group by group:
        ``(rows, traction (r, q, 2), facets)`` with the facets' geometry. With ``owned``, only
        the rows whose cell is owned (none at all if there is no such row)."""
        if self.owned is not None:
            mine = np.flatnonzero(self.owned[cell])
            if mine.size == 0:
                return
            if mine.size < len(cell):
                for rows, traction, facets in self._on_facets(cell[mine], k[mine], t):
                    yield mine[rows], traction, facets
                return
        yield from self._on_facets(cell, k, t)

    def _on_facets(self, cell, k, t):
        for rows, g, slot, facets in self.cells.local_facets(cell, k):
            yield rows, self._traction(g, slot, cell[rows], k[rows], t, facets), facets

    def traction(self, cell: np.ndarray, k: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``σ(u_h) n`` ``(e, q, 2)`` along local facet ``k`` of each ``cell`` (as
        :meth:`on_facets`, in one array, without the facets' geometry)."""
        parts = list(self.cells.split(cell))
        if len(parts) == 1:
            _, g, slot = parts[0]
            return self._traction(g, slot, cell, k, t, None)
        out = np.empty((len(cell), len(t), 2))
        for rows, g, slot in parts:
            out[rows] = self._traction(g, slot, cell[rows], k[rows], t, None)
        return out


def facet_traction(
    sigma_vertex: np.ndarray,
    points: np.ndarray,
    cells: np.ndarray,
    cell: np.ndarray,
    k: np.ndarray,
    t: np.ndarray,
) -> np.ndarray:
    """``σ(u_h) n`` along local facet ``k`` of ``cell`` (an edge), n the cell's outward normal.

    σ(u_h) is linear on each cell (P2 displacements), so it is interpolated from its
    values at the vertices.

    Parameters
    ----------
    sigma_vertex : (n_cells, 3, 2, 2) float array
        σ(u_h) of each cell at its vertices.
    points, cells : mesh arrays
    cell, k : (m,) int arrays
        Cell and local facet of each facet.
    t : (q,) float array
        Parameters along the facet, in the cell's counter-clockwise direction.

    Returns
    -------
    (m, q, 2) float array
    """
    # flat indices (one gather each, faster than indexing two axes)
    v0, v1 = 3 * cell + TRIANGLE.facets[k, 0], 3 * cell + TRIANGLE.facets[k, 1]
    corners = cells.ravel()
    _, n = facet_normals(points[corners[np.stack([v0, v1], axis=-1)]])
    # σ n at the facet's two vertices, then linear along it (σ is linear on the cell)
    sigma = sigma_vertex.reshape(-1, 2, 2)
    a = np.einsum("eij,ej->ei", sigma[v0], n)
    b = np.einsum("eij,ej->ei", sigma[v1], n)
    return (1 - t)[None, :, None] * a[:, None] + t[None, :, None] * b[:, None]


def direction_field(direction: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The constraint direction along contact facets: the normalised quadratic interpolant of
    the nodal directions n_z ``(k, 3, 2)`` at ``[start, end, midpoint]``, at parameters
    ``t (q,)``: ``(k, q, 2)`` unit vectors (docs/method.md, *Estimator*, "On curved
    boundaries"). Where the interpolant vanishes (nodal directions opposed across one edge,
    e.g. a facet spanning a slot of an obstacle) the midpoint node's direction is used."""
    d = np.einsum("qa,kac->kqc", P2.facet.basis(t), direction)
    size = np.hypot(d[..., 0], d[..., 1])[..., None]
    small = size <= 1e-8
    if small.any():
        d = np.where(small, direction[:, None, 2], d)
        size = np.where(small, 1.0, size)
    return d / size
