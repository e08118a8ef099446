"""MKL PARDISO's LU factorization of general real matrices (``mtype = 11``): the
non-symmetric systems of Coulomb friction (:mod:`.friction.system`), on the phases and
settings of :class:`~.pardiso.PardisoSolver`."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .pardiso import PardisoSolver

__all__ = ["REFINEMENT_STEPS", "PardisoLUSolver"]

#: Steps of iterative refinement in the solves of a factor with perturbed pivots: on a matrix
#: whose last pivot PARDISO perturbed (tests/algebra/backends/test_lu_solvers.py) the residual is
#: 8.5e-13 without and 5.6e-16 with them.
REFINEMENT_STEPS = 2


class PardisoLUSolver(PardisoSolver):
    """LU factorization of a general (non-symmetric) real matrix on MKL PARDISO (``mtype = 11``).

    The whole matrix is handed over in 0-based CSR form and PARDISO solves ``A x = b``; the
    analysis (ordering on ``A + A^T``, symbolic factorization) is done once per pattern, as in
    :class:`PardisoSolver`. Settings as there, plus PARDISO's pivot perturbation 1e-13 for
    non-symmetric matrices (``iparm[9]``) and :data:`REFINEMENT_STEPS` steps of iterative
    refinement (``iparm[7]``) in the solves of a factor with perturbed pivots
    (``iparm[13] > 0``), which need them. A factor without is solved without refinement: its
    residual is at round-off either way, and each step costs another solve (Coulomb's system
    at 205 154 unknowns: 0.045–0.073 s per solve against 0.150–0.207 s with two steps, the
    residuals alike). The caller checks the residual of every solve.

    Without ``matching`` (the default) the analysis reads no value, so that it can run beside
    the caller (:meth:`~.solvers.SPDSolver.analyze`): Coulomb's systems, whose diagonal is
    ``K``'s except on slipping nodes' rows, need no matching. Example 6.2 with Coulomb
    friction, F = 0.3, 1, 2 and 5, adaptively to about 35 000 unknowns: the same levels and
    iterations with and without it, the displacements within 2.3e-13 of each other, KKT
    residuals 7e-14 to 9e-14 either way.

    Parameters
    ----------
    A : scipy sparse matrix, optional
        Factorized right away if given. Its symmetry is not checked.
    matching : bool
        Scaling and weighted matching (``iparm[10] = iparm[12] = 1``), computed from the
        values of the analysed matrix (for matrices with small or zero diagonal entries);
        the analysis then reads the values and runs in the caller's thread.
    ordering : (n,) int array, optional
        A fill-reducing ordering, as in :class:`PardisoSolver`.
    """

    _mtype = 11  # real non-symmetric

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        matching: bool = False,
        ordering: np.ndarray | None = None,
    ) -> None:
        super().__init__(None, check_symmetry=False, ordering=ordering)
        self._iparm[9] = 13
        self._iparm[10] = int(matching)
        self._iparm[12] = int(matching)
        self.analysis_reads_values = matching  # scaling and weighted matching read them
        if A is not None:
            self.factorize(A)

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray) -> None:
        self._release()
        if A.nnz >= 2**31 - 1:
            raise ValueError("the matrix has too many entries for 32-bit PARDISO")
        self._upos = np.arange(A.nnz)
        self._ia = A.indptr.astype(np.int32)
        self._ja = A.indices.astype(np.int32)
        self._a = A.data.copy() if self.analysis_reads_values else np.zeros(A.nnz)
        self._n_eq = A.shape[0]
        self._use_ordering()
        self._handle_used = True
        self._call(11)

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        super()._factorize(A, keep)
        # refine the solves of this factor only if PARDISO perturbed a pivot (iparm[13])
        self._iparm[7] = REFINEMENT_STEPS if self._iparm[13] > 0 else 0
