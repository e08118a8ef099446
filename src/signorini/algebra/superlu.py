"""SuperLU as an SPD solver: always available, no reuse of the symbolic analysis."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .solvers import FactorizationError, SPDSolver
from .sparse import diagonal_positions

__all__ = ["SuperLULUSolver", "SuperLUSolver"]


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
        self._diag_pos = diagonal_positions(A, rows)

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


class SuperLULUSolver(SPDSolver):
    """LU factorization of a general (non-symmetric) sparse matrix on SuperLU.

    SuperLU's defaults: COLAMD column ordering and threshold partial pivoting. The CSR arrays
    of ``A`` read as CSC describe ``A^T``, which is factorized without a copy; a solve then
    uses the transposed factors. No reuse of the symbolic analysis (as :class:`SuperLUSolver`);
    the symmetry of ``A`` is not checked.

    Parameters
    ----------
    A : scipy sparse matrix, optional
    """

    backend = "scipy"
    reuses_analysis = False

    def __init__(self, A: sp.spmatrix | None = None) -> None:
        self._lu: spla.SuperLU | None = None
        super().__init__(A, check_symmetry=False)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        pass

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        self._lu = None
        data = A.data if keep is None else A.data * keep
        transposed = sp.csc_matrix((data, A.indices, A.indptr), shape=A.shape)
        try:
            self._lu = spla.splu(transposed)
        except RuntimeError as err:
            raise FactorizationError(
                f"SuperLU could not factorize the matrix ({err}): it is singular",
                backend=self.backend,
            ) from err

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(b, trans="T")

    def close(self) -> None:
        self._lu = None
        super().close()
