r"""The public norm functions: L², H^{1/2} seminorm and H^{1/2} norm of ``max(w, 0)`` on Γ_C.

Each takes the edges of Γ_C (``x0, x1 (k, 2)``) and a quadratic on each edge (values
``w (k, 3)`` at ``[start, end, midpoint]``) and returns the squared norm with its share
per edge. The shares sum to the total: the L² term and the zero-run term (functions of
``x`` alone once the ``y`` integral is done in closed form) go to the edge containing
``x``; a pair of pieces on edges ``e``, ``e'`` gives half of its (symmetric) contribution
to each. Edges where ``v = 0`` therefore receive exactly zero.
"""

from __future__ import annotations

import numpy as np

from ...fem.edge_trace import evaluate
from ...fem.quadrature import gauss_legendre
from . import parameters
from .pair_rules import same_edge_integral, same_edge_pairs
from .pieces import PositivePartPieces, positive_part_pieces
from .subdivision import cross_edge_integral, zero_run_pair_integral

__all__ = [
    "hhalf_norm2_positive_part",
    "hhalf_seminorm2_positive_part",
    "l2_norm2_positive_part",
    "l2_shares_of_pieces",
]


def _upper_pair_blocks(m: int, block: int):
    """Yield ``(i, j)`` index arrays of all pairs ``i < j < m`` in blocks of ~``block``."""
    if m < 2:
        return
    counts = np.arange(m - 1, 0, -1)
    cum = np.concatenate([[0], np.cumsum(counts)])
    row = 0
    while row < m - 1:
        stop = int(np.searchsorted(cum, cum[row] + block, side="right")) - 1
        stop = min(max(stop, row + 1), m - 1)
        rows = np.arange(row, stop)
        cnt = counts[row:stop]
        ii = np.repeat(rows, cnt)
        offs = np.arange(ii.size) - np.repeat(cum[row:stop] - cum[row], cnt)
        yield ii, ii + 1 + offs
        row = stop


def _l2_shares(pc: PositivePartPieces) -> np.ndarray:
    """``∫_P v^2`` per piece (3-point Gauss, exact for the quartic)."""
    t, wt = gauss_legendre(3)
    v = evaluate(pc.coef, np.broadcast_to(t, (pc.n_pieces, t.size)))
    return pc.length * ((v * v) @ wt)


def _seminorm_shares(pc: PositivePartPieces) -> np.ndarray:
    """The squared seminorm's share of each edge ``(k,)`` (see the module notes)."""
    k, m = pc.n_edges, pc.n_pieces
    if m == 0:
        return np.zeros(k)
    block = parameters.BLOCK
    share = np.zeros(m)  # per piece of S
    # pieces of the same edge (exact)
    ii, jj, mult = same_edge_pairs(pc)
    share += np.bincount(ii, weights=mult * same_edge_integral(pc, ii, jj), minlength=m)
    # pieces of different edges: each unordered pair counted twice, half to each piece
    for ii, jj in _upper_pair_blocks(m, block):
        keep = pc.edge[ii] != pc.edge[jj]
        ii, jj = ii[keep], jj[keep]
        if ii.size == 0:
            continue
        val = cross_edge_integral(pc, ii, jj)
        share += np.bincount(ii, weights=val, minlength=m)
        share += np.bincount(jj, weights=val, minlength=m)
    # S x (Γ_C \ S), both orders, to the piece in S
    r = pc.n_runs
    for start in range(0, m * r, block):
        ip, iz = np.divmod(np.arange(start, min(start + block, m * r)), r)
        share += np.bincount(ip, weights=2.0 * zero_run_pair_integral(pc, ip, iz), minlength=m)
    return np.bincount(pc.edge, weights=share, minlength=k)


def l2_norm2_positive_part(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> tuple[float, np.ndarray]:
    """``||max(w, 0)||^2_{L^2(Γ_C)}`` and its per-edge shares.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at ``[start, end, midpoint]``.
    validate : bool
        Check the input (see :func:`hhalf_norm2_positive_part`).
    scale : float, optional
        The size of the data ``w`` (see :func:`hhalf_norm2_positive_part`).

    Returns
    -------
    total : float
        The squared L² norm.
    eta2_edge : ndarray of float64, shape (k,)
        Share of each edge; sums to ``total``.
    """
    eta2 = l2_shares_of_pieces(positive_part_pieces(x0, x1, w, validate=validate, scale=scale))
    return float(eta2.sum()), eta2


def l2_shares_of_pieces(pc: PositivePartPieces) -> np.ndarray:
    """``(k,)`` float64: each edge's ``||max(w, 0)||^2_{L^2}`` from the pieces of ``{w > 0}``
    (:func:`.pieces.positive_part_pieces`), for callers that hold the pieces already."""
    eta2 = np.bincount(pc.edge, weights=_l2_shares(pc), minlength=pc.n_edges)
    return eta2.astype(np.float64)


def hhalf_seminorm2_positive_part(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> tuple[float, np.ndarray]:
    """``∫_{Γ_C}∫_{Γ_C} (v(x) - v(y))^2 / |x - y|^2``, ``v = max(w, 0)``, and per-edge shares.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at ``[start, end, midpoint]``.
    validate : bool
        Check the input (see :func:`hhalf_norm2_positive_part`).
    scale : float, optional
        The size of the data ``w`` (see :func:`hhalf_norm2_positive_part`).

    Returns
    -------
    total : float
        The squared Sobolev-Slobodeckij seminorm (full double integral).
    eta2_edge : ndarray of float64, shape (k,)
        Share of each edge (see the module notes); sums to ``total``.
    """
    eta2 = _seminorm_shares(positive_part_pieces(x0, x1, w, validate=validate, scale=scale))
    return float(eta2.sum()), eta2


def hhalf_norm2_positive_part(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> tuple[float, np.ndarray]:
    """η7² = ``||max(w, 0)||^2_{H^{1/2}(Γ_C)}`` and its split over the edges of Γ_C.

    The norm is ``||v||^2_{L^2} + ∫∫ (v(x) - v(y))^2 / |x - y|^2 ds_x ds_y``
    (η7 of Section 5 of the paper, with ``w = u_h·n - ψ`` on the contact edges).

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Start and end points of the straight edges of Γ_C, in any order;
        they may belong to several straight segments, connected or not.
    w : array_like of float64, shape (k, 3)
        Values of a quadratic on each edge at ``[start, end, midpoint]`` (the package's
        P2 edge-node order); its positive part must be continuous at shared end points.
    validate : bool
        Check shapes, finiteness, edge lengths and the continuity of ``max(w, 0)`` at
        shared end points. The estimator passes ``False``: its arrays come from a valid
        contact set (docs/method.md, *Estimator*).
    scale : float, optional
        The size of the data ``w`` is computed from (the estimator passes the largest
        displacement and gap). Where edges meet, ``max(w, 0)`` may differ by round-off of the
        data, ``CONTINUITY_RTOL · scale``, and is taken as continuous; a larger jump is
        an error. Default ``max|w|``: with ``w`` itself of the size of round-off (a contact
        zone closed to round-off), its own round-off would read as a jump.

    Returns
    -------
    total : float
        The squared norm (0.0 exactly if ``w <= 0`` everywhere).
    eta2_edge : ndarray of float64, shape (k,)
        Per-edge shares, ``>= 0``, summing to ``total``; zero on edges where
        ``v = 0``.

    Raises
    ------
    ValueError
        With ``validate``: on malformed input, zero-length edges or a jump of
        ``max(w, 0)`` at a shared end point. Always: on edges that cross or overlap where
        ``v > 0`` (found by the quadrature itself).
    """
    pc = positive_part_pieces(x0, x1, w, validate=validate, scale=scale)
    eta2 = _seminorm_shares(pc)
    eta2 = eta2 + np.bincount(pc.edge, weights=_l2_shares(pc), minlength=pc.n_edges)
    return float(eta2.sum()), eta2
