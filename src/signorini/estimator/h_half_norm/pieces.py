r"""Γ_C cut at the roots of ``w``: the pieces of ``S = {w > 0}`` and the zero runs.

Every edge is cut at the sign-changing roots of its quadratic
(:func:`signorini.fem.edge_trace.roots_in_unit_interval`), so that ``v = max(w, 0)`` is a
polynomial on each piece. The pieces where ``v = w > 0`` form ``S``; the rest of Γ_C is
merged into maximal straight *zero runs*, over which the inner integral of the seminorm is
done in closed form (:mod:`.panels`). Validation of the edge data lives here too
(:func:`check_edge_data`), for the public functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ...fem.edge_trace import (
    evaluate,
    maximum_on_unit_interval,
    monomial_coefficients,
    roots_in_unit_interval,
)
from . import parameters

__all__ = ["PositivePartPieces", "check_edge_data", "positive_part_pieces"]


@dataclass(frozen=True)
class PositivePartPieces:
    """Γ_C cut at the roots of ``w``: the pieces of ``S = {w > 0}`` and the zero runs.

    Attributes
    ----------
    n_edges : int
        Number ``k`` of input edges.
    edge : ndarray of int64, shape (m,)
        Input edge of each piece of S (pieces of one edge are consecutive).
    s : ndarray of float64, shape (m, 2)
        Parameter range ``[s_start, s_end]`` of the piece in its edge
        (``x = x0 + s (x1 - x0)``).
    start, end : ndarray of float64, shape (m, 2)
        End points of the pieces.
    length : ndarray of float64, shape (m,)
        Piece lengths.
    coef : ndarray of float64, shape (m, 3)
        ``v = coef[0] + coef[1] u + coef[2] u**2`` on the piece, ``u`` in [0, 1]
        from ``start`` to ``end``.
    edge_coef : ndarray of float64, shape (m, 3)
        ``w = a + b s + c s**2`` on the whole edge of the piece.
    run_start, run_end : ndarray of float64, shape (r, 2)
        End points of the maximal straight runs of ``Γ_C \\ S`` (where v = 0).
    tol : float
        Distance below which two points are taken as the same point.
    scale : float
        The size of the data ``w`` comes from (default ``max|w|``; the estimator passes the
        displacement's and the gap's): a jump of ``v`` at a point where edges meet below
        ``CONTINUITY_RTOL · scale`` is round-off, not a discontinuity.
    """

    n_edges: int
    edge: np.ndarray
    s: np.ndarray
    start: np.ndarray
    end: np.ndarray
    length: np.ndarray
    coef: np.ndarray
    edge_coef: np.ndarray
    run_start: np.ndarray
    run_end: np.ndarray
    tol: float
    scale: float = 0.0

    @property
    def n_pieces(self) -> int:
        """Number ``m`` of pieces of S."""
        return int(self.edge.shape[0])

    @property
    def n_runs(self) -> int:
        """Number ``r`` of zero runs."""
        return int(self.run_start.shape[0])

    @property
    def v_scale(self) -> float:
        """The scale of ``v`` for continuity checks: :attr:`scale`, or the largest value of v
        at the ends and midpoints of the pieces if that is larger (0.0 if S is empty)."""
        if self.n_pieces == 0:
            return 0.0
        c0, c1, c2 = self.coef.T
        ends = np.abs(np.concatenate([c0, c0 + c1 + c2, c0 + 0.5 * c1 + 0.25 * c2]))
        return max(float(ends.max()), self.scale)


# --------------------------------------------------------------------------- validation


def check_edge_data(x0, x1, w) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Float64 contiguous copies of the edge data, or a ``ValueError`` saying what is wrong.

    Parameters
    ----------
    x0, x1 : array_like, shape (k, 2)
        Edge end points.
    w : array_like, shape (k, 3)
        Values of a quadratic on each edge at ``[start, end, midpoint]``.

    Raises
    ------
    ValueError
        On non-real or non-finite values, wrong shapes, different edge counts, or edges
        of zero length.
    """
    arrays = []
    for name, arr, width in (("x0", x0, 2), ("x1", x1, 2), ("w", w, 3)):
        try:
            a = np.asarray(arr, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{name} must be a real array of shape (k, {width}): {exc}") from None
        if a.ndim != 2 or a.shape[1] != width:
            raise ValueError(f"{name} must have shape (k, {width}), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{name} contains NaN or infinite values")
        arrays.append(np.ascontiguousarray(a))
    x0a, x1a, wa = arrays
    k = x0a.shape[0]
    if x1a.shape[0] != k or wa.shape[0] != k:
        raise ValueError(
            f"x0, x1 and w must have the same number of edges, got "
            f"{k}, {x1a.shape[0]} and {wa.shape[0]}"
        )
    length = np.hypot(*(x1a - x0a).T)
    bad = np.flatnonzero(length == 0.0)
    if bad.size:
        raise ValueError(f"edges of zero length (x0 == x1) at indices {bad[:10].tolist()}")
    return x0a, x1a, wa


def _check_continuity(pid: np.ndarray, v_end: np.ndarray, n_edges: int, scale: float) -> None:
    """Raise ``ValueError`` if ``v`` jumps at an end point shared by several edges."""
    if pid.size == 0:
        return
    n_ids = int(pid.max()) + 1
    vmax = np.full(n_ids, -np.inf)
    vmin = np.full(n_ids, np.inf)
    np.maximum.at(vmax, pid, v_end)
    np.minimum.at(vmin, pid, v_end)
    jump = vmax - vmin
    bad = np.flatnonzero(jump > parameters.CONTINUITY_RTOL * scale)
    if bad.size:
        where = np.flatnonzero(np.isin(pid, bad[:1]))
        edges = sorted({int(i) % n_edges for i in where})
        raise ValueError(
            f"v = max(w, 0) is discontinuous at {bad.size} shared end point(s) "
            f"(largest jump {jump[bad].max():.3e}, e.g. between edges {edges}); "
            "a jump has an infinite H^1/2 norm"
        )


# --------------------------------------------------------------------------- cutting


def _point_ids(points: np.ndarray) -> np.ndarray:
    """Integer id per row of ``points (n, 2)``; equal coordinates get equal ids."""
    if points.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    key = np.ascontiguousarray(points).view(np.complex128).ravel()
    _, inv = np.unique(key, return_inverse=True)
    return inv.reshape(-1).astype(np.int64)


def _edge_pieces(abc: np.ndarray, snap: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cut edges at their roots (``snap`` as in ``roots_in_unit_interval``).

    Returns
    -------
    owner : ndarray of int64, shape (p,)
        Row of ``abc`` the piece belongs to.
    s : ndarray of float64, shape (p, 2)
        Parameter range of the piece.
    positive : ndarray of bool, shape (p,)
        Whether ``w > 0`` on the piece.
    """
    n = abc.shape[0]
    roots = roots_in_unit_interval(abc, snap)
    bp = np.concatenate(
        [np.zeros((n, 1)), np.where(np.isnan(roots), 1.0, roots), np.ones((n, 1))], axis=1
    )
    bp.sort(axis=1)
    lo, hi = bp[:, :3], bp[:, 1:]
    keep = hi > lo
    owner = np.repeat(np.arange(n), keep.sum(axis=1))
    s = np.stack([lo[keep], hi[keep]], axis=1)
    # sign: a non-zero quadratic vanishes at <= 2 of 3 sample points; use the largest |w|
    t = s[:, :1] + (s[:, 1:] - s[:, :1]) * np.array([0.25, 0.5, 0.75])
    vals = evaluate(abc[owner], t)
    pick = vals[np.arange(vals.shape[0]), np.abs(vals).argmax(axis=1)]
    return owner, s, pick > 0.0


def _zero_runs(
    start: np.ndarray, end: np.ndarray, pid0: np.ndarray, pid1: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Merge zero pieces into maximal straight runs.

    Two pieces are merged when they share an end point (same id, ``>= 0``),
    are parallel and lie on opposite sides of that point.  At a point shared
    by more than two pieces only two of them are considered (the result is
    still exact, merging only saves work).
    """
    n = start.shape[0]
    if n == 0:
        return np.zeros((0, 2)), np.zeros((0, 2))
    d = end - start
    d /= np.hypot(*d.T)[:, None]
    ids = np.concatenate([pid0, pid1])
    piece = np.concatenate([np.arange(n), np.arange(n)])
    valid = ids >= 0
    ids, piece = ids[valid], piece[valid]
    # the first and the last piece seen at each point (no sort needed)
    n_ids = int(ids.max()) + 1 if ids.size else 0
    first = np.full(n_ids, -1, dtype=np.int64)
    last = np.full(n_ids, -1, dtype=np.int64)
    first[ids[::-1]] = piece[::-1]
    last[ids] = piece
    pts = np.flatnonzero((first >= 0) & (first != last))
    pa, pb = first[pts], last[pts]
    at_a = np.where((pid0[pa] == pts)[:, None], start[pa], end[pa])
    far_a = np.where((pid0[pa] == pts)[:, None], end[pa], start[pa])
    far_b = np.where((pid0[pb] == pts)[:, None], end[pb], start[pb])
    cross = d[pa, 0] * d[pb, 1] - d[pa, 1] * d[pb, 0]
    opposite = np.einsum("ij,ij->i", far_a - at_a, far_b - at_a) < 0.0
    link = (np.abs(cross) <= parameters.PARALLEL_TOL) & opposite
    graph = coo_matrix((np.ones(int(link.sum())), (pa[link], pb[link])), shape=(n, n))
    n_comp, label = connected_components(graph.tocsr(), directed=False)
    # extreme points of each component along its direction (exact input coordinates)
    rep = np.full(n_comp, n, dtype=np.int64)
    np.minimum.at(rep, label, np.arange(n))
    ref, dref = start[rep], d[rep]
    both = np.concatenate([start, end])
    lab = np.concatenate([label, label])
    proj = np.einsum("ij,ij->i", both - ref[lab], dref[lab])
    lo_val = np.full(n_comp, np.inf)
    hi_val = np.full(n_comp, -np.inf)
    np.minimum.at(lo_val, lab, proj)
    np.maximum.at(hi_val, lab, proj)
    idx = np.arange(lab.size)
    lo = np.full(n_comp, lab.size, dtype=np.int64)
    hi = np.full(n_comp, lab.size, dtype=np.int64)
    m_lo = proj == lo_val[lab]
    m_hi = proj == hi_val[lab]
    np.minimum.at(lo, lab[m_lo], idx[m_lo])
    np.minimum.at(hi, lab[m_hi], idx[m_hi])
    return both[lo].copy(), both[hi].copy()


def _zero_set_runs(x0, x1, pid, rest, zedge, zs, z_lo, z_hi) -> tuple[np.ndarray, np.ndarray]:
    """The maximal straight runs of ``Γ_C \\ S``: the edges ``rest`` where ``w ≤ 0`` and
    the non-positive pieces ``[z_lo, z_hi]`` (parameters ``zs``) of the edges ``zedge``.

    ``pid (2k,)`` are the point ids of the edges' start and end points; a piece keeps the
    id of an edge end point it reaches, so runs are merged across edges.
    """
    k = x0.shape[0]
    zpid0 = np.where(zs[:, 0] == 0.0, pid[zedge], -1)
    zpid1 = np.where(zs[:, 1] == 1.0, pid[k + zedge], -1)
    return _zero_runs(
        np.concatenate([x0[rest], z_lo]),
        np.concatenate([x1[rest], z_hi]),
        np.concatenate([pid[rest], zpid0]),
        np.concatenate([pid[k + rest], zpid1]),
    )


def _no_pieces(k: int, tol: float, scale: float) -> PositivePartPieces:
    """``S`` empty: nothing to integrate (the zero runs are not needed either)."""
    empty2 = np.zeros((0, 2))
    empty3 = np.zeros((0, 3))
    none = np.zeros(0, dtype=np.int64)
    return PositivePartPieces(
        k, none, empty2, empty2, empty2, np.zeros(0), empty3, empty3, empty2, empty2, tol, scale
    )


def positive_part_pieces(
    x0, x1, w, *, validate: bool = True, scale: float | None = None
) -> PositivePartPieces:
    """Cut Γ_C at the roots of ``w``: pieces of ``{w > 0}`` and straight zero runs.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Start and end points of the straight edges of Γ_C.
    w : array_like of float64, shape (k, 3)
        Values of a quadratic on each edge at ``[start, end, midpoint]``; ``w``
        must be continuous where edges share an end point (at least its
        positive part).
    validate : bool
        Check the input (:func:`check_edge_data` and the continuity of ``max(w, 0)``);
        callers whose arrays come from a valid mesh pass ``False``.
    scale : float, optional
        The size of the data ``w`` is computed from (for ``w = u_h·n − ψ_h``: the largest
        displacement and gap); ``v`` may jump by round-off, ``CONTINUITY_RTOL · scale``, where
        edges meet. Default ``max|w|``; a larger ``scale`` only widens that allowance.

    Returns
    -------
    PositivePartPieces
        Pieces where ``v = max(w, 0) = w > 0`` and maximal straight runs of
        the rest of Γ_C.

    Raises
    ------
    ValueError
        With ``validate``: on malformed input, zero-length edges, or if ``max(w, 0)``
        jumps at a shared end point.
    """
    if validate:
        x0, x1, w = check_edge_data(x0, x1, w)
    k = x0.shape[0]
    coords = np.concatenate([x0, x1])
    extent = np.abs(coords).max() + np.ptp(coords, axis=0).max() if k else 1.0
    tol = float(parameters.POINT_TOL * extent)
    pid = _point_ids(coords)
    own = float(np.abs(w).max()) if k else 0.0
    scale = own if scale is None else max(own, float(scale))
    if validate:
        ends = np.maximum(np.concatenate([w[:, 0], w[:, 1]]), 0.0)
        _check_continuity(pid, ends, k, scale)

    abc = monomial_coefficients(w)
    cand = maximum_on_unit_interval(w, abc) > 0.0  # edges where v > 0 somewhere
    cand_idx = np.flatnonzero(cand)
    if cand_idx.size == 0:
        return _no_pieces(k, tol, scale)

    elen = np.hypot(*(x1 - x0).T)
    snap = np.maximum(parameters.ROOT_SNAP, 4.0 * tol / elen[cand_idx])
    owner, s, positive = _edge_pieces(abc[cand_idx], snap)
    edge_all = cand_idx[owner]
    pt_lo = x0[edge_all] * (1.0 - s[:, :1]) + x1[edge_all] * s[:, :1]
    pt_hi = x0[edge_all] * (1.0 - s[:, 1:]) + x1[edge_all] * s[:, 1:]

    # S, each piece re-parametrised by u in [0, 1]
    edge = edge_all[positive]
    sp = s[positive]
    ea, eb, ec = abc[edge].T
    s0, ds = sp[:, 0], sp[:, 1] - sp[:, 0]
    coef = np.stack([ea + s0 * (eb + s0 * ec), (eb + 2.0 * ec * s0) * ds, ec * ds * ds], axis=1)

    zero = ~positive
    run_start, run_end = _zero_set_runs(
        x0, x1, pid, np.flatnonzero(~cand), edge_all[zero], s[zero], pt_lo[zero], pt_hi[zero]
    )
    return PositivePartPieces(
        n_edges=k,
        edge=edge.astype(np.int64),
        s=sp,
        start=pt_lo[positive],
        end=pt_hi[positive],
        length=ds * elen[edge],
        coef=coef,
        edge_coef=abc[edge],
        run_start=run_start,
        run_end=run_end,
        tol=tol,
        scale=scale,
    )
