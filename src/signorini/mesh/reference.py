"""The reference cells: the one owner of a cell's local topology (docs/method.md, *Data
conventions*).

A :class:`ReferenceCell` states, once, what every layer used to write by hand: the reference
coordinates of the vertices, which local vertices each local edge and each local facet joins,
the reference cell of a facet, and the names of the cell in VTK and meshio. Entity lists of a
mesh are read from it: the edges of the cells ``cells (n_cells, n_vertices)`` are
``cells[:, cell.edges]``, ``(n_cells, n_edges, 2)``, in the order of local edges.

- :data:`TRIANGLE`: local edge ``k`` joins vertices ``k`` and ``(k + 1) mod 3`` (so it runs
  counter-clockwise around the cell, and is opposite vertex ``(k + 2) mod 3``); its facets
  are its edges. Local edge 0 is the refinement edge of newest vertex bisection
  (:mod:`signorini.mesh.refine`).
- :data:`TETRAHEDRON` (data only, for the third dimension): the six edges in the order of
  VTK's quadratic tetrahedron (``tetra10``: nodes 4–9 sit at their midpoints), the first
  three those of the triangle ``0 1 2``; local face ``k`` is opposite vertex ``k``, ordered so
  that its normal by the right-hand rule points out of the cell.
- :data:`INTERVAL`: the facet of the triangle, ``t`` in [0, 1] from vertex 0 to vertex 1.

The P2 node of local edge ``k`` is local node ``n_vertices + k`` for every cell here (the
order of VTK's and meshio's quadratic cells), :attr:`ReferenceCell.edge_nodes`.

References
----------
Gustafsson, T., McBain, G. D. (2020). scikit-fem: A Python package for finite element
assembly. *Journal of Open Source Software* 5(52), 2369 (``skfem/refdom.py``: one table per
reference cell).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["INTERVAL", "TETRAHEDRON", "TRIANGLE", "ReferenceCell"]


def _table(rows: list, dtype: type) -> np.ndarray:
    """A read-only array of a table's rows."""
    a = np.array(rows, dtype=dtype)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class ReferenceCell:
    """One reference cell's local topology (read-only arrays).

    Parameters
    ----------
    name : str
        ``"interval"``, ``"triangle"`` or ``"tetrahedron"``.
    dim : int
        Its topological dimension.
    vertices : (n_vertices, dim) float64 array
        Reference coordinates of the vertices.
    edges : (n_edges, 2) int64 array
        The local vertices each local edge joins, from its start to its end.
    facets : (n_facets, dim) int64 array
        The local vertices of each local facet (the entities of dimension ``dim - 1``).
    facet_cell : ReferenceCell or None
        The reference cell of a facet (``None`` for the interval, whose facets are points).
    vtk_name, vtk_p2_name : str
        meshio's names of the cell with its vertices only and with its P2 nodes.
    vtk_id, vtk_p2_id : int
        VTK's cell type numbers of the same two.
    """

    name: str
    dim: int
    vertices: np.ndarray
    edges: np.ndarray
    facets: np.ndarray
    facet_cell: ReferenceCell | None
    vtk_name: str
    vtk_p2_name: str
    vtk_id: int
    vtk_p2_id: int

    def __repr__(self) -> str:
        return self.name.upper()

    @property
    def n_vertices(self) -> int:
        """The number of vertices."""
        return self.vertices.shape[0]

    @property
    def n_edges(self) -> int:
        """The number of edges."""
        return self.edges.shape[0]

    @property
    def n_facets(self) -> int:
        """The number of facets."""
        return self.facets.shape[0]

    @property
    def edge_nodes(self) -> np.ndarray:
        """``(n_edges, 3)`` int64: each local edge's start, end and P2 midpoint node
        (``n_vertices + k``)."""
        mid = self.n_vertices + np.arange(self.n_edges, dtype=np.int64)
        return _table(np.column_stack([self.edges, mid]).tolist(), np.int64)


INTERVAL = ReferenceCell(
    name="interval",
    dim=1,
    vertices=_table([[0.0], [1.0]], np.float64),
    edges=_table([[0, 1]], np.int64),
    facets=_table([[0], [1]], np.int64),
    facet_cell=None,
    vtk_name="line",
    vtk_p2_name="line3",
    vtk_id=3,
    vtk_p2_id=21,
)

TRIANGLE = ReferenceCell(
    name="triangle",
    dim=2,
    vertices=_table([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], np.float64),
    edges=_table([[0, 1], [1, 2], [2, 0]], np.int64),
    facets=_table([[0, 1], [1, 2], [2, 0]], np.int64),
    facet_cell=INTERVAL,
    vtk_name="triangle",
    vtk_p2_name="triangle6",
    vtk_id=5,
    vtk_p2_id=22,
)

TETRAHEDRON = ReferenceCell(
    name="tetrahedron",
    dim=3,
    vertices=_table(
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], np.float64
    ),
    edges=_table([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]], np.int64),
    facets=_table([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], np.int64),
    facet_cell=TRIANGLE,
    vtk_name="tetra",
    vtk_p2_name="tetra10",
    vtk_id=10,
    vtk_p2_id=24,
)
