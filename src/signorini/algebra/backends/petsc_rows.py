"""The rows a process hands PETSc, for the PETSc backends (:mod:`.petsc`, :mod:`.petsc_gamg`).

Each process passes a scipy CSR matrix that is either

- *whole*, the same on every process (a user's script): PETSc's rows are split in contiguous
  blocks (:meth:`PetscRows._whole_rows`; :func:`row_block` as PETSc splits them);
- or *split by rows* (:mod:`.ranks`; what ``assemble`` builds on a rank of several): each
  process's matrix holds its own rows, the other rows empty, and the matrix is the sum of
  the processes' copies. PETSc needs each process's rows contiguous, so its numbering is a
  permutation of the unknowns (computed once per pattern): process 0's rows first, then
  process 1's, … (:attr:`PetscRows.split`).

:class:`PetscRows` tells them apart by counting the non-empty rows over the processes (at each
new pattern, collectively): ``n`` on every process is whole, ``n`` in total is split, anything
else is refused. It computes PETSc's numbering, this process's rows of it as local CSR arrays
with the positions of their values in ``A.data``, and maps replicated vectors in the caller's
numbering to PETSc's rows and back (docs/parallel.md, *A stiffness matrix split by rows*).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import FactorizationError
from ..ranks import SERIAL, Ranks, world_ranks
from ..sparse import diagonal_positions, list_indices
from .petsc_import import petsc_module
from .solvers import SPDSolver

__all__ = ["PetscRows", "row_block"]


def row_block(n: int, rank: int, size: int) -> tuple[int, int]:
    """The rows ``[start, end)`` that process ``rank`` of ``size`` owns in an ``n``-row
    matrix: contiguous blocks, the first ``n % size`` one row longer (PETSc's
    ``PetscSplitOwnership``)."""
    base, extra = divmod(n, size)
    start = rank * base + min(rank, extra)
    return start, start + base + (rank < extra)


class PetscRows(SPDSolver):
    """An :class:`~.solvers.SPDSolver` whose matrix PETSc holds by rows on
    ``PETSC_COMM_WORLD``, whole or split by rows over the processes (module docstring).

    A backend calls :meth:`_rows` in its analysis, writes :meth:`_values` into the PETSc
    matrix at each factorization, sets right-hand sides from :meth:`_local_entries` and maps
    gathered solutions back with :meth:`_caller_order`.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given: whole on every process, or split by rows over them.
    check_symmetry : bool
        As in :class:`~.solvers.SPDSolver` (for a split matrix: on the values, at the first
        factorization, by PETSc).
    ordering : (n,) int array, optional
        As in :class:`~.solvers.SPDSolver`; PETSc's numbering follows it where the backend
        says so (:meth:`_row_ordering`).

    Attributes
    ----------
    split : bool
        Whether the last analysed matrix was split by rows over the processes (else whole
        on every process).
    comm_size : int
        Processes of ``PETSC_COMM_WORLD`` sharing the matrix's rows.

    Raises
    ------
    BackendUnavailableError
        If petsc4py (or, for the ``"petsc"`` backend, MUMPS) is missing.
    """

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
    ) -> None:
        self._PETSc = petsc_module()
        comm = self._PETSc.COMM_WORLD
        self.comm_size = comm.getSize()
        self._rank = comm.getRank()
        self._ranks: Ranks = SERIAL if self.comm_size == 1 else world_ranks()
        self.split = False
        self._order: np.ndarray | None = None
        self._own: np.ndarray | slice = slice(0, 0)
        self._mat = None
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    # -- hooks of the backends ---------------------------------------------------------------
    def _whole_rows(self, n: int) -> tuple[int, int]:
        """This process's block ``[lo, hi)`` of a whole matrix's rows (in PETSc's numbering)."""
        return row_block(n, self._rank, self.comm_size)

    def _row_ordering(self) -> np.ndarray | None:
        """The order PETSc's numbering follows (within each process's rows when split); the
        checked ordering by default."""
        return self._perm

    # -- collective decisions ----------------------------------------------------------------
    def _everywhere(self, flag: bool) -> bool:
        """Whether ``flag`` holds on every process (collective on several)."""
        if self.comm_size == 1:
            return flag
        return self._ranks.max(0.0 if flag else 1.0) == 0.0

    def same_pattern(self, A: sp.csr_matrix) -> bool:
        """Whether ``A`` has the pattern of the last analysis on every rank (collective: the
        ranks analyse together or not at all)."""
        return self._everywhere(super().same_pattern(A))

    def _check_new_pattern(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        """Decide whether ``A`` is whole on every rank or split by rows over the ranks
        (:attr:`split`), and check it (collective; every rank raises the same error)."""
        n = A.shape[0]
        owned = np.diff(A.indptr) > 0
        counts = self._ranks.gather(np.array([np.count_nonzero(owned)]))
        self.split = self.comm_size > 1 and n > 0 and not (counts == n).all()
        if not self.split:
            super()._check_new_pattern(A, rows)
            return
        if counts.sum() != n:
            raise ValueError(
                f"A must be whole on every rank or split by rows over the {self.comm_size} "
                f"ranks, each row on one: the ranks store {counts.tolist()} non-empty rows of {n}"
            )
        here = np.flatnonzero(owned)
        missing = np.sort(self._ranks.gather(here[diagonal_positions(A, rows)[here] < 0]))
        if missing.size:
            raise ValueError(
                f"A must store every diagonal entry; rows {list_indices(missing)} have none"
            )
        self._symmetry_pending = self.check_symmetry  # on the values, at the factorization

    # -- PETSc's numbering and this process's rows -------------------------------------------
    def _numbering(self, A: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
        """PETSc's numbering of the unknowns: ``order`` (its row ``k`` is ``A``'s row
        ``order[k]``) and this rank's rows in it.

        A whole matrix: contiguous blocks of rows (:meth:`_whole_rows`), in the order of
        :meth:`_row_ordering` if there is one. A split one: the ranks' own (non-empty) rows in
        rank order, each rank's in the order of :meth:`_row_ordering`, else increasing. Raises
        a :class:`ValueError` if a row is on no rank or on several (collective).
        """
        n = A.shape[0]
        perm = self._row_ordering()
        if not self.split:
            order = np.arange(n) if perm is None else perm
            lo, hi = self._whole_rows(n)
            return order, order[lo:hi]
        own = np.flatnonzero(np.diff(A.indptr) > 0)
        if perm is not None:
            position = np.empty(n, dtype=np.int64)
            position[perm] = np.arange(n)
            own = own[np.argsort(position[own], kind="stable")]
        order = self._ranks.gather(own)
        seen = np.bincount(order, minlength=n)
        if (seen != 1).any():
            wrong = np.flatnonzero(seen != 1)
            raise ValueError(f"A's rows {list_indices(wrong)} are on no rank or on several")
        return order, own

    def _rows(self, A: sp.csr_matrix) -> np.ndarray:
        """Compute PETSc's numbering of ``A`` (:attr:`_order`: None for the identity) and
        this rank's rows of it as local CSR arrays (:meth:`_local`); return those rows
        (``A``'s indices, in PETSc's order)."""
        n = A.shape[0]
        order, own = self._numbering(A)
        identity = not self.split and self._row_ordering() is None
        to_petsc = None
        if not identity:
            to_petsc = np.empty(n, dtype=np.int64)
            to_petsc[order] = np.arange(n)
        self._local(A, own, to_petsc)
        self._order = None if identity else order
        return own

    def _local(self, A: sp.csr_matrix, own: np.ndarray, to_petsc: np.ndarray | None) -> None:
        """This rank's rows ``own`` of ``A`` as PETSc's local CSR arrays (``self._csr``) and
        the positions in ``A.data`` of their values (``self._src``; a slice ``(first, last)``
        when ``own`` is a contiguous block in ``A``'s numbering, as in the whole-matrix case
        without an ordering)."""
        int_type = self._PETSc.IntType
        if to_petsc is None:  # rows lo..hi of A as they are
            lo, hi = (int(own[0]), int(own[-1]) + 1) if own.size else (0, 0)
            first, last = A.indptr[lo], A.indptr[hi]
            indptr = (A.indptr[lo : hi + 1] - first).astype(int_type)
            self._csr = (indptr, A.indices[first:last].astype(int_type))
            self._src, self._own = slice(first, last), slice(lo, hi)
            return
        starts = A.indptr[own]
        lengths = A.indptr[own + 1] - starts
        indptr = np.zeros(own.size + 1, dtype=np.int64)
        np.cumsum(lengths, out=indptr[1:])
        src = np.repeat(starts - indptr[:-1], lengths) + np.arange(indptr[-1])
        columns = to_petsc[A.indices[src]]
        by_row = np.lexsort((columns, np.repeat(np.arange(own.size), lengths)))
        self._csr = (indptr.astype(int_type), columns[by_row].astype(int_type))
        self._src, self._own = src[by_row], own

    def _values(self, A: sp.csr_matrix, keep: np.ndarray | None) -> np.ndarray:
        """The values of this rank's PETSc rows of ``A`` with the entries off ``keep``
        zeroed."""
        values = np.array(A.data[self._src], dtype=np.float64)
        if keep is not None:
            values *= keep[self._src]
        return values

    def _write_values(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        """Write ``A``'s values (the entries off ``keep`` zeroed) into the kept PETSc matrix
        and assemble it; a split matrix's symmetry is checked at its first factorization."""
        values = self._values(A, keep)
        self._mat.setValuesCSR(*self._csr, values)
        self._mat.assemble()
        if self.split and self._symmetry_pending:
            self._check_symmetry(values)

    def _set_up(self, failure: str) -> None:
        """Hand the written matrix to the KSP and set it up (MUMPS's factorization, GAMG's
        hierarchy); a PETSc error raises :class:`~.errors.FactorizationError` with the
        message ``failure`` formatted with its ``ierr``."""
        self._ksp.setOperators(self._mat)
        try:
            self._ksp.setUp()
        except self._PETSc.Error as err:
            raise FactorizationError(
                failure.format(ierr=err.ierr), backend=self.backend, code=int(err.ierr)
            ) from err

    def _local_entries(self, v: np.ndarray) -> np.ndarray:
        """This rank's entries of a replicated vector (or of the rows of an ``(n, k)``
        array) in the caller's numbering, in PETSc's order."""
        return np.ascontiguousarray(v[self._own])

    def _caller_order(self, gathered: np.ndarray, out: np.ndarray) -> None:
        """Write a vector gathered from PETSc (in its numbering) into ``out`` in the caller's
        numbering."""
        if self._order is None:
            out[...] = gathered
        else:
            out[self._order] = gathered

    def _check_symmetry(self, values: np.ndarray) -> None:
        """Refuse a split matrix that is not symmetric to ``1e-12 max |A|`` (as the serial
        check of :class:`~.solvers.SPDSolver`; PETSc compares it with its transpose)."""
        self._symmetry_pending = False
        scale = self._ranks.max(float(np.abs(values).max(initial=0.0)))
        if not self._mat.isSymmetric(1e-12 * scale):
            raise ValueError("A is not symmetric: max|A - A^T| > 1e-12 max|A|")
