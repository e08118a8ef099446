"""Sparse symmetric positive definite solvers that keep their symbolic analysis.

The active set solver (:mod:`signorini.pdas`) solves one linear system per iteration. Every
system has the *same* sparsity pattern: Dirichlet and active contact DOFs are eliminated
symmetrically by zeroing values (:func:`eliminate_symmetric`), never by removing entries. A
sparse direct solver can therefore do its symbolic analysis (fill-reducing ordering, elimination
tree, storage of the factor) once and only repeat the numerical factorization.

Backends
--------
``"pardiso"``
    Intel MKL PARDISO, reached through the shared library that the ``pypardiso`` package locates.
    Real symmetric positive definite mode (``mtype = 2``, sparse Cholesky) on the upper triangle
    in CSR form, with the phases called separately: 11 (analysis, once per pattern), 22
    (numerical factorization), 33 (solve).
``"scipy"``
    SuperLU (:func:`scipy.sparse.linalg.splu`) in symmetric mode with a minimum degree ordering
    of ``A + A^T`` and diagonal pivoting. SuperLU offers no split between the symbolic and the
    numerical phase, so every :meth:`SPDSolver.factorize` is a full factorization (the analysis
    counter still counts pattern changes). Reusing SuperLU's column ordering by permuting the
    matrix beforehand was measured and saves nothing: the ordering is a few per cent of the
    factorization time.

``make_solver("auto")`` takes ``"pardiso"`` when it loads and solves a small test system, and
``"scipy"`` otherwise; :attr:`SPDSolver.backend` tells which one was taken.
"""

from __future__ import annotations

import ctypes
import logging
import time
from collections.abc import Callable, Sequence
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = [
    "BACKENDS",
    "FactorizationError",
    "PardisoSolver",
    "SPDSolver",
    "SuperLUSolver",
    "SymmetricEliminator",
    "as_csr",
    "available_backends",
    "csr_row_indices",
    "eliminate_symmetric",
    "make_solver",
    "upper_triangle",
]

logger = logging.getLogger(__name__)

#: Names accepted by :func:`make_solver` besides ``"auto"``.
BACKENDS: tuple[str, ...] = ("pardiso", "scipy")


class FactorizationError(np.linalg.LinAlgError):
    """The matrix could not be factorized as symmetric positive definite.

    A subclass of :class:`numpy.linalg.LinAlgError` (itself a :class:`ValueError`).

    Attributes
    ----------
    backend : str
        The backend that failed.
    code : int or None
        The backend's error code (PARDISO's ``error``), if any.
    equation : int or None
        0-based index of the equation where a non-positive pivot was met, if known.
    """

    def __init__(
        self,
        message: str,
        *,
        backend: str = "",
        code: int | None = None,
        equation: int | None = None,
    ) -> None:
        super().__init__(message)
        self.backend = backend
        self.code = code
        self.equation = equation


# ----------------------------------------------------------------------------------------------
# CSR helpers
# ----------------------------------------------------------------------------------------------


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


def _upper_positions(A: sp.csr_matrix, rows: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
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


def upper_triangle(A: sp.spmatrix) -> sp.csr_matrix:
    """Upper triangle (diagonal included) of a square sparse matrix, in CSR form.

    A vectorized mask on the stored entries (``indices >= row``), which keeps explicitly stored
    zeros. On a 200 978 x 200 978 P2 elasticity matrix (4.6 M entries) it took 26 ms against
    35 ms for ``scipy.sparse.triu``; the solvers go one step further and keep the positions of
    the upper entries, so a refactorization only gathers ``A.data[positions]`` (6 ms).

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n)

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n, n)
    """
    A = as_csr(A)
    positions, indptr = _upper_positions(A)
    return sp.csr_matrix((A.data[positions], A.indices[positions], indptr), shape=A.shape)


def _diagonal_positions(A: sp.csr_matrix, rows: np.ndarray) -> np.ndarray:
    """Position in ``A.data`` of each diagonal entry, ``-1`` where it is not stored."""
    pos = np.full(A.shape[0], -1, dtype=np.int64)
    on_diag = np.flatnonzero(A.indices == rows)
    pos[rows[on_diag]] = on_diag
    return pos


def _first(indices: np.ndarray, limit: int = 5) -> str:
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    return shown + (f" (and {indices.size - limit} more)" if indices.size > limit else "")


def _symmetry_defect(A: sp.csr_matrix) -> float:
    """``max |A - A^T| / max |A|`` (0 for an empty matrix)."""
    scale = float(np.abs(A.data).max()) if A.nnz else 0.0
    if scale == 0.0:
        return 0.0
    D = A - A.T
    return float(np.abs(D.data).max()) / scale if D.nnz else 0.0


# ----------------------------------------------------------------------------------------------
# Symmetric elimination with a fixed pattern
# ----------------------------------------------------------------------------------------------


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

    Parameters
    ----------
    A : scipy sparse matrix, shape (n, n)
        Symmetric; converted to canonical CSR (sorted indices) if it is not.
    """

    def __init__(self, A: sp.spmatrix) -> None:
        A = as_csr(A)
        self.shape = A.shape
        self.indptr = A.indptr
        self.indices = A.indices
        rows = csr_row_indices(A)
        self.is_diagonal = self.indices == rows
        self.diagonal_positions = _diagonal_positions(A, rows)
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
        if (diag_pos < 0).any():
            missing = np.flatnonzero(fixed)[diag_pos < 0]
            raise ValueError(f"no stored diagonal entry in fixed rows {_first(missing)}")

        keep = self.keep_mask(fixed)
        if out is None:
            data = np.where(keep, A.data, 0.0)
            A_elim = sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)
        else:
            if not self.matches(out):
                raise ValueError("out does not have the sparsity pattern of A")
            np.multiply(A.data, keep, out=out.data)
            A_elim = out
        return A_elim, self._rhs(A, b, fixed, values, diag_pos)

    def keep_mask(self, fixed: np.ndarray) -> np.ndarray:
        """``(nnz,)`` bool: the stored entries that survive the elimination of ``fixed``
        (neither in a fixed row nor in a fixed column, or on the diagonal)."""
        keep = np.repeat(fixed, self.row_lengths)  # fixed row of every stored entry
        keep |= fixed[self.indices]
        np.logical_not(keep, out=keep)
        keep |= self.is_diagonal
        return keep

    def rhs(
        self, A: sp.csr_matrix, b: np.ndarray, fixed: np.ndarray, values: np.ndarray
    ) -> np.ndarray:
        """Right-hand side of the eliminated system, for full-length ``values`` (read on
        ``fixed`` only, zero elsewhere)."""
        return self._rhs(A, b, fixed, values, self.diagonal_positions[fixed])

    @staticmethod
    def _rhs(A, b, fixed, values, diag_pos) -> np.ndarray:
        b_elim = b - A @ np.where(fixed, values, 0.0)
        b_elim[fixed] = A.data[diag_pos] * values[fixed]
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


# ----------------------------------------------------------------------------------------------
# Solvers
# ----------------------------------------------------------------------------------------------


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
    """

    backend: str = ""
    reuses_analysis: bool = False

    def __init__(self, A: sp.spmatrix | None = None, *, check_symmetry: bool = True) -> None:
        self.check_symmetry = check_symmetry
        self.n_analyses = 0
        self.n_factorizations = 0
        self.n_solves = 0
        self.time_analysis = 0.0
        self.time_factorization = 0.0
        self.time_solve = 0.0
        self._indptr: np.ndarray | None = None
        self._indices: np.ndarray | None = None
        self._n = 0
        self._factorized = False
        if A is not None:
            self.factorize(A)

    # -- bookkeeping ------------------------------------------------------------------------
    @property
    def n(self) -> int:
        """Size of the analysed matrix (0 before the first factorization)."""
        return self._n

    @property
    def stats(self) -> dict[str, float | int | str]:
        """Counters and timers as a dictionary."""
        return {
            "backend": self.backend,
            "n_analyses": self.n_analyses,
            "n_factorizations": self.n_factorizations,
            "n_solves": self.n_solves,
            "time_analysis": self.time_analysis,
            "time_factorization": self.time_factorization,
            "time_solve": self.time_solve,
        }

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
        if not self.same_pattern(A):
            n = A.shape[0]
            if n == 0:
                raise ValueError("A is empty (shape (0, 0))")
            rows = csr_row_indices(A)
            missing = np.flatnonzero(_diagonal_positions(A, rows) < 0)
            if missing.size:
                raise ValueError(
                    f"A must store every diagonal entry; rows {_first(missing)} have none"
                )
            if self.check_symmetry:
                defect = _symmetry_defect(A)
                if defect > 1e-12:
                    raise ValueError(f"A is not symmetric: max|A - A^T| / max|A| = {defect:.3e}")
            self._factorized = False
            t0 = time.perf_counter()
            self._analyze(A, rows)
            self.time_analysis += time.perf_counter() - t0
            self.n_analyses += 1
            self._n = n
            self._indptr = A.indptr.copy()
            self._indices = A.indices  # a reference: patterns are not modified in place
        if keep is not None:
            keep = np.asarray(keep)
            if keep.dtype != np.bool_ or keep.shape != (A.nnz,):
                raise ValueError(f"keep must be a boolean mask of shape ({A.nnz},)")
        self._factorized = False
        t0 = time.perf_counter()
        self._factorize(A, keep)
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

    def close(self) -> None:
        """Release the factorization (the object can factorize again afterwards)."""
        self._factorized = False
        self._indptr = self._indices = None

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


class SuperLUSolver(SPDSolver):
    """SPD solver on SuperLU (:func:`scipy.sparse.linalg.splu`), always available.

    Symmetric mode, minimum degree ordering on ``A + A^T``, diagonal pivots. SuperLU has no
    separate symbolic phase, so *every* factorization redoes the ordering and the symbolic work:
    there is no reuse across refactorizations (:attr:`reuses_analysis` is False).

    Positive definiteness is checked after the factorization: with diagonal pivoting the
    diagonal of ``U`` holds the pivots of ``L D L^T``; the matrix is accepted when no row
    interchange happened and every pivot exceeds ``pivot_rtol * max(diag A)``. Extracting the
    diagonal of ``U`` costs some 15-30 % of the factorization; pass ``check_pivots=False`` to
    skip it.

    Parameters
    ----------
    A : scipy sparse matrix, optional
    check_symmetry : bool
    check_pivots : bool
    pivot_rtol : float
    """

    backend = "scipy"
    reuses_analysis = False

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        check_pivots: bool = True,
        pivot_rtol: float = 1e-13,
    ) -> None:
        self.check_pivots = check_pivots
        self.pivot_rtol = pivot_rtol
        self._lu: spla.SuperLU | None = None
        super().__init__(A, check_symmetry=check_symmetry)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        self._diag_pos = _diagonal_positions(A, rows)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._lu = None
        data = A.data if keep is None else A.data * keep
        # A is symmetric, so its CSR arrays read as CSC describe A itself (no copy).
        C = sp.csc_matrix((data, A.indices, A.indptr), shape=A.shape)
        try:
            lu = spla.splu(
                C,
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as err:
            raise FactorizationError(
                f"SuperLU could not factorize the matrix ({err}): it is singular",
                backend=self.backend,
            ) from err
        if self.check_pivots:
            if not np.array_equal(lu.perm_r, lu.perm_c):
                raise FactorizationError(
                    "SuperLU needed off-diagonal pivots: the matrix is not positive definite",
                    backend=self.backend,
                )
            pivots = lu.U.diagonal()
            scale = float(A.data[self._diag_pos].max())
            bad = np.flatnonzero(pivots <= self.pivot_rtol * max(scale, np.finfo(float).tiny))
            if bad.size:
                k = int(bad[np.argmin(pivots[bad])])
                equation = int(np.flatnonzero(lu.perm_c == k)[0])
                raise FactorizationError(
                    f"the matrix is not positive definite (numerically): pivot "
                    f"{pivots[k]:.3e} at equation {equation}, max diagonal {scale:.3e}",
                    backend=self.backend,
                    equation=equation,
                )
        self._lu = lu

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(b)

    def close(self) -> None:
        self._lu = None
        super().close()


# PARDISO error codes (MKL reference manual, "pardiso"), with what they mean here.
_PARDISO_ERRORS = {
    -1: "input inconsistent",
    -2: "not enough memory",
    -3: "reordering problem",
    -4: "zero or negative pivot: the matrix is singular or not positive definite",
    -5: "unclassified (internal) error",
    -6: "reordering failed",
    -7: "diagonal matrix is singular",
    -8: "32-bit integer overflow problem",
    -9: "not enough memory for out-of-core solver",
    -10: "error opening out-of-core files",
    -11: "read/write error with out-of-core files",
    -12: "pardiso_64 called from 32-bit library",
    -13: "interrupted by the progress callback",
    -15: "internal error during iterative refinement or reordering",
}


@lru_cache(maxsize=1)
def _pardiso_function() -> Callable[..., None]:
    """The ``pardiso`` symbol of MKL's runtime library (located by ``pypardiso``)."""
    # optional dependency, imported on demand; its module-level solver has already located
    # MKL's runtime library (a directory search that takes about a second), so reuse it
    from pypardiso.scipy_aliases import pypardiso_solver

    located = pypardiso_solver.libmkl
    lib = ctypes.CDLL(located._name)
    func = lib.pardiso
    i32p = ctypes.POINTER(ctypes.c_int32)
    func.argtypes = [
        ctypes.POINTER(ctypes.c_int64),  # pt: internal handle, 64 pointers
        i32p,  # maxfct
        i32p,  # mnum
        i32p,  # mtype
        i32p,  # phase
        i32p,  # n
        ctypes.c_void_p,  # a
        i32p,  # ia
        i32p,  # ja
        i32p,  # perm
        i32p,  # nrhs
        i32p,  # iparm
        i32p,  # msglvl
        ctypes.c_void_p,  # b
        ctypes.c_void_p,  # x
        i32p,  # error
    ]
    func.restype = None
    return func


class PardisoSolver(SPDSolver):
    """SPD solver on MKL PARDISO (sparse Cholesky) with the analysis done once per pattern.

    The upper triangle (diagonal included) is handed to PARDISO in 0-based CSR form; its
    positions in the full matrix are found once per pattern, so a refactorization only gathers
    values. Settings (``iparm``, 0-based): user values (``[0] = 1``), nested dissection
    ordering from parallel METIS (``[1] = 3``), no iterative refinement by default (``[7] = 0``),
    double precision, in-core, 0-based indices (``[34] = 1``). A zero or negative pivot stops
    the factorization with error -4, reported as :class:`FactorizationError` with the equation.

    The MKL handle is freed by :meth:`close` (also called on garbage collection and at the end
    of a ``with`` block).

    Parameters
    ----------
    A : scipy sparse matrix, optional
    check_symmetry : bool
    """

    backend = "pardiso"
    reuses_analysis = True

    def __init__(self, A: sp.spmatrix | None = None, *, check_symmetry: bool = True) -> None:
        self._func = _pardiso_function()
        self._pt = np.zeros(64, dtype=np.int64)
        self._handle_used = False
        iparm = np.zeros(64, dtype=np.int32)
        iparm[0] = 1  # use the values below, not the defaults
        iparm[1] = 3  # nested dissection ordering, parallel (OpenMP) METIS: analysis 2.0–2.4 s
        #               against 2.9–3.5 s serial at 10⁶ unknowns, same factor
        iparm[7] = 0  # iterative refinement steps (none unless pivots are perturbed)
        iparm[9] = 8  # pivot perturbation 1e-8 (only for indefinite types)
        iparm[17] = -1  # report the number of non-zeros of the factor in iparm[17]
        iparm[26] = 0  # no matrix checker (indices are sorted and checked here)
        iparm[27] = 0  # double precision
        iparm[34] = 1  # 0-based indexing
        iparm[59] = 0  # in-core
        self._iparm = iparm
        self._upos = np.zeros(0, dtype=np.int64)
        self._ia = np.zeros(1, dtype=np.int32)
        self._ja = np.zeros(0, dtype=np.int32)
        self._a = np.zeros(0)
        self._n_eq = 0
        super().__init__(A, check_symmetry=check_symmetry)

    @property
    def factor_nnz(self) -> int:
        """Non-zeros in the Cholesky factor (reported by the last analysis)."""
        return int(self._iparm[17])

    def _call(self, phase: int, b: np.ndarray | None = None, x: np.ndarray | None = None) -> None:
        nrhs = 1 if b is None or b.ndim == 1 else b.shape[1]
        error = ctypes.c_int32(0)
        i32 = ctypes.c_int32
        i32p = ctypes.POINTER(ctypes.c_int32)
        self._func(
            self._pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(2)),  # real symmetric positive definite
            ctypes.byref(i32(phase)),
            ctypes.byref(i32(self._n_eq)),
            self._a.ctypes.data,
            self._ia.ctypes.data_as(i32p),
            self._ja.ctypes.data_as(i32p),
            None,
            ctypes.byref(i32(nrhs)),
            self._iparm.ctypes.data_as(i32p),
            ctypes.byref(i32(0)),
            None if b is None else b.ctypes.data,
            None if x is None else x.ctypes.data,
            ctypes.byref(error),
        )
        if error.value != 0:
            code = int(error.value)
            meaning = _PARDISO_ERRORS.get(code, "unknown error")
            equation = None
            if code == -4 and phase == 22 and self._iparm[29] > 0:
                equation = int(self._iparm[29]) - 1
                meaning += f" (at equation {equation})"
            raise FactorizationError(
                f"PARDISO phase {phase} failed with error {code}: {meaning}",
                backend=self.backend,
                code=code,
                equation=equation,
            )

    def _release(self) -> None:
        if self._handle_used:
            self._handle_used = False
            try:
                self._call(-1)
            finally:
                self._pt[:] = 0

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        self._release()
        positions, indptr = _upper_positions(A, rows)
        if positions.size >= 2**31 - 1:
            raise ValueError("the upper triangle has too many entries for 32-bit PARDISO")
        self._upos = positions
        self._ia = indptr.astype(np.int32)
        self._ja = A.indices[positions].astype(np.int32)
        self._a = A.data[positions]
        self._n_eq = A.shape[0]
        self._handle_used = True
        self._call(11)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        np.take(A.data, self._upos, out=self._a)
        if keep is not None:  # only the upper triangle is gathered: no copy of the matrix
            self._a *= keep[self._upos]
        self._call(22)

    def _solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asfortranarray(b)
        x = np.zeros_like(b, order="F")
        self._call(33, b, x)
        return np.ascontiguousarray(x)

    def close(self) -> None:
        """Free PARDISO's internal memory for this handle (phase -1) and the stored pattern."""
        self._release()
        self._upos = np.zeros(0, dtype=np.int64)
        self._ia = np.zeros(1, dtype=np.int32)
        self._ja = np.zeros(0, dtype=np.int32)
        self._a = np.zeros(0)
        self._n_eq = 0
        super().close()

    def __del__(self) -> None:
        try:
            self._release()
        except Exception:  # never raise from a finalizer
            pass


@lru_cache(maxsize=1)
def _pardiso_works() -> bool:
    """Whether PARDISO loads and solves a 2 x 2 SPD system correctly."""
    try:
        A = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
        with PardisoSolver(A) as solver:
            x = solver.solve(np.array([1.0, 2.0]))
        return bool(np.allclose(A @ x, [1.0, 2.0], rtol=1e-12, atol=0))
    except Exception as err:  # any failure means "not usable"
        logger.info("PARDISO backend unavailable: %s", err)
        return False


def available_backends() -> tuple[str, ...]:
    """Backends that work on this machine, best first (``"scipy"`` is always there)."""
    return ("pardiso", "scipy") if _pardiso_works() else ("scipy",)


def make_solver(
    backend: str = "auto", A: sp.spmatrix | None = None, **options: object
) -> SPDSolver:
    """Create an SPD solver.

    Parameters
    ----------
    backend : {"auto", "pardiso", "scipy"}
        ``"auto"`` takes PARDISO when it loads and works, SuperLU otherwise.
    A : scipy sparse matrix, optional
        Factorized right away if given.
    **options
        Passed to the solver class (e.g. ``check_symmetry=False``).

    Returns
    -------
    SPDSolver
        Its :attr:`~SPDSolver.backend` names the backend taken.

    Raises
    ------
    ValueError
        For an unknown backend name.
    RuntimeError
        If ``"pardiso"`` is asked for and cannot be loaded.
    """
    valid: Sequence[str] = ("auto", *BACKENDS)
    if backend not in valid:
        raise ValueError(f"unknown backend {backend!r}; valid backends are {', '.join(valid)}")
    if backend == "auto":
        backend = available_backends()[0]
    if backend == "pardiso":
        if not _pardiso_works():
            raise RuntimeError(
                "the pardiso backend is not usable here (is pypardiso with MKL installed?)"
            )
        return PardisoSolver(A, **options)
    return SuperLUSolver(A, **options)
