"""MKL PARDISO as an SPD solver, called through ``ctypes``.

Real symmetric positive definite mode (``mtype = 2``, sparse Cholesky) on the upper triangle in
0-based CSR form, with the phases called separately: 11 (analysis, once per pattern), 22
(numerical factorization), 33 (solve).

MKL is found and loaded by :mod:`.mkl`. :func:`pardiso_problem` loads it, solves a 2 x 2
system, and says why PARDISO cannot be used (``None`` when it can);
:func:`pardiso_solver` (the backend's solver factory) turns it into an error, the ``"auto"``
choice of :mod:`.selection` into a warning.
:func:`metis_ordering` returns PARDISO's METIS ordering of a graph (docs/method.md,
*Ordering of the unknowns*).

pydiso's ``MKLPardisoSolver`` (the same MKL calls from Cython, with the analysis reused) was
measured against this module on the matrices PDAS factorizes (``benchmarks/pardiso_wrappers.py``,
figures in its docstring): at 10⁶ unknowns its refactorizations take 1.11 times as long, its
analysis twice as long (its constructor analyses with its own settings first) and its peak
memory is 1.4 times ours, so it is not used.
"""

from __future__ import annotations

import ctypes
from functools import lru_cache

import numpy as np
import scipy.sparse as sp

from ..errors import BackendUnavailableError, FactorizationError
from ..sparse import block_upper_positions, upper_positions
from .mkl import openmp_sleep_at_once, pardiso_function
from .solvers import SolverRequest, SPDSolver

__all__ = [
    "metis_ordering",
    "PardisoSolver",
    "pardiso_problem",
    "pardiso_solver",
]

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


class PardisoSolver(SPDSolver):
    """SPD solver on MKL PARDISO (sparse Cholesky) with the analysis done once per pattern.

    The upper triangle (diagonal included) is handed to PARDISO in 0-based CSR form, or, for a
    matrix of 2 x 2 node blocks, the upper block triangle in BSR form (``blocks``); its
    positions in the full matrix are found once per pattern, so a refactorization only gathers
    values. Settings (``iparm``, 0-based): user values (``[0] = 1``), nested dissection
    ordering from parallel METIS (``[1] = 3``), no iterative refinement by default (``[7] = 0``),
    double precision, in-core, 0-based indices (``[34] = 1``); the analysis reports the factor's
    non-zeros (``[17]``, :attr:`factor_nnz`) and the factorization's operation count (``[18]``,
    :attr:`factor_mflop`), and PARDISO its memory (``[14..16]``, :attr:`memory_kib`). A zero
    or negative pivot stops the factorization with error -4, reported as
    :class:`FactorizationError` with the equation.

    MKL is found by :func:`pardiso_function`; when it cannot be loaded the constructor raises
    :class:`~.errors.BackendUnavailableError`. The MKL handle is freed by :meth:`close` (also
    called on garbage collection and at the end of a ``with`` block).

    Parameters
    ----------
    A : scipy sparse matrix, optional
    check_symmetry : bool
    ordering : (n,) int array, optional
        A fill-reducing ordering (:class:`~.solvers.SPDSolver`), handed to PARDISO as its user
        permutation (``iparm[4] = 1``, ``perm``) instead of its own METIS analysis; the
        symbolic factorization is still PARDISO's.
    blocks : bool
        Hand a matrix stored in 2 x 2 node blocks over in BSR form (``iparm[36] = 2``) where
        the ordering keeps each node's two rows together: the analysis works on the node
        graph, in about a third of the time and memory (docs/method.md, *Block Cholesky*).
        False: always CSR.
    """

    backend = "pardiso"
    reuses_analysis = True
    analysis_reads_values = False  # an SPD analysis: no scaling or matching
    _mtype = 2  # real symmetric positive definite

    def __init__(
        self,
        A: sp.spmatrix | None = None,
        *,
        check_symmetry: bool = True,
        ordering: np.ndarray | None = None,
        blocks: bool = True,
    ) -> None:
        self._func = pardiso_function()
        # MKL's OpenMP threads sleep as soon as a call ends instead of spinning for 200 ms
        # beside the NumPy work between calls (docs/method.md, *Ordering of the unknowns*)
        openmp_sleep_at_once()
        self.blocks = blocks
        self._pt = np.zeros(64, dtype=np.int64)
        self._handle_used = False
        iparm = np.zeros(64, dtype=np.int32)
        iparm[0] = 1  # use the values below, not the defaults
        iparm[1] = 3  # nested dissection ordering, parallel (OpenMP) METIS: analysis 2.0–2.4 s
        #               against 2.9–3.5 s serial at 10⁶ unknowns, same factor
        iparm[7] = 0  # iterative refinement steps (none unless pivots are perturbed)
        iparm[9] = 8  # pivot perturbation 1e-8 (only for indefinite types)
        iparm[17] = -1  # report the number of non-zeros of the factor in iparm[17]
        iparm[18] = -1  # report the factorization's operation count (Mflop) in iparm[18]
        iparm[26] = 0  # no matrix checker (indices are sorted and checked here)
        iparm[27] = 0  # double precision
        iparm[34] = 1  # 0-based indexing
        iparm[36] = 0  # CSR, or 2: 2 x 2 blocks (BSR), set per pattern by _load_upper
        iparm[59] = 0  # in-core
        self._iparm = iparm
        self._upos = np.zeros(0, dtype=np.int64)
        self._ia = np.zeros(1, dtype=np.int32)
        self._ja = np.zeros(0, dtype=np.int32)
        self._a = np.zeros(0)
        self._n_eq = 0
        self._block = 1  # 2: the pattern is handed over in 2 x 2 blocks (BSR)
        self._perm32: np.ndarray | None = None  # PARDISO's perm: a user ordering (iparm[4])
        super().__init__(A, check_symmetry=check_symmetry, ordering=ordering)

    @property
    def factor_nnz(self) -> int:
        """Non-zeros in the Cholesky factor (reported by the last analysis; in 2 x 2 blocks,
        four per block, as stored)."""
        return int(self._iparm[17]) * self._block**2

    @property
    def block_size(self) -> int:
        """The form of the last analysis: 1, the upper triangle in CSR; 2, the upper block
        triangle in 2 x 2 blocks (``blocks``)."""
        return self._block

    @property
    def factor_mflop(self) -> int:
        """Floating-point operations of one numerical factorization, in millions (``iparm[18]``,
        reported by the last analysis; PARDISO counts a 2 x 2 block's product as one); 0 before
        the first analysis."""
        return int(self._iparm[18]) * self._block**3

    @property
    def memory_kib(self) -> dict[str, int]:
        """PARDISO's own memory as reported by the last analysis and factorization, in KiB.

        Returns
        -------
        dict
            ``analysis_peak`` (``iparm[14]``, peak of the analysis), ``permanent``
            (``iparm[15]``, kept from the analysis for the factorization and solves) and
            ``factorization`` (``iparm[16]``, the factor and the working memory of the
            factorization and solves). PARDISO's peak is ``max(analysis_peak, permanent +
            factorization)``.
        """
        return {
            "analysis_peak": int(self._iparm[14]),
            "permanent": int(self._iparm[15]),
            "factorization": int(self._iparm[16]),
        }

    def _call(self, phase: int, b: np.ndarray | None = None, x: np.ndarray | None = None) -> None:
        nrhs = 1 if b is None or b.ndim == 1 else b.shape[1]
        error = ctypes.c_int32(0)
        i32 = ctypes.c_int32
        i32p = ctypes.POINTER(ctypes.c_int32)
        self._func(
            self._pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(1)),
            ctypes.byref(i32(self._mtype)),
            ctypes.byref(i32(phase)),
            ctypes.byref(i32(self._n_eq)),
            self._a.ctypes.data,
            self._ia.ctypes.data_as(i32p),
            self._ja.ctypes.data_as(i32p),
            None if self._perm32 is None else self._perm32.ctypes.data_as(i32p),
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
                equation = (int(self._iparm[29]) - 1) * self._block  # a block's first row
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

    def _analyze(self, A: sp.csr_matrix, rows: np.ndarray | None, *, blocks: bool = True) -> None:
        self._load_upper(A, rows, blocks=blocks)
        self._use_ordering()
        self._handle_used = True
        self._call(11)

    def _load_upper(
        self, A: sp.csr_matrix, rows: np.ndarray | None = None, *, blocks: bool = True
    ) -> None:
        """Release the handle and hold the pattern of the upper triangle of ``A`` in
        PARDISO's 32-bit arrays, with its positions in ``A.data`` for the factorizations,
        which gather the values (the analysis does not read them, and ``A.data`` may be
        written meanwhile: :meth:`~.solvers.SPDSolver.analyze`).

        With ``blocks``, a matrix stored in 2 x 2 node blocks whose ordering (if any) keeps
        each node's two rows together goes over as its upper block triangle in BSR form
        (``iparm[36] = 2``; docs/method.md, *Block Cholesky*); any other in CSR form."""
        self._release()
        found = None
        if blocks and self.blocks and _keeps_pairs(self._perm, A.shape[0]):
            found = block_upper_positions(A, rows)
        if found is None:
            positions, indptr = upper_positions(A, rows)
            columns = A.indices[positions]
            self._block = 1
        else:
            positions, indptr, columns = found
            self._block = 2
        if positions.size >= 2**31 - 1:
            raise ValueError("the upper triangle has too many entries for 32-bit PARDISO")
        self._iparm[36] = 0 if self._block == 1 else self._block
        self._upos = positions
        self._ia = indptr.astype(np.int32)
        self._ja = columns.astype(np.int32)
        self._a = np.zeros(positions.size)
        self._n_eq = A.shape[0] // self._block

    def computed_ordering(self, A: sp.csr_matrix) -> np.ndarray:
        """PARDISO's own fill-reducing ordering of canonical CSR ``A`` (an analysis with
        ``iparm[4] = 2``, which writes it into ``perm``); this handle is released afterwards.

        Returns
        -------
        (n,) int64 array
            ``order[k]``: the unknown eliminated k-th.
        """
        self._load_upper(A, blocks=False)
        self._perm32 = np.zeros(A.shape[0], dtype=np.int32)
        self._iparm[4] = 2
        self._handle_used = True
        try:
            self._call(11)
            return self._perm32.astype(np.int64)
        finally:
            self._release()
            self._iparm[4] = 0
            self._perm32 = None

    def _use_ordering(self) -> None:
        """Hand the checked ordering of this analysis to PARDISO (``iparm[4] = 1``: the
        permutation in ``perm`` replaces its own nested dissection), or none."""
        if self._perm is None:
            self._iparm[4] = 0
            self._perm32 = None
        else:
            self._iparm[4] = 1
            self._perm32 = (self._perm[0::2] // 2 if self._block == 2 else self._perm).astype(
                np.int32
            )

    def _factorize(self, A: sp.csr_matrix, keep: np.ndarray | None) -> None:
        np.take(A.data, self._upos, out=self._a, mode="clip")  # valid positions: unbuffered
        if keep is not None:  # only the upper triangle is gathered: no copy of the matrix
            self._a *= keep[self._upos]
        try:
            self._call(22)
        except FactorizationError:
            if self._block == 1:
                raise
            # in blocks PARDISO reports a zero pivot vaguely (a singular matrix as error -13):
            # the same matrix in CSR form says what failed, and at which equation
            self._analyze(A, None, blocks=False)
            self._factorize(A, keep)

    def _solve(self, b: np.ndarray) -> np.ndarray:
        b = np.asfortranarray(b)  # PARDISO's layout of several right-hand sides (no copy for one)
        x = np.empty_like(b, order="F")  # phase 33 writes all of it
        self._call(33, b, x)
        return x

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


def _keeps_pairs(perm: np.ndarray | None, n: int) -> bool:
    """Whether the ordering ``perm`` of ``n`` unknowns (or PARDISO's own, ``None``) can be
    one of 2 x 2 blocks: each node's rows ``2z, 2z + 1`` eliminated one after the other."""
    if n % 2:
        return False
    return perm is None or bool(
        np.all(perm[0::2] % 2 == 0) and np.array_equal(perm[1::2], perm[0::2] + 1)
    )


def pardiso_solver(request: SolverRequest) -> PardisoSolver:
    """The PARDISO backend's solver factory (:class:`~.solvers.SolverFactory`).

    :class:`PardisoSolver` (Cholesky) for a symmetric request,
    :class:`~.pardiso_lu.PardisoLUSolver` otherwise; the request's ordering, if any, is
    computed and handed to PARDISO as its user permutation (docs/method.md, *Ordering of the
    unknowns*).

    Raises
    ------
    BackendUnavailableError
        If PARDISO cannot be used here (:func:`pardiso_problem` says why).
    """
    problem = pardiso_problem()
    if problem is not None:
        raise BackendUnavailableError(f"the pardiso backend is not usable here: {problem}")
    if request.symmetric:
        solver = PardisoSolver(check_symmetry=request.check_symmetry)
    else:
        from .pardiso_lu import PardisoLUSolver  # a subclass of PardisoSolver, defined there

        solver = PardisoLUSolver()
    if request.ordering is not None:
        solver.ordering = request.ordering()
    return solver


#: PARDISO takes the ordering it is offered (:func:`~.selection.takes_ordering`)
pardiso_solver.takes_ordering = True  # type: ignore[attr-defined]


def metis_ordering(graph: sp.spmatrix) -> np.ndarray:
    """METIS nested dissection ordering of a symmetric graph, from PARDISO's analysis.

    PARDISO analyses (phase 11, parallel METIS, ``iparm[1] = 3``) an SPD matrix with the
    graph's pattern — its Laplacian plus the identity — and returns the ordering it computed
    (``iparm[4] = 2``); the handle is released at once. On the vertex graph of a mesh this
    costs about a tenth of PARDISO's analysis of the P2 stiffness matrix (docs/method.md,
    *Ordering of the unknowns*).

    Parameters
    ----------
    graph : scipy sparse matrix, shape (n, n)
        Symmetric pattern: an entry (i, j) is an edge; values and the diagonal are ignored.

    Returns
    -------
    (n,) int64 array
        ``order[k]``: the vertex eliminated k-th.

    Raises
    ------
    BackendUnavailableError
        If MKL cannot be loaded.
    """
    pattern = sp.coo_matrix(graph)
    n = pattern.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    edge = pattern.row != pattern.col
    adjacency = sp.csr_matrix(
        (np.ones(edge.sum()), (pattern.row[edge], pattern.col[edge])), shape=(n, n)
    )
    adjacency.data[:] = 1.0  # an edge stored twice counts once
    degree = np.diff(adjacency.indptr)
    L = (sp.diags(degree + 1.0) - adjacency).tocsr()
    L.sort_indices()
    with PardisoSolver(check_symmetry=False) as solver:
        return solver.computed_ordering(L)


@lru_cache(maxsize=1)
def pardiso_problem() -> str | None:
    """Why PARDISO cannot be used here, or ``None`` when it loads and solves a 2 x 2 SPD system.

    Cached: the library is probed once per process.

    Returns
    -------
    str or None
        The reason (library not found or not loadable, a PARDISO error on the test system, or
        a wrong solution).
    """
    A = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    b = np.array([1.0, 2.0])
    try:
        with PardisoSolver(A) as solver:
            x = solver.solve(b)
    except (BackendUnavailableError, FactorizationError) as err:
        return str(err)
    if not np.allclose(A @ x, b, rtol=1e-12, atol=0):
        return f"PARDISO solved a 2 x 2 test system wrongly (x = {x})"
    return None
