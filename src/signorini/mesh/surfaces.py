"""Boundary surfaces: the exact geometry a boundary part of a tetrahedral mesh may carry,
the 3D analogue of :mod:`signorini.mesh.curves`.

A surface answers, vectorized over points ``x`` of shape ``(n, 3)``:

- :meth:`~Surface.project`: the nearest point of the surface to each point;
- :meth:`~Surface.normal`: the unit normal at points on it (away from the centre or axis);
- :meth:`~Surface.halfway`: the point halfway along the surface between two points on it
  (the midpoint of the geodesic), where refinement puts the new vertex of a bisected edge of
  the part and where the P2 space puts the edge's midpoint node
  (:attr:`signorini.mesh.Mesh.curved_midpoints`).

For the sphere and the cylinder the geodesic midpoint is the projection of the chord
midpoint (the great circle's and the helix's symmetry), so :meth:`Surface.halfway` is
``project((p + q) / 2)`` for both. The edges of a part carrying a surface are the edges of
its faces (:func:`signorini.mesh.tetrahedra.facet_edges`); an edge on the rim of the part
(shared with a plane part) moves onto the surface too, and for the builders' planes through
the centre or along the axis it stays in its plane.

A part carries a surface through :meth:`signorini.mesh.Mesh.with_curve`.
"""

from __future__ import annotations

import numpy as np

from .validation import MeshError

__all__ = ["Cylinder", "Sphere", "Surface"]


def _points(x: np.ndarray) -> np.ndarray:
    return np.asarray(x, dtype=np.float64).reshape(-1, 3)


def _triple(value: object, what: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        a = np.full(4, np.nan)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise MeshError(f"{what} must be three finite numbers (x, y, z), got {value!r}")
    return a


def _radius(value: object, what: str) -> float:
    try:
        r = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        r = np.nan
    if not np.isfinite(r) or r <= 0:
        raise MeshError(f"{what}: radius must be a positive number, got {value!r}")
    return r


def _unit(v: np.ndarray) -> np.ndarray:
    """``v (n, 3)`` over its norms; a zero vector (the centre, a point of the axis: no
    nearest point) goes to ``(1, 0, 0)``."""
    norm = np.sqrt(np.einsum("ij,ij->i", v, v))
    out = np.zeros_like(v)
    out[:, 0] = 1.0
    ok = norm > 0
    out[ok] = v[ok] / norm[ok, None]
    return out


class Surface:
    """A boundary surface. Subclasses define :meth:`project` and :meth:`normal`."""

    #: whether :meth:`normal` is available
    has_normal = True

    def project(self, x: np.ndarray) -> np.ndarray:
        """``(n, 3)`` nearest points of the surface to the points ``x (n, 3)``."""
        raise NotImplementedError

    def normal(self, x: np.ndarray) -> np.ndarray:
        """``(n, 3)`` unit normals at the points ``x (n, 3)`` of the surface."""
        raise NotImplementedError

    def halfway(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """``(n, 3)`` the geodesic midpoints between the points ``p`` and ``q`` ``(n, 3)`` of
        the surface: the projection of the chord midpoint (module docstring)."""
        return self.project(0.5 * (_points(p) + _points(q)))


class Sphere(Surface):
    """The sphere of centre ``center`` and radius ``radius``; the normal points away from
    the centre (outward for a ball). Points are placed as ``center + radius · unit``, on the
    sphere to round-off."""

    def __init__(self, center: object, radius: object) -> None:
        self.center = _triple(center, "Sphere: center")
        self.radius = _radius(radius, "Sphere")

    def normal(self, x: np.ndarray) -> np.ndarray:
        return _unit(_points(x) - self.center)

    def project(self, x: np.ndarray) -> np.ndarray:
        return self.center + self.radius * self.normal(x)

    def __repr__(self) -> str:
        return f"Sphere({self.center.tolist()}, {self.radius})"


class Cylinder(Surface):
    """The circular cylinder of radius ``radius`` around the line through ``point`` along
    ``axis`` (infinite); the normal points away from the axis."""

    def __init__(self, point: object, axis: object, radius: object) -> None:
        self.point = _triple(point, "Cylinder: point")
        a = _triple(axis, "Cylinder: axis")
        if not np.any(a):
            raise MeshError("Cylinder: axis must not be the zero vector")
        self.axis = a / np.sqrt(a @ a)
        self.radius = _radius(radius, "Cylinder")

    def _split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each point's foot on the axis and its offset from it, both ``(n, 3)``."""
        d = _points(x) - self.point
        foot = self.point + (d @ self.axis)[:, None] * self.axis
        return foot, _points(x) - foot

    def normal(self, x: np.ndarray) -> np.ndarray:
        return _unit(self._split(x)[1])

    def project(self, x: np.ndarray) -> np.ndarray:
        foot, off = self._split(x)
        return foot + self.radius * _unit(off)

    def __repr__(self) -> str:
        return f"Cylinder({self.point.tolist()}, {self.axis.tolist()}, {self.radius})"
