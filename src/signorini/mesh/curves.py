"""Boundary curves: the exact geometry a boundary part may carry.

A curve answers three questions, vectorized over points ``x`` of shape ``(n, 2)``:

- :meth:`~Curve.project`: the nearest point of the curve to each point;
- :meth:`~Curve.normal` (and :meth:`~Curve.tangent`): the unit normal and tangent of the curve
  at points on it;
- :meth:`~Curve.halfway`: the point halfway along the curve between two points on it, where
  refinement puts the new vertex of a bisected boundary edge and where the P2 space puts the
  edge's midpoint node.

A part carries a curve through :meth:`signorini.mesh.Mesh.with_curve`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .validation import MeshError

__all__ = ["Circle", "Curve", "Line", "ProjectedCurve"]


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
        Unit normals at points of the curve; without it :meth:`normal` raises.

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
        if self._normal is None:
            raise MeshError("ProjectedCurve: no normal function was given")
        return self._call("normal", self._normal, x)

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return self.project(0.5 * (_points(p) + _points(q)))

    def __repr__(self) -> str:
        return f"ProjectedCurve({getattr(self._project, '__name__', 'project')})"
