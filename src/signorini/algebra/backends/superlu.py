"""SuperLU as an SPD solver: always available, no reuse of the symbolic analysis."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import FactorizationError
from ..sparse import diagonal_positions
from .solvers import SolverRequest, SPDSolver

__all__ = ["PIVOT_RTOL", "SuperLULUSolver", "SuperLUSolver", "superlu_solver"]

#: a pivot of SuperLU's symmetric-mode factorization at most this times the largest diagonal
#: entry of the matrix means the matrix is not (numerically) positive definite
PIVOT_RTOL = 1e-13


class SuperLUSolver(SPDSolver):
    """SPD solver on SuperLU (:func:`scipy.sparse.linalg.splu`), always available.

    Symmetric mode, minimum degree ordering on ``A + A^T``, diagonal pivots. SuperLU has no
    separate symbolic phase, so *every* factorization redoes the ordering and the symbolic work:
    there is no reuse across refactorizations (:attr:`reuses_analysis` is False).

    Positive definiteness is checked after the factorization: with diagonal pivoting the
    diagonal of ``U`` holds the pivots of ``L D L^T``; the matrix is accepted when no row
    interchange happened and every pivot exceeds :data:`PIVOT_RTOL` ``* max(diag A)``
    (extracting the diagonal of ``U`` costs some 15-30 % of the factorization).

    With an ``ordering`` (:class:`~.solvers.SPDSolver`) SuperLU factorizes the symmetrically
    permuted matrix in that order (``permc_spec="NATURAL"``) instead of its own.

    Parameters
    ----------
    A : scipy sparse matrix, optional
    check_symmetry : bool
    ordering : (n,) int array, optional
    """

    backend = "scipy"
    reuses_analysis = False

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
    ) -> None:
        self._lu: spla.SuperLU | None = None
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        self._diag_pos = diagonal_positions(A, rows)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._lu = None
        data = A.data if keep is None else A.data * keep
        # A is symmetric, so its CSR arrays read as CSC describe A itself (no copy).
        C = _in_order(sp.csc_matrix((data, A.indices, A.indptr), shape=A.shape), self._perm)
        try:
            lu = spla.splu(
                C,
                permc_spec="MMD_AT_PLUS_A" if self._perm is None else "NATURAL",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as err:
            raise FactorizationError(
                f"SuperLU could not factorize the matrix ({err}): it is singular",
                backend=self.backend,
            ) from err
        if not np.array_equal(lu.perm_r, lu.perm_c):
            raise FactorizationError(
                "SuperLU needed off-diagonal pivots: the matrix is not positive definite",
                backend=self.backend,
            )
        pivots = lu.U.diagonal()
        scale = float(A.data[self._diag_pos].max())
        bad = np.flatnonzero(pivots <= PIVOT_RTOL * max(scale, np.finfo(float).tiny))
        if bad.size:
            k = int(bad[np.argmin(pivots[bad])])
            equation = int(np.flatnonzero(lu.perm_c == k)[0])
            if self._perm is not None:
                equation = int(self._perm[equation])
            raise FactorizationError(
                f"the matrix is not positive definite (numerically): pivot "
                f"{pivots[k]:.3e} at equation {equation}, max diagonal {scale:.3e}",
                backend=self.backend,
                equation=equation,
            )
        self._lu = lu

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return _solve_in_order(lambda c: self._lu.solve(c), b, self._perm)

    def close(self) -> None:
        self._lu = None
        super().close()


class SuperLULUSolver(SPDSolver):
    """LU factorization of a general (non-symmetric) sparse matrix on SuperLU.

    SuperLU's defaults: COLAMD column ordering and threshold partial pivoting. The CSR arrays
    of ``A`` read as CSC describe ``A^T``, which is factorized without a copy; a solve then
    uses the transposed factors. No reuse of the symbolic analysis (as :class:`SuperLUSolver`);
    the symmetry of ``A`` is not checked.

    With an ``ordering`` the permuted matrix is factorized in that column order
    (``permc_spec="NATURAL"``), rows still pivoted by threshold.

    Parameters
    ----------
    A : scipy sparse matrix, optional
    ordering : (n,) int array, optional
    """

    backend = "scipy"
    reuses_analysis = False

    def __init__(self, A: sp.spmatrix | None = None, *, ordering: np.ndarray | None = None) -> None:
        self._lu: spla.SuperLU | None = None
        super().__init__(A, check_symmetry=False, ordering=ordering)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        pass

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._lu = None
        data = A.data if keep is None else A.data * keep
        transposed = _in_order(
            sp.csc_matrix((data, A.indices, A.indptr), shape=A.shape), self._perm
        )
        try:
            self._lu = spla.splu(
                transposed, permc_spec="COLAMD" if self._perm is None else "NATURAL"
            )
        except RuntimeError as err:
            raise FactorizationError(
                f"SuperLU could not factorize the matrix ({err}): it is singular",
                backend=self.backend,
            ) from err

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return _solve_in_order(lambda c: self._lu.solve(c, trans="T"), b, self._perm)

    def close(self) -> None:
        self._lu = None
        super().close()


def superlu_solver(request: SolverRequest) -> SPDSolver:
    """The SuperLU backend's solver factory (:class:`~.solvers.SolverFactory`), always
    available: :class:`SuperLUSolver` for a symmetric request, :class:`SuperLULUSolver`
    otherwise. The request's ordering is not used: SuperLU keeps its own (minimum degree,
    COLAMD), and the contact layer's needs MKL's METIS."""
    if request.symmetric:
        return SuperLUSolver(check_symmetry=request.check_symmetry)
    return SuperLULUSolver()


def _in_order(C: sp.csc_matrix, perm: np.ndarray | None) -> sp.csc_matrix:
    """``C`` with rows and columns taken in the order ``perm`` (``C`` itself without one)."""
    if perm is None:
        return C
    return C[perm][:, perm].tocsc()


def _solve_in_order(solve, b: np.ndarray, perm: np.ndarray | None) -> np.ndarray:
    """The solution of the original system from ``solve`` of the permuted one."""
    if perm is None:
        return solve(b)
    x = np.empty_like(b)
    x[perm] = solve(b[perm])
    return x
