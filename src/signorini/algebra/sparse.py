"""Helpers on sparse matrices in canonical CSR form: checks, row indices, triangles, diagonals.

Every function here takes a square matrix and knows nothing of where it came from; the
solvers (:mod:`.solvers`, :mod:`.pardiso`), the symmetric elimination (:mod:`.elimination`)
and the node rotations of :mod:`signorini.contact.node_frames` build on them.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .ranks import SERIAL, Ranks

__all__ = [
    "abs_matvec",
    "as_csr",
    "block_upper_positions",
    "csr_row_indices",
    "concatenated_ranges",
    "diagonal_positions",
    "in_node_blocks",
    "list_indices",
    "STIFFNESS_RANGE",
    "stiffness_unit",
    "symmetry_defect",
    "upper_positions",
]


def as_csr(A: object, name: str = "A") -> sp.csr_matrix:
    """Check a square float64 sparse matrix and return it in canonical CSR form.

    A matrix that already is canonical float64 CSR is returned as it is (no copy), so its
    index arrays keep their identity and pattern comparisons stay cheap.

    Parameters
    ----------
    A : scipy sparse matrix or array, shape (n, n)
    name : str
        Name used in error messages.

    Returns
    -------
    scipy.sparse.csr_matrix
        Sorted indices, no duplicates, float64 values.

    Raises
    ------
    ValueError
        If ``A`` is not sparse, not square, or has non-finite values.
    """
    if not sp.issparse(A):
        raise ValueError(f"{name} must be a scipy sparse matrix, got {type(A).__name__}")
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{name} must be square, got shape {A.shape}")
    if A.dtype != np.float64:
        if not (np.issubdtype(A.dtype, np.floating) or np.issubdtype(A.dtype, np.integer)):
            raise ValueError(f"{name} must have real values, got dtype {A.dtype}")
        A = A.astype(np.float64)
    if not (isinstance(A, sp.csr_matrix) and A.has_canonical_format):
        A = sp.csr_matrix(A)
        A.sum_duplicates()
    if not np.isfinite(A.data).all():
        raise ValueError(f"{name} has non-finite (NaN or inf) entries")
    return A


def csr_row_indices(A: sp.csr_matrix) -> np.ndarray:
    """Row index of every stored entry of a CSR matrix.

    Parameters
    ----------
    A : scipy.sparse.csr_matrix, shape (n, n)

    Returns
    -------
    rows : (A.nnz,) int32 (int64 for n ≥ 2³¹) array
        ``rows[p]`` is the row of ``A.data[p]`` (the companion of ``A.indices``).
    """
    n = A.shape[0]
    dtype = np.int32 if n < np.iinfo(np.int32).max else np.int64
    return np.repeat(np.arange(n, dtype=dtype), np.diff(A.indptr))


def concatenated_ranges(start: np.ndarray, length: np.ndarray) -> np.ndarray:
    """``start[i] + j`` for ``j < length[i]``, range after range: e.g. the positions of the
    stored entries of some rows of a CSR matrix (``start = indptr[rows]``)."""
    return np.repeat(start - (np.cumsum(length) - length), length) + np.arange(length.sum())


def upper_positions(A: sp.csr_matrix, rows: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """Positions in ``A.data`` of the upper triangle (with diagonal) and its CSR ``indptr``."""
    if rows is None:
        rows = csr_row_indices(A)
    upper = A.indices >= rows
    positions = np.flatnonzero(upper)
    if A.nnz < np.iinfo(np.int32).max:
        positions = positions.astype(np.int32)
    indptr = np.zeros(A.shape[0] + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows[positions], minlength=A.shape[0]), out=indptr[1:])
    return positions, indptr


def _node_block_starts(
    indptr: np.ndarray, indices: np.ndarray, rows: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Where the rows ``indptr, indices`` (CSR, an even number of them, from an even row)
    store full 2 x 2 blocks: each block's first entry in row ``2z`` and in row ``2z + 1``,
    and each entry's row; else None."""
    length = np.diff(indptr)
    if length.size % 2 or np.any(length % 2) or not np.array_equal(length[0::2], length[1::2]):
        return None
    first, second = indices[0::2], indices[1::2]  # each row starts at an even position: pairs
    if np.any(first % 2) or not np.array_equal(second, first + 1):
        return None
    if rows is None:
        rows = np.repeat(np.arange(length.size, dtype=np.int64), length)
    starts = 2 * np.flatnonzero(rows[0::2] % 2 == 0)  # a block's first entry in row 2z
    below = starts + length[rows[starts]]  # the same block's first entry in row 2z + 1
    if not np.array_equal(indices[below], indices[starts]):
        return None
    return starts, below, rows


def in_node_blocks(indptr: np.ndarray, indices: np.ndarray) -> bool:
    """Whether CSR rows (an even number of them, the first an even row of the whole
    matrix, e.g. one process's rows) store every entry in a fully stored 2 x 2 block of rows
    ``2z, 2z + 1`` and columns ``2w, 2w + 1`` (docs/method.md, *Block Cholesky*)."""
    return _node_block_starts(indptr, indices) is not None


def block_upper_positions(
    A: sp.csr_matrix, rows: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The upper block triangle of ``A`` in 2 x 2 blocks (block sparse rows, BSR), where ``A``
    stores them: ``None`` unless every stored entry lies in a fully stored block of rows
    ``2z, 2z + 1`` and columns ``2w, 2w + 1`` (the node blocks of a stiffness matrix
    assembled by :mod:`signorini.fem.stiffness`, docs/method.md, *Block Cholesky*).

    Parameters
    ----------
    A : scipy.sparse.csr_matrix, shape (n, n)
        Canonical (sorted indices).
    rows : (A.nnz,) int array, optional
        :func:`csr_row_indices` of ``A``, if known.

    Returns
    -------
    positions : (4 m,) int32 (int64 for nnz ≥ 2³¹) array
        Positions in ``A.data`` of the ``m`` blocks ``(z, w)`` with ``w ≥ z``, block after
        block in block-row order, each row by row: ``(2z, 2w), (2z, 2w + 1), (2z + 1, 2w),
        (2z + 1, 2w + 1)``.
    indptr : (n / 2 + 1,) int64 array
        The blocks' rows in CSR form.
    columns : (m,) int array
        Each block's column ``w``.
    """
    n = A.shape[0]
    if n % 2 or A.nnz == 0:
        return None
    found = _node_block_starts(A.indptr, A.indices, rows)
    if found is None:
        return None
    starts, below, rows = found
    upper = A.indices[starts] >= rows[starts]
    p = starts[upper]
    q = below[upper]
    del starts, below, upper
    dtype = np.int32 if A.nnz < np.iinfo(np.int32).max else np.int64
    positions = np.empty((p.size, 4), dtype=dtype)
    positions[:, 0] = p
    positions[:, 1] = p + 1
    positions[:, 2] = q
    positions[:, 3] = q + 1
    indptr = np.zeros(n // 2 + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows[p] // 2, minlength=n // 2), out=indptr[1:])
    return positions.reshape(-1), indptr, A.indices[p] // 2


def diagonal_positions(A: sp.csr_matrix, rows: np.ndarray) -> np.ndarray:
    """Position in ``A.data`` of each diagonal entry, ``-1`` where it is not stored."""
    pos = np.full(A.shape[0], -1, dtype=np.int64)
    on_diag = np.flatnonzero(A.indices == rows)
    pos[rows[on_diag]] = on_diag
    return pos


def abs_matvec(A: sp.csr_matrix, v: np.ndarray, chunk: int = 1 << 20) -> np.ndarray:
    """``|A| |v|`` (entrywise absolute values) without a copy of ``|A.data|``.

    Rows are taken in blocks of about ``chunk`` stored entries, whose absolute values go
    through one reused buffer: at 1.2 M unknowns (46 M entries) the copy of ``|A.data|`` took
    0.5 s, most of it writing fresh memory.

    Parameters
    ----------
    A : scipy.sparse.csr_matrix, shape (n, m)
    v : (m,) float array

    Returns
    -------
    (n,) float array
    """
    n = A.shape[0]
    av = np.abs(v)
    out = np.zeros(n)
    buffer = np.empty(min(chunk, A.nnz))
    indptr = A.indptr
    # row boundaries of the blocks: the first row that starts at or after each multiple of chunk
    cuts = np.unique(np.searchsorted(indptr, np.arange(0, A.nnz, chunk), side="left"))
    bounds = np.append(cuts[cuts < n], n)
    # a few dozen blocks: not a loop over rows
    for r0, r1 in zip(bounds[:-1], bounds[1:], strict=True):
        s, e = indptr[r0], indptr[r1]
        block = buffer[: e - s] if e - s <= buffer.size else np.empty(e - s)
        np.abs(A.data[s:e], out=block)
        part = sp.csr_matrix(
            (block, A.indices[s:e], indptr[r0 : r1 + 1] - s), shape=(r1 - r0, A.shape[1])
        )
        out[r0:r1] = part @ av
    return out


def list_indices(indices: np.ndarray, limit: int = 5) -> str:
    """The first ``limit`` of ``indices`` as text, for error messages."""
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    return shown + (f" (and {indices.size - limit} more)" if indices.size > limit else "")


def symmetry_defect(A: sp.csr_matrix) -> float:
    """``max |A - A^T| / max |A|`` (0 for an empty matrix)."""
    scale = float(np.abs(A.data).max()) if A.nnz else 0.0
    if scale == 0.0:
        return 0.0
    D = A - A.T
    return float(np.abs(D.data).max()) / scale if D.nnz else 0.0


#: a stiffness matrix whose largest diagonal entry lies in this range is solved as it is;
#: outside it (E beyond about 1e±77) K and F are divided by a power of 2 first
STIFFNESS_RANGE = (2.0**-256, 2.0**256)


def stiffness_unit(K, ranks: Ranks = SERIAL) -> float:
    """1 if ``max |diag K|`` lies in ``STIFFNESS_RANGE`` (or is 0), else the power of 2
    not above it. Dividing K and F by it is exact, so u_h is the same; it keeps sums over
    K (the active set rule's constant c = mean diag K, the force scales of the KKT check)
    and the factorization's products away from overflow and underflow when E is extreme.
    ``ranks``: those that split ``K`` by rows (the same unit on every rank)."""
    d = ranks.max(float(np.abs(K.diagonal()).max(initial=0.0)))
    lo, hi = STIFFNESS_RANGE
    if d == 0.0 or not np.isfinite(d) or lo <= d <= hi:
        return 1.0
    return float(np.ldexp(1.0, int(np.floor(np.log2(d)))))
