"""Symmetric elimination of fixed DOFs that keeps the sparsity pattern (docs/method.md, *Solver*).

PDAS imposes the Dirichlet values and the active contact bounds as equalities by zeroing rows
and columns *in place* (the diagonal kept), never by removing entries, so every system of a
mesh has one pattern and a sparse direct solver analyses it once.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .ranks import SERIAL, Ranks, stored_values
from .sparse import as_csr, csr_row_indices, diagonal_positions, list_indices

__all__ = ["SymmetricEliminator", "eliminate_symmetric"]


class SymmetricEliminator:
    """Impose ``x[fixed] = x_fixed`` on ``A x = b`` symmetrically, keeping the sparsity pattern.

    The eliminated system has the rows *and* columns of the fixed DOFs zeroed except for the
    diagonal, which keeps its original value (so the scaling of the matrix stays sane), and the
    right-hand side ``b - A[:, fixed] @ x_fixed`` on free rows, ``diag * x_fixed`` on fixed rows.
    Its solution is ``x_fixed`` on the fixed DOFs and the solution of the reduced system
    ``A[free][:, free] y = b[free] - A[free][:, fixed] @ x_fixed`` on the free ones. Zeroed
    entries stay stored, so the pattern (and a solver's symbolic analysis) never changes.

    The row index of every stored entry and the positions of the diagonal are computed once in
    the constructor and reused by every :meth:`apply`.

    On a run of several ranks that split ``A`` by rows (:mod:`.ranks`), each rank masks the
    entries of its own rows (:meth:`keep_mask`), the products with ``A`` are summed over the
    ranks and the diagonal entries of the fixed rows are read on the rank that stores them.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n)
        Symmetric; converted to canonical CSR (sorted indices) if it is not.
    ranks : Ranks
        The ranks that share ``A`` by rows (default one process, a whole matrix).
    """

    def __init__(self, A: sp.spmatrix, ranks: Ranks = SERIAL) -> None:
        A = as_csr(A)
        self.ranks = ranks
        self.shape = A.shape
        self.indptr = A.indptr
        self.indices = A.indices
        rows = csr_row_indices(A)
        self.is_diagonal = self.indices == rows
        self.diagonal_positions = diagonal_positions(A, rows)
        self.row_lengths = np.diff(self.indptr)  # rows are expanded on demand: less memory

    @property
    def n(self) -> int:
        return self.shape[0]

    def matches(self, A: sp.csr_matrix) -> bool:
        """Whether ``A`` (canonical CSR) has exactly the stored pattern."""
        if A.shape != self.shape or A.nnz != self.indices.size:
            return False
        same_ptr = A.indptr is self.indptr or np.array_equal(A.indptr, self.indptr)
        return same_ptr and (A.indices is self.indices or np.array_equal(A.indices, self.indices))

    def apply(
        self,
        A: sp.spmatrix,
        b: np.ndarray,
        fixed: np.ndarray,
        x_fixed: np.ndarray | float,
        *,
        out: sp.csr_matrix | None = None,
    ) -> tuple[sp.csr_matrix, np.ndarray]:
        """Eliminate the fixed DOFs from ``A x = b``.

        Parameters
        ----------
        A : scipy sparse matrix, shape (n, n)
            Same pattern as the matrix given to the constructor.
        b : (n,) float array
        fixed : (n,) bool array
            DOFs whose value is imposed.
        x_fixed : float, (n,) or (n_fixed,) float array
            Imposed values: a full-length vector (only its ``fixed`` entries are read) or one
            value per fixed DOF, in increasing DOF order.
        out : scipy.sparse.csr_matrix, optional
            A matrix with the same pattern whose ``data`` is overwritten (no allocation).

        Returns
        -------
        A_elim : scipy.sparse.csr_matrix, shape (n, n)
            Shares ``indptr`` and ``indices`` with ``A``; new ``data`` (or ``out``).
        b_elim : (n,) float array

        Raises
        ------
        ValueError
            On shape mismatches, a different pattern, or a fixed DOF without stored diagonal.
        """
        A = as_csr(A)
        if not self.matches(A):
            raise ValueError("A does not have the sparsity pattern the eliminator was built for")
        n = self.n
        b = np.asarray(b, dtype=np.float64)
        if b.shape != (n,):
            raise ValueError(f"b must have shape ({n},), got {b.shape}")
        fixed = np.asarray(fixed)
        if fixed.dtype != np.bool_ or fixed.shape != (n,):
            raise ValueError(f"fixed must be a boolean mask of shape ({n},)")
        values = np.zeros(n)
        x_fixed = np.asarray(x_fixed, dtype=np.float64)
        n_fixed = int(fixed.sum())
        if x_fixed.ndim == 0:
            values[fixed] = x_fixed
        elif x_fixed.shape == (n,):
            values[fixed] = x_fixed[fixed]
        elif x_fixed.shape == (n_fixed,):
            values[fixed] = x_fixed
        else:
            raise ValueError(
                f"x_fixed must be a scalar or have shape ({n},) or ({n_fixed},), "
                f"got {x_fixed.shape}"
            )
        if not np.isfinite(values).all():
            raise ValueError("x_fixed has non-finite (NaN or inf) values")
        diag_pos = self.diagonal_positions[fixed]
        stored = self.ranks.sum((diag_pos >= 0).astype(np.int32))  # on one rank of several
        if (stored == 0).any():
            missing = np.flatnonzero(fixed)[stored == 0]
            raise ValueError(f"no stored diagonal entry in fixed rows {list_indices(missing)}")

        keep = self.keep_mask(fixed)
        if out is None:
            data = np.where(keep, A.data, 0.0)
            A_elim = sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)
        else:
            if not self.matches(out):
                raise ValueError("out does not have the sparsity pattern of A")
            np.multiply(A.data, keep, out=out.data)
            A_elim = out
        return A_elim, self._rhs(A, b, fixed, values, self.diagonal(A, diag_pos))

    def keep_mask(self, fixed: np.ndarray) -> np.ndarray:
        """``(nnz,)`` bool: the stored entries that survive the elimination of ``fixed``
        (neither in a fixed row nor in a fixed column, or on the diagonal)."""
        keep = np.repeat(fixed, self.row_lengths)  # fixed row of every stored entry
        keep |= fixed[self.indices]
        np.logical_not(keep, out=keep)
        keep |= self.is_diagonal
        return keep

    def diagonal(self, A: sp.csr_matrix, positions: np.ndarray | None = None) -> np.ndarray:
        """The diagonal entries of ``A`` (the constructor's pattern) at ``positions`` (some
        of :attr:`diagonal_positions`; default all), on every rank."""
        positions = self.diagonal_positions if positions is None else positions
        return stored_values(A.data, positions, self.ranks)

    def rhs(
        self,
        A: sp.csr_matrix,
        b: np.ndarray,
        fixed: np.ndarray,
        values: np.ndarray,
        diagonal: np.ndarray | None = None,
    ) -> np.ndarray:
        """Right-hand side of the eliminated system, for full-length ``values`` (read on
        ``fixed`` only, zero elsewhere); ``diagonal``: ``A``'s (:meth:`diagonal`), if known."""
        if diagonal is None:
            fixed_diagonal = self.diagonal(A, self.diagonal_positions[fixed])
        else:
            fixed_diagonal = diagonal[fixed]
        return self._rhs(A, b, fixed, values, fixed_diagonal)

    def _rhs(self, A, b, fixed, values, fixed_diagonal) -> np.ndarray:
        b_elim = b - self.ranks.sum(A @ np.where(fixed, values, 0.0))
        b_elim[fixed] = fixed_diagonal * values[fixed]
        return b_elim


def eliminate_symmetric(
    A: sp.spmatrix, b: np.ndarray, fixed: np.ndarray, x_fixed: np.ndarray | float
) -> tuple[sp.csr_matrix, np.ndarray]:
    """Impose ``x[fixed] = x_fixed`` symmetrically without changing the sparsity pattern.

    One-shot form of :meth:`SymmetricEliminator.apply`; see there for the details.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), symmetric
    b : (n,) float array
    fixed : (n,) bool array
    x_fixed : float, (n,) or (n_fixed,) float array

    Returns
    -------
    A_elim : scipy.sparse.csr_matrix, shape (n, n)
    b_elim : (n,) float array
    """
    return SymmetricEliminator(A).apply(A, b, fixed, x_fixed)
