"""The interface of a sparse SPD direct solver that keeps its symbolic analysis.

PDAS solves one linear system per iteration, and all of them have the *same* sparsity pattern
(:mod:`.elimination`). A sparse direct solver can therefore do its symbolic analysis
(fill-reducing ordering, elimination tree, storage of the factor) once and only repeat the
numerical factorization. :class:`SPDSolver` checks the matrix, detects pattern changes, counts
and times the phases; a backend (:mod:`.superlu`, :mod:`.pardiso`) supplies three hooks:
``_analyze``, ``_factorize``, ``_solve``.

Callers that solve many systems (one per active set iteration, one sequence per mesh) do not
make solvers themselves: they ask a *solver factory* (:class:`SolverFactory`), a callable
that takes a :class:`SolverRequest` (symmetric or not, check the symmetry or not, a
fill-reducing ordering on demand) and returns a new :class:`SPDSolver`. A backend module
supplies one (:func:`~.pardiso.pardiso_solver`, :func:`~.superlu.superlu_solver`); the
registry of :mod:`.selection` names them for the command line.
"""

from __future__ import annotations

import time
from concurrent.futures import Future

import numpy as np
import scipy.sparse as sp

from ..sparse import as_csr, csr_row_indices, diagonal_positions, list_indices, symmetry_defect
from . import beside as background
from .requests import SolverFactory, SolverRequest

__all__ = [
    "SPDSolver",
    "SolverFactory",
    "SolverRequest",
    "checked_ordering",
    "solver_usage",
]


class SPDSolver:
    """Factorization of a sparse symmetric positive definite matrix with a fixed pattern.

    :meth:`factorize` compares the pattern of the new matrix with the last one; only when it
    differs is the symbolic analysis redone. The counters and timers below accumulate over the
    life of the object.

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n), optional
        Factorized right away if given.
    check_symmetry : bool
        Check ``max |A - A^T| <= 1e-12 max |A|`` at each analysis (costs one transpose).
    ordering : (n,) int array, optional
        A fill-reducing ordering for the symbolic analysis: ``ordering[k]`` is the unknown
        eliminated k-th (new position → original index), e.g. a nested dissection of the mesh's
        vertex graph (docs/method.md, *Ordering of the unknowns*). Checked and used at each
        analysis (it may be set as an attribute before one); ``None`` lets the backend order
        (PARDISO: METIS nested dissection of the matrix graph; SuperLU: minimum degree).

    Attributes
    ----------
    backend : str
        ``"pardiso"`` or ``"scipy"``.
    reuses_analysis : bool
        Whether a refactorization with the same pattern skips the symbolic analysis.
    n_analyses, n_factorizations, n_solves : int
        Symbolic analyses, numerical factorizations and solve calls (one per call, whatever the
        number of right-hand sides).
    time_analysis, time_factorization, time_solve : float
        Seconds spent in each phase (wall clock).
    analysis_reads_values : bool
        Whether the symbolic analysis reads the matrix's values (scaling, matching); where it
        does not, :meth:`analyze` may run beside the caller.
    rtol : float or None
        An iterative solver's tolerance: its solves stop at ``‖b − A x‖₂ ≤ rtol ‖b‖₂``, and
        the active set methods then follow the inexact stopping rule of :mod:`.inexact`
        (they may change it for a confirming solve). None (every direct backend): exact to
        round-off.
    takes_guess : bool
        Whether :meth:`start_from` sets the initial iterate of the next solve (an iterative
        solver's warm start); a direct solver ignores it.
    """

    backend: str = ""
    reuses_analysis: bool = False
    rtol: float | None = None
    analysis_reads_values: bool = True
    takes_guess: bool = False

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
    ) -> None:
        self.check_symmetry = check_symmetry
        self.ordering = ordering
        self._perm: np.ndarray | None = None  # the checked ordering of the last analysis
        self.n_analyses = 0
        self.n_factorizations = 0
        self.n_solves = 0
        self.time_analysis = 0.0
        self.time_factorization = 0.0
        self.time_solve = 0.0
        self._indptr: np.ndarray | None = None
        self._indices: np.ndarray | None = None
        self._matrix: sp.csr_matrix | None = None  # the matrix of the last factorize()
        self._n = 0
        self._factorized = False
        self._ahead: Future | None = None  # an analysis running beside the caller (analyze)
        if A is not None:
            self.factorize(A)

    # -- bookkeeping ------------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Size of the analysed matrix (0 before the first factorization)."""
        return self._n

    def same_pattern(self, A: sp.csr_matrix) -> bool:
        """Whether canonical CSR ``A`` has the pattern of the last analysis."""
        if self._indptr is None or A.shape != (self._n, self._n):
            return False
        if A.nnz != self._indices.size:
            return False
        same_ptr = A.indptr is self._indptr or np.array_equal(A.indptr, self._indptr)
        return same_ptr and (A.indices is self._indices or np.array_equal(A.indices, self._indices))

    # -- public interface -------------------------------------------------------------------
    def factorize(self, A: sp.spmatrix, keep: np.ndarray | None = None) -> None:
        """Factorize ``A``, reusing the symbolic analysis when the pattern is unchanged.

        Parameters
        ----------
        A : scipy sparse matrix, shape (n, n)
            Symmetric positive definite, both triangles stored (an explicitly stored zero is
            part of the pattern).
        keep : (A.nnz,) bool array, optional
            Factorize ``A`` with the stored entries where ``keep`` is False taken as zero
            (same pattern), e.g. :meth:`SymmetricEliminator.keep_mask`. Lets a backend
            gather only what it needs instead of copying the whole matrix.

        Raises
        ------
        ValueError
            If ``A`` is not a square finite sparse matrix, not symmetric, or misses a diagonal
            entry.
        FactorizationError
            If the matrix is singular or not positive definite.
        """
        A = as_csr(A)
        self._wait()
        if not self.same_pattern(A):
            self._counted(self._analysis(A))
        if keep is not None:
            keep = np.asarray(keep)
            if keep.dtype != np.bool_ or keep.shape != (A.nnz,):
                raise ValueError(f"keep must be a boolean mask of shape ({A.nnz},)")
        self._matrix = A
        self._numeric(keep)

    def analyze(self, A: sp.spmatrix, *, beside: bool = False) -> None:
        """The symbolic analysis of ``A``'s pattern now, ahead of :meth:`factorize`, which
        reuses it for a matrix of that pattern (``A`` checked as there; its values are not
        read where :attr:`analysis_reads_values` is False, and may be written until then).

        With ``beside`` (and :attr:`analysis_reads_values` False) the analysis runs in a
        background (:func:`~.beside.beside`), beside the caller's work; the next
        :meth:`factorize` or :meth:`close` waits for it and raises its error, if any.
        """
        A = as_csr(A)
        self._wait()
        if self.same_pattern(A):
            return
        if beside and not self.analysis_reads_values:
            self._ahead = background.beside(self._analysis, A)
        else:
            self._counted(self._analysis(A))

    def _analysis(self, A: sp.csr_matrix) -> float:
        """Check a new pattern, analyse it, and remember it; the seconds of the analysis."""
        rows = csr_row_indices(A)
        self._check_new_pattern(A, rows)
        self._perm = checked_ordering(self.ordering, A.shape[0])
        self._factorized = False
        t0 = time.perf_counter()
        self._analyze(A, rows)
        seconds = time.perf_counter() - t0
        del rows  # 4 bytes per stored entry, not needed by the factorization's peak
        self._n = A.shape[0]
        self._indptr = A.indptr.copy()
        self._indices = A.indices  # a reference: patterns are not modified in place
        return seconds

    def _counted(self, seconds: float) -> None:
        """Count an analysis of ``seconds``: when it is done, or when the factorization that
        uses it waits for it (an analysis beside the caller belongs to the call that uses it,
        for the counters a caller differences, :func:`solver_usage`)."""
        self.n_analyses += 1
        self.time_analysis += seconds

    def _wait(self) -> None:
        """Wait for an analysis started by :meth:`analyze` beside the caller, if any."""
        ahead, self._ahead = self._ahead, None
        if ahead is not None:
            self._counted(ahead.result())

    def refactorize(self, keep: np.ndarray) -> None:
        """Factorize the matrix of the last :meth:`factorize` again, with another ``keep``.

        The matrix and its pattern were checked by :meth:`factorize` and are not checked again,
        nor is ``keep``: this is the step an active set iteration repeats.

        Parameters
        ----------
        keep : (nnz,) bool array
            As in :meth:`factorize`.
        """
        if self._matrix is None:
            raise RuntimeError("refactorize() called before factorize()")
        self._numeric(keep)

    def _check_new_pattern(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        """Reject an empty matrix, a missing diagonal entry and (if asked) an unsymmetric one."""
        if A.shape[0] == 0:
            raise ValueError("A is empty (shape (0, 0))")
        missing = np.flatnonzero(diagonal_positions(A, rows) < 0)
        if missing.size:
            raise ValueError(
                f"A must store every diagonal entry; rows {list_indices(missing)} have none"
            )
        if self.check_symmetry:
            defect = symmetry_defect(A)
            if defect > 1e-12:
                raise ValueError(f"A is not symmetric: max|A - A^T| / max|A| = {defect:.3e}")

    def _numeric(self, keep: np.ndarray | None) -> None:
        """The numerical factorization of the current matrix, counted and timed."""
        self._factorized = False
        t0 = time.perf_counter()
        self._factorize(self._matrix, keep)
        self.time_factorization += time.perf_counter() - t0
        self.n_factorizations += 1
        self._factorized = True

    def solve(self, b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` with the current factorization.

        Parameters
        ----------
        b : (n,) or (n, k) float array

        Returns
        -------
        x : float array, same shape as ``b``
        """
        if not self._factorized:
            raise RuntimeError("solve() called before a successful factorize()")
        b = np.asarray(b, dtype=np.float64)
        if b.ndim not in (1, 2) or b.shape[0] != self._n:
            raise ValueError(f"b must have shape ({self._n},) or ({self._n}, k), got {b.shape}")
        if not np.isfinite(b).all():
            raise ValueError("b has non-finite (NaN or inf) entries")
        if b.ndim == 2 and b.shape[1] == 0:
            return np.zeros_like(b)
        t0 = time.perf_counter()
        x = self._solve(b)
        self.time_solve += time.perf_counter() - t0
        self.n_solves += 1
        return x

    def start_from(self, x: np.ndarray) -> None:
        """Start the next solve (of one right-hand side) from the iterate ``x (n,)`` instead
        of zero, where :attr:`takes_guess` (an iterative solver: the active set methods hand
        over the previous step's solution, the warm start in the first step; docs/method.md,
        *Three dimensions: warm-started CG*); a direct solver ignores it. The solve's
        stopping test is unchanged, so its answer is as accurate as from zero.

        Raises
        ------
        ValueError
            For an ``x`` of the wrong shape or with non-finite entries (where it is taken).
        """
        if not self.takes_guess:
            return
        x = np.array(x, dtype=np.float64)
        if x.shape != (self.n,) or not np.isfinite(x).all():
            raise ValueError(f"x must be a finite ({self.n},) array, got shape {x.shape}")
        self._guess = x

    def close(self) -> None:
        """Release the factorization (the object can factorize again afterwards)."""
        ahead, self._ahead = self._ahead, None
        if ahead is not None:  # wait for it; its error, if any, concerns no one now
            ahead.exception()
        self._factorized = False
        self._indptr = self._indices = self._matrix = None

    def __enter__(self) -> SPDSolver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(n={self._n}, analyses={self.n_analyses}, "
            f"factorizations={self.n_factorizations}, solves={self.n_solves})"
        )

    # -- backend hooks ----------------------------------------------------------------------
    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:  # pragma: no cover
        raise NotImplementedError

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:  # pragma: no cover
        raise NotImplementedError

    def _solve(self, b: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


def checked_ordering(ordering: object, n: int) -> np.ndarray | None:
    """``ordering`` as an int64 permutation of ``0 … n−1``, or None; a ValueError naming
    ``ordering`` otherwise."""
    if ordering is None:
        return None
    perm = np.asarray(ordering)
    if perm.shape != (n,) or not np.issubdtype(perm.dtype, np.integer):
        raise ValueError(
            f"ordering must be an integer array of shape ({n},) (one entry per unknown), got "
            f"dtype {perm.dtype} and shape {perm.shape}"
        )
    perm = perm.astype(np.int64)
    outside = np.flatnonzero((perm < 0) | (perm >= n))
    if outside.size:
        raise ValueError(
            f"ordering has entries outside 0..{n - 1} at positions {list_indices(outside)}"
        )
    seen = np.zeros(n, dtype=bool)
    seen[perm] = True
    if not seen.all():
        raise ValueError(
            f"ordering is not a permutation: unknowns {list_indices(np.flatnonzero(~seen))} "
            "never appear"
        )
    return perm


def solver_usage(solver: SPDSolver) -> dict[str, float]:
    """The solver's counters and timers (seconds), to be differenced around a call."""
    return {
        "n_solves": solver.n_solves,
        "n_factorizations": solver.n_factorizations,
        "n_analyses": solver.n_analyses,
        "analysis": solver.time_analysis,
        "factorization": solver.time_factorization,
        "solve": solver.time_solve,
    }
