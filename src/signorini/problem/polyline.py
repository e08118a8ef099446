"""A rigid obstacle bounded by a polyline, its convex corners optionally rounded
(:class:`Polyline`; the protocol is :class:`~signorini.problem.obstacle_base.Obstacle`).

Where the closest point is not unique (a point on the bisector of a sharp inner corner, in the
middle of a slot), every piece of the boundary whose distance is within ``TIE`` times the
obstacle's scale of the smallest one is a candidate (docs/method.md, *Obstacles as shapes*).
"""

from __future__ import annotations

import numpy as np

from .obstacle_base import TIE, Obstacle, checked_positive, cross, finite_array, unit_vectors

__all__ = ["Polyline"]


class Polyline(Obstacle):
    """The region on the left of a polyline walked from its first point to its last.

    The first segment is extended backwards and the last one forwards to rays, so the polyline
    splits the plane in two; the obstacle is the part on the left (walking a closed obstacle's
    outline counter-clockwise keeps it on the left). A flat punch pressed down is therefore
    given from its upper left to its upper right corner, down one side, along the bottom and up
    the other side; a groove in a foundation below the body from right to left.

    With ``radius > 0`` every convex corner of the obstacle (where the polyline turns left) is
    replaced by a circular arc of that radius tangent to both segments; the tangent points lie
    ``radius / tan(alpha / 2)`` from the corner, ``alpha`` the obstacle's interior angle there.
    Inner (reflex) corners stay sharp; a point on the bisector of one has two closest points
    and gets the module's tie rule (the normalised mean of both directions).

    Parameters
    ----------
    points : (m, 2) float array, m >= 2
        Corners in order; all distinct, no turn back on the same line, and the polyline
        (its end segments extended to rays) does not cross or touch itself.
    radius : float, >= 0
        Radius of the rounded convex corners.

    Notes
    -----
    :meth:`gap_and_direction` loops over the pieces (segments, then arcs): once over all points
    for the distances, then each piece computes sign and direction on the points it is nearest
    to, and once more only for the points with a tie. Each iteration is a NumPy operation on
    all (or the selected) points.
    """

    def __init__(self, points, radius=0.0):
        points = finite_array(points, "Polyline", "points")
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(f"Polyline: points must have shape (m, 2), got {points.shape}")
        if points.shape[0] < 2:
            raise ValueError(f"Polyline: points needs at least 2 points, got {points.shape[0]}")
        radius = checked_positive(radius, "Polyline", "radius", allow_zero=True)
        self.points = points
        self.radius = radius
        edge = np.diff(points, axis=0)
        length = np.hypot(edge[:, 0], edge[:, 1])
        self.scale = float(np.hypot(*np.ptp(points, axis=0)))
        _, first_seen, inverse = np.unique(points, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        repeated = np.flatnonzero(first_seen[inverse] != np.arange(points.shape[0]))
        if repeated.size:
            j = int(repeated[0])
            i = int(first_seen[inverse[j]])
            raise ValueError(
                f"Polyline: points[{i}] and points[{j}] are the same point {points[j].tolist()}"
            )
        _check_no_crossing(points)
        tangent = edge / length[:, None]
        turn = cross(tangent[:-1], tangent[1:])
        along = np.einsum("ij,ij->i", tangent[:-1], tangent[1:])
        back = (np.abs(turn) <= 1e-12) & (along < 0)
        if back.any():
            k = int(np.flatnonzero(back)[0]) + 1
            raise ValueError(
                f"Polyline: the polyline turns back on itself at points[{k}] = {points[k].tolist()}"
            )
        # inward (left) normals of the segments
        inward = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
        convex = (turn > 1e-12) & (radius > 0)
        # tangent points: distance radius / tan(alpha / 2) = radius * tan(theta / 2) from the
        # corner, theta = pi - alpha the turning angle
        theta = np.arctan2(turn, along)
        cut = np.where(convex, radius * np.tan(np.abs(theta) / 2), 0.0)
        cut_start = np.concatenate([[0.0], cut])
        cut_end = np.concatenate([cut, [0.0]])
        too_long = cut_start + cut_end > length * (1 + 1e-12)
        if too_long.any():
            k = int(np.flatnonzero(too_long)[0])
            raise ValueError(
                f"Polyline: radius {radius!r} is too large: the rounded corners need "
                f"{cut_start[k] + cut_end[k]:.6g} of the segment from points[{k}] to "
                f"points[{k + 1}], which is {length[k]:.6g} long"
            )
        start = points[:-1] + cut_start[:, None] * tangent
        end = points[1:] - cut_end[:, None] * tangent
        # pseudo-normals at the segment ends: the bisector of the two inward normals at a sharp
        # vertex (its sign test tells inside from outside), the segment's own at a tangent point
        vertex_normal = unit_vectors(inward[:-1] + inward[1:])
        start_normal = inward.copy()
        end_normal = inward.copy()
        sharp = ~convex
        start_normal[1:][sharp] = vertex_normal[sharp]
        end_normal[:-1][sharp] = vertex_normal[sharp]
        self._segments = (start, end, tangent, inward, start_normal, end_normal)
        # a sharp vertex is the closest point of two segments; count it once, as an end
        self._shared_start = np.concatenate([[False], sharp])
        corner = np.flatnonzero(convex)
        # arcs: centre inside the obstacle at distance radius from both lines
        self._arcs = (
            end[corner] + radius * inward[corner],
            -inward[corner],
            -inward[corner + 1],
        )
        # the arc (or -1) whose first point is a segment's end / whose last is its start
        self._arc_at_end = np.full(start.shape[0], -1)
        self._arc_at_end[corner] = np.arange(corner.size)
        self._arc_at_start = np.full(start.shape[0], -1)
        self._arc_at_start[corner + 1] = np.arange(corner.size)
        self.points.flags.writeable = False

    def __repr__(self) -> str:
        return f"Polyline(points={self.points.tolist()}, radius={self.radius!r})"

    @property
    def n_pieces(self) -> int:
        """Number of pieces of the boundary: the segments, then the corner arcs."""
        return self._segments[0].shape[0] + self._arcs[0].shape[0]

    def _piece(self, k: int, x: np.ndarray, full: bool):
        """Distance from ``x`` to piece ``k``; with ``full`` also ``(sign, direction)``.

        Every boundary point is counted once: a segment whose foot is its start at a sharp
        vertex reports ``inf`` (the vertex is the previous segment's end), and so does a
        segment whose foot is a tangent point where the corner arc claims the point.
        """
        start, end, tangent, inward, start_normal, end_normal = self._segments
        n_segments = start.shape[0]
        if k < n_segments:
            t = (x - start[k]) @ tangent[k]
            lower = -np.inf if k == 0 else 0.0
            upper = np.inf if k == n_segments - 1 else float(np.hypot(*(end[k] - start[k])))
            foot = start[k] + np.clip(t, lower, upper)[:, None] * tangent[k]
            offset = foot - x
            distance = np.hypot(offset[:, 0], offset[:, 1])
            if self._shared_start[k]:
                distance[t <= lower] = np.inf
            for arc, beyond in (
                (self._arc_at_start[k], t <= lower),
                (self._arc_at_end[k], t >= upper),
            ):
                if arc >= 0:
                    candidates = np.flatnonzero(beyond)
                    claimed = self._arc_claims(arc, x[candidates])[0]
                    distance[candidates[claimed]] = np.inf
            if not full:
                return distance
            # inside where the offset from the foot points along the (pseudo-)normal there
            normal = np.where(
                (t <= lower)[:, None],
                start_normal[k],
                np.where((t >= upper)[:, None], end_normal[k], inward[k]),
            )
            sign = np.where(np.einsum("ij,ij->i", offset, normal) < 0, -1.0, 1.0)
            # from the interior of a segment the direction is its inward normal, exactly
            direction = _direction(offset, distance, sign, normal)
            interior = (t > lower) & (t < upper)
            return distance, (sign, np.where(interior[:, None], inward[k], direction))
        in_sector, radial, r = self._arc_claims(k - n_segments, x)
        distance = np.where(in_sector, np.abs(r - self.radius), np.inf)
        if not full:
            return distance
        sign = np.where(r < self.radius, -1.0, 1.0)
        # into the obstacle is towards the arc's centre, inside and outside alike
        with np.errstate(invalid="ignore", divide="ignore"):
            return distance, (sign, -radial / r[:, None])

    def _arc_claims(self, j: int, x: np.ndarray):
        """Points whose closest point on the circle of arc ``j`` lies on the arc (its ends
        included), the vectors from the centre and their lengths."""
        centers, first, last = self._arcs
        radial = x - centers[j]
        r = np.hypot(radial[:, 0], radial[:, 1])
        in_sector = (cross(first[j], radial) >= 0) & (cross(radial, last[j]) >= 0)
        # the centre sees every arc point: it is left to the segments' tangent points
        return in_sector & (r > TIE * self.radius), radial, r

    def _gap_and_direction(self, x):
        n_points = x.shape[0]
        # pass 1, distances only: the nearest piece (the first of equals) and the runner-up
        best = np.full(n_points, np.inf)
        second = np.full(n_points, np.inf)
        nearest = np.zeros(n_points, dtype=np.int64)
        for k in range(self.n_pieces):
            distance = self._piece(k, x, full=False)
            closer = distance < best
            second = np.where(closer, best, np.minimum(second, distance))
            nearest[closer] = k
            best = np.where(closer, distance, best)
        # pass 2: sign and direction from each point's nearest piece, on its points only
        psi = np.empty(n_points)
        n = np.empty((n_points, 2))
        order = np.argsort(nearest, kind="stable")
        bounds = np.searchsorted(nearest[order], np.arange(self.n_pieces + 1))
        for k in range(self.n_pieces):
            points = order[bounds[k] : bounds[k + 1]]
            if points.size:
                distance, (sign, direction) = self._piece(k, x[points], full=True)
                psi[points] = sign * distance
                n[points] = direction
        # ties: points with a runner-up within the tolerance get the mean direction
        tied = np.flatnonzero(second <= best + TIE * max(self.scale, self.radius))
        if tied.size:
            n[tied] = self._tie_direction(x[tied], best[tied])
        return psi, n

    def _tie_direction(self, x: np.ndarray, best: np.ndarray) -> np.ndarray:
        """The module's tie rule at points with several closest pieces."""
        tolerance = TIE * max(self.scale, self.radius)
        total = np.zeros_like(x)
        first = np.full_like(x, np.nan)
        for k in range(self.n_pieces):
            distance, (_, direction) = self._piece(k, x, full=True)
            candidate = distance <= best + tolerance
            total[candidate] += direction[candidate]
            unset = candidate & np.isnan(first[:, 0])
            first[unset] = direction[unset]
        length = np.hypot(total[:, 0], total[:, 1])
        opposite = length <= 1e-12
        return np.where(opposite[:, None], first, total / np.where(opposite, 1.0, length)[:, None])


#: pairs of segments tested at once by :func:`_check_no_crossing` (memory ~ 20 floats each)
_PAIRS_CHUNK = 1 << 18


def _check_no_crossing(points: np.ndarray) -> None:
    """Refuse a polyline ``points (m, 2)`` that crosses or touches itself: two segments that
    are not neighbours (the first one extended backwards and the last one forwards to rays,
    as the obstacle's boundary is) meet, or are collinear and overlap. A crossing boundary
    has no left side: the obstacle it would bound is not a region.

    The candidates are the pairs whose x-extents overlap (found by sorting) and every pair
    with an end ray; they are tested at once (chunked): segments ``p + t d`` and ``q + s e``
    meet where ``t = (q − p) × e / (d × e)`` and ``s = (q − p) × d / (d × e)`` lie in their
    ranges.
    """
    m = points.shape[0] - 1  # segments
    if m < 3:
        return
    i, j = _candidates(points)
    lo = np.zeros(m)
    hi = np.ones(m)
    lo[0], hi[-1] = -np.inf, np.inf
    d = np.diff(points, axis=0)
    scale = float(np.hypot(*np.ptp(points, axis=0)))
    for start in range(0, i.size, _PAIRS_CHUNK):
        a, b = i[start : start + _PAIRS_CHUNK], j[start : start + _PAIRS_CHUNK]
        offset = points[b] - points[a]
        det = cross(d[a], d[b])
        parallel = np.abs(det) <= TIE * np.hypot(*d[a].T) * np.hypot(*d[b].T)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = cross(offset, d[b]) / det
            u = cross(offset, d[a]) / det
        meet = ~parallel & (t >= lo[a]) & (t <= hi[a]) & (u >= lo[b]) & (u <= hi[b])
        # collinear pieces overlap where their extents along the line overlap
        on_line = parallel & (np.abs(cross(offset, d[a])) <= TIE * scale * np.hypot(*d[a].T))
        along = d[a] / np.hypot(*d[a].T)[:, None]
        t0 = np.einsum("kc,kc->k", offset, along)  # b's start along a, from a's start
        t1 = t0 + np.einsum("kc,kc->k", d[b], along)
        b_lo = np.where(b == m - 1, np.where(t1 > t0, t0, -np.inf), np.minimum(t0, t1))
        b_hi = np.where(b == m - 1, np.where(t1 > t0, np.inf, t0), np.maximum(t0, t1))
        a_lo = np.where(a == 0, -np.inf, 0.0)
        a_hi = np.hypot(*d[a].T)
        meet |= on_line & (b_lo <= a_hi) & (a_lo <= b_hi)
        if meet.any():
            k = int(np.flatnonzero(meet)[0])
            p, q = int(a[k]), int(b[k])

            def named(n: int) -> str:
                ray = " (extended to a ray)" if n in (0, m - 1) else ""
                return f"points[{n}]–points[{n + 1}]{ray}"

            raise ValueError(
                f"Polyline: the polyline crosses itself: the segments {named(p)} from "
                f"{points[p].tolist()} to {points[p + 1].tolist()} and {named(q)} from "
                f"{points[q].tolist()} to {points[q + 1].tolist()} meet, so it bounds no "
                "region on its left; walk the obstacle's outline once, without crossings"
            )


def _candidates(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``i < j − 1`` of the segments of ``points (m + 1, 2)`` that may meet: those whose
    x-extents overlap (segment ``j``'s left end within segment ``i``'s extent or the other
    way round, by a sort), and every pair with the first or the last segment (rays)."""
    m = points.shape[0] - 1
    x = np.stack([points[:-1, 0], points[1:, 0]], axis=1)
    lo, hi = x.min(axis=1), x.max(axis=1)
    order = np.argsort(lo, kind="stable")
    start = np.searchsorted(lo[order], lo, "left")
    count = np.searchsorted(lo[order], hi, "right") - start
    first = np.repeat(np.arange(m), count)
    offset = np.arange(first.size) - np.repeat(np.cumsum(count) - count, count)
    second = order[np.repeat(start, count) + offset]
    rays = np.arange(m)
    a = np.concatenate([first, np.zeros(m, np.int64), rays])
    b = np.concatenate([second, rays, np.full(m, m - 1)])
    a, b = np.minimum(a, b), np.maximum(a, b)
    keep = b - a >= 2
    pairs = np.unique(np.stack([a[keep], b[keep]], axis=1), axis=0)
    return pairs[:, 0], pairs[:, 1]


def _direction(offset, distance, sign, normal):
    """Unit direction into the obstacle: ``sign * offset / distance``; ``normal`` on it."""
    on = distance <= 0
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = sign[:, None] * offset / distance[:, None]
    return np.where(on[:, None], normal, direction)
