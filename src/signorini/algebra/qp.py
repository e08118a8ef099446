"""The bound-constrained quadratic program that PDAS solves, checked once at the public entry.

.. math::

    \\min_x \\tfrac12 x^T K x - F^T x
    \\quad\\text{subject to}\\quad x_c \\le g,\\quad x_d = x_D,

the discrete Signorini problem of docs/method.md, *Discrete problem*, once the contact DOFs are
rotated into their normal frames (:mod:`signorini.contact.node_frames`). :func:`check_qp` turns the
arguments of :func:`~.pdas.solve_pdas` and :func:`~.kkt.kkt_residuals` into a :class:`BoundQP`
or raises a :class:`ValueError` naming the argument; everything after it trusts the data.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from .ranks import SERIAL, Ranks
from .sparse import as_csr, list_indices

__all__ = ["BoundQP", "check_qp", "check_rows", "check_vector"]


@dataclass(frozen=True)
class BoundQP:
    """Checked data of ``min 1/2 x^T K x - F^T x`` subject to ``x_c <= g``, ``x_d = x_D``.

    Attributes
    ----------
    K : scipy.sparse.csr_matrix, shape (n, n)
        Canonical float64 CSR.
    F : (n,) float array
    constrained : (m,) int64 array
        The bounded DOFs ``c``, distinct.
    gap : (m,) float array
        The bounds ``g``, in the order of ``constrained``.
    dirichlet : (n_d,) int64 array
        The fixed DOFs ``d``, distinct and disjoint from ``constrained``.
    dirichlet_values : (n_d,) float array
        ``x_D``, in the order of ``dirichlet``.
    ranks : Ranks
        The processes that share ``K`` by rows (:mod:`.ranks`): on a rank of several, ``K``
        holds that rank's rows only and ``K`` is the sum over the ranks; :data:`~.ranks.SERIAL`
        for a whole matrix.
    """

    K: sp.csr_matrix
    F: np.ndarray
    constrained: np.ndarray
    gap: np.ndarray
    dirichlet: np.ndarray
    dirichlet_values: np.ndarray
    ranks: Ranks = SERIAL

    @property
    def n(self) -> int:
        """Number of unknowns."""
        return self.K.shape[0]

    def matvec(self, x: np.ndarray) -> np.ndarray:
        """``K x`` on every rank: each rank's rows times ``x``, summed over the ranks (with
        one process ``K @ x`` itself)."""
        return self.ranks.sum(self.K @ x)

    def diagonal(self) -> np.ndarray:
        """The diagonal of ``K`` on every rank (summed over the ranks), ``(n,)``."""
        return self.ranks.sum(self.K.diagonal())

    def on_ranks(self, ranks: Ranks) -> BoundQP:
        """The same problem with ``K`` split by rows over ``ranks`` (:attr:`ranks`), checked
        by :func:`check_rows`."""
        check_rows(self.K, ranks)
        return replace(self, ranks=ranks)


def check_qp(
    K: object,
    F: object,
    constrained: object,
    gap: object,
    dirichlet: object = None,
    dirichlet_values: object = None,
    *,
    ranks: Ranks = SERIAL,
) -> BoundQP:
    """Check and normalise the data of the bound-constrained QP.

    Parameters
    ----------
    K : scipy sparse matrix, shape (n, n)
    F : (n,) float array
    constrained : (m,) int array or (n,) bool mask
    gap : float or (m,) float array
    dirichlet : (n_d,) int array or (n,) bool mask, optional
    dirichlet_values : float, (n_d,) or (n,) float array, optional
        Default 0.
    ranks : Ranks
        As :attr:`BoundQP.ranks`; default a whole matrix.

    Returns
    -------
    BoundQP

    Raises
    ------
    ValueError
        Naming the argument: wrong shape or type, non-finite values, indices out of range or
        repeated, ``constrained`` meeting ``dirichlet``, rows of ``K`` not on exactly one of
        several ``ranks``.
    """
    K = as_csr(K, "K")
    check_rows(K, ranks)
    n = K.shape[0]
    F = check_vector(F, n, "F")
    c = _index_array(constrained, n, "constrained")
    g = check_vector(gap, c.size, "gap", allow_scalar=True)
    if dirichlet is None:
        d = np.zeros(0, dtype=np.int64)
    else:
        d = _index_array(dirichlet, n, "dirichlet")
    overlap = np.intersect1d(c, d)
    if overlap.size:
        raise ValueError(
            f"constrained and dirichlet overlap in {overlap.size} DOFs (first: {overlap[0]})"
        )
    if dirichlet_values is None:
        xd = np.zeros(d.size)
    else:
        vals = np.asarray(dirichlet_values, dtype=np.float64)
        if vals.shape == (n,) and d.size != n:
            vals = vals[d]
        xd = check_vector(vals, d.size, "dirichlet_values", allow_scalar=True)
    return BoundQP(K, F, c, g, d, xd, ranks)


def check_rows(K: sp.csr_matrix, ranks: Ranks) -> None:
    """Check that every row of ``K`` (canonical CSR) is stored on exactly one of ``ranks``
    when there are several (the split of :attr:`BoundQP.ranks`); nothing with one process.

    Collective: every rank gets the same answer.

    Raises
    ------
    ValueError
        Naming the rows stored on no rank or on several.
    """
    if not ranks.distributed:
        return
    holders = ranks.sum((np.diff(K.indptr) > 0).astype(np.int32))
    wrong = np.flatnonzero(holders != 1)
    if wrong.size:
        raise ValueError(
            f"K must hold each row on exactly one of the {ranks.size} ranks (its other rows "
            f"empty); rows {list_indices(wrong)} are stored on "
            f"{', '.join(str(int(h)) for h in holders[wrong[:5]])} ranks"
        )


def check_vector(v: object, n: int, name: str, *, allow_scalar: bool = False) -> np.ndarray:
    """A finite float64 vector of length ``n`` (a scalar is broadcast if allowed).

    Raises
    ------
    ValueError
        Naming ``name``, if ``v`` is not real, has another shape, or non-finite entries.
    """
    try:
        arr = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{name} must be a real array: {err}") from None
    if arr.ndim == 0 and allow_scalar:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} has non-finite (NaN or inf) entries")
    return arr


def _index_array(idx: object, n: int, name: str) -> np.ndarray:
    """Distinct DOF indices from an int array or a length-n bool mask."""
    arr = np.asarray(idx)
    if arr.dtype == np.bool_:
        if arr.shape != (n,):
            raise ValueError(f"{name} as a boolean mask must have shape ({n},), got {arr.shape}")
        return np.flatnonzero(arr)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a 1D index array, got shape {arr.shape}")
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        raise ValueError(f"{name} must hold integer DOF indices, got dtype {arr.dtype}")
    arr = arr.astype(np.int64)
    if arr.size and (arr.min() < 0 or arr.max() >= n):
        raise ValueError(f"{name} has indices outside [0, {n}): [{arr.min()}, {arr.max()}]")
    if np.unique(arr).size != arr.size:
        raise ValueError(f"{name} has repeated indices")
    return arr
