"""The topology of a simplicial mesh as pure functions on its arrays, every entity list read
from the reference cell (docs/method.md, *Data conventions*): each entity (edge, facet) once,
the entities of each cell, the cells of each facet and a facet's local index in them, the
boundary facets, and the cell order that puts the refinement edge first.
:class:`~signorini.mesh.mesh.Mesh` caches their results.

One function, :func:`entity_topology`, builds every list from a table of local entities
(``TRIANGLE.edges``, ``TRIANGLE.facets``, ``TETRAHEDRON.edges``, ``TETRAHEDRON.facets``), as
scikit-fem builds its ``t2f``/``f2t`` from ``refdom`` tables: the entities of the cells are
``cells[:, local]``, numbered by the sorted key of their vertex sets.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .reference import TRIANGLE
from .validation import MeshError, format_indices

__all__ = [
    "KEY_LIMIT",
    "boundary_facets",
    "common_keys",
    "edge_keys",
    "entity_keys",
    "entity_topology",
    "facet_local",
    "find_rows",
    "longest_edge_first",
    "rows_of",
]


def _frozen(a: np.ndarray) -> np.ndarray:
    """Mark a cached array read-only (a Mesh is immutable)."""
    a.flags.writeable = False
    return a


#: Keys are int64: every key is below this bound.
KEY_LIMIT = 2**63


def entity_keys(tuples: np.ndarray, n_points: int) -> np.ndarray:
    """Int64 key of each unordered vertex set ``tuples (n, k)`` (:func:`common_keys` of the
    one array): equal keys for equal sets, ordered as the sorted vertex rows are
    lexicographically; for ``k = 2``, ``min * n_points + max``."""
    return common_keys([tuples], n_points)[0]


def common_keys(arrays: Sequence[np.ndarray], n_points: int) -> list[np.ndarray]:
    """Int64 keys of the unordered vertex sets of each of ``arrays`` ``(n_i, k)`` (vertices
    below ``n_points``), comparable across the arrays: two sets have equal keys if and only
    if they are equal, and the keys are ordered as the sets' sorted vertex rows are
    lexicographically (so a sort by key is a lexicographic sort of the rows).

    While ``n_points ** k`` fits into an int64 (faces up to 2 097 152 points, cells up to
    55 108), the key is the sorted vertices read as the digits of a number in base
    ``n_points``, the same in every call. Beyond, the leading digits are first replaced by
    their rank among the rows of all ``arrays`` (one sort of the keys so far; the rank
    keeps the lexicographic order), so that ``rank * n_points + next`` fits again: keys of
    any mesh that fits in memory, comparable only among the arrays of one call —
    compare keys of different arrays by passing them together (:func:`find_rows`).

    Raises
    ------
    MeshError
        If even the ranks do not fit (more than ``2**63 / n_points`` rows).
    """
    k = arrays[0].shape[1]
    n = int(n_points)
    if k == 2 and n * n <= KEY_LIMIT:
        out = []
        for pairs in arrays:  # a loop over the arrays
            lo = np.minimum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
            hi = np.maximum(pairs[:, 0], pairs[:, 1]).astype(np.int64)
            out.append(lo * np.int64(n) + hi)
        return out
    rows = [np.sort(np.asarray(a), axis=1).astype(np.int64) for a in arrays]
    s = rows[0] if len(rows) == 1 else np.concatenate(rows)
    key, bound = s[:, 0], n  # every key is below bound
    for j in range(1, k):  # a loop over an entity's vertices
        if bound * n > KEY_LIMIT:
            _, key = np.unique(key, return_inverse=True)
            bound = int(key.max(initial=0)) + 1
            if bound * n > KEY_LIMIT:
                raise MeshError(f"{s.shape[0]} vertex sets of {n} points are too many for keys")
        key = key * np.int64(n) + s[:, j]
        bound *= n
    return np.split(key, np.cumsum([r.shape[0] for r in rows])[:-1])


def find_rows(
    reference: np.ndarray, queries: np.ndarray, n_points: int
) -> tuple[np.ndarray, np.ndarray]:
    """The row of ``reference (n, k)`` that holds the vertex set of each row of ``queries
    (m, k)`` (in any vertex order; the first such row), and whether there is one
    (:func:`common_keys`).

    Returns
    -------
    row : (m,) int64 array
        The row of ``reference``; any row where ``found`` is false.
    found : (m,) bool array
    """
    keys, want = common_keys([reference, queries], n_points)
    if keys.size == 0:
        return np.zeros(want.size, dtype=np.int64), np.zeros(want.size, dtype=bool)
    order = np.argsort(keys, kind="stable")
    pos = np.minimum(np.searchsorted(keys[order], want), keys.size - 1)
    return order[pos], keys[order[pos]] == want


def edge_keys(pairs: np.ndarray, n_points: int) -> np.ndarray:
    """Unique int64 key of each undirected vertex pair ``(n, 2)`` (:func:`entity_keys`)."""
    return entity_keys(pairs, n_points)


def boundary_facets(cells: np.ndarray, local: np.ndarray = TRIANGLE.facets) -> np.ndarray:
    """Facets ``(n_boundary, k)`` that belong to exactly one cell, in their cell's local
    order ``local`` (for positively oriented cells: counter-clockwise edges of triangles,
    outward faces of tetrahedra).

    Parameters
    ----------
    cells : (n_cells, n_vertices) int array
        Positively oriented cells.
    local : (n_facets, k) int array
        The reference cell's facets, e.g. :attr:`TRIANGLE.facets`.
    """
    cells = np.asarray(cells, dtype=np.int64)
    tuples = cells[:, local].reshape(-1, local.shape[1])
    n = int(cells.max()) + 1 if cells.size else 0
    _, first, counts = np.unique(entity_keys(tuples, n), return_index=True, return_counts=True)
    return tuples[first[counts == 1]]


def entity_topology(
    cells: np.ndarray, n_points: int, local: np.ndarray, *, facets: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The entities of ``cells`` whose local vertices are the rows of ``local``: ``entities
    (n, k)`` (sorted vertices, numbered by :func:`entity_keys`), ``cell2entity (n_cells,
    n_local)`` (the entity of local entity ``j``) and, for facets, ``entity2cell (n, 2)``
    (column 0 the first cell seen, column 1 the other or ``-1``; ``None`` for entities of
    lower dimension, which may have any number of cells); read-only.

    Raises
    ------
    MeshError
        If a facet is shared by more than two cells.
    """
    tuples = cells[:, local].reshape(-1, local.shape[1])
    uniq, first, inverse, counts = np.unique(
        entity_keys(tuples, n_points), return_index=True, return_inverse=True, return_counts=True
    )
    if facets and counts.max(initial=0) > 2:
        bad = np.flatnonzero(counts > 2)
        what = "edge" if local.shape[1] == 2 else "face"
        raise MeshError(
            f"non-manifold mesh: {bad.size} {what}(s) shared by more than two cells, first "
            f"{tuple(int(v) for v in tuples[first[bad[0]]])}"
        )
    entities = np.sort(tuples[first], axis=1)
    cell2entity = inverse.reshape(-1, local.shape[0])
    if not facets:
        return _frozen(entities), _frozen(cell2entity), None
    owner = np.repeat(np.arange(cells.shape[0], dtype=np.int64), local.shape[0])
    entity2cell = np.full((uniq.size, 2), -1, dtype=np.int64)
    entity2cell[:, 0] = owner[first]
    second = np.ones(inverse.size, dtype=bool)
    second[first] = False
    entity2cell[inverse[second], 1] = owner[second]
    return _frozen(entities), _frozen(cell2entity), _frozen(entity2cell)


def facet_local(cell2facet: np.ndarray, facet2cell: np.ndarray) -> np.ndarray:
    """``(n_facets, 2)`` local index of each facet in its cells ``facet2cell[:, 0]`` and
    ``facet2cell[:, 1]`` (``-1`` outside the domain): ``cell2facet[facet2cell[f, s],
    facet_local[f, s]] == f``; read-only."""
    n_cells, n_local = cell2facet.shape
    cells = np.repeat(np.arange(n_cells), n_local)
    k = np.tile(np.arange(n_local), n_cells)
    f = cell2facet.ravel()
    slot = (facet2cell[f, 0] != cells).astype(np.int64)
    out = np.full(facet2cell.shape, -1, dtype=np.int64)
    out[f, slot] = k
    return _frozen(out)


def rows_of(entities: np.ndarray, tuples: np.ndarray, n_points: int) -> np.ndarray:
    """The row of ``entities (n, k)`` (sorted by key, as :func:`entity_topology` makes them)
    of each vertex set ``tuples (m, k)``, in any vertex order; read-only.

    Raises
    ------
    MeshError
        Naming the rows of ``tuples`` that are not entities.
    """
    keys, k = common_keys([entities, tuples], n_points)  # keys sorted by construction
    pos = np.minimum(np.searchsorted(keys, k), keys.size - 1)
    if keys.size == 0 or not np.array_equal(keys[pos], k):
        bad = np.flatnonzero(keys[pos] != k)
        what = "edge" if tuples.shape[1] == 2 else "face"
        raise MeshError(f"boundary {what}(s) {format_indices(bad)} are not {what}s of the mesh")
    return _frozen(pos)


def longest_edge_first(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Rotate each cell's vertices cyclically so that local edge 0 is its longest edge (the
    rotation by ``k`` makes local edge ``k`` of :data:`TRIANGLE` local edge 0)."""
    p = points[cells]
    start, end = TRIANGLE.edges.T
    length2 = ((p[:, end] - p[:, start]) ** 2).sum(-1)  # local edge k
    k = np.argmax(length2, axis=1)
    rows = np.arange(len(cells))[:, None]
    return cells[rows, (k[:, None] + np.arange(3)[None, :]) % 3]
