"""MARK: Dörfler (bulk) marking (docs/method.md, *Marking and refinement*).

References
----------
.. [1] W. Dörfler, A convergent adaptive algorithm for Poisson's equation,
   SIAM J. Numer. Anal. 33 (1996) 1106–1124.
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_theta", "mark_doerfler"]


def check_theta(theta: float, name: str = "theta") -> float:
    """The Dörfler parameter as a float in (0, 1]; a ``ValueError`` naming ``name`` otherwise."""
    if isinstance(theta, bool) or not isinstance(theta, int | float | np.floating | np.integer):
        raise ValueError(f"{name} must be a number in (0, 1], got {theta!r}")
    theta = float(theta)
    if not 0.0 < theta <= 1.0:
        raise ValueError(f"{name} must lie in (0, 1], got {theta}")
    return theta


def mark_doerfler(eta2: np.ndarray, theta: float) -> np.ndarray:
    """The smallest set of cells M with ``Σ_{T∈M} η_T² ≥ θ Σ_T η_T²``.

    The cells with the largest indicators are taken first (a sort, no Python loop), so the
    set has minimal cardinality. ``θ = 1`` means uniform refinement: every cell is marked, as
    it is when all indicators vanish.

    Parameters
    ----------
    eta2 : (n_cells,) float array
        Squared element indicators η_T² ≥ 0.
    theta : float
        Bulk parameter in (0, 1].

    Returns
    -------
    (n_cells,) bool array
    """
    theta = check_theta(theta)
    eta2 = np.asarray(eta2, dtype=np.float64)
    if eta2.ndim != 1:
        raise ValueError(f"eta2 must be one indicator per cell (1-d), got shape {eta2.shape}")
    if not np.isfinite(eta2).all():
        raise ValueError("eta2 contains NaN or inf indicators")
    if np.any(eta2 < 0):
        raise ValueError("eta2 holds squared indicators and must be non-negative")
    total = eta2.sum()
    if theta == 1.0 or total == 0.0:
        return np.ones(eta2.size, dtype=bool)  # uniform refinement
    marked = np.zeros(eta2.size, dtype=bool)
    order = np.argsort(-_tie_key(eta2), kind="stable")
    cumulative = np.cumsum(eta2[order])
    # first index where the running sum reaches θ·total (guard against round-off at the end)
    k = int(np.searchsorted(cumulative, theta * total * (1 - 1e-14), side="left")) + 1
    marked[order[: min(k, eta2.size)]] = True
    return marked


#: Indicators closer than this, relative to the largest, count as equal when they are sorted:
#: the cell with the smaller index comes first. Symmetric problems have pairs of equal
#: indicators whose last bits depend on round-off (the ordering of the unknowns, the
#: summation order): without it, which of a pair is refined would too.
TIE_RTOL = 1e-10


def _tie_key(eta2: np.ndarray) -> np.ndarray:
    """``η_T²`` rounded to multiples of ``TIE_RTOL · max η_T²`` (the sort key of marking)."""
    step = TIE_RTOL * eta2.max(initial=0.0)
    return np.round(eta2 / step) if step > 0 else eta2
