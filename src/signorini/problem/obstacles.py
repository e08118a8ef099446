"""Rigid obstacles given as shapes: the gap and the constraint direction at boundary points.

Every obstacle answers :meth:`Obstacle.gap_and_direction` for points ``x (n, 2)``: with ``q``
the point of the obstacle closest to ``z``, ``n_z`` is the obstacle's unit normal at ``q``
pointing *into* the obstacle and ``psi(z)`` the signed distance from ``z`` to the obstacle
(positive outside, negative when ``z`` penetrates), so that ``q = z + psi(z) n_z`` in both
cases. The constraint ``u(z).n_z <= psi(z)`` is the linearisation of the exact
non-penetration condition at ``q``, exact for a flat obstacle (docs/method.md, *Obstacles as
shapes*).

Where the closest point is not unique (a point on the bisector of a sharp inner corner, in the
middle of a slot), every piece of the boundary whose distance is within ``1e-12`` times the
obstacle's scale of the smallest one is a candidate; ``n_z`` is the normalised mean of the
candidates' directions, ``psi`` is unchanged, and when that mean vanishes (opposite
candidates) ``n_z`` is the first candidate's direction in the order of the pieces.

The obstacles are immutable and check their arguments when built; :meth:`gap_and_direction`
checks ``x``. The work is vectorized over points; :class:`Polyline` loops over its pieces
(segments and corner arcs), each iteration a NumPy operation on all points or a subset.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Disc", "HalfPlane", "Obstacle", "Polyline", "SignedDistance"]

#: candidates whose distance is within TIE * scale of the smallest are all closest
TIE = 1e-12


def _finite_array(value, owner: str, name: str) -> np.ndarray:
    """``value`` as a finite float64 array (a copy)."""
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{owner}: {name} must be numeric, got {value!r}") from err
    if not np.isfinite(array).all():
        raise ValueError(f"{owner}: {name} has non-finite entries")
    return array


def _point(value, owner: str, name: str) -> np.ndarray:
    array = _finite_array(value, owner, name)
    if array.shape != (2,):
        raise ValueError(f"{owner}: {name} must have shape (2,), got {array.shape}")
    return array


def _positive(value, owner: str, name: str, allow_zero: bool = False) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError) as err:
        raise ValueError(f"{owner}: {name} must be a number, got {value!r}") from err
    if not np.isfinite(number) or number < 0 or (number == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{owner}: {name} must be finite and {bound}, got {value!r}")
    return number


def _unit(vectors: np.ndarray) -> np.ndarray:
    return vectors / np.hypot(vectors[..., 0], vectors[..., 1])[..., None]


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class Obstacle:
    """A rigid obstacle; subclasses implement :meth:`_gap_and_direction` on checked points."""

    def gap_and_direction(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance and constraint direction at the points ``x``.

        Parameters
        ----------
        x : (n, 2) float array
            Points, e.g. the body's boundary nodes.

        Returns
        -------
        psi : (n,) float array
            Signed distance from each point to the obstacle: positive outside, negative inside.
        n : (n, 2) float array
            Unit normal of the obstacle at the closest point, pointing into the obstacle;
            ``x + psi[:, None] * n`` is that closest point.
        """
        try:
            points = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{self!r}: x must be a numeric (n, 2) array") from err
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(f"{self!r}: x must have shape (n, 2), got {points.shape}")
        if not np.isfinite(points).all():
            k = int(np.flatnonzero(~np.isfinite(points).all(axis=1))[0])
            raise ValueError(f"{self!r}: x[{k}] is not finite: {points[k]}")
        return self._gap_and_direction(points)

    def _gap_and_direction(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


class HalfPlane(Obstacle):
    """The half-plane ``{y : (y - point) . normal <= 0}``.

    Parameters
    ----------
    point : (2,) float array
        A point of the boundary line.
    normal : (2,) float array
        Outward normal of the obstacle (pointing away from it, towards the body); normalised.
        The constraint direction is ``-normal`` and ``psi(z) = (z - point) . normal``.
    """

    def __init__(self, point, normal):
        self.point = _point(point, "HalfPlane", "point")
        normal = _point(normal, "HalfPlane", "normal")
        length = np.hypot(*normal)
        if length == 0:
            raise ValueError("HalfPlane: normal must be a non-zero vector, got (0, 0)")
        self.normal = normal / length
        self.point.flags.writeable = False
        self.normal.flags.writeable = False

    def __repr__(self) -> str:
        return f"HalfPlane(point={self.point.tolist()}, normal={self.normal.tolist()})"

    def _gap_and_direction(self, x):
        psi = (x - self.point) @ self.normal
        return psi, np.broadcast_to(-self.normal, x.shape).copy()


class Disc(Obstacle):
    """The disc ``{y : |y - center| <= radius}`` (a cylinder in plane strain).

    ``psi(z) = |z - center| - radius`` and ``n_z = (center - z) / |center - z|`` for points
    inside and outside alike. At the centre itself every boundary point is closest and no
    direction exists: points closer than ``1e-12 * radius`` to the centre are an error.

    Parameters
    ----------
    center : (2,) float array
    radius : float, > 0
    """

    def __init__(self, center, radius):
        self.center = _point(center, "Disc", "center")
        self.radius = _positive(radius, "Disc", "radius")
        self.center.flags.writeable = False

    def __repr__(self) -> str:
        return f"Disc(center={self.center.tolist()}, radius={self.radius!r})"

    def _gap_and_direction(self, x):
        to_center = self.center - x
        distance = np.hypot(to_center[:, 0], to_center[:, 1])
        at_center = distance <= TIE * self.radius
        if at_center.any():
            k = int(np.flatnonzero(at_center)[0])
            raise ValueError(
                f"{self!r}: x[{k}] = {x[k].tolist()} lies at the centre, where no direction "
                "to the closest point exists"
            )
        return distance - self.radius, to_center / distance[:, None]


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
        Corners in order; all distinct, no turn back on the same line. That the polyline does
        not cross itself is not checked.
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
        points = _finite_array(points, "Polyline", "points")
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(f"Polyline: points must have shape (m, 2), got {points.shape}")
        if points.shape[0] < 2:
            raise ValueError(f"Polyline: points needs at least 2 points, got {points.shape[0]}")
        radius = _positive(radius, "Polyline", "radius", allow_zero=True)
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
        tangent = edge / length[:, None]
        turn = _cross(tangent[:-1], tangent[1:])
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
        vertex_normal = _unit(inward[:-1] + inward[1:])
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
        in_sector = (_cross(first[j], radial) >= 0) & (_cross(radial, last[j]) >= 0)
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


def _direction(offset, distance, sign, normal):
    """Unit direction into the obstacle: ``sign * offset / distance``; ``normal`` on it."""
    on = distance <= 0
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = sign[:, None] * offset / distance[:, None]
    return np.where(on[:, None], normal, direction)


class SignedDistance(Obstacle):
    """An obstacle given by a signed-distance function ``phi`` (negative inside).

    ``psi(z) = phi(z)`` and ``n_z = -grad phi(z) / |grad phi(z)|``. The gradient is ``grad(x)``
    when given, otherwise central differences with the step ``h = eps**(1/3) * scale``
    (about ``6e-6 * scale``), which balances truncation and round-off; their error is
    ``O(h**2)`` where ``phi`` is smooth, and at kinks of ``phi`` (the bisector of a corner)
    the difference quotient averages the one-sided gradients.

    A distance is 1-Lipschitz, so each of its two difference quotients is at most 1 and their
    vector at most ``sqrt(2)`` long (1 where ``phi`` is smooth; more only at a kink, where the
    two quotients may come from different branches). Longer quotients (e.g. from
    ``|x|**2 - R**2`` instead of ``|x| - R`` away from the origin) show that ``phi`` is not a
    distance, so ``psi`` would be a wrong gap: the points are refused. A flatter ``phi`` (a
    distance divided by a constant) is not detected.

    Parameters
    ----------
    phi : callable
        ``phi(x)`` for ``x (n, 2)`` returns ``(n,)`` finite values: the signed distance.
    grad : callable, optional
        ``grad(x)`` for ``x (n, 2)`` returns ``(n, 2)`` finite values, non-zero.
    scale : float, > 0
        A length typical of the obstacle (its size), setting the difference step.
    """

    def __init__(self, phi, grad=None, scale=1.0):
        if not callable(phi):
            raise ValueError(f"SignedDistance: phi must be callable, got {phi!r}")
        if grad is not None and not callable(grad):
            raise ValueError(f"SignedDistance: grad must be callable or None, got {grad!r}")
        self.phi = phi
        self.grad = grad
        self.scale = _positive(scale, "SignedDistance", "scale")
        self.step = np.finfo(np.float64).eps ** (1 / 3) * self.scale

    def __repr__(self) -> str:
        name = getattr(self.phi, "__name__", repr(self.phi))
        return f"SignedDistance(phi={name}, scale={self.scale!r})"

    def _call(self, function, name: str, x: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
        try:
            value = np.asarray(function(x), dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{self!r}: {name}(x) did not return numbers: {err}") from err
        if value.shape != shape:
            raise ValueError(
                f"{self!r}: {name}(x) must return shape {shape} for x of shape {x.shape}, "
                f"got {value.shape}"
            )
        bad = ~np.isfinite(value.reshape(shape[0], -1)).all(axis=1)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{self!r}: {name}(x) is not finite at x[{k}] = {x[k].tolist()}")
        return value

    def _gap_and_direction(self, x):
        n_points = x.shape[0]
        psi = self._call(self.phi, "phi", x, (n_points,))
        if self.grad is not None:
            gradient = self._call(self.grad, "grad", x, (n_points, 2))
        else:
            h = self.step
            shifts = np.array([[h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]])
            stacked = (x[None, :, :] + shifts[:, None, :]).reshape(-1, 2)
            values = self._call(self.phi, "phi", stacked, (4 * n_points,)).reshape(4, n_points)
            gradient = np.stack([values[0] - values[1], values[2] - values[3]], axis=1) / (2 * h)
        length = np.hypot(gradient[:, 0], gradient[:, 1])
        flat = length <= 1e-12
        if flat.any():
            k = int(np.flatnonzero(flat)[0])
            raise ValueError(
                f"{self!r}: the gradient of phi vanishes at x[{k}] = {x[k].tolist()}, so no "
                "direction to the obstacle exists there"
            )
        if self.grad is None and (length > np.sqrt(2) * (1 + 1e-6)).any():
            k = int(np.argmax(length))
            raise ValueError(
                f"{self!r}: phi is not a signed distance: its difference quotients have "
                f"length {length[k]:.6g} > sqrt(2) at x[{k}] = {x[k].tolist()}"
            )
        return psi, -gradient / length[:, None]
