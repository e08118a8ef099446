"""The estimator on several ranks: each rank integrates its own cells and facets, and the
integrals are summed over the ranks before they are spread to nodes and cells (docs/parallel.md,
*The estimator on several ranks*).

Every term of (5.1) is a sum of integrals over single cells (η1) and single facets (edges in 2D; η2
… η6, η8), and η7's facet shares; :func:`~signorini.estimator.residual.estimate` spreads them to the
nodes and cells (:mod:`.terms`). On a run of several ranks (the mesh, the space and the solution
replicated on every rank, docs/parallel.md, *What is distributed*) rank r integrates

- η1 on its own cells (:attr:`~signorini.contact.partition.Partition.owned_cells`);
- every facet term on the facets whose first cell (``facet2cell[:, 0]``) is its own: an
  interior facet once, on one side's rank, with the stress of the neighbour across it (a ghost
  cell, whose σ(u_h) it computes too), a boundary facet on its cell's rank;
- the contact terms η4 … η8 on every contact facet, and keeps those of its own: Γ_C's data
  (the gap, the pressure, the contact set, the friction stresses: O(√n) numbers) is
  replicated, η7 is a norm on Γ_C whole, and all of them together take under 1 % of the
  estimator's time (docs/parallel.md), less than splitting them would save.

Each integral thus enters the sum (:meth:`~signorini.algebra.ranks.Ranks.sum`, one reduction
of all the integrals) from exactly one rank, zero from the others, so every rank holds each
integral as its rank computed it, and spreads them to nodes and cells as the serial run
does. A rank computes an integral by the serial operations on fewer rows; its value is the
serial one bit for bit on the meshes tested, and to round-off in general (a BLAS product may
take another kernel for another number of rows).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..algebra.ranks import SERIAL, Ranks
from ..contact.partition import Partition
from ..contact.partition import partition as partition_of
from ..contact.solution import ContactResult
from ..fem.mapping import CellMap, Cells

__all__ = ["OwnPart", "own_part", "per_cell_of"]


@dataclass(frozen=True)
class OwnPart:
    """What one rank integrates of the estimator.

    Attributes
    ----------
    ranks : Ranks
        The processes of the run (their :meth:`~Ranks.sum` and :meth:`~Ranks.max`).
    cells : (n_cells,) bool array
        This rank's cells: η1 on them, every facet term on the facets whose first cell is one.
    """

    ranks: Ranks
    cells: np.ndarray

    def facets(self, facet2cell: np.ndarray) -> np.ndarray:
        """``(k,)`` bool: which of the facets with cells ``facet2cell (k, 2)`` this rank
        integrates (those whose first cell is its own)."""
        return self.cells[facet2cell[:, 0]]

    def stressed_cells(self, facet2cell: np.ndarray, contact_facets: np.ndarray) -> np.ndarray:
        """The cells whose σ(u_h) this rank needs, ascending: its own, across its interior
        facets their neighbours (``facet2cell`` of the mesh), and the cells of the contact
        facets ``contact_facets`` (mesh facet numbers)."""
        mine = self.cells[facet2cell[:, 0]] & (facet2cell[:, 1] >= 0)
        need = self.cells.copy()
        need[facet2cell[mine, 1]] = True
        need[facet2cell[contact_facets, 0]] = True
        return np.flatnonzero(need)

    def sum(self, arrays: Sequence[np.ndarray]) -> list[np.ndarray]:
        """The elementwise sums over the ranks of ``arrays`` (float arrays of any shapes), in
        one reduction."""
        flat = self.ranks.sum(np.concatenate([np.ravel(a) for a in arrays]))
        ends = np.cumsum([np.size(a) for a in arrays])[:-1]
        return [
            part.reshape(np.shape(a)) for part, a in zip(np.split(flat, ends), arrays, strict=True)
        ]


def own_part(
    result: ContactResult, ranks: Ranks = SERIAL, partition: Partition | None = None
) -> OwnPart | None:
    """This rank's part of the estimator of ``result``: ``None`` on one process without a
    partition (the serial path), else the cells of ``partition`` (default: the partition of
    ``result.space`` over ``ranks``, :func:`~signorini.contact.partition.partition`).

    Raises
    ------
    ValueError
        If ``ranks`` is not a :class:`~signorini.algebra.ranks.Ranks`, or ``partition`` is not
        a :class:`~signorini.contact.partition.Partition` of ``result``'s cells for ``ranks``'s
        rank and size.
    """
    if not isinstance(ranks, Ranks):
        raise ValueError(f"ranks must be an algebra.ranks.Ranks, got {type(ranks).__name__}")
    if partition is None:
        if not ranks.distributed:
            return None
        partition = partition_of(result.space, ranks)
    if not isinstance(partition, Partition):
        raise ValueError(
            f"partition must be a contact.partition.Partition, got {type(partition).__name__}"
        )
    if (partition.rank, partition.size) != (ranks.rank, ranks.size):
        raise ValueError(
            f"partition is rank {partition.rank} of {partition.size}, but ranks is rank "
            f"{ranks.rank} of {ranks.size}"
        )
    n_cells = result.mesh.n_cells
    if np.shape(partition.cell_owner) != (n_cells,):
        raise ValueError(
            f"partition has {np.size(partition.cell_owner)} cell owners, the result's mesh "
            f"{n_cells} cells"
        )
    return OwnPart(ranks, partition.owned_cells)


def per_cell_of(
    cells: CellMap,
    subset: np.ndarray,
    func: Callable[[Cells, np.ndarray | slice], np.ndarray],
    shape: tuple[int, ...] = (),
) -> np.ndarray:
    """``func(group, rows)`` of the cells ``subset (m,)``, group by group (``group`` those of
    them of one geometry, ``rows`` their positions in ``subset``), as
    :meth:`~signorini.fem.mapping.CellMap.per_cell` gives it for every cell: ``(m, *shape)``
    in the order of ``subset``, ``shape`` the shape of one cell's value."""
    out = np.zeros((len(subset), *shape))
    if len(subset):
        for rows, g, slot in cells.split(subset):
            out[rows] = func(g.rows(slot), rows)
    return out
