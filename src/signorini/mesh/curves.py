"""Boundary curves: the exact geometry a boundary part may carry.

A curve answers three questions, vectorized over points ``x`` of shape ``(n, 2)``:

- :meth:`~Curve.project`: the nearest point of the curve to each point;
- :meth:`~Curve.normal` (and :meth:`~Curve.tangent`): the unit normal and tangent of the curve
  at points on it;
- :meth:`~Curve.halfway`: the point halfway along the curve between two points on it, where
  refinement puts the new vertex of a bisected boundary edge and where the P2 space puts the
  edge's midpoint node.

A part carries a curve through :meth:`signorini.mesh.Mesh.with_curve`;
:func:`signorini.mesh.read_mesh` attaches a :class:`QuadraticBoundary` to a part whose
second-order edges are curved.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial import cKDTree

from .geometry import spanned_normals
from .validation import MeshError

__all__ = ["Circle", "Curve", "Line", "ProjectedCurve", "QuadraticBoundary"]


def _points(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    return x.reshape(-1, 2)


def _pair(value: object, what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = np.full(3, np.nan)
    if a.shape != (2,) or not np.isfinite(a).all():
        raise MeshError(f"{what} must be two finite numbers (x, y), got {value!r}")
    return a


class Curve:
    """A boundary curve. Subclasses define :meth:`project`, :meth:`normal`, :meth:`halfway`.

    Normals follow one convention: the normal is the tangent turned clockwise by 90°, and
    each curve states which way its tangent runs, so the normal points out of a domain that
    lies to the left of the tangent (a counter-clockwise boundary).
    """

    #: whether :meth:`normal` is available
    has_normal = True

    def project(self, x: np.ndarray) -> np.ndarray:
        """``(n, 2)`` nearest points of the curve to the points ``x (n, 2)``."""
        raise NotImplementedError

    def normal(self, x: np.ndarray) -> np.ndarray:
        """``(n, 2)`` unit normals at the points ``x (n, 2)`` of the curve."""
        raise NotImplementedError

    def tangent(self, x: np.ndarray) -> np.ndarray:
        """``(n, 2)`` unit tangents at the points ``x (n, 2)``: the normal turned
        counter-clockwise by 90°."""
        n = self.normal(x)
        return np.column_stack([-n[:, 1], n[:, 0]])

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """``(n, 2)`` points halfway along the curve between the points ``p`` and ``q``
        ``(n, 2)`` of the curve."""
        raise NotImplementedError


class Line(Curve):
    """The straight line through ``a`` and ``b`` (not only the segment).

    The tangent runs from ``a`` to ``b``; the normal points to its right. Halfway points are
    chord midpoints, so a part carrying a line refines exactly as a part carrying nothing.
    """

    def __init__(self, a: object, b: object) -> None:
        self.a = _pair(a, "Line: a")
        self.b = _pair(b, "Line: b")
        d = self.b - self.a
        length = float(np.hypot(d[0], d[1]))
        if length == 0.0:
            raise MeshError(f"Line: a and b are the same point {self.a.tolist()}")
        self.direction = d / length

    def project(self, x: np.ndarray) -> np.ndarray:
        x = _points(x)
        s = (x - self.a) @ self.direction
        return self.a + s[:, None] * self.direction

    def normal(self, x: np.ndarray) -> np.ndarray:
        t = self.direction
        return np.broadcast_to(np.array([t[1], -t[0]]), _points(x).shape).copy()

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return 0.5 * (_points(p) + _points(q))

    def __repr__(self) -> str:
        return f"Line({self.a.tolist()}, {self.b.tolist()})"


class Circle(Curve):
    """The circle of centre ``center`` and radius ``radius``; a part on it is an arc.

    The normal points away from the centre (outward for a disc, inward for a hole); the
    tangent runs counter-clockwise. The halfway point of ``p`` and ``q`` is the midpoint of
    the *shorter* arc between them (for diametrically opposite points, which no mesh edge
    should join, the one reached counter-clockwise from ``p``). Points are placed as
    ``center + radius (cos φ, sin φ)``, so they lie on the circle to round-off.
    """

    def __init__(self, center: object, radius: object) -> None:
        self.center = _pair(center, "Circle: center")
        try:
            r = float(radius)
        except (TypeError, ValueError):
            r = np.nan
        if not np.isfinite(r) or r <= 0:
            raise MeshError(f"Circle: radius must be a positive number, got {radius!r}")
        self.radius = r

    def _angle(self, x: np.ndarray) -> np.ndarray:
        d = _points(x) - self.center
        return np.arctan2(d[:, 1], d[:, 0])

    def _at(self, phi: np.ndarray) -> np.ndarray:
        return self.center + self.radius * np.column_stack([np.cos(phi), np.sin(phi)])

    def project(self, x: np.ndarray) -> np.ndarray:
        """Nearest points; the centre itself (no nearest point) goes to angle 0."""
        return self._at(self._angle(x))

    def normal(self, x: np.ndarray) -> np.ndarray:
        phi = self._angle(x)
        return np.column_stack([np.cos(phi), np.sin(phi)])

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        a = self._angle(p)
        turn = np.mod(self._angle(q) - a + np.pi, 2 * np.pi) - np.pi  # in [-π, π)
        turn = np.where(turn == -np.pi, np.pi, turn)
        return self._at(a + 0.5 * turn)

    def __repr__(self) -> str:
        return f"Circle({self.center.tolist()}, {self.radius})"


class ProjectedCurve(Curve):
    """A user curve given by its projection ``project(x) -> nearest points``.

    Parameters
    ----------
    project : callable ``project(x (n, 2)) -> (n, 2)``
        The nearest point of the curve to each point (the package's convention for user
        functions, docs/method.md *User functions*).
    normal : callable ``normal(x (n, 2)) -> (n, 2)``, optional
        Unit normals at points of the curve; without it :meth:`normal` raises. Checked where
        they are used: unit length (:data:`UNIT_TOL`), and, on a contact part, across the
        boundary (not along it) at each node.

    The halfway point of ``p`` and ``q`` is the projection of the chord midpoint
    ``(p + q) / 2``: the midpoint along the curve up to O(h³) for a smooth curve, not exactly.
    """

    def __init__(
        self,
        project: Callable[[np.ndarray], np.ndarray],
        normal: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> None:
        if not callable(project):
            raise MeshError(
                f"ProjectedCurve: project must be a function x (n, 2) -> (n, 2), got "
                f"{type(project).__name__}"
            )
        if normal is not None and not callable(normal):
            raise MeshError(
                f"ProjectedCurve: normal must be a function x (n, 2) -> (n, 2) or None, got "
                f"{type(normal).__name__}"
            )
        self._project = project
        self._normal = normal
        self.has_normal = normal is not None

    def _call(self, what: str, f: Callable, x: np.ndarray) -> np.ndarray:
        x = _points(x)
        try:
            y = np.asarray(f(x), dtype=np.float64)
        except Exception as exc:
            raise MeshError(f"ProjectedCurve: {what} raised {type(exc).__name__}: {exc}") from exc
        if y.shape != x.shape or not np.isfinite(y).all():
            raise MeshError(
                f"ProjectedCurve: {what} must return finite points of shape {x.shape}, got "
                f"shape {y.shape}" + ("" if y.shape != x.shape else " with non-finite values")
            )
        return y

    def project(self, x: np.ndarray) -> np.ndarray:
        return self._call("project", self._project, x)

    def normal(self, x: np.ndarray) -> np.ndarray:
        """The user's normals at ``x``; ``MeshError`` naming a point where |n| ≠ 1."""
        if self._normal is None:
            raise MeshError("ProjectedCurve: no normal function was given")
        n = self._call("normal", self._normal, x)
        length = np.hypot(n[:, 0], n[:, 1])
        bad = np.flatnonzero(np.abs(length - 1.0) > UNIT_TOL)
        if bad.size:
            i = bad[0]
            raise MeshError(
                f"ProjectedCurve: normal must return unit vectors; at the point "
                f"({x[i, 0]:.12g}, {x[i, 1]:.12g}) it returned ({n[i, 0]:.6g}, {n[i, 1]:.6g}) of "
                f"length {length[i]:.6g} ({bad.size} of {len(n)} points are off by more than "
                f"{UNIT_TOL:g}); normalise it"
            )
        return n

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return self.project(0.5 * (_points(p) + _points(q)))

    def __repr__(self) -> str:
        return f"ProjectedCurve({getattr(self._project, '__name__', 'project')})"


#: a user normal (:class:`ProjectedCurve`) whose length differs from 1 by more than this is
#: refused: a normal computed in floating point is a unit vector to about 1e-16
UNIT_TOL = 1e-8

#: Candidate (point, piece) pairs examined at once by :meth:`QuadraticBoundary.project`
#: when it compares a point with every piece.
CHUNK = 1 << 21

#: Parameters of each piece's sample points, and how many of the nearest samples a point
#: looks at before it falls back to comparing with every piece.
SAMPLES = np.linspace(0.0, 1.0, 5)
NEAREST_SAMPLES = 24

#: Newton steps on a piece's parameter (quadratic convergence from the chord projection).
NEWTON_STEPS = 8


class QuadraticBoundary(Curve):
    """A piecewise-quadratic curve: the quadratic edges of a second-order mesh's boundary part.

    Piece ``k`` with ``edges[k] = [a, b, m]`` (start, end, midpoint) is the P2 edge trace
    ``X(t) = a (1 - t)(1 - 2t) + b t (2t - 1) + 4 m t (1 - t)``, ``0 <= t <= 1``, the quadratic
    through ``a``, ``m``, ``b`` at ``t = 0, 1/2, 1`` (what Gmsh's ``line3`` elements mean).

    - :meth:`project`: the nearest point on the pieces. Each piece has five sample points
      (``t = 0, 1/4, …, 1``), any point of the piece lying within ``s = max |X'| / 8`` of
      one of them; with ``u`` the distance to the nearest sample (a k-d tree), every piece
      holding a point within ``u`` has a sample within ``u + s``: these are the candidates.
      A point with more than :data:`NEAREST_SAMPLES` samples in that radius (far from the
      curve) takes as candidates the pieces whose bounding box (of ``a``, ``b`` and the
      Bézier control point ``2m - (a + b)/2``, which hold the piece) is within ``u``. On
      each candidate, Newton's method on ``|X(t) - x|²`` from the chord projection and from
      both ends, ``t`` clamped to ``[0, 1]``; the nearest result wins.
    - :meth:`halfway` of ``p`` and ``q`` on one piece at parameters ``s`` and ``t``: the point
      ``X((s + t)/2)``. For the piece's own ends this is exactly its midpoint ``m``, so the P2
      midpoint nodes of the initial edges are the given ones; and the sub-arc between
      ``s`` and ``t`` *is* the quadratic through ``X(s)``, ``X((s + t)/2)``, ``X(t)``, so the
      isoparametric boundary of every refined mesh is the same piecewise quadratic. Points on
      different pieces (no edge of a refined mesh joins such points) get the projection of
      the chord midpoint.
    - :meth:`normal`: ``X'(t)`` turned clockwise, at the projected point. Each piece's tangent
      runs from ``a`` to ``b``; ``read_mesh`` lists the pieces counter-clockwise around the
      domain, so the normal points out of it. Where one piece ends and the next begins
      (``b`` of one is ``a`` of the other) the pieces meet at a small angle, O(H³) for a
      smooth curve sampled at spacing H; there the normal is the normalised mean of the
      two pieces' normals (for pieces through points of a circle at equal spacing, the
      circle's normal).

    Parameters
    ----------
    edges : (k, 3, 2) float array
        ``[a, b, m]`` of each piece.

    Raises
    ------
    MeshError
        If ``edges`` is not a finite ``(k, 3, 2)`` array with ``k >= 1``, a piece has
        ``a = b``, or a piece folds back on itself: ``X'(t)`` turns against the chord
        ``b - a`` somewhere in ``[0, 1]``, i.e. ``m`` projects onto the chord outside its
        middle half.
    """

    def __init__(self, edges: object) -> None:
        try:
            e = np.array(edges, dtype=np.float64)
        except (TypeError, ValueError):
            e = np.full((0,), np.nan)
        if e.ndim != 3 or e.shape[1:] != (3, 2) or not e.shape[0] or not np.isfinite(e).all():
            raise MeshError(
                "QuadraticBoundary: edges must be a finite (k, 3, 2) array of [start, end, "
                f"midpoint] points with k >= 1, got shape {np.shape(edges)}"
            )
        a, b, m = e[:, 0], e[:, 1], e[:, 2]
        chord = b - a
        length2 = (chord * chord).sum(1)
        if np.any(length2 == 0.0):
            k = int(np.flatnonzero(length2 == 0.0)[0])
            raise MeshError(f"QuadraticBoundary: piece {k} starts and ends at {a[k].tolist()}")
        along = ((m - a) * chord).sum(1) / length2  # X'(0).chord > 0 and X'(1).chord > 0
        bad = np.flatnonzero(~((along > 0.25) & (along < 0.75)))
        if bad.size:
            k = int(bad[0])
            raise MeshError(
                f"QuadraticBoundary: piece {k} from {a[k].tolist()} to {b[k].tolist()} folds "
                f"back on itself: its midpoint {m[k].tolist()} projects onto the chord at "
                f"{along[k]:.3g} of its length, outside (0.25, 0.75) ({bad.size} such pieces)"
            )
        e.flags.writeable = False
        self.edges = e
        self._B = 4.0 * m - 3.0 * a - b  # X(t) = a + B t + C t², the power form
        self._C = 2.0 * (a + b - 2.0 * m)
        control = 2.0 * m - 0.5 * (a + b)
        self._lo = np.minimum(np.minimum(a, b), control)
        self._hi = np.maximum(np.maximum(a, b), control)
        speed = np.maximum(np.hypot(*self._B.T), np.hypot(*(self._B + 2 * self._C).T))
        self._reach = speed * (0.5 * (SAMPLES[1] - SAMPLES[0]))  # |X'| is largest at an end
        k = np.arange(len(e))
        samples = self._at(np.repeat(k, SAMPLES.size), np.tile(SAMPLES, len(e)))
        self._sample_piece = np.repeat(k, SAMPLES.size)
        self._tree = cKDTree(samples)
        # the piece that ends where each piece starts, and the one that starts where it ends
        _, ends = np.unique(np.vstack([a, b]), axis=0, return_inverse=True)
        ends = ends.reshape(2, -1)
        owner = np.full(ends.max() + 1, -1)
        owner[ends[1]] = k
        self._previous = owner[ends[0]]
        owner[:] = -1
        owner[ends[0]] = k
        self._next = owner[ends[1]]

    def _at(self, piece: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``X(t)`` in the Lagrange form, so that ``t = 1/2`` gives ``m`` exactly."""
        a, b, m = (self.edges[piece, j] for j in range(3))
        t = t[:, None]
        return a * ((1 - t) * (1 - 2 * t)) + b * (t * (2 * t - 1)) + m * (4 * t * (1 - t))

    def _nearest_on(self, x: np.ndarray, piece: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Parameters ``t (n,)`` of the nearest points of the pieces ``piece (n,)`` to the
        points ``x (n, 2)`` and the squared distances ``(n,)``."""
        a, b = self.edges[piece, 0], self.edges[piece, 1]
        B, C = self._B[piece], self._C[piece]
        d = b - a
        start = np.clip(((x - a) * d).sum(1) / (d * d).sum(1), 0.0, 1.0)
        best_t, best_d2 = None, None
        for t in (start, np.zeros(len(x)), np.ones(len(x))):  # three starts, not a point loop
            for _ in range(NEWTON_STEPS):
                r = a + t[:, None] * (B + t[:, None] * C) - x
                dX = B + 2.0 * t[:, None] * C
                g = (r * dX).sum(1)
                speed2 = (dX * dX).sum(1)
                H = speed2 + 2.0 * (r * C).sum(1)
                t = np.clip(t - g / np.where(H > 0.0, H, speed2), 0.0, 1.0)
            t = np.where((x == a).all(1), 0.0, np.where((x == b).all(1), 1.0, t))
            d2 = ((self._at(piece, t) - x) ** 2).sum(1)
            if best_t is None:
                best_t, best_d2 = t, d2
            else:
                closer = d2 < best_d2
                best_t, best_d2 = np.where(closer, t, best_t), np.minimum(d2, best_d2)
        return best_t, best_d2

    def _locate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The piece ``(n,)`` and parameter ``(n,)`` of the nearest point to each point."""
        x = _points(x)
        if not len(x):
            return np.zeros(0, dtype=np.int64), np.zeros(0)
        k = min(NEAREST_SAMPLES, len(self._sample_piece))
        dist, sample = self._tree.query(x, k=k)
        dist, sample = dist.reshape(len(x), k), sample.reshape(len(x), k)
        u = dist[:, :1]
        crowded = (dist[:, -1:] <= u + self._reach.max()).ravel() & (k < len(self._sample_piece))
        piece = self._sample_piece[sample]
        i, c = np.nonzero((dist <= u + self._reach[piece]) & ~crowded[:, None])
        pairs = [np.unique(i * len(self.edges) + piece[i, c])]
        far = np.flatnonzero(crowded)
        step = max(1, CHUNK // len(self.edges))
        for s in range(0, far.size, step):  # chunks bound the (points, pieces) arrays' memory
            y = x[far[s : s + step]]
            gap = np.maximum(np.maximum(self._lo[None] - y[:, None], y[:, None] - self._hi), 0.0)
            lower = np.hypot(gap[..., 0], gap[..., 1])  # (n, k) distance to each box
            fi, fj = np.nonzero(lower <= dist[far[s : s + step], :1] * (1 + 1e-12))
            pairs.append(far[s : s + step][fi] * len(self.edges) + fj)
        key = np.sort(np.concatenate(pairs))  # sorted by point, every point present
        i, j = np.divmod(key, len(self.edges))
        t, d2 = self._nearest_on(x[i], j)
        order = np.lexsort((d2, i))  # per point, the nearest candidate first
        first = order[np.r_[True, i[order][1:] != i[order][:-1]]]
        return j[first], t[first]

    def project(self, x: np.ndarray) -> np.ndarray:
        piece, t = self._locate(x)
        return self._at(piece, t)

    def _piece_normal(self, piece: np.ndarray, t: np.ndarray) -> np.ndarray:
        dX = self._B[piece] + 2.0 * t[:, None] * self._C[piece]
        return spanned_normals(dX[:, None, :])[1]

    def normal(self, x: np.ndarray) -> np.ndarray:
        piece, t = self._locate(x)
        n = self._piece_normal(piece, t)
        for end, neighbour, other_end in ((0.0, self._previous, 1.0), (1.0, self._next, 0.0)):
            joint = np.flatnonzero((t == end) & (neighbour[piece] >= 0))
            mean = n[joint] + self._piece_normal(
                neighbour[piece[joint]], np.full(joint.size, other_end)
            )
            length = np.hypot(mean[:, 0], mean[:, 1])
            keep = length > 1e-8  # a cusp: the piece's own normal
            n[joint[keep]] = mean[keep] / length[keep, None]
        return n

    def _move_onto(
        self, x: np.ndarray, piece: np.ndarray, t: np.ndarray, target: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Pieces and parameters of the points ``x (n, 2)``, moved to the pieces ``target``
        where the points lie on them too (within 1e-10 of the piece's chord length)."""
        other = np.flatnonzero(piece != target)
        t_target, d2 = self._nearest_on(x[other], target[other])
        e = self.edges[target[other]]
        on = d2 <= 1e-20 * ((e[:, 1] - e[:, 0]) ** 2).sum(1)
        piece, t = piece.copy(), t.copy()
        piece[other[on]], t[other[on]] = target[other[on]], t_target[on]
        return piece, t

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        p, q = _points(p), _points(q)
        ip, s = self._locate(p)
        iq, t = self._locate(q)
        ip, s = self._move_onto(p, ip, s, iq)  # a vertex where two pieces meet is located
        iq, t = self._move_onto(q, iq, t, ip)  # on either: try the other point's piece
        out = self._at(ip, 0.5 * (s + t))
        other = ip != iq
        if other.any():
            out[other] = self.project(0.5 * (p[other] + q[other]))
        return out

    def __repr__(self) -> str:
        return f"QuadraticBoundary({len(self.edges)} pieces)"
