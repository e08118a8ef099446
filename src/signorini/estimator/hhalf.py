r"""The H^{1/2}(Γ_C) norm of the positive part of a piecewise quadratic (estimator term η7).

The last contribution of the residual estimator (Section 5, the definition of
η7 before (5.1); Section 6 for a non-zero gap) is

.. math::

    \eta_7^2 = \|v\|^2_{H^{1/2}(\Gamma_C)}, \qquad v = (u_h \cdot n - \psi)^+,

with the Sobolev-Slobodeckij norm

.. math::

    \|v\|^2_{H^{1/2}(\Gamma_C)} = \|v\|^2_{L^2(\Gamma_C)}
        + \int_{\Gamma_C}\int_{\Gamma_C} \frac{(v(x) - v(y))^2}{|x - y|^2}
          \, ds_x \, ds_y .

Γ_C is given as a list of straight edges ``x0 -> x1`` carrying a quadratic
``w`` (values at start, midpoint, end); ``v = max(w, 0)``.  Nothing else about
the mesh is needed.  The edges may lie on several straight segments, connected
or not, but must not cross or overlap (that is detected and reported).

Method (exact up to quadrature round-off, cost driven by the support of v):

* Every edge is cut at the real roots of its quadratic, so that v is a
  polynomial on each piece.  ``S`` is the set of pieces where ``v = w > 0``;
  the rest of Γ_C is merged into maximal straight *zero runs*.
* The double integral splits into ``∫_S∫_S`` plus
  ``2 ∫_S v(x)^2 (∫_{Γ_C \ S} |x - y|^{-2} ds_y) ds_x``.  The inner integral
  over a straight run ``[a, b]`` is analytic: ``L θ / |(a - x) × (b - x)|``
  with ``θ`` the angle the run subtends at ``x`` (``1/(ξ - L) - 1/ξ`` for
  collinear points, evaluated without cancellation).
* Pairs of pieces of the same edge (same quadratic) use the divided difference
  ``(w(s) - w(s')) / (s - s') = b + c (s + s')``, a polynomial: a 2 x 2
  Gauss rule is exact.
* Pairs of pieces of different edges are integrated by a vectorized
  hierarchical scheme: well separated panel pairs use tensor Gauss rules whose
  order depends on the separation; panels sharing an end point use a Duffy
  transformation that removes the non-smoothness at the common point (its
  angular order follows from the poles of the transformed integrand); all
  other pairs are subdivided.  A piece next to a zero run is subdivided until
  the run is long compared with the panel; there ``v^2 / t`` is a polynomial
  and ``t ∫_Z |x - y|^{-2}`` is analytic (``t`` = distance to the common
  point), so a Gauss rule converges geometrically.

Cost: O(k) vectorized work to find S and the runs (k = number of edges), then
O(|S|^2 + |S| r) panel pairs (r = number of zero runs), processed in blocks.

Per-edge shares ``eta2_edge`` sum to the total: the L² term and the zero-run
term (both functions of ``x`` alone once the ``y`` integral is done
analytically) go to the edge containing ``x``; a pair of pieces on edges
``e``, ``e'`` gives half of its (symmetric) contribution to each.  Edges where
``v = 0`` therefore receive exactly zero.

References
----------
.. [1] R. Khandelwal, K. Porwal, T. Wadhawan, "Adaptive quadratic finite
   element method for the unilateral contact problem", Section 5 (η7).
.. [2] M. G. Duffy, "Quadrature over a pyramid or cube of integrands with a
   singularity at a vertex", SIAM J. Numer. Anal. 19 (1982) 1260-1262.
.. [3] E. Di Nezza, G. Palatucci, E. Valdinoci, "Hitchhiker's guide to the
   fractional Sobolev spaces", Bull. Sci. Math. 136 (2012) 521-573.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import cache

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

__all__ = [
    "PositivePartPieces",
    "hhalf_norm2_positive_part",
    "hhalf_seminorm2_positive_part",
    "l2_norm2_positive_part",
    "positive_part_pieces",
    "segment_inverse_square_integral",
]

_log = logging.getLogger(__name__)

# ---- quadrature and subdivision parameters (module level so tests can tighten them)
#: (minimum separation / panel length, Gauss points per direction), tried in order
_FAR_TIERS: tuple[tuple[float, int], ...] = ((64.0, 4), (16.0, 6), (4.0, 8), (1.0, 12))
#: a panel touching a zero run is integrated once the run is this many times longer
_TOUCH_RUN_RATIO = 2.0
_TOUCH_RUN_ORDER = 12
#: touching panel pairs go to the Duffy rule once their lengths agree to this factor
#: (the longer one is cut first, which keeps the poles of the angular integrand away)
_DUFFY_RATIO = 1.0 + 1e-6
#: (radial, minimum angular) Gauss points of the Duffy rule; the radial integrand is a cubic
_DUFFY_ORDER = (3, 20)
#: the angular order is raised until the Gauss error bound is below exp(-_DUFFY_DIGITS)
_DUFFY_DIGITS = 40.0
_DUFFY_MAX_ORDER = 400
#: subdivision depth; separated pairs (distance > point tolerance) resolve long before
_MAX_LEVEL = 60
#: pairs per block (bounds the memory of the tensor rules)
_BLOCK = 4096
#: active panel pairs beyond which a subdivision is declared non-localising
_MAX_ACTIVE = 200_000
#: roots closer than this (in the edge parameter) to an end point are dropped
_ROOT_SNAP = 1e-13
#: a double root is assumed when |w| at the vertex of the parabola is below this (relative)
_TANGENT_TOL = 1e-13
#: relative tolerance for the continuity of v at shared end points
_CONTINUITY_RTOL = 1e-8
#: two directions are parallel when |sin| of their angle is below this
_PARALLEL_TOL = 1e-9


@cache
def _gauss01(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [0, 1] (read-only, cached)."""
    x, wts = np.polynomial.legendre.leggauss(n)
    pts, wt = 0.5 * (x + 1.0), 0.5 * wts
    pts.setflags(write=False)
    wt.setflags(write=False)
    return pts, wt


# --------------------------------------------------------------------------- input


def _check_input(x0, x1, w) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return float64 copies of the edge data, or raise ``ValueError``."""
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


def _point_ids(points: np.ndarray) -> np.ndarray:
    """Integer id per row of ``points (n, 2)``; equal coordinates get equal ids."""
    if points.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    key = np.ascontiguousarray(points).view(np.complex128).ravel()
    _, inv = np.unique(key, return_inverse=True)
    return inv.reshape(-1).astype(np.int64)


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
    bad = np.flatnonzero(jump > _CONTINUITY_RTOL * scale)
    if bad.size:
        where = np.flatnonzero(np.isin(pid, bad[:1]))
        edges = sorted({int(i) % n_edges for i in where})
        raise ValueError(
            f"v = max(w, 0) is discontinuous at {bad.size} shared end point(s) "
            f"(largest jump {jump[bad].max():.3e}, e.g. between edges {edges}); "
            "a jump has an infinite H^1/2 norm"
        )


# --------------------------------------------------------------------------- pieces


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
        """Largest value of v at the ends and midpoints of the pieces (0.0 if S is empty)."""
        if self.n_pieces == 0:
            return 0.0
        c0, c1, c2 = self.coef.T
        ends = np.abs(np.concatenate([c0, c0 + c1 + c2, c0 + 0.5 * c1 + 0.25 * c2]))
        return float(ends.max())


def _edge_monomials(w: np.ndarray) -> np.ndarray:
    """``(k, 3)`` coefficients of ``w(s) = a + b s + c s^2`` from (start, mid, end) values."""
    w0, wm, w1 = w[:, 0], w[:, 1], w[:, 2]
    return np.stack([w0, -3.0 * w0 + 4.0 * wm - w1, 2.0 * w0 - 4.0 * wm + 2.0 * w1], axis=1)


def _roots01(abc: np.ndarray, snap: np.ndarray) -> np.ndarray:
    """``(n, 2)`` sign-changing roots in (0, 1) of ``a + b s + c s^2``, NaN where absent.

    Double roots (tangency, no sign change), roots within ``snap (n,)`` of an
    end point and pairs of roots closer than ``snap`` are dropped (the sliver
    they would cut off is below the geometric tolerance).
    """
    scale = np.abs(abc).max(axis=1, keepdims=True)
    scale[scale == 0.0] = 1.0
    a, b, c = (abc / scale).T
    disc = b * b - 4.0 * a * c
    sq = np.sqrt(np.maximum(disc, 0.0))
    q = -0.5 * (b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(c != 0.0, q / np.where(c != 0.0, c, 1.0), np.nan)
        r2 = np.where(q != 0.0, a / np.where(q != 0.0, q, 1.0), np.nan)
        # |w| at the vertex of the parabola, |disc / (4 c)|: tiny means a double root
        tangent = (c != 0.0) & (np.abs(disc) <= 4.0 * _TANGENT_TOL * np.abs(c))
    roots = np.stack([r1, r2], axis=1)
    roots[(disc < 0.0) | tangent] = np.nan
    snap = snap[:, None]
    roots[~((roots > snap) & (roots < 1.0 - snap))] = np.nan
    roots[np.abs(roots[:, 0] - roots[:, 1]) <= snap[:, 0]] = np.nan
    return roots


def _edge_pieces(abc: np.ndarray, snap: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cut edges at their roots (see ``_roots01`` for ``snap``).

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
    roots = _roots01(abc, snap)
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
    a, b, c = abc[owner].T
    vals = a[:, None] + t * (b[:, None] + t * c[:, None])
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
    link = (np.abs(cross) <= _PARALLEL_TOL) & opposite
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


def positive_part_pieces(x0, x1, w) -> PositivePartPieces:
    """Cut Γ_C at the roots of ``w``: pieces of ``{w > 0}`` and straight zero runs.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Start and end points of the straight edges of Γ_C.
    w : array_like of float64, shape (k, 3)
        Values of a quadratic on each edge at (start, midpoint, end); ``w``
        must be continuous where edges share an end point (at least its
        positive part).

    Returns
    -------
    PositivePartPieces
        Pieces where ``v = max(w, 0) = w > 0`` and maximal straight runs of
        the rest of Γ_C.

    Raises
    ------
    ValueError
        On malformed input, zero-length edges, or if ``max(w, 0)`` jumps at a
        shared end point.
    """
    x0, x1, w = _check_input(x0, x1, w)
    k = x0.shape[0]
    coords = np.concatenate([x0, x1])
    if k:
        extent = np.abs(coords).max() + (coords.max(axis=0) - coords.min(axis=0)).max()
    else:
        extent = 1.0
    tol = 1e-12 * extent
    empty2 = np.zeros((0, 2))
    pid = _point_ids(coords)
    wscale = float(np.abs(w).max()) if k else 0.0
    _check_continuity(pid, np.maximum(np.concatenate([w[:, 0], w[:, 2]]), 0.0), k, wscale)

    abc = _edge_monomials(w)
    a, b, c = abc.T
    # edges where the quadratic is positive somewhere on [0, 1]
    cand = (w > 0.0).any(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        svert = np.where(c < 0.0, -b / np.where(c < 0.0, 2.0 * c, 1.0), -1.0)
    inner = (svert > 0.0) & (svert < 1.0)
    cand |= inner & (a + svert * (b + svert * c) > 0.0)
    cand_idx = np.flatnonzero(cand)

    if cand_idx.size == 0:
        return PositivePartPieces(
            k,
            np.zeros(0, dtype=np.int64),
            empty2,
            empty2,
            empty2,
            np.zeros(0),
            np.zeros((0, 3)),
            np.zeros((0, 3)),
            empty2,
            empty2,
            float(tol),
        )

    elen = np.hypot(*(x1 - x0).T)
    snap = np.maximum(_ROOT_SNAP, 4.0 * tol / elen[cand_idx])
    owner, s, positive = _edge_pieces(abc[cand_idx], snap)
    edge_all = cand_idx[owner]
    pt_lo = x0[edge_all] * (1.0 - s[:, :1]) + x1[edge_all] * s[:, :1]
    pt_hi = x0[edge_all] * (1.0 - s[:, 1:]) + x1[edge_all] * s[:, 1:]

    # S
    edge = edge_all[positive]
    sp = s[positive]
    ea, eb, ec = abc[edge].T
    s0, ds = sp[:, 0], sp[:, 1] - sp[:, 0]
    coef = np.stack([ea + s0 * (eb + s0 * ec), (eb + 2.0 * ec * s0) * ds, ec * ds * ds], axis=1)

    # zero set: whole non-candidate edges plus the non-positive pieces of candidates
    rest = np.flatnonzero(~cand)
    zsel = ~positive
    zedge = edge_all[zsel]
    zs = s[zsel]
    zpid0 = np.where(zs[:, 0] == 0.0, pid[zedge], -1)
    zpid1 = np.where(zs[:, 1] == 1.0, pid[k + zedge], -1)
    run_start, run_end = _zero_runs(
        np.concatenate([x0[rest], pt_lo[zsel]]),
        np.concatenate([x1[rest], pt_hi[zsel]]),
        np.concatenate([pid[rest], zpid0]),
        np.concatenate([pid[k + rest], zpid1]),
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
        tol=float(tol),
    )


# --------------------------------------------------------------------------- kernels


def segment_inverse_square_integral(x, a, b) -> np.ndarray:
    """``∫_{[a, b]} |x - y|^{-2} ds_y`` in closed form.

    Equal to ``L θ / |(a - x) × (b - x)|`` where ``L = |b - a|`` and ``θ`` is
    the angle subtended by the segment at ``x``; for ``x`` on the line of the
    segment (outside it) this is ``1/(ξ - L) - 1/ξ`` (``ξ`` = signed position
    along the segment), evaluated without cancellation.

    Parameters
    ----------
    x : array_like of float64, shape (..., 2)
        Evaluation points.
    a, b : array_like of float64, shape (..., 2)
        Segment end points, broadcast against ``x``.

    Returns
    -------
    ndarray of float64, shape (...)
        The integral; ``inf`` for points on the closed segment.
    """
    x = np.asarray(x, dtype=np.float64)
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if x.shape[-1:] != (2,) or a.shape[-1:] != (2,) or b.shape[-1:] != (2,):
        raise ValueError("x, a and b must have a last axis of length 2")
    return _inv_square(x, a, b)


def _inv_square(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ax0, ax1 = a[..., 0] - x[..., 0], a[..., 1] - x[..., 1]
    bx0, bx1 = b[..., 0] - x[..., 0], b[..., 1] - x[..., 1]
    cr = np.abs(ax0 * bx1 - ax1 * bx0)
    dt = ax0 * bx0 + ax1 * bx1
    length = np.hypot(b[..., 0] - a[..., 0], b[..., 1] - a[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        r = cr / dt
        small = (dt > 0.0) & (r < 1e-3)
        r2 = r * r
        series = (1.0 - r2 * (1.0 / 3.0 - r2 * (1.0 / 5.0 - r2 / 7.0))) / dt
        out = np.where(small, series, np.arctan2(cr, dt) / cr)
    return length * out


def _polyval(coef: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``coef[:, 0] + coef[:, 1] u + coef[:, 2] u^2`` with ``u (n, q)``."""
    return coef[:, :1] + u * (coef[:, 1:2] + u * coef[:, 2:3])


def _panel_points(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray):
    """End points of the sub-panels ``u (n, 2)`` of pieces ``idx``."""
    A, B = pc.start[idx], pc.end[idx]
    return A * (1.0 - u[:, :1]) + B * u[:, :1], A * (1.0 - u[:, 1:]) + B * u[:, 1:]


def _panel_nodes(pc: PositivePartPieces, idx: np.ndarray, u: np.ndarray, t: np.ndarray):
    """Coordinates ``x, y (n, q)`` and values ``v (n, q)`` at local nodes ``t (q,)``."""
    uu = u[:, :1] + (u[:, 1:] - u[:, :1]) * t
    A = pc.start[idx]
    D = pc.end[idx] - A
    return A[:, :1] + D[:, :1] * uu, A[:, 1:] + D[:, 1:] * uu, _polyval(pc.coef[idx], uu)


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    dd = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", p - a, d) / np.where(dd > 0.0, dd, 1.0)
    t = np.clip(t, 0.0, 1.0)
    return np.hypot(*(p - a - t[:, None] * d).T)


def _segment_distance(a1, b1, a2, b2) -> np.ndarray:
    """Distance between non-crossing segments ``[a1, b1]`` and ``[a2, b2]``."""
    return np.minimum.reduce(
        [
            _point_segment_distance(a1, a2, b2),
            _point_segment_distance(b1, a2, b2),
            _point_segment_distance(a2, a1, b1),
            _point_segment_distance(b2, a1, b1),
        ]
    )


def _tier_order(ratio: np.ndarray) -> np.ndarray:
    """Gauss order per pair from the separation ratio (0 = not admissible)."""
    order = np.zeros(ratio.shape, dtype=np.int64)
    for min_ratio, n in reversed(_FAR_TIERS):
        order[ratio >= min_ratio] = n
    return order


# --------------------------------------------------------------------------- S x S


def _same_edge_pairs(pc: PositivePartPieces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs of pieces of one edge (incl. a piece with itself), with multiplicity."""
    m = pc.n_pieces
    i = np.arange(m)
    nxt = np.flatnonzero(pc.edge[1:] == pc.edge[:-1])
    ii = np.concatenate([i, nxt])
    jj = np.concatenate([i, nxt + 1])
    mult = np.concatenate([np.ones(m), np.full(nxt.size, 2.0)])
    return ii, jj, mult


def _same_edge_integral(pc: PositivePartPieces, ii: np.ndarray, jj: np.ndarray) -> np.ndarray:
    """``∫_P∫_Q (v(x)-v(y))^2/|x-y|^2`` for pieces of one edge (exact, divided difference)."""
    t, wt = _gauss01(2)
    si = pc.s[ii, :1] + (pc.s[ii, 1:] - pc.s[ii, :1]) * t
    sj = pc.s[jj, :1] + (pc.s[jj, 1:] - pc.s[jj, :1]) * t
    b = pc.edge_coef[ii, 1][:, None, None]
    c = pc.edge_coef[ii, 2][:, None, None]
    dd = b + c * (si[:, :, None] + sj[:, None, :])
    jac = (pc.s[ii, 1] - pc.s[ii, 0]) * (pc.s[jj, 1] - pc.s[jj, 0])
    return jac * np.einsum("nij,i,j->n", dd * dd, wt, wt)


def _chunked(fn, n_items: int, *arrays) -> np.ndarray:
    """Apply ``fn`` to slices of ``_BLOCK`` rows of ``arrays`` and concatenate."""
    if n_items <= _BLOCK:
        return fn(*arrays)
    return np.concatenate(
        [fn(*(a[i : i + _BLOCK] for a in arrays)) for i in range(0, n_items, _BLOCK)]
    )


def _far_pair_integral(pc, p, up, q, uq, n: int) -> np.ndarray:
    """Tensor Gauss rule with ``n x n`` points on separated panel pairs."""
    return _chunked(lambda *a: _far_pair_kernel(pc, *a, n), p.size, p, up, q, uq)


def _far_pair_kernel(pc, p, up, q, uq, n: int) -> np.ndarray:
    t, wt = _gauss01(n)
    xp, yp, vp = _panel_nodes(pc, p, up, t)
    xq, yq, vq = _panel_nodes(pc, q, uq, t)
    diff = vp[:, :, None] - vq[:, None, :]
    d0 = xp[:, :, None] - xq[:, None, :]
    d1 = yp[:, :, None] - yq[:, None, :]
    f = diff * diff / (d0 * d0 + d1 * d1)
    lp = (up[:, 1] - up[:, 0]) * pc.length[p]
    lq = (uq[:, 1] - uq[:, 0]) * pc.length[q]
    return lp * lq * ((f @ wt) @ wt)


def _expansion(pc, idx, u, at_end):
    """Panel seen from its touching end: length, ``v = v_c + p1 t + p2 t^2``, direction."""
    lpc = pc.length[idx]
    uc = np.where(at_end, u[:, 1], u[:, 0])
    sigma = np.where(at_end, -1.0, 1.0)
    c0, c1, c2 = pc.coef[idx].T
    vc = c0 + uc * (c1 + uc * c2)
    p1 = sigma * (c1 + 2.0 * c2 * uc) / lpc
    p2 = c2 / lpc**2
    d = sigma[:, None] * (pc.end[idx] - pc.start[idx]) / lpc[:, None]
    return (u[:, 1] - u[:, 0]) * lpc, vc, p1, p2, d


def _duffy_angular_order(a: np.ndarray, b: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """Gauss points in ``z`` for the Duffy rule, from the poles of its integrand.

    The denominators vanish at ``z = (a/b) e^{±iα}`` and ``z = (b/a) e^{±iα}``;
    with ``ρ`` the Bernstein-ellipse parameter of the nearer pole for [0, 1],
    the Gauss error decays like ``ρ^{-2n}``.
    """
    alpha = np.arccos(np.clip(cos, -1.0, 1.0))
    rho = np.full(a.shape, np.inf)
    for r in (a / b, b / a):
        zeta = 2.0 * r * np.exp(1j * alpha) - 1.0
        root = np.sqrt(zeta * zeta - 1.0)
        rho = np.minimum(rho, np.maximum(np.abs(zeta + root), np.abs(zeta - root)))
    with np.errstate(divide="ignore"):
        n = np.ceil(_DUFFY_DIGITS / (2.0 * np.log(rho)))
    nmin, nmax = _DUFFY_ORDER[1], _DUFFY_MAX_ORDER
    return np.clip(np.nan_to_num(n, nan=nmax, posinf=nmax), nmin, nmax).astype(np.int64)


def _duffy_pair_integral(pc, p, up, p_end, q, uq, q_end) -> np.ndarray:
    """Duffy rule on touching panel pairs (see ``_duffy_pair_kernel``)."""
    return _chunked(lambda *a: _duffy_pair_kernel(pc, *a), p.size, p, up, p_end, q, uq, q_end)


def _duffy_pair_kernel(pc, p, up, p_end, q, uq, q_end) -> np.ndarray:
    """Panels with a common end point ``c``: Duffy split of ``[0, a] x [0, b]``.

    With ``t = a ρ, s = b ρ z`` (and the mirror triangle) the factor ``ρ^2``
    of ``(v(t) - v(s))^2`` cancels that of ``|x - y|^2``; what remains is a
    cubic in ``ρ`` times a smooth rational function of ``z``.
    """
    a, vp, p1, p2, dp = _expansion(pc, p, up, p_end)
    b, vq, q1, q2, dq = _expansion(pc, q, uq, q_end)
    jump = np.abs(vp - vq)
    if np.any(jump > _CONTINUITY_RTOL * pc.v_scale):
        # shared end points were checked on input: this is a point where edges cross
        raise ValueError(
            f"H^1/2 quadrature: v jumps by {jump.max():.3e} where two edges meet away "
            "from a shared end point; the edges of Γ_C probably overlap or cross each other"
        )
    cos = np.einsum("ij,ij->i", dp, dq)
    order = _duffy_angular_order(a, b, cos)
    out = np.empty(a.size)
    r, wr = _gauss01(_DUFFY_ORDER[0])
    r = r[None, :, None]
    for nz in np.unique(order):
        sel = np.flatnonzero(order == nz)
        z, wz = _gauss01(int(nz))
        z = z[None, None, :]
        aa, bb, cc, pp1, pp2, qq1, qq2 = (v[sel, None, None] for v in (a, b, cos, p1, p2, q1, q2))
        num1 = aa * (pp1 + pp2 * aa * r) - bb * z * (qq1 + qq2 * bb * r * z)
        den1 = aa * aa + bb * bb * z * z - 2.0 * aa * bb * z * cc
        num2 = aa * z * (pp1 + pp2 * aa * r * z) - bb * (qq1 + qq2 * bb * r)
        den2 = aa * aa * z * z + bb * bb - 2.0 * aa * bb * z * cc
        f = r * (num1 * num1 / den1 + num2 * num2 / den2)
        out[sel] = a[sel] * b[sel] * np.einsum("nij,i,j->n", f, wr, wz)
    return out


def _touch_ends(a1, b1, a2, b2, tol):
    """Whether two segments share an end point, and which end of each (True = end)."""
    dists = np.stack(
        [
            np.hypot(*(a1 - a2).T),
            np.hypot(*(a1 - b2).T),
            np.hypot(*(b1 - a2).T),
            np.hypot(*(b1 - b2).T),
        ],
        axis=1,
    )
    k = dists.argmin(axis=1)
    touching = dists[np.arange(k.size), k] <= tol
    return touching, k >= 2, (k % 2) == 1


def _cut_at_touch(u: np.ndarray, at_end: np.ndarray, frac: np.ndarray):
    """Cut sub-panels ``u (n, 2)`` at relative length ``frac`` from their touching end."""
    width = u[:, 1] - u[:, 0]
    cut = np.where(at_end, u[:, 1] - width * frac, u[:, 0] + width * frac)
    return np.stack([u[:, 0], cut], axis=1), np.stack([cut, u[:, 1]], axis=1)


def _unresolved(count: int) -> None:
    """Pairs still closer than the point tolerance after ``_MAX_LEVEL`` bisections."""
    if count:
        raise ValueError(
            f"H^1/2 quadrature: {count} panel pairs meet away from their end points; "
            "the edges of Γ_C probably overlap or cross each other"
        )


def _check_growth(n_active: int) -> None:
    """Stop a subdivision that no longer localises (overlapping or crossing edges)."""
    if n_active > _MAX_ACTIVE:
        raise ValueError(
            f"H^1/2 quadrature: {n_active} panel pairs still unresolved; the edges of "
            "Γ_C probably overlap or cross each other"
        )


def _split_half(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mid = 0.5 * (u[:, 0] + u[:, 1])
    return np.stack([u[:, 0], mid], axis=1), np.stack([mid, u[:, 1]], axis=1)


def _cross_edge_block(pc: PositivePartPieces, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``∫_P∫_Q`` for pairs of pieces of different edges; returns one value per pair."""
    out = np.zeros(p.size)
    owner = np.arange(p.size)
    up = np.tile([0.0, 1.0], (p.size, 1))
    uq = up.copy()
    for level in range(_MAX_LEVEL + 1):
        if owner.size == 0:
            break
        ap, bp = _panel_points(pc, p, up)
        aq, bq = _panel_points(pc, q, uq)
        lp = (up[:, 1] - up[:, 0]) * pc.length[p]
        lq = (uq[:, 1] - uq[:, 0]) * pc.length[q]
        touching, p_end, q_end = _touch_ends(ap, bp, aq, bq, pc.tol)
        lmax = np.maximum(lp, lq)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(touching, 0.0, _segment_distance(ap, bp, aq, bq) / lmax)
        order = _tier_order(ratio)
        if level == _MAX_LEVEL:
            _unresolved(np.count_nonzero((order == 0) & ~touching))
        for n in np.unique(order[order > 0]):
            sel = np.flatnonzero(order == n)
            np.add.at(out, owner[sel], _far_pair_integral(pc, p[sel], up[sel], q[sel], uq[sel], n))
        equal = touching & (lmax <= _DUFFY_RATIO * np.minimum(lp, lq))
        if level == _MAX_LEVEL:
            equal = touching
        sel = np.flatnonzero(equal)
        if sel.size:
            val = _duffy_pair_integral(pc, p[sel], up[sel], p_end[sel], q[sel], uq[sel], q_end[sel])
            np.add.at(out, owner[sel], val)
        if level == _MAX_LEVEL:
            break
        # touching, unequal: cut the longer panel at the length of the shorter
        new = []
        uneq = np.flatnonzero(touching & ~equal)
        if uneq.size:
            p_long = lp[uneq] > lq[uneq]
            s = uneq[p_long]  # P is longer: cut P
            for child in _cut_at_touch(up[s], p_end[s], lq[s] / lp[s]):
                new.append((owner[s], p[s], child, q[s], uq[s]))
            s = uneq[~p_long]  # Q is longer: cut Q
            for child in _cut_at_touch(uq[s], q_end[s], lp[s] / lq[s]):
                new.append((owner[s], p[s], up[s], q[s], child))
        # separated but too close: halve the longer panel
        near = np.flatnonzero(~touching & (order == 0))
        if near.size:
            p_long = lp[near] >= lq[near]
            s = near[p_long]
            for child in _split_half(up[s]):
                new.append((owner[s], p[s], child, q[s], uq[s]))
            s = near[~p_long]
            for child in _split_half(uq[s]):
                new.append((owner[s], p[s], up[s], q[s], child))
        if not new:
            break
        _check_growth(sum(n_[0].size for n_ in new))
        owner = np.concatenate([n_[0] for n_ in new])
        p = np.concatenate([n_[1] for n_ in new])
        up = np.concatenate([n_[2] for n_ in new])
        q = np.concatenate([n_[3] for n_ in new])
        uq = np.concatenate([n_[4] for n_ in new])
    return out


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


# --------------------------------------------------------------------------- S x zero runs


def _zero_run_kernel(pc, p, u, za, zb, n: int) -> np.ndarray:
    """Gauss rule with ``n`` points for ``∫_P v^2 ∫_Z |x - y|^{-2}`` on panels ``u``."""
    t, wt = _gauss01(n)
    x, y, v = _panel_nodes(pc, p, u, t)
    f = _inv_square(np.stack([x, y], axis=-1), za[:, None, :], zb[:, None, :])
    lp = (u[:, 1] - u[:, 0]) * pc.length[p]
    return lp * ((v * v * f) @ wt)


def _zero_run_block(pc: PositivePartPieces, p: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``∫_P v(x)^2 ∫_Z |x - y|^{-2} ds_y ds_x`` for pairs (piece, zero run)."""
    out = np.zeros(p.size)
    owner = np.arange(p.size)
    u = np.tile([0.0, 1.0], (p.size, 1))
    for level in range(_MAX_LEVEL + 1):
        if owner.size == 0:
            break
        a, b = _panel_points(pc, p, u)
        za, zb = pc.run_start[z], pc.run_end[z]
        lp = (u[:, 1] - u[:, 0]) * pc.length[p]
        lz = np.hypot(*(zb - za).T)
        touching, _, _ = _touch_ends(a, b, za, zb, pc.tol)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(touching, 0.0, _segment_distance(a, b, za, zb) / lp)
        order = _tier_order(ratio)
        order[touching & (lz >= _TOUCH_RUN_RATIO * lp)] = _TOUCH_RUN_ORDER
        if level == _MAX_LEVEL:
            _unresolved(np.count_nonzero(order == 0))
        for n in np.unique(order[order > 0]):
            sel = np.flatnonzero(order == n)
            val = _chunked(
                lambda *a, n=int(n): _zero_run_kernel(pc, *a, n),
                sel.size,
                p[sel],
                u[sel],
                za[sel],
                zb[sel],
            )
            np.add.at(out, owner[sel], val)
        split = np.flatnonzero(order == 0)
        if split.size == 0:
            break
        _check_growth(2 * split.size)
        lo, hi = _split_half(u[split])
        owner = np.concatenate([owner[split], owner[split]])
        p = np.concatenate([p[split], p[split]])
        z = np.concatenate([z[split], z[split]])
        u = np.concatenate([lo, hi])
    return out


# --------------------------------------------------------------------------- assembly


def _l2_from_pieces(pc: PositivePartPieces) -> np.ndarray:
    """``∫_P v^2`` per piece (3-point Gauss, exact for the quartic)."""
    t, wt = _gauss01(3)
    v = _polyval(pc.coef, np.broadcast_to(t, (pc.n_pieces, t.size)))
    return pc.length * ((v * v) @ wt)


def _seminorm_from_pieces(pc: PositivePartPieces) -> tuple[float, np.ndarray]:
    """Squared seminorm and its per-edge shares (see the module notes)."""
    k, m = pc.n_edges, pc.n_pieces
    if m == 0:
        return 0.0, np.zeros(k)
    share = np.zeros(m)  # per piece of S
    # pieces of the same edge (exact)
    ii, jj, mult = _same_edge_pairs(pc)
    share += np.bincount(ii, weights=mult * _same_edge_integral(pc, ii, jj), minlength=m)
    # pieces of different edges: each unordered pair counted twice, half to each piece
    for ii, jj in _upper_pair_blocks(m, _BLOCK):
        keep = pc.edge[ii] != pc.edge[jj]
        ii, jj = ii[keep], jj[keep]
        if ii.size == 0:
            continue
        val = _cross_edge_block(pc, ii, jj)
        share += np.bincount(ii, weights=val, minlength=m)
        share += np.bincount(jj, weights=val, minlength=m)
    # S x (Γ_C \ S), both orders, to the piece in S
    r = pc.n_runs
    for start in range(0, m * r, _BLOCK):
        ip, iz = np.divmod(np.arange(start, min(start + _BLOCK, m * r)), r)
        share += np.bincount(ip, weights=2.0 * _zero_run_block(pc, ip, iz), minlength=m)
    eta2 = np.bincount(pc.edge, weights=share, minlength=k)
    return float(eta2.sum()), eta2


def l2_norm2_positive_part(x0, x1, w) -> tuple[float, np.ndarray]:
    """``||max(w, 0)||^2_{L^2(Γ_C)}`` and its per-edge shares.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at (start, midpoint, end).

    Returns
    -------
    total : float
        The squared L² norm.
    eta2_edge : ndarray of float64, shape (k,)
        Share of each edge; sums to ``total``.
    """
    pc = positive_part_pieces(x0, x1, w)
    eta2 = np.bincount(pc.edge, weights=_l2_from_pieces(pc), minlength=pc.n_edges)
    return float(eta2.sum()), eta2.astype(np.float64)


def hhalf_seminorm2_positive_part(x0, x1, w) -> tuple[float, np.ndarray]:
    """``∫_{Γ_C}∫_{Γ_C} (v(x) - v(y))^2 / |x - y|^2``, ``v = max(w, 0)``, and per-edge shares.

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Edge end points.
    w : array_like of float64, shape (k, 3)
        Quadratic on each edge, values at (start, midpoint, end).

    Returns
    -------
    total : float
        The squared Sobolev-Slobodeckij seminorm (full double integral).
    eta2_edge : ndarray of float64, shape (k,)
        Share of each edge (see the module notes); sums to ``total``.
    """
    return _seminorm_from_pieces(positive_part_pieces(x0, x1, w))


def hhalf_norm2_positive_part(x0, x1, w) -> tuple[float, np.ndarray]:
    """η7² = ``||max(w, 0)||^2_{H^{1/2}(Γ_C)}`` and its split over the edges of Γ_C.

    The norm is ``||v||^2_{L^2} + ∫∫ (v(x) - v(y))^2 / |x - y|^2 ds_x ds_y``
    (η7 of Section 5 of the paper, with ``w = u_h·n - ψ`` on the contact edges).

    Parameters
    ----------
    x0, x1 : array_like of float64, shape (k, 2)
        Start and end points of the straight edges of Γ_C, in any order;
        they may belong to several straight segments, connected or not.
    w : array_like of float64, shape (k, 3)
        Values of a quadratic on each edge at (start, midpoint, end); its
        positive part must be continuous at shared end points.

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
        On malformed input, zero-length edges, a jump of ``max(w, 0)`` at a
        shared end point, or edges that cross or overlap where v > 0.
    """
    pc = positive_part_pieces(x0, x1, w)
    _, eta2 = _seminorm_from_pieces(pc)
    eta2 = eta2 + np.bincount(pc.edge, weights=_l2_from_pieces(pc), minlength=pc.n_edges)
    return float(eta2.sum()), eta2
