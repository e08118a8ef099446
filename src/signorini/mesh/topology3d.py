"""The topology of a bisected tetrahedral mesh from its parent's, without a global sort
(docs/method.md, *Three dimensions: bisection*).

Bisection keeps most cells in their rows and creates known entities: an old edge or face
survives unless it contains a bisected edge, and every other entity of the child mesh is an
entity of a new cell. So the child's sorted entity list is the parent's survivors merged with
the new cells' new entities (a sort of the new ones only), the kept cells' entity indices are
the parent's renumbered, and ``facet2cell`` is a scatter of the cells over their faces. The
arrays are those :func:`~signorini.mesh.topology.entity_topology` computes, bit for bit (the
tests check it).
"""

from __future__ import annotations

import numpy as np

from .bisect3d import KEY_BASE, edge_key
from .reference import TETRAHEDRON
from .topology import _frozen

__all__ = ["refined_topology"]

#: Face keys use the base ``2**21``: up to about two million points.
FACE_BASE = np.int64(1 << 21)


def _keys(rows: np.ndarray) -> np.ndarray:
    """Keys of sorted vertex rows ``(n, 2)`` or ``(n, 3)``, in the order of the rows."""
    if rows.shape[1] == 2:
        return rows[:, 0] * KEY_BASE + rows[:, 1]
    return (rows[:, 0] * FACE_BASE + rows[:, 1]) * FACE_BASE + rows[:, 2]


def _sorted_rows(rows: np.ndarray) -> np.ndarray:
    """Rows ``(n, 2)`` or ``(n, 3)`` sorted by min/max (cheaper than a sort along rows)."""
    lo, hi = rows.min(axis=1), rows.max(axis=1)
    if rows.shape[1] == 2:
        return np.column_stack([lo, hi])
    return np.column_stack([lo, rows.sum(axis=1) - lo - hi, hi])


def _refined_entities(
    old: np.ndarray,
    old_cell2entity: np.ndarray,
    dead: np.ndarray,
    cells: np.ndarray,
    touched: np.ndarray,
    local: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """The sorted entities ``(n_e, k)`` and ``cell2entity (n_cells, m)`` of the child
    ``cells``: the ``old`` entities not ``dead`` and the new entities of the ``touched``
    cells (old rows ``~touched`` keep their cells)."""
    t = np.flatnonzero(touched)
    tuples = _sorted_rows(cells[t][:, local].reshape(-1, local.shape[1]))
    tk = _keys(tuples)
    uniq, first, inverse = np.unique(tk, return_index=True, return_inverse=True)
    old_key = _keys(old)
    pos = np.minimum(np.searchsorted(old_key, uniq), max(old_key.size - 1, 0))
    present = (old_key[pos] == uniq) & ~dead[pos]
    fresh, fresh_rows = uniq[~present], tuples[first[~present]]
    kept = np.flatnonzero(~dead)
    kept_key = old_key[kept]
    at_fresh = np.searchsorted(kept_key, fresh) + np.arange(fresh.size)
    at_kept = np.arange(kept.size) + np.searchsorted(fresh, kept_key)
    entities = np.empty((kept.size + fresh.size, local.shape[1]), dtype=np.int64)
    entities[at_kept] = old[kept]
    entities[at_fresh] = fresh_rows
    renumber = np.full(old.shape[0], -1, dtype=np.int64)
    renumber[kept] = at_kept
    index = np.empty(uniq.size, dtype=np.int64)  # of the touched cells' entities
    index[present] = renumber[pos[present]]
    index[~present] = at_fresh
    cell2entity = np.empty((cells.shape[0], local.shape[0]), dtype=np.int64)
    same = np.flatnonzero(~touched)
    cell2entity[same] = renumber[old_cell2entity[same]]
    cell2entity[t] = index[inverse].reshape(-1, local.shape[0])
    return entities, cell2entity


def _facet2cell(cell2facet: np.ndarray, n_facets: int) -> np.ndarray:
    """``(n_facets, 2)`` the cells of each face, the smaller first, ``-1`` outside."""
    owner = np.repeat(np.arange(cell2facet.shape[0], dtype=np.int64), cell2facet.shape[1])
    f = cell2facet.ravel()
    out = np.empty((n_facets, 2), dtype=np.int64)
    out[:, 0] = np.iinfo(np.int64).max
    out[:, 1] = -1
    np.minimum.at(out[:, 0], f, owner)
    np.maximum.at(out[:, 1], f, owner)
    out[out[:, 0] == out[:, 1], 1] = -1
    return out


def refined_topology(
    old_edges: np.ndarray,
    old_cell2edge: np.ndarray,
    old_facets: np.ndarray,
    old_cell2facet: np.ndarray,
    cells: np.ndarray,
    touched: np.ndarray,
    split_key: np.ndarray,
) -> tuple[tuple[np.ndarray, np.ndarray, None], tuple[np.ndarray, np.ndarray, np.ndarray]] | None:
    """The child mesh's ``(edges, cell2edge, None)`` and ``(facets, cell2facet,
    facet2cell)``, read-only, as :func:`~signorini.mesh.topology.entity_topology` gives them
    (edges and faces sorted, ``facet2cell`` the smaller cell first).

    Parameters
    ----------
    old_edges, old_cell2edge, old_facets, old_cell2facet : arrays
        The parent mesh's topology; its cells in the rows ``~touched`` are the child's.
    cells : (n_cells, 4) int64 array
        The child's cells.
    touched : (n_cells,) bool array
        The child's new cells (:attr:`~signorini.mesh.bisect3d.Bisection.touched`).
    split_key : (k,) int64 array
        The bisected edges (sorted :func:`~signorini.mesh.bisect3d.edge_key`).

    Returns
    -------
    tuple or None
        ``None`` when the points are too many for the face keys.
    """
    if int(cells.max(initial=0)) >= int(FACE_BASE):
        return None

    def split(pairs: np.ndarray) -> np.ndarray:
        key = edge_key(pairs[..., 0], pairs[..., 1])
        if split_key.size == 0:
            return np.zeros(key.shape, dtype=bool)
        pos = np.minimum(np.searchsorted(split_key, key), split_key.size - 1)
        return split_key[pos] == key

    edges, cell2edge = _refined_entities(
        old_edges, old_cell2edge, split(old_edges), cells, touched, TETRAHEDRON.edges
    )
    tri = TETRAHEDRON.facet_cell.edges  # the three edges of a face
    face_dead = split(old_facets[:, tri]).any(axis=1)
    facets, cell2facet = _refined_entities(
        old_facets, old_cell2facet, face_dead, cells, touched, TETRAHEDRON.facets
    )
    facet2cell = _facet2cell(cell2facet, facets.shape[0])
    return (
        (_frozen(edges), _frozen(cell2edge), None),
        (_frozen(facets), _frozen(cell2facet), _frozen(facet2cell)),
    )
